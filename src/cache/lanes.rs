//! The texels of 8 isotropic lookups at a time, for
//! [`AddressOnly::trace_all`](super::isotropic::AddressOnly): where the
//! portable code takes each lane's `(u, v)` and level through
//! `floor(u·w − ½)`, the inside-the-level test and the layout's address
//! formula one lane after another, here the 8 lanes of one level choice
//! (the finer or the coarser level of each lookup) go through the same
//! `f64` and integer operations in AVX-512 registers.
//!
//! Only lanes whose block (or texel) lies inside its level are given:
//! the others (the edge path, NaN, infinite or huge coordinates, a level
//! past the chain) take the portable code, which decides them as before.
//! Inside a level the floor is exact either way (the portable
//! `floor_fast` is exact below 2^51, far beyond any level), so a lane
//! given here reads what the portable code reads, at the addresses
//! `ChainLayout::address` gives (`tests/core/cache_report/cache_fast_paths.rs` compares
//! whole scene runs and written traces with the traced sampler's).
#![allow(unsafe_code)]

use std::arch::x86_64::*;

use super::layout::{LANE_LEVELS, Lanes};

/// Level widths and heights as `f64` tables of [`LANE_LEVELS`] entries
/// (NaN past the chain's last level, so never inside).
#[derive(Clone, Debug)]
pub(crate) struct Sizes {
    w: [f64; LANE_LEVELS],
    h: [f64; LANE_LEVELS],
    levels: u64,
}

impl Sizes {
    /// The tables of levels of `(w, h)`; `None` for more than
    /// [`LANE_LEVELS`] levels.
    pub(crate) fn new(levels: &[(u32, u32, f64, f64)]) -> Option<Sizes> {
        if levels.len() > LANE_LEVELS {
            return None;
        }
        let mut s = Sizes {
            w: [f64::NAN; LANE_LEVELS],
            h: [f64::NAN; LANE_LEVELS],
            levels: levels.len() as u64,
        };
        for (k, &(_, _, w, h)) in levels.iter().enumerate() {
            (s.w[k], s.h[k]) = (w, h);
        }
        Some(s)
    }
}

/// One level choice of 8 lookups: which lanes are inside their level
/// (bit `i`), their texel (nearest) or the block's first texel
/// (bilinear), and with a layout the addresses of the texel (`at[0]`) or
/// of the block's four texels in read order.
#[derive(Default)]
pub(crate) struct Cells8 {
    pub inside: u8,
    pub x: [u64; 8],
    pub y: [u64; 8],
    pub at: [[u64; 8]; 4],
}

