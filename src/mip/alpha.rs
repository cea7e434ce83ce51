//! Alpha-test coverage preservation (Castaño, "Computing Alpha Mipmaps").
//!
//! Filtering alpha makes alpha-tested foliage thin out or bloat in the
//! distance, because the fraction of texels passing `alpha > ref` changes
//! from level to level. For each level after 0 we find, by bisection, the
//! threshold `t` at which that level has level 0's coverage, then scale the
//! level's alpha by `ref / t`, so that testing against `ref` passes the
//! same fraction as level 0 did. Coverage here is the plain fraction of
//! texels with alpha > ref, so a level of n texels can match level 0's
//! coverage only to within 1/(2n).

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

/// Scale `level`'s alpha so its coverage at `reference` is as close as its
/// texel count allows to `target`.
pub fn preserve_coverage(level: &mut Texture, reference: f32, target: f32) {
    let Some(a) = level.format().alpha_channel() else {
        return;
    };
    let ch = level.channels();
    let mut lin = level.to_linear();
    let alphas: Vec<f32> = lin.chunks_exact(ch).map(|t| t[a]).collect();
    let n = alphas.len() as f32;
    // The achievable coverages are k/n; aim at the nearest one.
    let goal = (target * n).round() / n;
    // Coverage falls as the threshold rises. Bisect on [0, 1].
    let (mut lo, mut hi) = (0f32, 1f32);
    for _ in 0..32 {
        let mid = 0.5 * (lo + hi);
        if coverage_of(alphas.iter().copied(), mid) > goal {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    // `hi` is the lowest threshold found whose coverage is ≤ goal.
    let t = hi.max(1e-6);
    let scale = reference / t;
    for tx in lin.chunks_exact_mut(ch) {
        tx[a] = (tx[a] * scale).clamp(0.0, 1.0);
    }
    let fmt = level.format();
    crate::texel::encode_from_linear(&fmt, &lin, level.texels_mut());
}
