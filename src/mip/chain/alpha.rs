//! Alpha-test coverage preservation (Castaño, "Computing Alpha Mipmaps").
//!
//! Filtering alpha makes alpha-tested foliage thin out or bloat in the
//! distance, because the fraction of texels passing `alpha > ref` changes
//! from level to level. For each level after 0 we find, by bisection, the
//! threshold `t` at which that level has level 0's coverage, then scale the
//! level's alpha by `ref / t`, so that testing against `ref` passes the
//! same fraction as level 0 did. Coverage here is the plain fraction of
//! texels with alpha > ref, so a level of n texels can match level 0's
//! coverage only to within 1/(2n); it is measured on the alpha as stored
//! in the output type, so the bound holds after 8- and 16-bit rounding
//! too (unless rounding merges texels the test must separate: then the
//! closest achievable coverage is kept).

use crate::texel::ChannelType;
use crate::texture::Texture;

/// Fraction of texels whose alpha exceeds `reference` (0 if no alpha).
pub fn coverage(tex: &Texture, reference: f32) -> f32 {
    let Some(a) = tex.format().alpha_channel() else {
        return 0.0;
    };
    let lin = tex.to_linear();
    let ch = tex.channels();
    coverage_of(lin.chunks_exact(ch).map(|t| t[a]), reference)
}

fn coverage_of(alphas: impl Iterator<Item = f32>, t: f32) -> f32 {
    let (mut n, mut pass) = (0usize, 0usize);
    for a in alphas {
        n += 1;
        pass += usize::from(a > t);
    }
    if n == 0 { 0.0 } else { pass as f32 / n as f32 }
}

/// `v` as it reads back after being stored as `ty` (rounded to the nearest
/// code for unorm types, to the nearest half for f16).
fn stored(v: f32, ty: ChannelType) -> f32 {
    match ty {
        ChannelType::U8 => crate::texel::unorm8(v) as f32 / 255.0,
        ChannelType::U16 => crate::texel::unorm16(v) as f32 / 65535.0,
        ChannelType::F16 => half::f16::from_f32(v).to_f32(),
        ChannelType::F32 => v,
    }
}

/// Scale `level`'s alpha so its coverage at `reference`, measured on the
/// alpha as it will be stored in `store` (the output's channel type; the
/// level's own when it is written as built), is as close as its texel
/// count allows to `target`. Measuring after the rounding matters: a texel
/// scaled to just below the reference can round up onto the other side of
/// the test (8-bit levels drifted from coverage 0.209 to 0.50).
pub fn preserve_coverage(level: &mut Texture, reference: f32, target: f32, store: ChannelType) {
    let Some(a) = level.format().alpha_channel() else {
        return;
    };
    let ch = level.channels();
    let mut lin = level.to_linear();
    let alphas: Vec<f32> = lin.chunks_exact(ch).map(|t| t[a]).collect();
    let n = alphas.len() as f32;
    // The achievable coverages are k/n; aim at the nearest one.
    let goal = (target * n).round() / n;
    let covered = |scale: f32| {
        coverage_of(
            alphas
                .iter()
                .map(|&x| stored((x * scale).clamp(0.0, 1.0), store)),
            reference,
        )
    };
    // Coverage rises with the scale. Bisect the threshold t = reference /
    // scale on [0, 1] for the smallest scale whose stored coverage reaches
    // the goal, then keep it or the next lower one, whichever is closer.
    let (mut lo, mut hi) = (0f32, 1f32);
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        if covered(reference / mid.max(1e-6)) > goal {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    // `hi`: the lowest threshold found whose coverage is ≤ goal; `lo`: the
    // highest whose coverage is above it.
    let (c_hi, c_lo) = (
        covered(reference / hi.max(1e-6)),
        covered(reference / lo.max(1e-6)),
    );
    let t = if (c_lo - goal).abs() < (c_hi - goal).abs() {
        lo
    } else {
        hi
    };
    let scale = reference / t.max(1e-6);
    for tx in lin.chunks_exact_mut(ch) {
        tx[a] = (tx[a] * scale).clamp(0.0, 1.0);
    }
    let fmt = level.format();
    crate::texel::encode_from_linear(&fmt, &lin, level.texels_mut());
}
