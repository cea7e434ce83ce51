//! Shading normal-mapped texels with the lecture's BRDFs, to validate the
//! roughness chains of [`crate::mip::roughness`] against a ground truth
//! (SPEC.md "Normal maps and specular roughness").
//!
//! - [`Brdf::BlinnPhong`]: `((s + 2)/(2π))·(N·H)^s`.
//! - [`Brdf::CookTorrance`]: `D·G·F / (π (N·V)(N·L))` with Beckmann
//!   `D = exp(−tan²θ/m²) / (π m² cos⁴θ)`, the V-groove
//!   `G = min(1, 2(N·H)(N·V)/(V·H), 2(N·H)(N·L)/(V·H))` and Schlick's `F`
//!   with `F0 = 0.04`.
//!
//! Radiance is the BRDF times `N·L` (0 where the light or the viewer is
//! below the shading normal). The ground truth of a texel of level k is
//! the average of the radiance shaded with each unit level-0 normal of its
//! footprint and the base roughness; [`compare`] sets beside it the
//! renormalised normal shaded with the base roughness and with the
//! adjusted one. Blinn-Phong uses the exponent `s = 2/α² − 2` (Walter et
//! al. 2007) and, adjusted, Toksvig's `s'`.
//!
//! [`bumps`], [`v_grooves`] and [`height_field`] make the procedural
//! normal maps the validation runs on; [`render`] shades a normal-mapped
//! scene three ways (ground truth, renormalised, adjusted) so the effect
//! can be seen.

use crate::error::{Error, Result};
use crate::mip::roughness::{self, BaseRoughness, NormalChannels, Specular};
use crate::mip::{MipChain, MipFilter, MipOptions};
use crate::texel::Texels;
use crate::texture::Texture;

pub use crate::builtin::normals::{bumps, height_field, normals_of_height, v_grooves};
use crate::builtin::normals::{dot, unit};

use std::f64::consts::PI;

use rayon::prelude::*;

/// A unit vector in the normal map's tangent space (z out of the surface).
pub type Dir = [f64; 3];

/// The BRDFs of the validation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Brdf {
    /// Normalised Blinn-Phong.
    BlinnPhong,
    /// Cook-Torrance with Beckmann D, V-groove G and Schlick F.
    CookTorrance,
}

impl std::fmt::Display for Brdf {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Brdf::BlinnPhong => "blinn-phong",
            Brdf::CookTorrance => "cook-torrance",
        })
    }
}

/// The unit direction at `deg` degrees from the normal (+z), in the x-z
/// plane, towards +x for positive angles.
pub fn dir_at(deg: f64) -> Dir {
    let (s, c) = deg.to_radians().sin_cos();
    [s, 0.0, c]
}

/// Blinn-Phong exponent of Beckmann roughness `m`: `2/m² − 2`.
pub fn exponent_of(m: f64) -> f64 {
    2.0 / (m * m) - 2.0
}

/// Reflected radiance (BRDF × N·L) of normal `n` lit from `l`, seen from
/// `v`; `p` is the Beckmann roughness m for Cook-Torrance, the exponent s
/// for Blinn-Phong.
pub fn radiance(brdf: Brdf, n: Dir, l: Dir, v: Dir, p: f64) -> f64 {
    let (nl, nv) = (dot(n, l), dot(n, v));
    if nl <= 0.0 || nv <= 0.0 {
        return 0.0;
    }
    let h = unit([l[0] + v[0], l[1] + v[1], l[2] + v[2]]);
    let nh = dot(n, h).max(0.0);
    match brdf {
        Brdf::BlinnPhong => (p + 2.0) / (2.0 * PI) * nh.powf(p) * nl,
        Brdf::CookTorrance => {
            let m2 = (p * p).max(1e-12);
            let c2 = nh * nh;
            if c2 <= 0.0 {
                return 0.0;
            }
            let tan2 = (1.0 - c2) / c2;
            let d = (-tan2 / m2).exp() / (PI * m2 * c2 * c2);
            let vh = dot(v, h).max(1e-12);
            let g = (2.0 * nh * nv / vh).min(2.0 * nh * nl / vh).min(1.0);
            let f = 0.04 + 0.96 * (1.0 - vh).powi(5);
            d * g * f / (PI * nv * nl) * nl
        }
    }
}

/// How far one level's approximations are from the ground truth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LevelScore {
    /// The level.
    pub level: usize,
    /// RMSE over texels and light/view pairs: renormalised normal, base
    /// roughness.
    pub rmse_base: f64,
    /// The same with the adjusted roughness (or Toksvig's exponent).
    pub rmse_adjusted: f64,
    /// The brightest value of the level (over texels and pairs), base
    /// roughness, divided by the ground truth's brightest.
    pub peak_base: f64,
    /// The same with the adjusted roughness.
    pub peak_adjusted: f64,
    /// The ground truth's brightest value.
    pub peak_truth: f64,
}

