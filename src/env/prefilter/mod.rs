//! Prefiltered specular and diffuse environment levels (image-based
//! lighting): the split-sum approximation of Karis 2013 ("Real Shading in
//! Unreal Engine 4") with N = V = R, for the lecture's microfacet
//! distributions.
//!
//! # What level k holds
//! Level k of a prefiltered cube map (faces `size >> k`) holds, for each
//! texel direction n, the environment weighted by the lobe of roughness
//! `α_k = (k / (levels − 1))²` (perceptual roughness linear in k, as
//! Filament and UE4 map it; level 0 is the mirror, α = 0, a copy):
//!
//! `P(n) = ∫ L(l)·w(n, l) dl / ∫ w(n, l) dl` over `n·l > 0`, with
//! - GGX (Trowbridge–Reitz): `w = D(h)·(n·l)`, `D = α²/(π((n·h)²(α² − 1) + 1)²)`;
//! - Beckmann (Cook–Torrance's D): `w = D(h)·(n·l)`,
//!   `D = exp(−tan²θ_h/α²)/(π α² cos⁴θ_h)`;
//! - Phong: `w = (n·l)^(s + 1)`, the Phong lobe `(r·l)^s` around r = n times
//!   the cosine, with `s = 2/α² − 2` (the exponent whose Blinn–Phong lobe
//!   matches Beckmann's α, Walter et al. 2007);
//!
//! where `h = normalize(n + l)`. This is the weight Karis's estimator
//! `Σ L(l_i)(n·l_i) / Σ (n·l_i)` converges to with `l_i` drawn from the
//! lobe.
//!
//! # How it is computed
//! By default ([`Integration::Quadrature`]) as that integral over level 0's
//! texels — each a constant radiance over its exact solid angle — summed
//! on a quadtree of each face that keeps the error of every block it sums
//! whole below a stated fraction of the lobe's weight ([`quadrature`]):
//! deterministic, without noise, and close to the brute-force sum over
//! every texel (the tests and the README's table measure it). Level k of
//! the output is the lobe read at level k's texel centres.
//! [`Integration::Sampled`] is filtered importance sampling (`sampled.rs`),
//! what cmgen and the glTF IBL sampler do, kept for comparison.
//!
//! # Diffuse irradiance
//! `E(n) = (1/π)∫ L(l)·max(n·l, 0) dl` (the cosine lobe, normalised so a
//! constant environment gives itself) by the same quadrature; and its 9
//! spherical-harmonic coefficients (Ramamoorthi & Hanrahan 2001), projected
//! over every level-0 texel by its solid angle, from which irradiance is
//! `Σ Â_l·L_lm·Y_lm(n)`.

pub mod dfg;
pub mod quadrature;
mod sampled;

use std::f64::consts::PI;

use crate::error::{Error, Result};
use crate::mip::{MipChain, MipOptions};
use crate::sample::SamplerOptions;
use crate::texel::{ChannelType, ColorSpace, Format};
use crate::texture::Texture;

use super::cube::{CubeSampler, face_direction};
use super::vec3::unit;
use quadrature::Tree;

/// The quadrature's tolerance for the specular lobes ([`quadrature`]):
/// every level of openexr-images' KernerEnvCube within 1 % relative RMS of
/// the brute-force sum (the README's table).
pub const TOLERANCE: f64 = 1e-3;

/// The quadrature's tolerance for irradiance: cheap (the lobe is wide),
/// so tighter.
pub const IRRADIANCE_TOLERANCE: f64 = 1e-4;

/// How prefiltered levels are integrated (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Integration {
    /// Deterministic quadrature over level 0 (the default).
    Quadrature,
    /// Filtered importance sampling, this many lobe directions per texel.
    Sampled(u32),
}

impl Integration {
    /// Its words in a settings summary: `quadrature`, `N samples`.
    pub fn describe(self) -> String {
        match self {
            Integration::Quadrature => "quadrature".into(),
            Integration::Sampled(n) => format!("{n} samples"),
        }
    }
}

/// The lobe a prefiltered level is convolved with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Lobe {
    /// GGX / Trowbridge–Reitz (what engines use).
    Ggx,
    /// Beckmann (the lecture's Cook–Torrance D).
    Beckmann,
    /// Phong around the reflection direction.
    Phong,
}

