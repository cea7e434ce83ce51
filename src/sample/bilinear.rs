//! Filtering within one level: nearest and bilinear (SPEC.md "Texel
//! filtering").
//!
//! Coordinates arrive as `f64` normalized values; the texel-space position
//! `u·w` is formed in `f64` and floored to an `i64` before wrapping, so a
//! coordinate of 1e6 under `repeat` keeps its sub-texel position (an `f32`
//! product would have no fractional bits left at 2048 × 1e6). Weights are
//! full-precision `f32` (no 8-bit quantization).
//!
//! The fast path is a footprint entirely inside the level: the floor is a
//! magic-number round ([`floor_fast`]), then one bounds test per axis,
//! then the rows are read directly. Everything else — NaN, huge and
//! non-finite positions, footprints that cross an edge — takes one general
//! path per filter (`bilinear_edge`, `nearest_edge`), which moves `repeat`
//! and `mirror` coordinates into their first period and wraps each axis
//! once (two indices per axis, not one wrap per texel). The multi-probe
//! filters reduce the query's coordinates up front
//! ([`super::footprint::Lod::reduce`]), so their probes only leave the
//! fast path where they really straddle an edge.
//!
//! Non-finite positions never produce NaN: `floor_index` saturates ±Inf to
//! ±2^62 (then wrapped like any index) and the fraction is taken as 0.
//! NaN coordinates are replaced by 0 before they get here.

use crate::wrap::{FAST, WrapMode, fast_floor, floor_index, reduce_coordinate, wrap_index};

use super::fetch::{Addressing, Chain, Pixel, lerp};
use crate::trace::TexelSink;

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

/// 1.5·2^52: adding and subtracting it rounds an `f64` of magnitude below
/// 2^51 to an integer, whose value is then the low bits of the sum.
const MAGIC: f64 = 6_755_399_441_055_744.0;

/// `(floor(x), floor(x) as an integer)` for the fast paths, in a few
/// arithmetic instructions (no library call, no saturating conversion).
///
/// Exact for |x| < 2^51. For anything else — NaN, ±∞, huge values — the
/// integer is some value far outside every level (below −2^50 or above
/// 2^50 as an `i64`, so huge as a `u64`), which sends the caller to its
/// general path; that path does the full, defined handling. The bit
/// difference wraps by intent (for sums below 0 it leaves the `i64` range;
/// a plain `-` traps in builds with overflow checks).
#[inline(always)]
pub(crate) fn floor_fast(x: f64) -> (f64, i64) {
    let r = (x + MAGIC) - MAGIC;
    let r = r - if r > x { 1.0 } else { 0.0 };
    let i = ((r + MAGIC).to_bits() as i64).wrapping_sub(MAGIC.to_bits() as i64);
    (r, i)
}

/// A filter within one level, as a type so that filters are monomorphised
/// over it: [`Near`], [`Lin`], or a [`MagMin`] pair chosen at run time.
pub(crate) trait Filters: Copy {
    /// True when magnification and minification use the same filter, so
    /// the λ ≤ 0 test changes nothing but the level (level 0).
    const SAME: bool;
    /// True for [`Lin`] (bilinear for both), which has SIMD paths.
    const LINEAR: bool = false;
    /// True for [`Near`] (nearest for both), which has an isotropic SIMD
    /// path.
    const NEAREST: bool = false;
    /// Run the magnification (`magnify`) or minification filter on level
    /// `li`.
    #[allow(clippy::too_many_arguments)]
    fn run<P: Pixel, S: TexelSink>(
        self,
        magnify: bool,
        c: &Chain<P>,
        li: usize,
        u: f64,
        v: f64,
        a: &Addressing,
        sink: &mut S,
    ) -> [f32; 4];
}

/// Nearest for both magnification and minification.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Near;

/// Bilinear for both magnification and minification.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Lin;

/// Magnification and minification filters chosen at run time.
#[derive(Clone, Copy, Debug)]
pub(crate) struct MagMin {
    pub mag: super::TexelFilter,
    pub min: super::TexelFilter,
}

impl Filters for Near {
    const SAME: bool = true;
    const NEAREST: bool = true;
    #[inline(always)]
    fn run<P: Pixel, S: TexelSink>(
        self,
        _: bool,
        c: &Chain<P>,
        li: usize,
        u: f64,
        v: f64,
        a: &Addressing,
        sink: &mut S,
    ) -> [f32; 4] {
        nearest(c, li, u, v, a, sink)
    }
}

