//! Footprint assembly (EXT_texture_filter_anisotropic; SPEC.md
//! "Anisotropic probes").
//!
//! N = ceil(η) isotropic lookups at λ = log2(ρmax/η) (+ bias, clamped),
//! centred on `(u, v)` and spread along the longer derivative vector at
//! offsets `(i/(N+1) − 1/2)·major`, i = 1..N, each weighted 1/N. With
//! `max_aniso = 1` (or an isotropic footprint) N = 1 and the single probe
//! sits at `(u, v)`: this is the isotropic lookup, so "anisotropic with
//! η = 1 equals trilinear" holds bit for bit.
//!
//! λ, the levels and the blend weight are the same for every probe, so
//! they are worked out once per query (a [`Plan`]); each probe is then a
//! trilinear (or nearest/bilinear) read at its position.
//!
//! Work per query is bounded by `max_aniso` (≤ 16) probes of at most 8
//! texels. A probe position is computed in `f64`; huge derivative vectors
//! give huge (saturated, then wrapped) positions, never NaN. Each probe is
//! scaled by 1/N before it is added, so 16 probes of texels near `f32::MAX`
//! cannot overflow the sum.

use super::bilinear::Filters;
use super::fetch::{Addressing, Chain, Pixel};
use super::footprint::{Lod, Plan, footprint_f64};
use super::trace::TexelSink;
use super::trilinear::{mip_mode, probe};
use super::{Query, SamplerOptions};

/// Footprint-assembly lookup of `q`.
#[inline(always)]
pub(crate) fn anisotropic<P: Pixel, S: TexelSink, F: Filters, const MIP: u8>(
    c: &Chain<P>,
    f: F,
    lod: &Lod,
    o: &SamplerOptions,
    a: &Addressing,
    q: &Query,
    sink: &mut S,
) -> [f32; 4] {
    let (u, v) = lod.reduce(q);
    let fp = footprint_f64(q, lod.wf, lod.hf, o);
    let plan = Plan::at(fp.lambda, lod.q, mip_mode(MIP));
    let n = fp.probes;
    if n <= 1 {
        return probe(c, f, &plan, u, v, a, sink);
    }
    let step = 1.0 / (n as f64 + 1.0);
    let inv = 1.0 / n as f32;
    let mut acc = [0.0f32; 4];
    for i in 1..=n {
        let t = i as f64 * step - 0.5;
        let p = probe(
            c,
            f,
            &plan,
            u + t * fp.major[0],
            v + t * fp.major[1],
            a,
            sink,
        );
        for k in 0..4 {
            acc[k] += p[k] * inv;
        }
    }
    acc
}
