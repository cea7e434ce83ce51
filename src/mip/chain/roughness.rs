//! Roughness from normal variance (SPEC.md "Normal maps and specular
//! roughness"): the mip chain of a normal map together with the roughness
//! (or Blinn-Phong exponent) each level needs so that a distant, averaged
//! surface keeps the specular look of the bumps it averages.
//!
//! 1. Level 0's normals are decoded once to unit vectors: `2c − 1` for
//!    unorm codes, as stored for float; a two-channel map
//!    ([`NormalChannels::Xy`]) gets `z = sqrt(max(0, 1 − x² − y²))`.
//! 2. Each level's texel is the average `n̄` of the unit level-0 normals of
//!    its footprint, with the colour chain's filter and weights (for box
//!    mips of a power-of-two map, the 2^k × 2^k block; the chain of
//!    *unnormalised* averages is filtered level by level, never the
//!    renormalised normals). `r = |n̄| ≤ 1`; the stored normal is `n̄ / r`.
//! 3. The spread of the normals is a von Mises–Fisher lobe (Han et al.
//!    2007), `κ = (3r − r³) / (1 − r²)`, and the roughness (Beckmann `m`
//!    or GGX `α`) becomes `α' = sqrt(α² + 2/κ)`, at most 1 ([`adjusted_roughness`];
//!    Filament's roughness prefilter). The Blinn-Phong variant adjusts an
//!    exponent instead: `s' = s·r / (r + s·(1 − r))` (Toksvig 2005,
//!    [`toksvig_exponent`]).
//!
//! `α` is the base roughness: a constant, or a roughness map of the normal
//! map's size whose chain is built like colour (linear, averaged). Where
//! the normals do not spread (`1 − r` below [`FLAT`], which covers the f32
//! rounding of averaging identical unit vectors with any filter's
//! weights), `α' = α` and `s' = s` exactly, bit for bit.

use crate::error::{Error, Result};
use crate::texel::{AlphaMode, ChannelType, ColorSpace, Format, Texels};
use crate::texture::Texture;

use crate::mip::normal::normalize_vectors;
use crate::mip::{MipOptions, Progress};

/// Below this `1 − r` a texel's normals count as not spread at all. The
/// f32 average of identical unit vectors is within a few ulps of unit
/// length (about 1e-7); the smallest real spread this drops changes
/// `α'` of α = 0.01 by under 1%: `2/κ ≈ 2(1 − r)`.
pub const FLAT: f64 = 1.0 / (1u64 << 20) as f64;

/// Which channels of the normal map hold the vector.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum NormalChannels {
    /// The first three channels are x, y, z.
    #[default]
    Xyz,
    /// The first two channels are x, y; z is reconstructed (BC5-style
    /// two-channel maps).
    Xy,
}

/// The base roughness of every level-0 texel.
#[derive(Clone, Copy, Debug)]
pub enum BaseRoughness<'a> {
    /// One roughness for the whole map, in [0, 1].
    Constant(f32),
    /// A map of the normal map's size; its first channel is the roughness
    /// in [0, 1] (read as data: an sRGB tag is ignored).
    Map(&'a Texture),
}

/// What the second chain holds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Specular {
    /// Roughness α' (Beckmann m or GGX α), linear, in [0, 1].
    Roughness,
    /// Blinn-Phong exponents s' from this base exponent (above 0); the
    /// base roughness is not used.
    BlinnPhong(f32),
}

/// The two chains [`build`] makes, level 0 first, one level each of the
/// same sizes.
#[derive(Clone, Debug)]
pub struct RoughnessChain {
    /// Unit normals, three channels, linear f32 (encode them for output
    /// with [`crate::mip::normal::encode`]).
    pub normals: Vec<Texture>,
    /// One channel, linear f32: α' per texel, or s' for
    /// [`Specular::BlinnPhong`].
    pub specular: Vec<Texture>,
}