impl Filters for Lin {
    const SAME: bool = true;
    const LINEAR: bool = true;
    #[inline(always)]
    fn run<P: Pixel, S: TexelSink>(
        self,
        _: bool,
        c: &Chain<P>,
        li: usize,
        u: f64,
        v: f64,
        a: &Addressing,
        sink: &mut S,
    ) -> [f32; 4] {
        bilinear(c, li, u, v, a, sink)
    }
}

impl Filters for MagMin {
    const SAME: bool = false;
    #[inline(always)]
    fn run<P: Pixel, S: TexelSink>(
        self,
        magnify: bool,
        c: &Chain<P>,
        li: usize,
        u: f64,
        v: f64,
        a: &Addressing,
        sink: &mut S,
    ) -> [f32; 4] {
        match if magnify { self.mag } else { self.min } {
            super::TexelFilter::Nearest => nearest(c, li, u, v, a, sink),
            super::TexelFilter::Linear => bilinear(c, li, u, v, a, sink),
        }
    }
}

/// Nearest: texel `(floor(u·w), floor(v·h))` of level `li`. Reads one
/// texel. `u`, `v` may be anything, NaN included (read as 0).
#[inline(always)]
pub(crate) fn nearest<P: Pixel, S: TexelSink>(
    c: &Chain<P>,
    li: usize,
    u: f64,
    v: f64,
    a: &Addressing,
    sink: &mut S,
) -> [f32; 4] {
    let l = &c.levels[li];
    let (_, i) = floor_fast(u * l.wf);
    let (_, j) = floor_fast(v * l.hf);
    unpack(if (i as u64) < l.w as u64 && (j as u64) < l.h as u64 {
        pack(l.at(&c.lut, li as u32, i as usize, j as usize, sink))
    } else {
        nearest_edge(c, li, u, v, a, sink)
    })
}

/// An RGBA value as the out-of-line paths return it, in registers. The
/// Rust ABI returns an `[f32; 4]` from a call that is not inlined through
/// memory; the fast path's result then meets it in that stack slot,
/// written as four 4-byte stores and read back as wider loads, which no
/// x86 core forwards from the store buffer (it waits for the stores to
/// retire: a quarter of a single nearest lookup's time). The functions
/// that return it use the C convention (`C-unwind`: a panic stays a
/// panic), which returns an `__m128` in one register on x86-64, where SSE
/// is part of the base instruction set; [`pack`] makes it in registers.
#[cfg(target_arch = "x86_64")]
pub(crate) type Rgba = std::arch::x86_64::__m128;

/// An RGBA value as the out-of-line paths return it: a C struct of four
/// floats, which the C ABIs return in registers (AArch64: four).
#[cfg(not(target_arch = "x86_64"))]
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub(crate) struct Rgba([f32; 4]);

/// `c` as an [`Rgba`].
#[inline(always)]
#[allow(unsafe_code)]
pub(crate) fn pack(c: [f32; 4]) -> Rgba {
    // SAFETY: SSE is part of x86-64's base instruction set.
    #[cfg(target_arch = "x86_64")]
    unsafe {
        std::arch::x86_64::_mm_setr_ps(c[0], c[1], c[2], c[3])
    }
    #[cfg(not(target_arch = "x86_64"))]
    Rgba(c)
}

/// The four channels of `c`.
#[inline(always)]
#[allow(unsafe_code)]
pub(crate) fn unpack(c: Rgba) -> [f32; 4] {
    // SAFETY: as in `pack`.
    #[cfg(target_arch = "x86_64")]
    unsafe {
        use std::arch::x86_64::{_mm_cvtss_f32, _mm_shuffle_ps};
        [
            _mm_cvtss_f32(c),
            _mm_cvtss_f32(_mm_shuffle_ps::<0b01_01_01_01>(c, c)),
            _mm_cvtss_f32(_mm_shuffle_ps::<0b10_10_10_10>(c, c)),
            _mm_cvtss_f32(_mm_shuffle_ps::<0b11_11_11_11>(c, c)),
        ]
    }
    #[cfg(not(target_arch = "x86_64"))]
    c.0
}

