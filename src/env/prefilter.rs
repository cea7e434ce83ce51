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
//! Filtered importance sampling (Křivánek & Colbert 2008, as Filament's
//! cmgen and Khronos's glTF-IBL-Sampler do it): per texel, `samples`
//! directions drawn from the lobe on a Hammersley sequence (deterministic),
//! each a trilinear lookup of the source cube's mip chain (seamless) at
//! `λ = ½·log2(Ω_s/Ω_p) + 1`, with Ω_s = 1/(samples·pdf) the solid angle a
//! sample stands for and Ω_p = 4π/(6·size²) a level-0 texel's. The tests
//! hold the result to an `f64` brute-force integration of the definition
//! over every texel of a small environment (the bound is stated there).
//!
//! # Diffuse irradiance
//! `E(n) = (1/π)∫ L(l)·max(n·l, 0) dl` (the cosine lobe, normalised so a
//! constant environment gives itself), summed exactly over every texel of
//! the source level whose faces are at most 32 texels (the irradiance is
//! smooth), each weighted by its solid angle (divided by the sum of the
//! weights, which is π up to the sum's discretisation); and its 9 spherical-harmonic
//! coefficients (Ramamoorthi & Hanrahan 2001), from which irradiance is
//! `Σ Â_l·L_lm·Y_lm(n)`.

use std::f64::consts::PI;

use crate::error::{Error, Result};
use crate::mip::{MipChain, MipOptions};
use crate::sample::SamplerOptions;
use crate::texel::{ChannelType, ColorSpace, Format};
use crate::texture::Texture;

use super::DirQuery;
use super::cube::{CubeSampler, face_direction};
use super::vec3::{cross, unit};

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
    fn d(self, alpha: f64, nh: f64) -> f64 {
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

    /// A direction in the lobe around +z for the sequence point `(u1, u2)`
    /// and its density in l (per steradian).
    fn sample(self, alpha: f64, u1: f64, u2: f64) -> ([f64; 3], f64) {
        let phi = 2.0 * PI * u1;
        match self {
            Lobe::Phong => {
                let s = phong_exponent(alpha);
                let c = u2.powf(1.0 / (s + 2.0));
                let sin = (1.0 - c * c).max(0.0).sqrt();
                // Density of (n·l)^(s+1) over the hemisphere.
                let pdf = (s + 2.0) / (2.0 * PI) * c.powf(s + 1.0);
                ([sin * phi.cos(), sin * phi.sin(), c], pdf)
            }
            Lobe::Ggx | Lobe::Beckmann => {
                let a2 = alpha * alpha;
                let c = match self {
                    Lobe::Ggx => ((1.0 - u2) / (1.0 + (a2 - 1.0) * u2)).sqrt(),
                    _ => 1.0 / (1.0 - a2 * (1.0 - u2).ln()).sqrt(),
                };
                let sin = (1.0 - c * c).max(0.0).sqrt();
                let h = [sin * phi.cos(), sin * phi.sin(), c];
                // l = reflect(−v, h) with v = n = +z.
                let l = [2.0 * c * h[0], 2.0 * c * h[1], 2.0 * c * c - 1.0];
                // p(l) = D(h)(n·h)/(4(v·h)) = D(h)/4 with v = n.
                (l, self.d(alpha, c) / 4.0)
            }
        }
    }
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

/// Point `i` of an `n`-point Hammersley sequence.
fn hammersley(i: u32, n: u32) -> (f64, f64) {
    (
        (i as f64 + 0.5) / n as f64,
        i.reverse_bits() as f64 / 4_294_967_296.0,
    )
}

/// An orthonormal frame whose third axis is `n` (unit).
fn frame(n: [f64; 3]) -> [[f64; 3]; 3] {
    let up = if n[2].abs() < 0.999 {
        [0.0, 0.0, 1.0]
    } else {
        [1.0, 0.0, 0.0]
    };
    let t = unit(cross(up, n));
    let b = cross(n, t);
    [t, b, n]
}

/// Prefiltered levels of `faces` (six face chains of one square size, any
/// format): six face chains of `f32` RGBA whose level k is the lobe of
/// roughness [`alpha`]`(k, levels)` (module docs), `samples` lobe
/// directions per texel.
pub fn specular(faces: &[MipChain], lobe: Lobe, samples: u32) -> Result<Vec<MipChain>> {
    let source = CubeSampler::new(faces, SamplerOptions::trilinear())?;
    let size = source.face_size();
    let levels = faces[0].len();
    if samples == 0 {
        return Err(Error::InvalidOption(
            "prefiltering needs at least one sample per texel".into(),
        ));
    }
    let texel_angle = 4.0 * PI / (6.0 * size as f64 * size as f64);
    let mut out: Vec<Vec<Texture>> = (0..6).map(|_| Vec::with_capacity(levels)).collect();
    for k in 0..levels {
        let n = (size >> k).max(1);
        let a = alpha(k, levels);
        for (f, chain) in out.iter_mut().enumerate() {
            let v = face_texels(f, n, |d| {
                if a == 0.0 {
                    return source.sample(&DirQuery::point(d.map(|x| x as f32)));
                }
                lobe_average(&source, lobe, a, d, samples, texel_angle)
            });
            chain.push(Texture::from_f32(n, n, rgba_f32(), v)?);
        }
    }
    out.into_iter()
        .map(|levels| MipChain::from_levels(levels, MipOptions::default()))
        .collect()
}

/// Karis's estimator at direction `n` (unit).
fn lobe_average(
    source: &CubeSampler,
    lobe: Lobe,
    a: f64,
    n: [f64; 3],
    samples: u32,
    texel_angle: f64,
) -> [f32; 4] {
    let [t, b, z] = frame(n);
    let mut acc = [0.0f64; 4];
    let mut wsum = 0.0;
    for i in 0..samples {
        let (u1, u2) = hammersley(i, samples);
        let (l, pdf) = lobe.sample(a, u1, u2);
        let nl = l[2];
        if nl <= 0.0 || pdf <= 0.0 {
            continue;
        }
        let dir: [f64; 3] = std::array::from_fn(|c| l[0] * t[c] + l[1] * b[c] + l[2] * z[c]);
        let omega_s = 1.0 / (samples as f64 * pdf);
        let lod = (0.5 * (omega_s / texel_angle).log2() + 1.0).max(0.0);
        let v = source.sample_level(dir.map(|x| x as f32), lod as f32);
        // Phong's lobe already includes the cosine in its density: its
        // samples are weighted equally.
        let w = if lobe == Lobe::Phong { 1.0 } else { nl };
        for c in 0..4 {
            acc[c] += w * v[c] as f64;
        }
        wsum += w;
    }
    if wsum > 0.0 {
        acc.map(|x| (x / wsum) as f32)
    } else {
        source.sample(&DirQuery::point(n.map(|x| x as f32)))
    }
}

/// The values of an `n × n` face `f`, `f(direction of texel centre)` (unit
/// directions), RGBA.
fn face_texels(f: usize, n: u32, mut value: impl FnMut([f64; 3]) -> [f32; 4]) -> Vec<f32> {
    let mut v = Vec::with_capacity(n as usize * n as usize * 4);
    for j in 0..n {
        for i in 0..n {
            let d = unit(face_direction(
                f,
                (i as f64 + 0.5) / n as f64,
                (j as f64 + 0.5) / n as f64,
            ));
            v.extend(value(d));
        }
    }
    v
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
                let d = unit(face_direction(
                    f,
                    (i as f64 + 0.5) / n as f64,
                    (j as f64 + 0.5) / n as f64,
                ));
                v.push((d, texel_solid_angle(n, i, j), level.texel_linear(i, j)));
            }
        }
    }
    v
}

