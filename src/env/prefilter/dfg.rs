//! The split-sum BRDF table ("DFG LUT", Karis 2013): the second factor of
//! the split-sum approximation, the specular BRDF's directional albedo as
//! a scale and a bias of F0, `∫ f(v, l)(n·l) dl = F0·A + B`, over `n·v` and
//! roughness — what Filament's cmgen (`--ibl-dfg`) and Khronos's glTF IBL
//! sampler write beside a prefiltered GGX cube map.
//!
//! With GGX's D, Smith's height-correlated masking-shadowing as the
//! visibility `V = G/(4(n·l)(n·v))` (Heitz 2014, as Filament and the glTF
//! sample viewer use it) and Schlick's Fresnel `F = F0 + (1 − F0)·Fc`,
//! `Fc = (1 − v·h)⁵`:
//!
//! `A = ∫ D(h)·V·(n·l)·(1 − Fc) dl`, `B = ∫ D(h)·V·(n·l)·Fc dl`.
//!
//! # How it is computed
//! Over the half vector, `dl = 4(v·h) dh`, and with u = the GGX
//! distribution's CDF in θ_h (the map GGX importance sampling uses,
//! `cos²θ_h = (1 − u)/(1 + (α² − 1)u)`), `D(h)(n·h) dh = du dφ/(2π)`: the
//! integrand left, `4·V·(n·l)·(v·h)/(n·h)`, is smooth in (u, φ). It is
//! summed by Gauss–Legendre quadrature in `√(1 − u)` (which takes away
//! the `1/(n·h)` growth towards θ_h = 90° a grazing view reaches) and in
//! φ: in two rules split where the arc of `n·l > 0` stops being the whole
//! circle (θ_h = π/4 − θ_v/2), up to the largest θ_h with any `n·l > 0`
//! (π/4 + θ_v/2), and φ only over that arc (found exactly for each u), so
//! the horizon is no kink inside a rule. The tests hold it to a brute-force `f64`
//! sum over l.

use std::f64::consts::PI;

use crate::error::Result;
use crate::texel::{ChannelType, ColorSpace, Format};
use crate::texture::Texture;

/// Gauss–Legendre points in u and in φ.
const POINTS: usize = 48;

/// The `n` Gauss–Legendre nodes and weights on `[0, 1]` (Newton's method
/// on the Legendre polynomial, from the usual initial guesses).
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            // P_n(x) and its derivative by the three-term recurrence.
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let dx = p1 / dp;
            x -= dx;
            if dx.abs() < 1e-15 {
                break;
            }
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        out.push(((1.0 - x) * 0.5, w * 0.5));
    }
    out
}

/// Smith's height-correlated visibility `G/(4(n·l)(n·v))` for GGX.
pub fn visibility(nov: f64, nol: f64, alpha: f64) -> f64 {
    let a2 = alpha * alpha;
    let gv = nol * (nov * nov * (1.0 - a2) + a2).sqrt();
    let gl = nov * (nol * nol * (1.0 - a2) + a2).sqrt();
    0.5 / (gv + gl)
}

/// `(A, B)` of the module docs at `n·v = nov` (in (0, 1]) and GGX
/// roughness `alpha` (> 0).
pub fn dfg(nov: f64, alpha: f64) -> [f64; 2] {
    dfg_with(nov, alpha, &gauss_legendre(POINTS))
}

fn dfg_with(nov: f64, alpha: f64, rule: &[(f64, f64)]) -> [f64; 2] {
    let nov = nov.clamp(1e-6, 1.0);
    let alpha = alpha.max(1e-6);
    let a2 = alpha * alpha;
    let sin_v = (1.0 - nov * nov).max(0.0).sqrt();
    // Every φ has n·l > 0 for θ_h < π/4 − θ_v/2, some φ up to π/4 + θ_v/2
    // (where 2cos(θ_v ± θ_h)cos θ_h = cos θ_v): u in two rules split
    // there, so that neither spans a kink.
    let u_of = |theta: f64| {
        let c2 = theta.max(0.0).cos().powi(2);
        ((1.0 - c2) / (1.0 + c2 * (a2 - 1.0))).clamp(0.0, 1.0)
    };
    let tv = nov.acos();
    let (u1, u2) = (u_of(PI / 4.0 - 0.5 * tv), u_of(PI / 4.0 + 0.5 * tv));
    // In s = √(1 − u) (du = 2s ds): the integrand grows as 1/√(1 − u)
    // towards θ_h = 90° (1/(n·h)), which a grazing view reaches; in s it is
    // smooth.
    let (s1, s2) = ((1.0 - u1).sqrt(), (1.0 - u2).sqrt());
    let span = |lo: f64, hi: f64| {
        rule.iter().map(move |&(t, w)| {
            let s = lo + t * (hi - lo);
            (1.0 - s * s, 2.0 * s * w * (hi - lo))
        })
    };
    let points = span(s1, 1.0).chain(span(s2, s1));
    let (mut a, mut b) = (0.0, 0.0);
    for (u, wu) in points {
        let ch = ((1.0 - u) / (1.0 + (a2 - 1.0) * u)).sqrt();
        let sh = (1.0 - ch * ch).max(0.0).sqrt();
        // n·l = 2(v·h)(n·h) − n·v > 0 ⇔ cos φ > c0.
        let c0 = if sin_v * sh > 0.0 {
            (nov / (2.0 * ch) - nov * ch) / (sin_v * sh)
        } else if 2.0 * nov * ch * ch - nov > 0.0 {
            -1.0
        } else {
            1.0
        };
        if c0 >= 1.0 {
            continue;
        }
        let phi_max = c0.max(-1.0).acos();
        for &(t, wt) in rule {
            let phi = t * phi_max;
            let voh = sin_v * sh * phi.cos() + nov * ch;
            let nol = 2.0 * voh * ch - nov;
            if nol <= 0.0 || voh <= 0.0 {
                continue;
            }
            let g = 4.0 * visibility(nov, nol, alpha) * nol * voh / ch;
            let fc = (1.0 - voh).powi(5);
            // φ over [−φmax, φmax]: twice the half arc, over 2π.
            let w = wu * wt * phi_max / PI;
            a += w * g * (1.0 - fc);
            b += w * g * fc;
        }
    }
    [a, b]
}

/// The table, `size × size` texels of linear f32 RGB: R = A (the scale of
/// F0), G = B (the bias), B = 0. Column i holds `n·v = (i + ½)/size`,
/// row j (row 0 first) perceptual roughness `(j + ½)/size`, α its square
/// (as cmgen lays it out): a lookup at `(n·v, roughness)` with t = 0 at
/// the first row reads it.
pub fn table(size: u32) -> Result<Texture> {
    use rayon::prelude::*;
    let size = size.max(1);
    let rule = gauss_legendre(POINTS);
    let v: Vec<f32> = (0..size)
        .into_par_iter()
        .flat_map_iter(|j| {
            let r = (j as f64 + 0.5) / size as f64;
            let rule = &rule;
            (0..size).flat_map(move |i| {
                let [a, b] = dfg_with((i as f64 + 0.5) / size as f64, r * r, rule);
                [a as f32, b as f32, 0.0]
            })
        })
        .collect();
    Texture::from_f32(
        size,
        size,
        Format::new(3, ChannelType::F32, ColorSpace::Linear),
        v,
    )
}