/// [`Cells8`] of the lanes `(u, v)` at levels `level` (`linear`:
/// bilinear blocks, else nearest texels), with the addresses of `layout`
/// when given, into `c` (in place: a returned value was copied by
/// `memmove`, a tenth of the run).
///
/// # Safety
/// The CPU has AVX-512 F and DQ (a [`crate::sample::simd::Planner`]
/// exists).
#[target_feature(enable = "avx512f,avx512dq")]
pub(crate) unsafe fn cells8(
    sizes: &Sizes,
    level: &[i64; 8],
    u: &[f64; 8],
    v: &[f64; 8],
    linear: bool,
    layout: Option<&Lanes>,
    c: &mut Cells8,
) {
    const FLOOR: i32 = _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC;
    // SAFETY: unaligned loads of whole arrays of a register's size, and
    // of the two halves of the 16-entry tables.
    let (k, u, v, w_lo, w_hi, h_lo, h_hi) = unsafe {
        (
            _mm512_loadu_si512(level.as_ptr().cast()),
            _mm512_loadu_pd(u.as_ptr()),
            _mm512_loadu_pd(v.as_ptr()),
            _mm512_loadu_pd(sizes.w.as_ptr()),
            _mm512_loadu_pd(sizes.w[8..].as_ptr()),
            _mm512_loadu_pd(sizes.h.as_ptr()),
            _mm512_loadu_pd(sizes.h[8..].as_ptr()),
        )
    };
    // A level past the chain (or negative, as unsigned) is never inside.
    let known = _mm512_cmplt_epu64_mask(k, _mm512_set1_epi64(sizes.levels as i64));
    let wf = _mm512_permutex2var_pd(w_lo, k, w_hi);
    let hf = _mm512_permutex2var_pd(h_lo, k, h_hi);
    // The portable code's `u·w − ½` (bilinear) or `u·w` (nearest), then
    // its inside test `0 ≤ i < w − 1` (or `< w`) on the exact floor;
    // ordered compares, so NaN is outside.
    let (half, one) = if linear {
        (_mm512_set1_pd(0.5), _mm512_set1_pd(1.0))
    } else {
        (_mm512_setzero_pd(), _mm512_setzero_pd())
    };
    let x = _mm512_roundscale_pd::<FLOOR>(_mm512_sub_pd(_mm512_mul_pd(u, wf), half));
    let y = _mm512_roundscale_pd::<FLOOR>(_mm512_sub_pd(_mm512_mul_pd(v, hf), half));
    let zero = _mm512_setzero_pd();
    let inside = known
        & _mm512_cmp_pd_mask::<_CMP_GE_OQ>(x, zero)
        & _mm512_cmp_pd_mask::<_CMP_GE_OQ>(y, zero)
        & _mm512_cmp_pd_mask::<_CMP_LT_OQ>(x, _mm512_sub_pd(wf, one))
        & _mm512_cmp_pd_mask::<_CMP_LT_OQ>(y, _mm512_sub_pd(hf, one));
    // Lanes outside may hold anything: nothing reads them.
    let (xi, yi) = (_mm512_cvttpd_epu64(x), _mm512_cvttpd_epu64(y));
    c.inside = inside;
    // SAFETY: unaligned stores of whole registers into arrays of their
    // size.
    unsafe {
        _mm512_storeu_si512(c.x.as_mut_ptr().cast(), xi);
        _mm512_storeu_si512(c.y.as_mut_ptr().cast(), yi);
    }
    let Some(l) = layout else {
        return;
    };
    // SAFETY: as the loads above.
    let (b_lo, b_hi, r_lo, r_hi) = unsafe {
        (
            _mm512_loadu_si512(l.base.as_ptr().cast()),
            _mm512_loadu_si512(l.base[8..].as_ptr().cast()),
            _mm512_loadu_si512(l.row.as_ptr().cast()),
            _mm512_loadu_si512(l.row[8..].as_ptr().cast()),
        )
    };
    let base = _mm512_permutex2var_epi64(b_lo, k, b_hi);
    let row = _mm512_permutex2var_epi64(r_lo, k, r_hi);
    let (bx, by) = (
        _mm512_set1_epi64(l.bx as i64),
        _mm512_set1_epi64(l.by as i64),
    );
    let bxy = _mm512_set1_epi64((l.bx + l.by) as i64);
    let (mx, my) = (
        _mm512_set1_epi64((1i64 << l.bx) - 1),
        _mm512_set1_epi64((1i64 << l.by) - 1),
    );
    let texel = _mm512_set1_epi64(l.texel as i64);
    // `base + tiled_offset(row, bx, by, x, y) · texel`, as
    // `ChainLayout::address` computes it.
    let address = |x: __m512i, y: __m512i| {
        let tile = _mm512_add_epi64(
            _mm512_mullo_epi64(_mm512_srlv_epi64(y, by), row),
            _mm512_srlv_epi64(x, bx),
        );
        let inner = _mm512_or_si512(
            _mm512_sllv_epi64(_mm512_and_si512(y, my), bx),
            _mm512_and_si512(x, mx),
        );
        let offset = _mm512_add_epi64(_mm512_sllv_epi64(tile, bxy), inner);
        _mm512_add_epi64(base, _mm512_mullo_epi64(offset, texel))
    };
    let at: [__m512i; 4] = if linear {
        let (x1, y1) = (
            _mm512_add_epi64(xi, _mm512_set1_epi64(1)),
            _mm512_add_epi64(yi, _mm512_set1_epi64(1)),
        );
        [
            address(xi, yi),
            address(x1, yi),
            address(xi, y1),
            address(x1, y1),
        ]
    } else {
        let a = address(xi, yi);
        [a, a, a, a]
    };
    for (out, a) in c.at.iter_mut().zip(at) {
        // SAFETY: as the stores above.
        unsafe { _mm512_storeu_si512(out.as_mut_ptr().cast(), a) };
    }
}
