//! The AVX-512 inner loops of the fast EWA for packed RGBA8 chains
//! (lookups on CPUs with AVX-512 F, BW, DQ, VL and VBMI; see
//! [`super::ewa`]).
//!
//! [`scan`] takes one level of one lookup. Its lines (rows, or columns for
//! an ellipse taller than wide) are solved 16 at a time in vectors: each
//! run's ends, its r² at the start and first difference, and whether it
//! lies inside the level. The texels are then *staged*: their codes and
//! r² stored 16 at a time at the end of a buffer that advances by the
//! number kept, so the texels of a level lie end to end with no gaps and
//! no branch per texel. The buffer is summed 16 texels at a time: the
//! weight polynomial on 16 lanes, the 64 codes decoded at once
//! ([`super::simd::decode_rgba8`], RGBA `f32` per 128-bit group) and each
//! texel's weight spread over its group, into four independent sets of
//! sums.
//!
//! How the texels reach the buffer:
//! - along rows, each run is one masked load ([`Runs::push`]);
//! - down columns, a gather per run costs more than everything else, so
//!   the rows the runs cover are *swept* instead ([`sweep`]): 16 / C rows
//!   of the C ≥ n adjacent texels of the n lines per step, each row one
//!   masked load, r² from the quadratic form, the texels with r² < 1
//!   compressed into the buffer. Across an edge of the level the sweep
//!   reads each row and line at its wrapped index (gathers; the border
//!   colour where the wrap mode says so);
//! - what is left (a run crossing an edge along rows, levels too large for
//!   32-bit offsets) is read texel by texel through the wrap rules.
//!
//! The weights are the scalar path's polynomial; r² is computed from the
//! run's polynomial or the quadratic form at each texel rather than
//! stepped, and the sums are taken in another order, so the result differs
//! from the scalar build in the last bits (both are held to the
//! exact-weight EWA within 1e-3). Traced and untraced lookups take the
//! same path and give the same result, bit for bit.

// Intrinsics: every `unsafe` block says which features are enabled and
// why its memory accesses stay in bounds.
#![allow(unsafe_code)]

use std::arch::x86_64::*;
use std::mem::MaybeUninit;

use super::ewa::{MAX_LINES, WEIGHT_POLY, weight_poly};
use super::fetch::Lut8;
use super::simd::decode_rgba8;
use crate::wrap::{WrapMode, fast_floor, wrap_index};

/// Texels the buffer holds before it is summed (runs are at most about
/// `2·MAX_RADIUS + 3` texels, far below this).
const CAP: usize = 512;

/// The staged texels of one level of one lookup, and the sums of those
/// already summed.
pub(crate) struct Runs {
    codes: [MaybeUninit<u32>; CAP + 16],
    r2: [MaybeUninit<f32>; CAP + 16],
    /// Staged texels: entries `0..n` of both buffers hold them, and every
    /// entry below `n` rounded up to 16 has been written.
    n: usize,
    sums: [f32; 5],
}

impl Runs {
    /// An empty buffer (nothing written, nothing to clear).
    #[inline(always)]
    pub(crate) fn new() -> Runs {
        Runs {
            codes: [const { MaybeUninit::uninit() }; CAP + 16],
            r2: [const { MaybeUninit::uninit() }; CAP + 16],
            n: 0,
            sums: [0.0; 5],
        }
    }