/// [`nearest`] in general: NaN, huge and outside coordinates, wrapping,
/// the border colour.
#[inline(never)]
#[allow(improper_ctypes_definitions)] // called from Rust only: see `Rgba`
extern "C-unwind" fn nearest_edge<P: Pixel, S: TexelSink>(
    c: &Chain<P>,
    li: usize,
    u: f64,
    v: f64,
    a: &Addressing,
    sink: &mut S,
) -> Rgba {
    let l = &c.levels[li];
    let i = fast_floor(reduce_coordinate(u, a.wrap.u) * l.wf);
    let j = fast_floor(reduce_coordinate(v, a.wrap.v) * l.hf);
    pack(l.fetch(&c.lut, li as u32, i, j, a, sink))
}

/// Bilinear: the 2×2 texels around `(u·w − 0.5, v·h − 0.5)` of level `li`
/// with weights `(1−α)(1−β), α(1−β), (1−α)β, αβ`. Always reads (and
/// reports) four texels, as hardware does, in the order (i0,j0), (i1,j0),
/// (i0,j1), (i1,j1). `u`, `v` may be anything, NaN included (read as 0).
#[inline(always)]
pub(crate) fn bilinear<P: Pixel, S: TexelSink>(
    c: &Chain<P>,
    li: usize,
    u: f64,
    v: f64,
    a: &Addressing,
    sink: &mut S,
) -> [f32; 4] {
    let l = &c.levels[li];
    let x = u * l.wf - 0.5;
    let y = v * l.hf - 0.5;
    let (fx, i0) = floor_fast(x);
    let (fy, j0) = floor_fast(y);
    // `w − 1` cannot underflow (w ≥ 1); a 1-texel axis always wraps. NaN
    // and huge positions fail this test too (see `floor_fast`).
    unpack(
        if (i0 as u64) < (l.w - 1) as u64 && (j0 as u64) < (l.h - 1) as u64 {
            let (al, be) = ((x - fx) as f32, (y - fy) as f32);
            let (x, y, w) = (i0 as usize, j0 as usize, l.w as usize);
            let k = y * w + x;
            // One bounds check for the 2×2 block (both rows).
            let b = &l.texels[k..k + w + 2];
            let li = li as u32;
            let (x, y) = (x as u32, y as u32);
            sink.texel(li, x, y);
            sink.texel(li, x + 1, y);
            sink.texel(li, x, y + 1);
            sink.texel(li, x + 1, y + 1);
            pack(P::bilerp([b[0], b[1], b[w], b[w + 1]], &c.lut, al, be))
        } else {
            bilinear_edge(c, li, u, v, a, sink)
        },
    )
}

/// Column (or row) indices `i` and `i + 1` after wrapping; `None` reads
/// the border colour.
#[inline(always)]
fn axis_pair(mode: WrapMode, i: i64, size: u32) -> (Option<u32>, Option<u32>) {
    let s = size as i64;
    match mode {
        WrapMode::Repeat => {
            // One reduction for both indices, usually without a division.
            let x = if (0..s).contains(&i) {
                i
            } else if (-s..0).contains(&i) {
                i + s
            } else {
                i.rem_euclid(s)
            };
            let x1 = if x + 1 == s { 0 } else { x + 1 };
            (Some(x as u32), Some(x1 as u32))
        }
        _ => (wrap_index(mode, i, size), wrap_index(mode, i + 1, size)),
    }
}

/// [`bilinear`] in general: NaN, huge and non-finite coordinates, and
/// footprints that cross the edge of the level (each axis wrapped once).
#[inline(never)]
#[allow(improper_ctypes_definitions)] // called from Rust only: see `Rgba`
extern "C-unwind" fn bilinear_edge<P: Pixel, S: TexelSink>(
    c: &Chain<P>,
    li: usize,
    u: f64,
    v: f64,
    a: &Addressing,
    sink: &mut S,
) -> Rgba {
    let l = &c.levels[li];
    let (i0, al) = split(reduce_coordinate(u, a.wrap.u) * l.wf - 0.5);
    let (j0, be) = split(reduce_coordinate(v, a.wrap.v) * l.hf - 0.5);
    let (x0, x1) = axis_pair(a.wrap.u, i0, l.w);
    let (y0, y1) = axis_pair(a.wrap.v, j0, l.h);
    let mut get = |x: Option<u32>, y: Option<u32>| match (x, y) {
        (Some(x), Some(y)) => l.at(&c.lut, li as u32, x as usize, y as usize, sink),
        _ => a.border,
    };
    let t00 = get(x0, y0);
    let t10 = get(x1, y0);
    let t01 = get(x0, y1);
    let t11 = get(x1, y1);
    pack(lerp(lerp(t00, t10, al), lerp(t01, t11, al), be))
}
