//! Normal maps: the chain of a map whose first three channels are unit
//! vectors.
//!
//! Stored values and vectors are different things: a unorm (u8/u16) map
//! stores a component `n` as the code `(n + 1) / 2`, a float map stores `n`
//! itself (SPEC.md, "Normal maps"). So the chain is built in three steps:
//!
//! 1. [`to_vectors`]: level 0 decoded once to f32 vectors (`2c − 1` for
//!    unorm, as stored for float) and made unit length;
//! 2. every later level filters the previous level's *unnormalised*
//!    averages with the colour filter and its weights (so a box chain of a
//!    power-of-two map averages the unit level-0 normals of each texel's
//!    footprint), in f32; no level is rounded to the storage type on the
//!    way;
//! 3. each level is renormalised and [`encode`]d once, into whatever type
//!    the output has: codes `(n + 1) / 2` for unorm, `n` for float.
//!
//! Channels after the third (alpha, or data) are filtered as they are;
//! the vectors are never weighted by alpha. A zero or non-finite average
//! becomes +Z.

use crate::error::{Error, Result};
use crate::texel::{AlphaMode, ChannelType, ColorSpace, Format, Texels};
use crate::texture::Texture;

use crate::mip::{MipOptions, Progress};

/// Make the first three of every `ch` values a unit vector (+Z for a zero
/// or non-finite one).
pub fn normalize_vectors(v: &mut [f32], ch: usize) {
    for t in v.chunks_exact_mut(ch) {
        let (x, y, z) = (t[0] as f64, t[1] as f64, t[2] as f64);
        let len = (x * x + y * y + z * z).sqrt();
        if len > 1e-12 && len.is_finite() {
            t[0] = (x / len) as f32;
            t[1] = (y / len) as f32;
            t[2] = (z / len) as f32;
        } else {
            t[..3].copy_from_slice(&[0.0, 0.0, 1.0]);
        }
    }
}

/// Level 0 of a normal map as f32 unit vectors (see the module docs). The
/// result has `t`'s channels, linear f32, alpha mode [`AlphaMode::None`] so
/// that filtering never weights the vectors by alpha.
pub fn to_vectors(t: &Texture) -> Result<Texture> {
    let f = t.format();
    check(&f)?;
    let ch = f.channels as usize;
    let mut v = t.to_linear();
    if !f.channel_type.is_float() {
        for px in v.chunks_exact_mut(ch) {
            for c in &mut px[..3] {
                *c = *c * 2.0 - 1.0;
            }
        }
    }
    normalize_vectors(&mut v, ch);
    let vf =
        Format::new(f.channels, ChannelType::F32, ColorSpace::Linear).with_alpha(AlphaMode::None);
    Texture::from_f32(t.width(), t.height(), vf, v)
}

/// Encode a level of unit vectors (f32, from [`build_levels`]) into `out`'s
/// type: `(n + 1) / 2` codes for unorm, the components for float; the
/// channels after the third are encoded as they are.
pub fn encode(vectors: &Texture, out: Format) -> Result<Texture> {
    let Texels::F32(v) = vectors.texels() else {
        return Err(Error::InvalidOption(
            "normal vectors must be f32 (from normal::build_levels)".into(),
        ));
    };
    if out.channels != vectors.format().channels || out.color_space != ColorSpace::Linear {
        return Err(Error::InvalidOption(format!(
            "a normal map level cannot be encoded as {out}"
        )));
    }
    let ch = out.channels as usize;
    let mut v = v.clone();
    if !out.channel_type.is_float() {
        for px in v.chunks_exact_mut(ch) {
            for c in &mut px[..3] {
                *c = *c * 0.5 + 0.5;
            }
        }
    }
    Texture::from_linear(vectors.width(), vectors.height(), out, &v)
}

fn check(f: &Format) -> Result<()> {
    if f.channels < 3 {
        return Err(Error::InvalidOption(
            "a normal map needs at least 3 channels".into(),
        ));
    }
    if f.color_space == ColorSpace::Srgb {
        return Err(Error::InvalidOption(
            "normal maps hold vectors, not colours: load them as linear".into(),
        ));
    }
    Ok(())
}

/// Every level of `base`'s normal chain as f32 unit vectors, level 0 first
/// (see the module docs; `options.normal_map` is implied, the other
/// options apply as for colour; alpha coverage is refused, a fourth channel
/// of a normal map being data).
pub fn build_levels(
    base: &Texture,
    options: &MipOptions,
    progress: &mut dyn FnMut(Progress),
) -> Result<Vec<Texture>> {
    if options.alpha_coverage.is_some() {
        return Err(Error::InvalidOption(
            "alpha coverage does not apply to normal maps (their fourth channel is data)".into(),
        ));
    }
    // NaN/Inf policy first: decoding would turn them into +Z unseen.
    let repaired;
    let base = if base.channel_type().is_float() {
        if options.nan_policy == crate::mip::NanPolicy::Error {
            crate::mip::nan::check(base)?;
            base
        } else {
            let mut b = base.clone();
            crate::mip::nan::apply(&mut b, options.nan_policy)?;
            repaired = b;
            &repaired
        }
    } else {
        base
    };
    let v0 = to_vectors(base)?;
    let plain = MipOptions {
        normal_map: false,
        nan_policy: crate::mip::NanPolicy::Error,
        ..*options
    };
    // The chain of averages, unnormalised; the output is renormalised.
    let averages = crate::mip::build_with_progress(v0, &plain, progress)?;
    let ch = base.channels();
    let mut out = averages.into_levels();
    for l in &mut out {
        if let Texels::F32(v) = l.texels_mut() {
            normalize_vectors(v, ch);
        }
    }
    Ok(out)
}

/// The normal chain of `base` encoded as `out` (same channel count, any
/// type; see [`encode`]). Level 0 is `base` itself, untouched, when `out`
/// is its format.
pub fn build(
    base: Texture,
    options: &MipOptions,
    out: Format,
    progress: &mut dyn FnMut(Progress),
) -> Result<Vec<Texture>> {
    let vectors = build_levels(&base, options, progress)?;
    let mut levels = Vec::with_capacity(vectors.len());
    let keep0 = base.format() == out;
    if keep0 {
        levels.push(base);
    }
    for v in &vectors[usize::from(keep0)..] {
        levels.push(encode(v, out)?);
    }
    Ok(levels)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unorm_codes_decode_as_two_c_minus_one_and_encode_back() {
        // (128, 128, 255) is (≈0, ≈0, 1); (255, 128, 128) is (1, ≈0, ≈0).
        let f = Format::new(3, ChannelType::U8, ColorSpace::Linear);
        let t = Texture::from_u8(2, 1, f, vec![128, 128, 255, 255, 128, 128]).unwrap();
        let v = to_vectors(&t).unwrap();
        let Texels::F32(x) = v.texels() else { panic!() };
        assert!((x[2] - 1.0).abs() < 1e-4 && x[0].abs() < 0.01);
        assert!((x[3] - 1.0).abs() < 1e-4 && x[5].abs() < 0.01);
        assert_eq!(encode(&v, f).unwrap().texels(), t.texels());
    }
}