    /// Stage the run of `len` texels starting at `first`, `stride` texels
    /// apart (1 along a row, the level's width down a column), whose r² at
    /// texel `k` is `r2 + k·d + k(k−1)/2·dd`. With `trace`, `hit(k)` is
    /// called for every texel `k` of the run that will get a weight (r² <
    /// 1, the test [`Self::sum`] applies to the same stored r²).
    ///
    /// # Safety
    /// The CPU has AVX-512 F, BW, DQ, VL and VBMI; `first`, `first +
    /// stride`, … `first + (len − 1)·stride` are texels of one allocation;
    /// `1 ≤ len ≤ CAP − 16`; `15·stride` fits an `i32`.
    #[inline]
    #[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
    #[allow(clippy::too_many_arguments)]
    pub(crate) unsafe fn push(
        &mut self,
        lut: &Lut8,
        first: *const u32,
        stride: usize,
        len: usize,
        (r2, d, dd): (f32, f32, f32),
        trace: bool,
        hit: &mut impl FnMut(usize),
    ) {
        if self.n + len + 16 > CAP {
            self.sum(lut);
        }
        let lanes = _mm512_setr_ps(
            0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0, 11.0, 12.0, 13.0, 14.0, 15.0,
        );
        let offsets = _mm512_mullo_epi32(
            _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15),
            _mm512_set1_epi32(stride as i32),
        );
        let (r2v, dv, ddv) = (_mm512_set1_ps(r2), _mm512_set1_ps(d), _mm512_set1_ps(dd));
        let half = _mm512_set1_ps(0.5);
        let codes = self.codes.as_mut_ptr().cast::<u32>();
        let r2s = self.r2.as_mut_ptr().cast::<f32>();
        let mut done = 0;
        while done < len {
            let m = (len - done).min(16);
            let mask = (((1u32 << m) - 1) & 0xffff) as u16;
            // SAFETY: lanes below `m` read texels `done … done + m − 1` of
            // the run, inside its allocation (the caller's contract); the
            // masked-off lanes read nothing.
            let c = unsafe {
                let p = first.add(done * stride);
                if stride == 1 {
                    _mm512_maskz_loadu_epi32(mask, p.cast::<i32>())
                } else {
                    _mm512_mask_i32gather_epi32::<4>(
                        _mm512_setzero_si512(),
                        mask,
                        offsets,
                        p.cast::<i32>(),
                    )
                }
            };
            // r² at k = done + lane: r2 + k·d + k(k−1)/2·dd.
            let k = _mm512_add_ps(lanes, _mm512_set1_ps(done as f32));
            let tri = _mm512_mul_ps(
                _mm512_mul_ps(k, _mm512_sub_ps(k, _mm512_set1_ps(1.0))),
                half,
            );
            let r = _mm512_fmadd_ps(tri, ddv, _mm512_fmadd_ps(k, dv, r2v));
            if trace {
                let mut m = _mm512_mask_cmp_ps_mask::<_CMP_LT_OQ>(mask, r, _mm512_set1_ps(1.0));
                while m != 0 {
                    hit(done + m.trailing_zeros() as usize);
                    m &= m - 1;
                }
            }
            // SAFETY: `n + m + 16 ≤ CAP + 16` (checked above, m ≤ len), so
            // the 16 entries from `n` are inside both buffers.
            unsafe {
                _mm512_storeu_si512(codes.add(self.n).cast(), c);
                _mm512_storeu_ps(r2s.add(self.n), r);
            }
            self.n += m;
            done += m;
        }
    }

    /// Stage the lanes of `codes` (texel codes) and `r2` (their r²)
    /// that `keep` selects, packed at the end of the buffer.
    ///
    /// # Safety
    /// The CPU has AVX-512 F, BW, DQ, VL and VBMI.
    #[inline]
    #[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi,popcnt")]
    pub(crate) unsafe fn compress(&mut self, lut: &Lut8, codes: __m512i, r2: __m512, keep: u16) {
        if self.n + 16 > CAP {
            self.sum(lut);
        }
        let codes = _mm512_maskz_compress_epi32(keep, codes);
        let r2 = _mm512_maskz_compress_ps(keep, r2);
        // SAFETY: `n + 16 ≤ CAP` (checked above), so the 16 entries from
        // `n` are inside both buffers.
        unsafe {
            let at = self.n;
            _mm512_storeu_si512(self.codes.as_mut_ptr().cast::<u32>().add(at).cast(), codes);
            _mm512_storeu_ps(self.r2.as_mut_ptr().cast::<f32>().add(at), r2);
        }
        self.n += keep.count_ones() as usize;
    }

    /// Sum the staged texels into the sums and empty the buffer.
    #[inline]
    #[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
    fn sum(&mut self, lut: &Lut8) {
        let n = self.n;
        if n == 0 {
            return;
        }
        let codes = self.codes.as_mut_ptr().cast::<u32>();
        let r2s = self.r2.as_mut_ptr().cast::<f32>();
        // Pad to a whole vector with texels outside the ellipse (r² = 2:
        // weight 0).
        // SAFETY: `n ≤ CAP` (every push keeps `n + 16 ≤ CAP`), so the 16
        // entries from `n` are inside both buffers.
        unsafe {
            _mm512_storeu_si512(codes.add(n).cast(), _mm512_setzero_si512());
            _mm512_storeu_ps(r2s.add(n), _mm512_set1_ps(2.0));
        }
        // Lane 4j + k of spread `g` is lane 4j + g of the weights: each
        // texel's weight over the four floats of its decoded RGBA.
        let groups = _mm512_setr_epi32(0, 0, 0, 0, 4, 4, 4, 4, 8, 8, 8, 8, 12, 12, 12, 12);
        let mut spread = [groups; 4];
        for (g, s) in spread.iter_mut().enumerate() {
            *s = _mm512_add_epi32(groups, _mm512_set1_epi32(g as i32));
        }
        let mut acc = [_mm512_setzero_ps(); 4];
        let mut wsum = _mm512_setzero_ps();
        let mut i = 0;
        while i < n {
            // SAFETY: entries `i … i + 15` with `i < n` lie below `n`
            // rounded up to 16, all written (by the pushes and the pad).
            let (x, codes) = unsafe {
                (
                    _mm512_loadu_ps(r2s.add(i)),
                    _mm512_loadu_si512(codes.add(i).cast()),
                )
            };
            let w = weights16(x);
            wsum = _mm512_add_ps(wsum, w);
            let t = decode_rgba8(lut, codes);
            for g in 0..4 {
                let wg = _mm512_permutexvar_ps(spread[g], w);
                acc[g] = _mm512_fmadd_ps(wg, t[g], acc[g]);
            }
            i += 16;
        }
        let a = _mm512_add_ps(_mm512_add_ps(acc[0], acc[1]), _mm512_add_ps(acc[2], acc[3]));
        let lo = _mm_add_ps(
            _mm512_extractf32x4_ps::<0>(a),
            _mm512_extractf32x4_ps::<1>(a),
        );
        let hi = _mm_add_ps(
            _mm512_extractf32x4_ps::<2>(a),
            _mm512_extractf32x4_ps::<3>(a),
        );
        let mut rgba = [0f32; 4];
        // SAFETY: a 16-byte store into a 16-byte array.
        unsafe { _mm_storeu_ps(rgba.as_mut_ptr(), _mm_add_ps(lo, hi)) };
        for (s, x) in self.sums.iter_mut().zip(rgba) {
            *s += x;
        }
        self.sums[4] += _mm512_reduce_add_ps(wsum);
        self.n = 0;
    }

    /// Sum what is staged and return the weighted RGBA sums and the sum of
    /// the weights.
    ///
    /// # Safety
    /// The CPU has AVX-512 F, BW, DQ, VL and VBMI.
    #[inline]
    #[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
    pub(crate) unsafe fn finish(&mut self, lut: &Lut8) -> ([f32; 4], f32) {
        self.sum(lut);
        let s = self.sums;
        ([s[0], s[1], s[2], s[3]], s[4])
    }
}

