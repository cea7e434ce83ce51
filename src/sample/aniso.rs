//! Footprint assembly (EXT_texture_filter_anisotropic; SPEC.md
//! "Anisotropic probes").
//!
//! N = ceil(η) isotropic lookups at λ = log2(ρmax/η) (+ bias, clamped),
//! centred on `(u, v)` and spread along the longer derivative vector at
//! offsets `(i/(N+1) − 1/2)·major`, i = 1..N, each weighted 1/N. With
//! `max_aniso = 1` (or an isotropic footprint) N = 1 and the single probe
//! sits at `(u, v)`: this *is* the nearest/bilinear/trilinear path, so
//! "anisotropic with η = 1 equals trilinear" holds bit for bit.
//!
//! Work per query is bounded by `max_aniso` (≤ 16) probes of at most 8
//! texels. A probe position is computed in `f64`; huge derivative vectors
//! give huge (saturated, then wrapped) positions, never NaN.

use super::fetch::{Addressing, Level};
use super::footprint::Footprint;
use super::trace::TexelSink;
use super::trilinear::{Iso, isotropic};

/// Footprint-assembly lookup of `(u, v)` with footprint `fp`.
#[inline(always)]
pub(crate) fn anisotropic<S: TexelSink>(
    levels: &[Level],
    o: Iso,
    a: &Addressing,
    u: f64,
    v: f64,
    fp: &Footprint,
    sink: &mut S,
) -> [f32; 4] {
    let n = fp.probes;
    if n <= 1 {
        return isotropic(levels, o, a, u, v, fp.lambda, sink);
    }
    let step = 1.0 / (n as f64 + 1.0);
    // f64 sum: 16 probes of texels near f32::MAX must not overflow.
    let mut acc = [0.0f64; 4];
    for i in 1..=n {
        let t = i as f64 * step - 0.5;
        let p = isotropic(
            levels,
            o,
            a,
            u + t * fp.major[0],
            v + t * fp.major[1],
            fp.lambda,
            sink,
        );
        for c in 0..4 {
            acc[c] += p[c] as f64;
        }
    }
    let inv = 1.0 / n as f64;
    acc.map(|x| (x * inv) as f32)
}