impl Lobe {
    /// Its name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Lobe::Ggx => "ggx",
            Lobe::Beckmann => "beckmann",
            Lobe::Phong => "phong",
        }
    }

    /// The weight `w(n, l)` of the module docs for `c = n·l` (l in the
    /// upper hemisphere), with `α > 0`. `n·h = sqrt((1 + c)/2)`.
    pub fn weight(self, alpha: f64, c: f64) -> f64 {
        if c <= 0.0 {
            return 0.0;
        }
        match self {
            Lobe::Phong => c.powf(phong_exponent(alpha) + 1.0),
            Lobe::Ggx | Lobe::Beckmann => self.d(alpha, ((1.0 + c) * 0.5).sqrt()) * c,
        }
    }

    /// The normal distribution D at `n·h = nh`.
    pub(crate) fn d(self, alpha: f64, nh: f64) -> f64 {
        let a2 = alpha * alpha;
        let c2 = nh * nh;
        match self {
            Lobe::Ggx => {
                let x = c2 * (a2 - 1.0) + 1.0;
                a2 / (PI * x * x)
            }
            Lobe::Beckmann => {
                let tan2 = (1.0 - c2) / c2;
                (-tan2 / a2).exp() / (PI * a2 * c2 * c2)
            }
            Lobe::Phong => unreachable!("Phong is weighted in l, not through D"),
        }
    }
}

/// Prefiltered levels of `faces` (six face chains of one square size, any
/// format): six face chains of `f32` RGBA, as many levels as `faces`
/// have, whose level k is the lobe of roughness [`alpha`]`(k, levels)`
/// (module docs) integrated as `how` says.
pub fn specular(faces: &[MipChain], lobe: Lobe, how: Integration) -> Result<Vec<MipChain>> {
    super::cube::check_faces(faces)?;
    let levels = faces[0].len();
    let size = faces[0].levels()[0].width();
    let mut out: Vec<Vec<Texture>> = (0..6).map(|_| Vec::with_capacity(levels)).collect();
    // Level 0 is the mirror: the source's level 0 itself.
    for (chain, src) in out.iter_mut().zip(faces) {
        let l0 = &src.levels()[0];
        let lin = l0.to_linear();
        let ch = l0.channels();
        let v = lin
            .chunks_exact(ch)
            .flat_map(crate::texture::expand_to_rgba)
            .collect();
        chain.push(Texture::from_f32(size, size, rgba_f32(), v)?);
    }
    match how {
        Integration::Quadrature => {
            let tree = Tree::new(faces);
            for k in 1..levels {
                let a = alpha(k, levels);
                let total = quadrature::total_weight(|c| lobe.weight(a, c));
                let m = (size >> k).max(1);
                // One copy of the sum per lobe, its weight in f32.
                let (a2, pi) = ((a * a) as f32, std::f32::consts::PI);
                let s1 = (phong_exponent(a) + 1.0) as f32;
                let faces: Vec<Vec<f32>> = match lobe {
                    Lobe::Ggx => quadrature::cube(
                        &tree,
                        m,
                        move |c| {
                            let x = (1.0 + c) * 0.5 * (a2 - 1.0) + 1.0;
                            a2 / (pi * x * x) * c
                        },
                        total,
                        TOLERANCE,
                    ),
                    Lobe::Beckmann => quadrature::cube(
                        &tree,
                        m,
                        move |c| {
                            let c2 = (1.0 + c) * 0.5;
                            (-(1.0 - c2) / (c2 * a2)).exp() / (pi * a2 * c2 * c2) * c
                        },
                        total,
                        TOLERANCE,
                    ),
                    Lobe::Phong => {
                        quadrature::cube(&tree, m, move |c| (s1 * c.ln()).exp(), total, TOLERANCE)
                    }
                };
                for (chain, v) in out.iter_mut().zip(faces) {
                    chain.push(Texture::from_f32(m, m, rgba_f32(), v)?);
                }
            }
        }
        Integration::Sampled(samples) => {
            if samples == 0 {
                return Err(Error::InvalidOption(
                    "prefiltering needs at least one sample per texel".into(),
                ));
            }
            let source = CubeSampler::new(faces, SamplerOptions::trilinear())?;
            let texel_angle = 4.0 * PI / (6.0 * size as f64 * size as f64);
            for k in 1..levels {
                let a = alpha(k, levels);
                let m = (size >> k).max(1);
                for (f, chain) in out.iter_mut().enumerate() {
                    let v = face_texels(f, m, |d| {
                        sampled::lobe_average(&source, lobe, a, d, samples, texel_angle)
                    });
                    chain.push(Texture::from_f32(m, m, rgba_f32(), v)?);
                }
            }
        }
    }
    out.into_iter()
        .map(|levels| MipChain::from_levels(levels, MipOptions::default()))
        .collect()
}

/// Phong exponent of roughness α: `2/α² − 2`.
pub fn phong_exponent(alpha: f64) -> f64 {
    (2.0 / (alpha * alpha) - 2.0).max(0.0)
}

/// α of level `k` of `levels`: `(k/(levels − 1))²` (0 for one level).
pub fn alpha(k: usize, levels: usize) -> f64 {
    if levels <= 1 {
        return 0.0;
    }
    let r = k as f64 / (levels - 1) as f64;
    r * r
}