/// One level's ellipse as [`scan`] walks it: runs along `s` (x, or y when
/// scanning columns), one per line of `t`; `r² = qa·s² + qb·s·t + qc·t²`
/// at the texel `base + (is, jt)` (in run, line order) with
/// `s = is − frac.0`, `t = jt − frac.1`; `ext` is the extent in `t`.
pub(crate) struct Ellipse {
    pub q: (f32, f32, f32),
    pub base: (i64, i64),
    pub frac: (f32, f32),
    pub ext: f64,
    /// The wrap modes along runs and across them, and the border colour.
    pub wrap: (WrapMode, WrapMode),
    pub border: [f32; 4],
}

/// The weighted RGBA sums and the sum of the weights of one level of one
/// EWA lookup of a packed RGBA8 level (`texels`, `w × h`), its runs along
/// rows, or down columns with `COLUMNS` (see the module docs). Texels read
/// one by one go through `texel(x, y, true)`, which applies the wrap rules
/// and reports to the sink; with `trace`, every staged texel with a weight
/// is reported through `texel(x, y, false)`.
///
/// # Safety
/// The CPU has AVX-512 F, BW, DQ, VL and VBMI; `texels` points to the
/// `w·h` texels of the level (any alignment); `15·w` fits an `i32`.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi,popcnt,bmi1")]
pub(crate) unsafe fn scan<const COLUMNS: bool>(
    lut: &Lut8,
    texels: *const u32,
    (w, h): (usize, usize),
    e: &Ellipse,
    trace: bool,
    texel: &mut impl FnMut(i64, i64, bool) -> [f32; 4],
) -> ([f32; 4], f32) {
    let (qa, qb, qc) = e.q;
    let (fs, ft) = e.frac;
    let (ib, jb) = e.base;
    // Along a run: s; across runs: t.
    let (len_s, len_t) = if COLUMNS { (h, w) } else { (w, h) };
    let stride = if COLUMNS { w } else { 1 };
    let t0 = -fast_floor(e.ext - ft as f64);
    let t1 = fast_floor(ft as f64 + e.ext);
    let n = ((t1 - t0 + 1).max(0) as usize).min(MAX_LINES);
    // The level in the ellipse's offsets: a run is inside when its line
    // offset lies in [t_lo, t_hi) and its ends in [s_lo, s_hi). Offsets
    // are small (|offset| ≤ MAX_LINES), so the bounds are clamped to
    // ±2²⁴ and compared exactly in f32.
    let bound = |x: i64| x.clamp(-(1 << 24), 1 << 24) as f32;
    let (s_lo, s_hi) = (
        bound(ib.saturating_neg()),
        bound((len_s as i64).saturating_sub(ib)),
    );
    let (t_lo, t_hi) = (
        bound(jb.saturating_neg()),
        bound((len_t as i64).saturating_sub(jb)),
    );
    let lanes = _mm512_setr_ps(
        0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0, 11.0, 12.0, 13.0, 14.0, 15.0,
    );
    let (vqa, vqb, vqc, vfs) = (
        _mm512_set1_ps(qa),
        _mm512_set1_ps(qb),
        _mm512_set1_ps(qc),
        _mm512_set1_ps(fs),
    );
    let inv2a = _mm512_set1_ps(0.5 / qa);
    let one = _mm512_set1_ps(1.0);
    let zero = _mm512_setzero_ps();
    let dd = 2.0 * qa;
    let mut staged = Runs::new();
    // Texels read one by one (runs crossing the level's edge).
    let mut slow = [0f32; 5];
    let mut base = 0;
    while base < n {
        // Line offsets t0 + base + lane, and t = offset − ft.
        let off = _mm512_add_ps(lanes, _mm512_set1_ps((t0 + base as i64) as f32));
        let tt = _mm512_sub_ps(off, _mm512_set1_ps(ft));
        // Solve qa·s² + qb·tt·s + (qc·tt² − 1) < 0 for s.
        let btt = _mm512_mul_ps(vqb, tt);
        let ctt = _mm512_mul_ps(_mm512_mul_ps(vqc, tt), tt);
        let disc = _mm512_fmsub_ps(
            btt,
            btt,
            _mm512_mul_ps(
                _mm512_mul_ps(_mm512_set1_ps(4.0), vqa),
                _mm512_sub_ps(ctt, one),
            ),
        );
        let half = _mm512_mul_ps(_mm512_sqrt_ps(_mm512_max_ps(disc, zero)), inv2a);
        let centre = _mm512_fnmadd_ps(btt, inv2a, vfs);
        let s0 = _mm512_sub_ps(zero, floor16(_mm512_sub_ps(half, centre)));
        let s1 = floor16(_mm512_add_ps(centre, half));
        // r² at s0 and its first difference; the second is 2·qa.
        let ss0 = _mm512_sub_ps(s0, vfs);
        let r2 = _mm512_fmadd_ps(_mm512_mul_ps(vqa, ss0), ss0, _mm512_fmadd_ps(btt, ss0, ctt));
        let d = _mm512_fmadd_ps(vqa, _mm512_fmadd_ps(_mm512_set1_ps(2.0), ss0, one), btt);
        // Lines with a run (and below n).
        let live = (if n - base >= 16 {
            0xffff
        } else {
            (1u32 << (n - base)) - 1
        }) as u16;
        let runs = _mm512_mask_cmp_ps_mask::<_CMP_GT_OQ>(live, disc, zero)
            & _mm512_cmp_ps_mask::<_CMP_LE_OQ>(s0, s1);
        let inside = runs
            & _mm512_cmp_ps_mask::<_CMP_GE_OQ>(off, _mm512_set1_ps(t_lo))
            & _mm512_cmp_ps_mask::<_CMP_LT_OQ>(off, _mm512_set1_ps(t_hi))
            & _mm512_cmp_ps_mask::<_CMP_GE_OQ>(s0, _mm512_set1_ps(s_lo))
            & _mm512_cmp_ps_mask::<_CMP_LT_OQ>(s1, _mm512_set1_ps(s_hi));
        if COLUMNS && n <= 16 && runs != 0 {
            // Columns: sweep the rows the runs cover, one masked load of
            // the n lines' texels per row (adjacent in memory), instead of
            // one gather per run (gathers down a column cost more than
            // everything else here).
            let y0 = _mm512_mask_reduce_min_ps(runs, s0) as i64;
            let y1 = _mm512_mask_reduce_max_ps(runs, s1) as i64;
            let (ya, yb) = (ib.saturating_add(y0), ib.saturating_add(y1));
            let xa = jb.saturating_add(t0);
            let xb = xa.saturating_add(n as i64 - 1);
            let inside = ya >= 0 && yb < len_s as i64 && xa >= 0 && xb < len_t as i64;
            let rows = (y1 - y0 + 1) as usize;
            // Across an edge of the level: each row's and line's wrapped
            // index (−1: the border colour), texels gathered by offset.
            let mut row_at;
            let wrapped = if inside {
                None
            } else if w.saturating_mul(h) <= i32::MAX as usize && rows <= MAX_LINES {
                row_at = [-1i32; MAX_LINES];
                let at = |mode, i: i64, size: usize| {
                    wrap_index(mode, i, size as u32).map_or(-1, |x| x as i32)
                };
                for (r, y) in row_at.iter_mut().zip(ya..=yb) {
                    *r = at(e.wrap.0, y, len_s);
                }
                let mut line_at = [-1i32; 16];
                for (k, x) in line_at.iter_mut().enumerate().take(n) {
                    *x = at(e.wrap.1, xa.saturating_add(k as i64), len_t);
                }
                Some(Wrapped {
                    rows: &row_at[..rows],
                    lines: line_at,
                })
            } else {
                None
            };
            if inside || wrapped.is_some() {
                let sw = Sweep {
                    texels,
                    w,
                    origin: (xa, ya),
                    rows,
                    s: (y0 as f32) - fs,
                    t: ((t0 as f32) - ft, runs),
                    q: e.q,
                    wrapped,
                };
                let at = |x: i64, y: i64| {
                    texel(x, y, false);
                };
                // SAFETY: inside the level, rows ya … yb < h and columns
                // xa … xb < w (checked above); across an edge, every
                // offset is a wrapped index's; the caller's contract for
                // the rest.
                let border_w = unsafe {
                    match (n, inside) {
                        (..=4, true) => sweep::<4, false>(lut, &sw, &mut staged, trace, at),
                        (..=8, true) => sweep::<8, false>(lut, &sw, &mut staged, trace, at),
                        (_, true) => sweep::<16, false>(lut, &sw, &mut staged, trace, at),
                        (..=4, false) => sweep::<4, true>(lut, &sw, &mut staged, trace, at),
                        (..=8, false) => sweep::<8, true>(lut, &sw, &mut staged, trace, at),
                        (_, false) => sweep::<16, true>(lut, &sw, &mut staged, trace, at),
                    }
                };
                for (s, b) in slow.iter_mut().zip(e.border) {
                    *s = border_w.mul_add(b, *s);
                }
                slow[4] += border_w;
                break;
            }
        }
        let mut a = [[0f32; 16]; 4];
        // SAFETY: 64-byte stores into 16-float arrays.
        unsafe {
            _mm512_storeu_ps(a[0].as_mut_ptr(), s0);
            _mm512_storeu_ps(a[1].as_mut_ptr(), s1);
            _mm512_storeu_ps(a[2].as_mut_ptr(), r2);
            _mm512_storeu_ps(a[3].as_mut_ptr(), d);
        }
        let mut m = inside;
        while m != 0 {
            let k = m.trailing_zeros() as usize;
            m &= m - 1;
            let (s0, s1) = (a[0][k] as i64, a[1][k] as i64);
            // Inside the level: these are the texel indices.
            let line = (jb + t0 + (base + k) as i64) as usize;
            let x0 = (ib + s0) as usize;
            let len = (s1 - s0 + 1) as usize;
            let first = if COLUMNS {
                x0 * w + line
            } else {
                line * w + x0
            };
            let mut hit = |i: usize| {
                let x = (x0 + i) as i64;
                let (tx, ty) = if COLUMNS {
                    (line as i64, x)
                } else {
                    (x, line as i64)
                };
                texel(tx, ty, false);
            };
            // SAFETY: the run's `len` texels, `stride` apart from `first`,
            // lie inside the level (the `inside` test); len ≤ 2·(MAX_RADIUS
            // + 2) + 1 ≤ CAP − 16; 15·stride fits an i32 (the caller's
            // contract).
            unsafe {
                staged.push(
                    lut,
                    texels.add(first),
                    stride,
                    len,
                    (a[2][k], a[3][k], dd),
                    trace,
                    &mut hit,
                )
            };
        }
        let mut m = runs & !inside;
        while m != 0 {
            let k = m.trailing_zeros() as usize;
            m &= m - 1;
            let (s0, s1) = (a[0][k] as i64, a[1][k] as i64);
            let (mut r2, mut d) = (a[2][k], a[3][k]);
            let line = jb.saturating_add(t0 + (base + k) as i64);
            for x in ib.saturating_add(s0)..=ib.saturating_add(s1) {
                if r2 < 1.0 {
                    let wt = weight_poly::<true>(r2);
                    let (tx, ty) = if COLUMNS { (line, x) } else { (x, line) };
                    let t = texel(tx, ty, true);
                    for ch in 0..4 {
                        slow[ch] = wt.mul_add(t[ch], slow[ch]);
                    }
                    slow[4] += wt;
                }
                r2 += d;
                d += dd;
            }
        }
        base += 16;
    }
    // SAFETY: the caller's contract (the CPU features).
    let (rgba, ws) = unsafe { staged.finish(lut) };
    (
        [
            rgba[0] + slow[0],
            rgba[1] + slow[1],
            rgba[2] + slow[2],
            rgba[3] + slow[3],
        ],
        ws + slow[4],
    )
}