/// The vMF concentration of a lobe whose mean vector has length `r`
/// (SPEC.md): `(3r − r³) / (1 − r²)`, infinite at `r ≥ 1`.
pub fn kappa(r: f64) -> f64 {
    if r >= 1.0 {
        f64::INFINITY
    } else {
        let r = r.max(0.0);
        (3.0 * r - r * r * r) / (1.0 - r * r)
    }
}

/// `α' = min(1, sqrt(α² + 2/κ(r)))`; `α` itself where `1 − r < FLAT`.
pub fn adjusted_roughness(alpha: f32, r: f64) -> f32 {
    if 1.0 - r < FLAT {
        return alpha;
    }
    let a = alpha as f64;
    ((a * a + 2.0 / kappa(r)).sqrt().min(1.0)) as f32
}

/// Toksvig's `s' = s·r / (r + s·(1 − r))`; `s` itself where
/// `1 − r < FLAT`.
pub fn toksvig_exponent(s: f32, r: f64) -> f32 {
    if 1.0 - r < FLAT {
        return s;
    }
    let (s64, r) = (s as f64, r.max(0.0));
    (s64 * r / (r + s64 * (1.0 - r))) as f32
}

/// Level 0 as three-channel f32 unit vectors (+Z for a zero or non-finite
/// vector).
pub fn unit_vectors(t: &Texture, channels: NormalChannels) -> Result<Texture> {
    let f = t.format();
    let need = match channels {
        NormalChannels::Xyz => 3,
        NormalChannels::Xy => 2,
    };
    if (f.channels as usize) < need {
        return Err(Error::InvalidOption(format!(
            "a {} normal map needs at least {need} channels; this one has {}",
            match channels {
                NormalChannels::Xyz => "three-channel (xyz)",
                NormalChannels::Xy => "two-channel (xy)",
            },
            f.channels
        )));
    }
    if f.color_space == ColorSpace::Srgb {
        return Err(Error::InvalidOption(
            "normal maps hold vectors, not colours: load them as linear".into(),
        ));
    }
    let ch = f.channels as usize;
    let src = t.to_linear();
    let unorm = !f.channel_type.is_float();
    let mut v = Vec::with_capacity(t.texel_count() * 3);
    for px in src.chunks_exact(ch) {
        let dec = |c: f32| if unorm { c * 2.0 - 1.0 } else { c };
        let (x, y) = (dec(px[0]), dec(px[1]));
        let z = match channels {
            NormalChannels::Xyz => dec(px[2]),
            NormalChannels::Xy => (1.0 - x * x - y * y).max(0.0).sqrt(),
        };
        v.extend_from_slice(&[x, y, z]);
    }
    normalize_vectors(&mut v, 3);
    let vf = Format::new(3, ChannelType::F32, ColorSpace::Linear).with_alpha(AlphaMode::None);
    Texture::from_f32(t.width(), t.height(), vf, v)
}

