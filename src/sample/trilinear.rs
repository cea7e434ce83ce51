//! The isotropic lookup at a given λ: magnification, the six
//! minification/mip combinations, trilinear (SPEC.md "Level of detail").
//!
//! - λ ≤ 0: the magnification filter on level 0.
//! - λ > 0: the minification filter on the level(s) the mip mode selects:
//!   `none` → level 0; `nearest` → d = ceil(d' + 0.5) − 1; `linear` →
//!   (1 − δ)·τ[floor(d')] + δ·τ[floor(d') + 1]. When δ = 0 the second level
//!   has weight 0 and is not read (so not traced).
//!
//! Trilinear is `min = mag = linear, mip = linear`: 8 texel reads.

use super::bilinear::texel_filter;
use super::fetch::{Addressing, Level, lerp};
use super::footprint::levels_for;
use super::trace::TexelSink;
use super::{MipMode, TexelFilter};

/// The parts of the options an isotropic lookup needs.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Iso {
    pub mag: TexelFilter,
    pub min: TexelFilter,
    pub mip: MipMode,
}

/// Isotropic lookup of `(u, v)` at λ.
#[inline(always)]
pub(crate) fn isotropic<S: TexelSink>(
    levels: &[Level],
    o: Iso,
    a: &Addressing,
    u: f64,
    v: f64,
    lambda: f32,
    sink: &mut S,
) -> [f32; 4] {
    // λ is never NaN (see footprint); the guard costs nothing.
    if lambda <= 0.0 || lambda.is_nan() {
        return texel_filter(o.mag, &levels[0], 0, u, v, a, sink);
    }
    let q = levels.len() - 1;
    let (hi, lo, delta) = levels_for(lambda, q, o.mip);
    let t = texel_filter(o.min, &levels[hi], hi as u32, u, v, a, sink);
    if delta > 0.0 && lo != hi {
        let t2 = texel_filter(o.min, &levels[lo], lo as u32, u, v, a, sink);
        lerp(t, t2, delta)
    } else {
        t
    }
}