/// `floor` of each lane (round toward −∞, no exceptions).
#[inline]
#[target_feature(enable = "avx512f")]
fn floor16(x: __m512) -> __m512 {
    _mm512_roundscale_ps::<{ _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC }>(x)
}

/// The rows a tall ellipse's runs cover, for [`sweep`]: `rows` rows from
/// `origin` (texel x, y), each holding the ellipse's lines as adjacent
/// texels (those of the mask `t.1`, line `k` at x + k); `s` is the run
/// coordinate of the first row and `t.0` the line coordinate of line 0;
/// `q` the quadratic form (run, cross, line). With `wrapped`, the rows
/// and lines cross an edge of the level and are read at their wrapped
/// indices.
struct Sweep<'a> {
    texels: *const u32,
    w: usize,
    origin: (i64, i64),
    rows: usize,
    s: f32,
    t: (f32, u16),
    q: (f32, f32, f32),
    wrapped: Option<Wrapped<'a>>,
}

/// The wrapped index of each row and line of a [`Sweep`] (−1: the border
/// colour is read there).
struct Wrapped<'a> {
    rows: &'a [i32],
    lines: [i32; 16],
}

/// Stage the texels of `sw` inside the ellipse, 16 / C rows of C lines at
/// a time (one masked load per row, no gathers; gathers across an edge);
/// with `trace`, report each (at its wrapped index) through `at(x, y)`.
/// Returns the sum of the weights of the texels that read the border
/// colour.
///
/// # Safety
/// The CPU has AVX-512 F, BW, DQ, VL and VBMI; `sw.texels` points to the
/// level's `w·h` texels; without `wrapped`, `sw`'s rows and lines (the
/// lines of its mask, all below C) lie inside the level; with it, every
/// index it holds does, and `w·h` fits an `i32`.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi,popcnt,bmi1")]
unsafe fn sweep<const C: usize, const WRAPPED: bool>(
    lut: &Lut8,
    sw: &Sweep,
    staged: &mut Runs,
    trace: bool,
    mut at: impl FnMut(i64, i64),
) -> f32 {
    let rows_per = 16 / C;
    let (qa, qb, qc) = sw.q;
    // Lane k: line k % C, row k / C of the block.
    let mut li = [0f32; 16];
    let mut lj = [0f32; 16];
    for k in 0..16 {
        li[k] = (k % C) as f32;
        lj[k] = (k / C) as f32;
    }
    // SAFETY: 64-byte loads of 16-float arrays.
    let (vi, vj) = unsafe { (_mm512_loadu_ps(li.as_ptr()), _mm512_loadu_ps(lj.as_ptr())) };
    let tt = _mm512_add_ps(vi, _mm512_set1_ps(sw.t.0));
    // r² = qa·s² + (qb·t)·s + qc·t².
    let bt = _mm512_mul_ps(_mm512_set1_ps(qb), tt);
    let ct = _mm512_mul_ps(_mm512_mul_ps(_mm512_set1_ps(qc), tt), tt);
    let vqa = _mm512_set1_ps(qa);
    let one = _mm512_set1_ps(1.0);
    let line_mask = sw.t.1 as u32 & ((1u32 << C) - 1);
    let (x0, y0) = sw.origin;
    let mut border = _mm512_setzero_ps();
    let mut r = 0;
    while r < sw.rows {
        let left = sw.rows - r;
        // The lines of every row of the block that exists.
        let mut mask = 0u32;
        for j in 0..rows_per.min(left) {
            mask |= line_mask << (j * C);
        }
        let mask = mask as u16;
        let s = _mm512_add_ps(vj, _mm512_set1_ps(sw.s + r as f32));
        let r2 = _mm512_fmadd_ps(_mm512_mul_ps(vqa, s), s, _mm512_fmadd_ps(bt, s, ct));
        let mut keep = _mm512_mask_cmp_ps_mask::<_CMP_LT_OQ>(mask, r2, one);
        let codes = if WRAPPED && let Some(wr) = &sw.wrapped {
            // Offsets of the lanes that read a texel (wrapped row and line
            // both ≥ 0); the others of `keep` read the border colour.
            let mut rowv = [0i32; 16];
            for (k, v) in rowv.iter_mut().enumerate() {
                *v = wr.rows[(r + k / C).min(sw.rows - 1)];
            }
            let mut linev = [0i32; 16];
            for (k, v) in linev.iter_mut().enumerate() {
                *v = wr.lines[k % C];
            }
            // SAFETY: 64-byte loads of 16-int arrays.
            let (rv, lv) = unsafe {
                (
                    _mm512_loadu_si512(rowv.as_ptr().cast()),
                    _mm512_loadu_si512(linev.as_ptr().cast()),
                )
            };
            let zero = _mm512_setzero_si512();
            let texel =
                _mm512_mask_cmpge_epi32_mask(keep, rv, zero) & _mm512_cmpge_epi32_mask(lv, zero);
            let offsets =
                _mm512_add_epi32(_mm512_mullo_epi32(rv, _mm512_set1_epi32(sw.w as i32)), lv);
            if keep & !texel != 0 {
                border = _mm512_mask_add_ps(border, keep & !texel, border, weights16(r2));
            }
            keep = texel;
            if trace {
                let mut m = keep;
                while m != 0 {
                    let k = m.trailing_zeros() as usize;
                    at(wr.lines[k % C] as i64, wr.rows[r + k / C] as i64);
                    m &= m - 1;
                }
            }
            // SAFETY: every offset of a lane of `keep` is a wrapped
            // texel's, inside the level (the caller's contract).
            unsafe {
                _mm512_mask_i32gather_epi32::<4>(
                    _mm512_setzero_si512(),
                    keep,
                    offsets,
                    sw.texels.cast(),
                )
            }
        } else {
            if trace {
                let mut m = keep;
                while m != 0 {
                    let k = m.trailing_zeros() as usize;
                    at(x0 + (k % C) as i64, y0 + (r + k / C) as i64);
                    m &= m - 1;
                }
            }
            // SAFETY: the rows below `rows` and lines of the mask are
            // texels (the caller's contract); masked-off lanes are not
            // read.
            unsafe {
                let p = sw.texels.add((y0 as usize + r) * sw.w + x0 as usize);
                match C {
                    16 => _mm512_maskz_loadu_epi32(mask, p.cast()),
                    8 => {
                        let lo = _mm256_maskz_loadu_epi32(mask as u8, p.cast());
                        let hi = _mm256_maskz_loadu_epi32((mask >> 8) as u8, p.add(sw.w).cast());
                        _mm512_inserti64x4::<1>(_mm512_castsi256_si512(lo), hi)
                    }
                    _ => {
                        let m = |j: usize| ((mask >> (4 * j)) & 0xf) as u8;
                        let row = |j: usize| _mm_maskz_loadu_epi32(m(j), p.add(j * sw.w).cast());
                        let lo =
                            _mm256_inserti128_si256::<1>(_mm256_castsi128_si256(row(0)), row(1));
                        let hi =
                            _mm256_inserti128_si256::<1>(_mm256_castsi128_si256(row(2)), row(3));
                        _mm512_inserti64x4::<1>(_mm512_castsi256_si512(lo), hi)
                    }
                }
            }
        };
        // SAFETY: the caller's contract (the CPU features).
        unsafe { staged.compress(lut, codes, r2, keep) };
        r += rows_per;
    }
    _mm512_reduce_add_ps(border)
}

/// The EWA weight of each lane's r² (the scalar path's polynomial,
/// Estrin's scheme, floored at 10⁻¹²), 0 where r² ≥ 1.
#[inline]
#[target_feature(enable = "avx512f")]
fn weights16(x: __m512) -> __m512 {
    let c = |k: usize| _mm512_set1_ps(WEIGHT_POLY[k]);
    let x2 = _mm512_mul_ps(x, x);
    let p01 = _mm512_fmadd_ps(c(1), x, c(0));
    let p23 = _mm512_fmadd_ps(c(3), x, c(2));
    let p45 = _mm512_fmadd_ps(c(5), x, c(4));
    let p46 = _mm512_fmadd_ps(c(6), x2, p45);
    let p26 = _mm512_fmadd_ps(p46, x2, p23);
    let p = _mm512_max_ps(_mm512_fmadd_ps(p26, x2, p01), _mm512_set1_ps(1e-12));
    let inside = _mm512_cmp_ps_mask::<_CMP_LT_OQ>(x, _mm512_set1_ps(1.0));
    _mm512_maskz_mov_ps(inside, p)
}