/// The first level of `faces` whose faces are at most `max` texels.
fn level_at_most(faces: &[MipChain], max: u32) -> usize {
    let chain = &faces[0];
    (0..chain.len())
        .find(|&k| chain.levels()[k].width() <= max)
        .unwrap_or(chain.len() - 1)
}

/// Diffuse irradiance (module docs): six `size × size` faces of `f32`
/// RGBA, one level each.
pub fn irradiance(faces: &[MipChain], size: u32) -> Result<Vec<MipChain>> {
    super::cube::check_faces(faces)?;
    let src = texels_with_solid_angles(faces, level_at_most(faces, 32));
    (0..6)
        .map(|f| {
            let v = face_texels(f, size.max(1), |n| {
                let mut acc = [0.0f64; 4];
                let mut wsum = 0.0;
                for (l, omega, c) in &src {
                    let nl = n[0] * l[0] + n[1] * l[1] + n[2] * l[2];
                    if nl > 0.0 {
                        for k in 0..4 {
                            acc[k] += c[k] as f64 * nl * omega;
                        }
                        wsum += nl * omega;
                    }
                }
                // Divided by the sum of the weights (π in the limit), so a
                // constant environment gives itself exactly.
                acc.map(|x| (x / wsum) as f32)
            });
            let t = Texture::from_f32(size.max(1), size.max(1), rgba_f32(), v)?;
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
/// (projected over every texel of the level whose faces are at most 32
/// texels, weighted by solid angle).
pub fn sh9(faces: &[MipChain]) -> Result<[[f64; 3]; 9]> {
    super::cube::check_faces(faces)?;
    let mut coef = [[0.0f64; 3]; 9];
    for (d, omega, c) in texels_with_solid_angles(faces, level_at_most(faces, 32)) {
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
