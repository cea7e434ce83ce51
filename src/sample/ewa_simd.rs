//! The AVX-512 inner loop of the fast EWA for packed RGBA8 chains
//! (untraced lookups on CPUs with AVX-512 F, BW, DQ, VL and VBMI; see
//! [`super::ewa`]).
//!
//! The scalar loop spends most of its time on what surrounds each texel:
//! a run of an ellipse is a handful of texels, so its setup and its last,
//! mispredicted loop exit cost more than the texels. Here the runs that
//! lie inside the level are first *staged*: each run's codes (one masked
//! load along a row, one masked gather down a column) and the r² of each
//! of its texels (from the run's start, first and second difference) are
//! stored 16 at a time at the end of a buffer, which then advances by the
//! run's length, so the runs of a level lie end to end with no gaps and a
//! run of up to 16 texels costs no branch. The buffer is then summed 16
//! texels at a time: the weight polynomial on 16 lanes, the 64 codes
//! decoded at once ([`super::simd::decode_rgba8`], RGBA `f32` per 128-bit
//! group) and each texel's weight spread over its group, into four
//! independent sets of sums. The weights are the scalar path's
//! polynomial; r² is computed from the run's polynomial at each texel
//! rather than stepped, and the sums are taken in another order, so the
//! result differs from the scalar build in the last bits (both are held to
//! the exact-weight EWA within 1e-3).

// Intrinsics: every `unsafe` block says which features are enabled and
// why its memory accesses stay in bounds.
#![allow(unsafe_code)]

use std::arch::x86_64::*;
use std::mem::MaybeUninit;

use super::ewa::WEIGHT_POLY;
use super::fetch::Lut8;
use super::simd::decode_rgba8;

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
        let one = _mm512_set1_ps(1.0);
        let floor = _mm512_set1_ps(1e-12);
        let mut c = [_mm512_setzero_ps(); 7];
        for (c, &k) in c.iter_mut().zip(&WEIGHT_POLY) {
            *c = _mm512_set1_ps(k);
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
            // The scalar path's polynomial (Estrin's scheme) and floor.
            let x2 = _mm512_mul_ps(x, x);
            let p01 = _mm512_fmadd_ps(c[1], x, c[0]);
            let p23 = _mm512_fmadd_ps(c[3], x, c[2]);
            let p45 = _mm512_fmadd_ps(c[5], x, c[4]);
            let p46 = _mm512_fmadd_ps(c[6], x2, p45);
            let p26 = _mm512_fmadd_ps(p46, x2, p23);
            let p = _mm512_max_ps(_mm512_fmadd_ps(p26, x2, p01), floor);
            let inside = _mm512_cmp_ps_mask::<_CMP_LT_OQ>(x, one);
            let w = _mm512_maskz_mov_ps(inside, p);
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
