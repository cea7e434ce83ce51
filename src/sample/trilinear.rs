//! The isotropic lookup: magnification, the six minification/mip
//! combinations, trilinear (SPEC.md "Level of detail").
//!
//! - λ ≤ 0: the magnification filter on level 0.
//! - λ > 0: the minification filter on the level(s) the mip mode selects:
//!   `none` → level 0; `nearest` → d = ceil(d' + 0.5) − 1; `linear` →
//!   (1 − δ)·τ[floor(d')] + δ·τ[floor(d') + 1]. When δ = 0 the second level
//!   has weight 0 and is not read (so not traced).
//!
//! Trilinear is `min = mag = linear, mip = linear`: 8 texel reads.
//!
//! A lookup is split in two: a [`Plan`] (which filter, which levels, what
//! blend) made once per query, and [`probe`], which carries it out at a
//! position. Footprint assembly makes one plan and runs up to 16 probes
//! with it. The mip mode is a const parameter and the filters a type
//! ([`Filters`]), so each combination compiles to its own loop: the
//! nearest-mip path never takes a logarithm ([`Lod::plan_nearest`]), and
//! `mip = none` with equal filters never looks at the derivatives.

use super::bilinear::Filters;
use super::fetch::{Addressing, Chain, Pixel, lerp};
use super::footprint::{Lod, Plan};
use super::{MipMode, Query, SamplerOptions};
use crate::trace::TexelSink;

/// Mip mode `none` as a const parameter.
pub(crate) const MIP_NONE: u8 = 0;
/// Mip mode `nearest` as a const parameter.
pub(crate) const MIP_NEAREST: u8 = 1;
/// Mip mode `linear` as a const parameter.
pub(crate) const MIP_LINEAR: u8 = 2;

/// The [`MipMode`] of a const parameter.
#[inline(always)]
pub(crate) const fn mip_mode(m: u8) -> MipMode {
    match m {
        MIP_NONE => MipMode::None,
        MIP_NEAREST => MipMode::Nearest,
        _ => MipMode::Linear,
    }
}

/// Carry out `plan` at `(u, v)`.
#[inline(always)]
pub(crate) fn probe<P: Pixel, S: TexelSink, F: Filters>(
    c: &Chain<P>,
    f: F,
    plan: &Plan,
    u: f64,
    v: f64,
    a: &Addressing,
    sink: &mut S,
) -> [f32; 4] {
    let t = f.run(plan.magnify, c, plan.hi, u, v, a, sink);
    if plan.delta > 0.0 && plan.lo != plan.hi {
        let t2 = f.run(false, c, plan.lo, u, v, a, sink);
        lerp(t, t2, plan.delta)
    } else {
        t
    }
}

/// The plan of an isotropic lookup of `q` (the first half of a lookup;
/// [`probe`] at `(q.u, q.v)` moved into the first wrap period by
/// [`Lod::reduce`] is the second: the per-level filters then wrap only
/// footprints that really cross an edge).
#[inline(always)]
pub(crate) fn plan<F: Filters, const MIP: u8>(lod: &Lod, o: &SamplerOptions, q: &Query) -> Plan {
    match MIP {
        MIP_NONE if F::SAME => Plan::MAGNIFY,
        MIP_NONE => lod.plan_level0(q),
        MIP_NEAREST => lod.plan_nearest(q),
        _ => Plan::at(lod.lambda(q, o), lod.q, MipMode::Linear),
    }
}