/// Light/view pairs of the validation: the viewer at 0°, 30°, 60° and 80°
/// from the normal (80° grazing), each with the light at the mirror
/// direction (the highlight) and 20° off it.
pub fn default_directions() -> Vec<(Dir, Dir)> {
    let mut d = Vec::new();
    for view in [0.0, 30.0, 60.0, 80.0] {
        for off in [0.0, 20.0] {
            let light: f64 = -view + off;
            d.push((dir_at(light.clamp(-89.0, 89.0)), dir_at(view)));
        }
    }
    d
}

/// The box roughness chain of `normals` for `brdf` at base roughness
/// `alpha` (Toksvig's exponents for Blinn-Phong), and the base parameter
/// the BRDF takes (m, or the exponent 2/α² − 2).
fn base_chain(
    normals: &Texture,
    alpha: f32,
    brdf: Brdf,
) -> Result<(roughness::RoughnessChain, f64)> {
    if !(alpha > 0.0 && alpha <= 1.0) {
        return Err(Error::InvalidOption(format!(
            "the base roughness must be above 0 and at most 1, not {alpha}"
        )));
    }
    let (spec, base_p) = match brdf {
        Brdf::CookTorrance => (Specular::Roughness, alpha as f64),
        Brdf::BlinnPhong => {
            let s = exponent_of(alpha as f64);
            (Specular::BlinnPhong(s as f32), s)
        }
    };
    let chain = roughness::build(
        normals,
        NormalChannels::Xyz,
        BaseRoughness::Constant(alpha),
        spec,
        &MipOptions::with_filter(MipFilter::Box),
        &mut |_| {},
    )?;
    Ok((chain, base_p))
}

/// Per level from 1 on, the renormalised and the adjusted chains of
/// `normals` (a square power-of-two map, box mips) shaded with `brdf` at
/// base roughness `alpha` against the ground truth, over `dirs`.
pub fn compare(
    normals: &Texture,
    alpha: f32,
    brdf: Brdf,
    dirs: &[(Dir, Dir)],
) -> Result<Vec<LevelScore>> {
    let (w, h) = (normals.width() as usize, normals.height() as usize);
    if !w.is_power_of_two() || !h.is_power_of_two() {
        return Err(Error::InvalidOption(format!(
            "the shading comparison needs a power-of-two map (footprints are blocks), not {w}x{h}"
        )));
    }
    let (chain, base_p) = base_chain(normals, alpha, brdf)?;
    let n0: Vec<Dir> = f32s(&chain.normals[0])?
        .chunks_exact(3)
        .map(|n| [n[0] as f64, n[1] as f64, n[2] as f64])
        .collect();
    let mut out = Vec::new();
    for k in 1..chain.normals.len() {
        let lw = (w >> k).max(1);
        let lh = (h >> k).max(1);
        let (bw, bh) = (w / lw, h / lh);
        let nk = f32s(&chain.normals[k])?;
        let pk = f32s(&chain.specular[k])?;
        let (mut se_b, mut se_a, mut n) = (0f64, 0f64, 0usize);
        let (mut peak_t, mut peak_b, mut peak_a) = (0f64, 0f64, 0f64);
        for ty in 0..lh {
            for tx in 0..lw {
                let i = ty * lw + tx;
                let nbar = [nk[3 * i] as f64, nk[3 * i + 1] as f64, nk[3 * i + 2] as f64];
                let p_adj = pk[i] as f64;
                for &(l, v) in dirs {
                    let mut truth = 0.0;
                    for y in ty * bh..(ty + 1) * bh {
                        for x in tx * bw..(tx + 1) * bw {
                            truth += radiance(brdf, n0[y * w + x], l, v, base_p);
                        }
                    }
                    truth /= (bw * bh) as f64;
                    let b = radiance(brdf, nbar, l, v, base_p);
                    let a = radiance(brdf, nbar, l, v, p_adj);
                    se_b += (b - truth).powi(2);
                    se_a += (a - truth).powi(2);
                    n += 1;
                    peak_t = peak_t.max(truth);
                    peak_b = peak_b.max(b);
                    peak_a = peak_a.max(a);
                }
            }
        }
        let peak_t = peak_t.max(1e-300);
        out.push(LevelScore {
            level: k,
            rmse_base: (se_b / n as f64).sqrt(),
            rmse_adjusted: (se_a / n as f64).sqrt(),
            peak_base: peak_b / peak_t,
            peak_adjusted: peak_a / peak_t,
            peak_truth: peak_t,
        });
    }
    Ok(out)
}