/// The values of an `n × n` face `f`, `f(direction of texel centre)` (unit
/// directions), RGBA.
fn face_texels(f: usize, n: u32, mut value: impl FnMut([f64; 3]) -> [f32; 4]) -> Vec<f32> {
    let mut v = Vec::with_capacity(n as usize * n as usize * 4);
    for j in 0..n {
        for i in 0..n {
            let d = texel_direction(f, n, i, j);
            v.extend(value(d));
        }
    }
    v
}

/// The unit direction of the centre of texel `(i, j)` of an `n × n` face
/// `f`.
pub fn texel_direction(f: usize, n: u32, i: u32, j: u32) -> [f64; 3] {
    unit(face_direction(
        f,
        (i as f64 + 0.5) / n as f64,
        (j as f64 + 0.5) / n as f64,
    ))
}

/// Solid angle of texel `(i, j)` of an `n × n` face (exact: the area
/// of the spherical rectangle, from the corners' `atan2` formula).
pub fn texel_solid_angle(n: u32, i: u32, j: u32) -> f64 {
    let area = |x: f64, y: f64| (x * y).atan2((x * x + y * y + 1.0).sqrt());
    let inv = 2.0 / n as f64;
    let (x0, y0) = (i as f64 * inv - 1.0, j as f64 * inv - 1.0);
    let (x1, y1) = (x0 + inv, y0 + inv);
    area(x0, y0) - area(x0, y1) - area(x1, y0) + area(x1, y1)
}

/// Every texel of level `k` of `faces` as (unit direction, solid angle,
/// linear RGBA).
pub fn texels_with_solid_angles(faces: &[MipChain], k: usize) -> Vec<([f64; 3], f64, [f32; 4])> {
    let mut v = Vec::new();
    for (f, chain) in faces.iter().enumerate() {
        let Some(level) = chain.level(k) else {
            continue;
        };
        let n = level.width();
        for j in 0..n {
            for i in 0..n {
                let d = texel_direction(f, n, i, j);
                v.push((d, texel_solid_angle(n, i, j), level.texel_linear(i, j)));
            }
        }
    }
    v
}

/// Diffuse irradiance (module docs): six `size × size` faces of `f32`
/// RGBA, one level each.
pub fn irradiance(faces: &[MipChain], size: u32) -> Result<Vec<MipChain>> {
    super::cube::check_faces(faces)?;
    let tree = Tree::new(faces);
    let m = size.max(1);
    quadrature::cube(&tree, m, |c| c, std::f64::consts::PI, IRRADIANCE_TOLERANCE)
        .into_iter()
        .map(|v| {
            let t = Texture::from_f32(m, m, rgba_f32(), v)?;
            MipChain::from_levels(vec![t], MipOptions::default())
        })
        .collect()
}

/// The 9 real spherical-harmonic basis functions (bands 0–2) at unit `d`.
pub fn sh9_basis(d: [f64; 3]) -> [f64; 9] {
    let [x, y, z] = d;
    [
        0.282_094_791_773_878_1,
        0.488_602_511_902_919_9 * y,
        0.488_602_511_902_919_9 * z,
        0.488_602_511_902_919_9 * x,
        1.092_548_430_592_079 * x * y,
        1.092_548_430_592_079 * y * z,
        0.315_391_565_252_520_05 * (3.0 * z * z - 1.0),
        1.092_548_430_592_079 * x * z,
        0.546_274_215_296_039_5 * (x * x - y * y),
    ]
}

/// The environment's 9 spherical-harmonic coefficients per RGB channel
/// (projected over every level-0 texel, weighted by its solid angle).
pub fn sh9(faces: &[MipChain]) -> Result<[[f64; 3]; 9]> {
    super::cube::check_faces(faces)?;
    let mut coef = [[0.0f64; 3]; 9];
    for (d, omega, c) in texels_with_solid_angles(faces, 0) {
        let y = sh9_basis(d);
        for (k, yk) in y.iter().enumerate() {
            for ch in 0..3 {
                coef[k][ch] += c[ch] as f64 * yk * omega;
            }
        }
    }
    Ok(coef)
}

/// Irradiance at unit `n` from [`sh9`] coefficients, normalised as
/// [`irradiance`] is (a constant environment gives itself): the cosine
/// lobe's band factors π, 2π/3, π/4, divided by π.
pub fn sh9_irradiance(coef: &[[f64; 3]; 9], n: [f64; 3]) -> [f64; 3] {
    const A: [f64; 9] = [
        1.0,
        2.0 / 3.0,
        2.0 / 3.0,
        2.0 / 3.0,
        0.25,
        0.25,
        0.25,
        0.25,
        0.25,
    ];
    let y = sh9_basis(n);
    std::array::from_fn(|ch| (0..9).map(|k| A[k] * coef[k][ch] * y[k]).sum())
}

fn rgba_f32() -> Format {
    Format::new(4, ChannelType::F32, ColorSpace::Linear)
}
