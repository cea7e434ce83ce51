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
use super::trilinear::{mip_mode, probe};
use super::{Query, SamplerOptions};
use crate::trace::TexelSink;

/// What footprint assembly needs per query, worked out before any texel
/// is read: the shared plan, the probe count, the centre (reduced to the
/// first wrap period) and the longer derivative vector.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Setup {
    pub plan: Plan,
    pub probes: u32,
    pub u: f64,
    pub v: f64,
    pub major: [f64; 2],
}

impl Setup {
    /// Position of probe `i` (1 ≤ i ≤ `probes`) with `step` = 1/(probes + 1):
    /// `centre + (i·step − 1/2)·major` (SPEC.md "Anisotropic probes").
    #[inline(always)]
    pub(crate) fn probe_at(&self, i: u32, step: f64) -> (f64, f64) {
        let t = i as f64 * step - 0.5;
        (self.u + t * self.major[0], self.v + t * self.major[1])
    }

    /// A placeholder (overwritten before use).
    pub const EMPTY: Setup = Setup {
        plan: Plan::MAGNIFY,
        probes: 1,
        u: 0.0,
        v: 0.0,
        major: [0.0; 2],
    };
}

/// The first half of a footprint-assembly lookup of `q`.
#[inline(always)]
pub(crate) fn setup<F: Filters, const MIP: u8>(lod: &Lod, o: &SamplerOptions, q: &Query) -> Setup {
    let (u, v) = lod.reduce(q);
    let fp = footprint_f64(q, lod.wf, lod.hf, o);
    Setup {
        plan: Plan::at(fp.lambda, lod.q, mip_mode(MIP)),
        probes: fp.probes,
        u,
        v,
        major: fp.major,
    }
}

/// The second half: the probes.
#[inline(always)]
pub(crate) fn anisotropic<P: Pixel, S: TexelSink, F: Filters>(
    c: &Chain<P>,
    f: F,
    st: &Setup,
    a: &Addressing,
    sink: &mut S,
) -> [f32; 4] {
    let (n, u, v) = (st.probes, st.u, st.v);
    if n <= 1 {
        return probe(c, f, &st.plan, u, v, a, sink);
    }
    let step = 1.0 / (n as f64 + 1.0);
    let inv = 1.0 / n as f32;
    let mut acc = [0.0f32; 4];
    for i in 1..=n {
        let (pu, pv) = st.probe_at(i, step);
        let p = probe(c, f, &st.plan, pu, pv, a, sink);
        for k in 0..4 {
            acc[k] += p[k] * inv;
        }
    }
    acc
}
