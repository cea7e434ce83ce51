//! Filtered importance sampling (Křivánek & Colbert 2008, as Filament's
//! cmgen and Khronos's glTF-IBL-Sampler do it), kept as the alternative to
//! the quadrature for comparison: per texel, `samples` directions drawn
//! from the lobe on a Hammersley sequence (deterministic), each a
//! trilinear lookup of the source cube's mip chain (seamless) at
//! `λ = ½·log2(Ω_s/Ω_p) + 1`, with Ω_s = 1/(samples·pdf) the solid angle a
//! sample stands for and Ω_p = 4π/(6·size²) a level-0 texel's. Karis's
//! estimator `Σ L(l_i)(n·l_i) / Σ (n·l_i)` with `l_i` drawn from `D(h)`
//! converges to the weight of the module docs of [`super`]. It is noisy
//! where the environment has a small bright source (the README's table).

use std::f64::consts::PI;

use super::super::DirQuery;
use super::super::cube::CubeSampler;
use super::super::vec3::{cross, unit};
use super::{Lobe, phong_exponent};

/// A direction in `lobe` around +z for the sequence point `(u1, u2)` and
/// its density in l (per steradian).
fn sample(lobe: Lobe, alpha: f64, u1: f64, u2: f64) -> ([f64; 3], f64) {
    let phi = 2.0 * PI * u1;
    match lobe {
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
            let c = match lobe {
                Lobe::Ggx => ((1.0 - u2) / (1.0 + (a2 - 1.0) * u2)).sqrt(),
                _ => 1.0 / (1.0 - a2 * (1.0 - u2).ln()).sqrt(),
            };
            let sin = (1.0 - c * c).max(0.0).sqrt();
            let h = [sin * phi.cos(), sin * phi.sin(), c];
            // l = reflect(−v, h) with v = n = +z.
            let l = [2.0 * c * h[0], 2.0 * c * h[1], 2.0 * c * c - 1.0];
            // p(l) = D(h)(n·h)/(4(v·h)) = D(h)/4 with v = n.
            (l, lobe.d(alpha, c) / 4.0)
        }
    }
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

/// Karis's estimator at direction `n` (unit) over `source`, whose level-0
/// texels subtend `texel_angle` steradians.
pub(super) fn lobe_average(
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
        let (l, pdf) = sample(lobe, a, u1, u2);
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