/// The normal chain and its roughness (or exponent) chain of `normals`
/// (see the module docs). `options` are the colour chain's (filter, wrap,
/// rounding, levels); alpha coverage is refused.
pub fn build(
    normals: &Texture,
    channels: NormalChannels,
    base: BaseRoughness,
    specular: Specular,
    options: &MipOptions,
    progress: &mut dyn FnMut(Progress),
) -> Result<RoughnessChain> {
    if options.alpha_coverage.is_some() {
        return Err(Error::InvalidOption(
            "alpha coverage does not apply to normal and roughness chains".into(),
        ));
    }
    if let Specular::BlinnPhong(s) = specular
        && !(s > 0.0 && s.is_finite())
    {
        return Err(Error::InvalidOption(format!(
            "the Blinn-Phong exponent must be a number above 0, not {s}"
        )));
    }
    let plain = MipOptions {
        normal_map: false,
        nan_policy: crate::mip::NanPolicy::Error,
        ..*options
    };
    // The base roughness chain first: its errors come before any work.
    let alphas: Option<Vec<Texture>> = match (specular, base) {
        (Specular::BlinnPhong(_), _) => None,
        (_, BaseRoughness::Constant(a)) => {
            check_roughness(a)?;
            None
        }
        (_, BaseRoughness::Map(m)) => Some(roughness_levels(m, normals, &plain)?),
    };
    let mut nf = normals.clone();
    if nf.channel_type().is_float() {
        crate::mip::nan::apply(&mut nf, options.nan_policy)?;
    }
    let v0 = unit_vectors(&nf, channels)?;
    let averages = crate::mip::build_with_progress(v0, &plain, progress)?.into_levels();
    let mut out_n = Vec::with_capacity(averages.len());
    let mut out_s = Vec::with_capacity(averages.len());
    for (k, mut lvl) in averages.into_iter().enumerate() {
        let (w, h) = (lvl.width(), lvl.height());
        let Texels::F32(v) = lvl.texels_mut() else {
            return Err(Error::InvalidOption("normal averages must be f32".into()));
        };
        let alpha_k: Option<Vec<f32>> = alphas.as_ref().map(|a| a[k].to_linear());
        let mut s = Vec::with_capacity(v.len() / 3);
        for (i, n) in v.chunks_exact(3).enumerate() {
            let r = (n[0] as f64).hypot(n[1] as f64).hypot(n[2] as f64);
            let r = if r.is_finite() { r } else { 1.0 };
            s.push(match specular {
                Specular::BlinnPhong(e) => toksvig_exponent(e, r),
                Specular::Roughness => {
                    let a = match (&alpha_k, base) {
                        // A map's chain is filtered like colour: the
                        // negative lobes of Kaiser, Lanczos and Mitchell
                        // ring past 0 and 1 at sharp edges, and roughness
                        // outside [0, 1] means nothing (fuzzing found
                        // −0.012 in the output).
                        (Some(a), _) => a[i].clamp(0.0, 1.0),
                        (None, BaseRoughness::Constant(a)) => a,
                        (None, BaseRoughness::Map(_)) => unreachable!("maps are built above"),
                    };
                    adjusted_roughness(a, r)
                }
            });
        }
        normalize_vectors(v, 3);
        out_n.push(lvl);
        let sf = Format::new(1, ChannelType::F32, ColorSpace::Linear).with_alpha(AlphaMode::None);
        out_s.push(Texture::from_f32(w, h, sf, s)?);
    }
    Ok(RoughnessChain {
        normals: out_n,
        specular: out_s,
    })
}

fn check_roughness(a: f32) -> Result<()> {
    if (0.0..=1.0).contains(&a) {
        Ok(())
    } else {
        Err(Error::InvalidOption(format!(
            "roughness must be a number from 0 to 1, not {a}"
        )))
    }
}

/// The chain of a roughness map's first channel, linear f32, built like
/// colour with `options`.
fn roughness_levels(m: &Texture, normals: &Texture, options: &MipOptions) -> Result<Vec<Texture>> {
    if (m.width(), m.height()) != (normals.width(), normals.height()) {
        return Err(Error::InvalidOption(format!(
            "the roughness map is {}x{}, the normal map {}x{}: they must be the same size",
            m.width(),
            m.height(),
            normals.width(),
            normals.height()
        )));
    }
    let ch = m.channels();
    // Roughness is data: codes are read as they are stored, whatever
    // transfer the file declares for colour.
    let mut data = m.format();
    data.color_space = ColorSpace::Linear;
    let raw = m.clone().reinterpret(data)?.to_linear();
    let first: Vec<f32> = raw.chunks_exact(ch).map(|t| t[0]).collect();
    if let Some(bad) = first.iter().find(|a| !(0.0..=1.0).contains(*a)) {
        return Err(Error::InvalidOption(format!(
            "the roughness map holds {bad}; roughness must be from 0 to 1"
        )));
    }
    let f = Format::new(1, ChannelType::F32, ColorSpace::Linear).with_alpha(AlphaMode::None);
    let t = Texture::from_f32(m.width(), m.height(), f, first)?;
    Ok(crate::mip::build(t, options)?.into_levels())
}
