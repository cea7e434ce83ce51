//! Filtering within one level: nearest and bilinear (SPEC.md "Texel
//! filtering").
//!
//! Coordinates arrive as `f64` normalized values; the texel-space position
//! `u·w` is formed in `f64` and floored to an `i64` before wrapping, so a
//! coordinate of 1e6 under `repeat` keeps its sub-texel position (an `f32`
//! product would have no fractional bits left at 2048 × 1e6). Weights are
//! full-precision `f32` (no 8-bit quantization).
//!
//! Non-finite positions never produce NaN: `floor_index` saturates ±Inf to
//! ±2^62 (then wrapped like any index) and the fraction is taken as 0.
//! NaN coordinates are replaced by 0 before they get here.

use crate::wrap::floor_index;

use super::TexelFilter;
use super::fetch::{Addressing, Level, lerp};
use super::trace::TexelSink;

/// Below this magnitude the truncating cast gives the floor directly.
const FAST: f64 = 4_503_599_627_370_496.0; // 2^52

/// `floor(x)` as an index, saturating like [`floor_index`] (NaN → 0).
///
/// `f64::floor` is a library call on the x86-64 baseline (no SSE4.1
/// `roundsd`); a truncating cast and a compare are a few cycles.
#[inline(always)]
pub(crate) fn fast_floor(x: f64) -> i64 {
    if x.abs() < FAST {
        let i = x as i64;
        i - i64::from((i as f64) > x)
    } else {
        floor_index(x)
    }
}

/// Floor (saturating, as an index) and fraction in [0, 1] of a texel-space
/// coordinate; the fraction is 0 for non-finite or huge input (there is
/// no fractional part left above 2^52).
#[inline(always)]
pub(crate) fn split(x: f64) -> (i64, f32) {
    if x.abs() < FAST {
        let i = x as i64;
        let i = i - i64::from((i as f64) > x);
        (i, (x - i as f64) as f32)
    } else {
        (floor_index(x), 0.0)
    }
}

/// Nearest: texel `(floor(u·w), floor(v·h))`. Reads one texel.
#[inline(always)]
pub(crate) fn nearest<S: TexelSink>(
    l: &Level,
    li: u32,
    u: f64,
    v: f64,
    a: &Addressing,
    sink: &mut S,
) -> [f32; 4] {
    l.fetch(li, fast_floor(u * l.wf), fast_floor(v * l.hf), a, sink)
}

/// Bilinear: the 2×2 texels around `(u·w − 0.5, v·h − 0.5)` with weights
/// `(1−α)(1−β), α(1−β), (1−α)β, αβ`. Always reads (and reports) four
/// texels, as hardware does, in the order (i0,j0), (i1,j0), (i0,j1),
/// (i1,j1).
#[inline(always)]
pub(crate) fn bilinear<S: TexelSink>(
    l: &Level,
    li: u32,
    u: f64,
    v: f64,
    a: &Addressing,
    sink: &mut S,
) -> [f32; 4] {
    let (i0, al) = split(u * l.wf - 0.5);
    let (j0, be) = split(v * l.hf - 0.5);
    let (t00, t10, t01, t11);
    if i0 >= 0 && j0 >= 0 && i0 + 1 < l.w as i64 && j0 + 1 < l.h as i64 {
        // Interior: no wrapping needed.
        let (x, y) = (i0 as usize, j0 as usize);
        t00 = l.at(li, x, y, sink);
        t10 = l.at(li, x + 1, y, sink);
        t01 = l.at(li, x, y + 1, sink);
        t11 = l.at(li, x + 1, y + 1, sink);
    } else {
        t00 = l.fetch(li, i0, j0, a, sink);
        t10 = l.fetch(li, i0 + 1, j0, a, sink);
        t01 = l.fetch(li, i0, j0 + 1, a, sink);
        t11 = l.fetch(li, i0 + 1, j0 + 1, a, sink);
    }
    lerp(lerp(t00, t10, al), lerp(t01, t11, al), be)
}

/// Nearest or bilinear, as chosen.
#[inline(always)]
pub(crate) fn texel_filter<S: TexelSink>(
    f: TexelFilter,
    l: &Level,
    li: u32,
    u: f64,
    v: f64,
    a: &Addressing,
    sink: &mut S,
) -> [f32; 4] {
    match f {
        TexelFilter::Nearest => nearest(l, li, u, v, a, sink),
        TexelFilter::Linear => bilinear(l, li, u, v, a, sink),
    }
}