fn f32s(t: &Texture) -> Result<&[f32]> {
    match t.texels() {
        Texels::F32(v) => Ok(v),
        _ => Err(Error::InvalidOption("expected f32 texels".into())),
    }
}

/// Which shading [`render`] draws.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shading {
    /// Every level-0 normal under the pixel shaded with the base roughness
    /// and averaged (stratified over the pixel's square, as the box
    /// reference image samples it).
    Truth,
    /// The filtered, renormalised normal with the base roughness.
    Renormalised,
    /// The filtered, renormalised normal with the adjusted roughness (or
    /// Toksvig's exponent for Blinn-Phong).
    Adjusted,
}

impl std::str::FromStr for Shading {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "truth" => Ok(Shading::Truth),
            "renormalised" | "renormalized" => Ok(Shading::Renormalised),
            "adjusted" => Ok(Shading::Adjusted),
            _ => Err(Error::parse(
                "shading",
                s,
                "expected truth, renormalised or adjusted",
            )),
        }
    }
}

/// Shades `scene` in `frame`, normal-mapped with `normals` (three channels,
/// codes or floats as [`crate::mip::roughness`] reads them), lit from
/// `light` (tangent space), with base roughness `alpha`: one grey radiance
/// value per pixel (row-major, `None` where the scene shows nothing). The
/// plane's view direction follows its camera; other scenes are seen from
/// straight above. Filtered chains are read with trilinear filtering.
pub fn render(
    normals: &Texture,
    alpha: f32,
    brdf: Brdf,
    light: Dir,
    scene: &crate::scene::Scene,
    frame: crate::scene::Frame,
    shading: Shading,
) -> Result<Vec<Option<f64>>> {
    use crate::sample::{Query, Sampler, SamplerOptions};
    use crate::scene::Scene;
    use crate::scene::reference::{PixelFilter, Reference};
    let light = unit(light);
    if !light.iter().all(|c| c.is_finite()) || light[2] <= 0.0 {
        return Err(Error::InvalidOption(
            "the light must be a direction above the surface (z > 0)".into(),
        ));
    }
    let (chain, base_p) = base_chain(normals, alpha, brdf)?;
    let o = MipOptions::with_filter(MipFilter::Box);
    let tex = (normals.width(), normals.height());
    let n_chain = MipChain::from_levels(chain.normals.clone(), o)?;
    let p_chain = MipChain::from_levels(chain.specular, o)?;
    let level0 = MipChain::from_levels(vec![chain.normals[0].clone()], o)?;
    let tri = SamplerOptions::trilinear();
    let ns = Sampler::new(&n_chain, tri)?;
    let ps = Sampler::new(&p_chain, tri)?;
    let n0 = Sampler::new(&level0, SamplerOptions::bilinear())?;
    let view = |x: f64, y: f64| -> Option<Dir> {
        match scene {
            Scene::Plane(p) => p.view_dir(frame, x, y),
            _ => scene.uv(frame, tex, x, y).map(|_| [0.0, 0.0, 1.0]),
        }
    };
    let normal_of = |c: [f32; 4]| -> Dir { unit([c[0] as f64, c[1] as f64, c[2] as f64]) };
    let grid = Reference::new(PixelFilter::Box);
    let rows: Vec<Vec<Option<f64>>> = (0..frame.height)
        .into_par_iter()
        .map(|py| {
            (0..frame.width)
                .map(|px| {
                    let (cx, cy) = (px as f64 + 0.5, py as f64 + 0.5);
                    let q = scene.query_at(frame, tex, cx, cy)?;
                    let v = view(cx, cy)?;
                    match shading {
                        Shading::Truth => {
                            let n = grid.grid(&q, tex);
                            let (mut sum, mut cnt) = (0.0, 0usize);
                            for j in 0..n {
                                for i in 0..n {
                                    let dx = (i as f64 + 0.5) / n as f64 - 0.5;
                                    let dy = (j as f64 + 0.5) / n as f64 - 0.5;
                                    let Some((u, w)) = scene.uv(frame, tex, cx + dx, cy + dy)
                                    else {
                                        continue;
                                    };
                                    let c = n0.sample(&Query::new(
                                        u as f32, w as f32, 0.0, 0.0, 0.0, 0.0,
                                    ));
                                    sum += radiance(brdf, normal_of(c), light, v, base_p);
                                    cnt += 1;
                                }
                            }
                            (cnt > 0).then(|| sum / cnt as f64)
                        }
                        Shading::Renormalised | Shading::Adjusted => {
                            let n = normal_of(ns.sample(&q));
                            let p = if shading == Shading::Adjusted {
                                ps.sample(&q)[0] as f64
                            } else {
                                base_p
                            };
                            Some(radiance(brdf, n, light, v, p))
                        }
                    }
                })
                .collect()
        })
        .collect();
    Ok(rows.into_iter().flatten().collect())
}
