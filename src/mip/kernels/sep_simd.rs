//! The fast row kernel of the separable filters (Kaiser, Lanczos3,
//! Mitchell, triangle, and the box on sizes that do not halve): AVX-512
//! where the CPU has it (F, BW, DQ, VL, VBMI, detected once at run time;
//! `PARVO_NO_AVX` turns it off), else the AVX2 kernel of
//! [`crate::mip::separable`], else its portable one.
//!
//! - Vertical pass: 64 values per step in four zmm registers, one fused
//!   multiply-add per register and source row.
//! - Horizontal pass: each destination texel's taps are one contiguous run
//!   of `taps · channels` floats (everywhere but wrapped edges), so the
//!   pass is a dot product of that run with the texel's weights expanded
//!   per channel ([`Expanded`]): 16 floats per fused multiply-add instead
//!   of one tap per instruction, folded to the channels at the end. The
//!   expanded weights are stored once per distinct pattern (a 2:1
//!   reduction has one pattern for the whole interior), so they stay in L1.
//!
//! The sums are taken in another order than the portable kernel's (and
//! fused), so the last bits of a value differ; the fast chains are tested
//! against the plain path within one code (`tests/files/mip_separable_fast.rs`).

use std::collections::HashMap;

use crate::mip::weights::AxisWeights;

/// One axis's weights expanded per channel: for each distinct weight
/// pattern, `pad` floats (tap `t`, channel `c` at `t · ch + c`, zeros
/// after `taps · ch`); `pattern[x]` names destination texel `x`'s pattern
/// (unused where its taps are not contiguous).
#[derive(Clone, Debug)]
pub(crate) struct Expanded {
    pad: usize,
    weights: Vec<f32>,
    pattern: Vec<u32>,
    /// RGBA only: the longest stretch of destination texels that step
    /// two source texels each with one weight pattern (the interior of a
    /// 2:1 reduction), filtered four texels per register ([`Stride2`]).
    stride2: Option<Stride2>,
}

/// Destination texels `x0..x1` whose taps start at source texel
/// `first + 2·(x − x0)` and share the weights `w`: four destination
/// texels fill one zmm register, so each tap is one fused multiply-add of
/// a register of four source texels (picked from two loads by one
/// permute) with a broadcast weight; no per-texel fold.
#[derive(Clone, Debug)]
struct Stride2 {
    x0: usize,
    x1: usize,
    first: usize,
    w: Vec<f32>,
}

impl Stride2 {
    fn new(wx: &AxisWeights, pattern: &[u32]) -> Option<Stride2> {
        let runs = wx.contiguous_runs();
        let mut best: Option<(usize, usize)> = None;
        let mut x = 0;
        while x < runs.len() {
            let Some(r) = runs[x] else {
                x += 1;
                continue;
            };
            let mut end = x + 1;
            while end < runs.len()
                && runs[end] == Some(r + 2 * (end - x) as u32)
                && pattern[end] == pattern[x]
            {
                end += 1;
            }
            if best.is_none_or(|(a, b)| end - x > b - a) {
                best = Some((x, end));
            }
            x = end;
        }
        let (x0, x1) = best.filter(|&(a, b)| b - a >= 8 && wx.taps <= 32)?;
        Some(Stride2 {
            x0,
            x1,
            first: runs[x0]? as usize,
            w: wx.weight[x0 * wx.taps..][..wx.taps].to_vec(),
        })
    }
}

impl Expanded {
    pub(crate) fn new(wx: &AxisWeights, ch: usize) -> Expanded {
        let taps = wx.taps;
        let pad = (taps * ch).div_ceil(16) * 16;
        let mut seen: HashMap<Vec<u32>, u32> = HashMap::new();
        let mut weights = Vec::new();
        let mut pattern = Vec::with_capacity(wx.weight.len() / taps.max(1));
        for wgt in wx.weight.chunks_exact(taps.max(1)) {
            let key: Vec<u32> = wgt.iter().map(|w| w.to_bits()).collect();
            let next = seen.len() as u32;
            let id = *seen.entry(key).or_insert_with(|| {
                let start = weights.len();
                weights.resize(start + pad, 0.0);
                for (t, &w) in wgt.iter().enumerate() {
                    weights[start + t * ch..][..ch].fill(w);
                }
                next
            });
            pattern.push(id);
        }
        let stride2 = if ch == 4 {
            Stride2::new(wx, &pattern)
        } else {
            None
        };
        Expanded {
            pad,
            weights,
            pattern,
            stride2,
        }
    }
}

/// True when the AVX-512 kernel may run.
pub(crate) fn available() -> bool {
    crate::cpu::avx512_sample()
}

/// Vertical then horizontal pass of one destination row with the fastest
/// kernel this CPU has (see the module docs).
pub(crate) fn filter_row(
    rows: &[(&[f32], f32)],
    tmp: &mut [f32],
    dst: &mut [f32],
    wx: &AxisWeights,
    runs: &[Option<u32>],
    ex: &Expanded,
    ch: usize,
) {
    #[cfg(target_arch = "x86_64")]
    if available() {
        #[allow(unsafe_code)]
        // SAFETY: `available()` checked AVX-512 F, BW, DQ, VL (and VBMI),
        // a superset of what `x86::filter_row` is compiled for.
        unsafe {
            x86::filter_row(rows, tmp, dst, wx, runs, ex, ch)
        };
        return;
    }
    let _ = ex;
    crate::mip::separable::filter_row(rows, tmp, dst, wx, runs, ch);
}

/// Destination texel `x` from its taps by index (wrapped edges).
#[inline]
fn texel_by_index(tmp: &[f32], d: &mut [f32], wx: &AxisWeights, x: usize, ch: usize) {
    let taps = wx.taps;
    let mut acc = [0f32; 4];
    let idx = &wx.index[x * taps..][..taps];
    let wgt = &wx.weight[x * taps..][..taps];
    for (&i, &w) in idx.iter().zip(wgt) {
        let px = &tmp[i as usize * ch..][..ch];
        for c in 0..ch {
            acc[c] += w * px[c];
        }
    }
    d.copy_from_slice(&acc[..ch]);
}

#[cfg(target_arch = "x86_64")]
pub(crate) mod x86 {
    use std::arch::x86_64::*;

    use super::{Expanded, Stride2, texel_by_index};
    use crate::mip::weights::AxisWeights;
    use crate::simd::{load_ps as load, store_ps as store};

    #[target_feature(enable = "avx512f,avx512vl,avx512dq,fma")]
    pub(crate) fn filter_row(
        rows: &[(&[f32], f32)],
        tmp: &mut [f32],
        dst: &mut [f32],
        wx: &AxisWeights,
        runs: &[Option<u32>],
        ex: &Expanded,
        ch: usize,
    ) {
        vertical(rows, tmp);
        let all = 0..dst.len() / ch.max(1);
        match ch {
            1 => horizontal::<1>(tmp, dst, wx, runs, ex, all),
            2 => horizontal::<2>(tmp, dst, wx, runs, ex, all),
            3 => horizontal::<3>(tmp, dst, wx, runs, ex, all),
            _ => {
                let (a, b) = match &ex.stride2 {
                    Some(p) => stride2(tmp, dst, p),
                    None => (0, 0),
                };
                horizontal::<4>(tmp, dst, wx, runs, ex, 0..a);
                horizontal::<4>(tmp, dst, wx, runs, ex, b..all.end);
            }
        }
    }

    /// The texels of `p` four at a time (see [`Stride2`]), as far as
    /// their loads stay inside the row; returns the range done.
    #[target_feature(enable = "avx512f,avx512vl,avx512dq,fma")]
    fn stride2(tmp: &[f32], dst: &mut [f32], p: &Stride2) -> (usize, usize) {
        let taps = p.w.len();
        let mut w = [_mm512_setzero_ps(); 32];
        for (r, &v) in w.iter_mut().zip(&p.w) {
            *r = _mm512_set1_ps(v);
        }
        // Texels 0, 2 of two loads (tap 2u) or 1, 3 (tap 2u + 1).
        let pick = |odd: i32| {
            let o = 4 * odd;
            _mm512_setr_epi32(
                o,
                o + 1,
                o + 2,
                o + 3,
                o + 8,
                o + 9,
                o + 10,
                o + 11,
                o + 16,
                o + 17,
                o + 18,
                o + 19,
                o + 24,
                o + 25,
                o + 26,
                o + 27,
            )
        };
        let (even, odd) = (pick(0), pick(1));
        let sw = tmp.len() / 4;
        // The last texel a group reads: load u + 2 of the last tap pair.
        let reach = 2 * ((taps - 1) / 2 + 2) + 4;
        let mut x = p.x0;
        while x + 4 <= p.x1 && p.first + 2 * (x - p.x0) + reach <= sw {
            let i0 = p.first + 2 * (x - p.x0);
            let mut acc = [_mm512_setzero_ps(); 4];
            let mut t = 0;
            while t < taps {
                let u = t / 2;
                let lo = load(&tmp[4 * (i0 + 2 * u)..][..16].as_chunks::<16>().0[0]);
                let hi = load(&tmp[4 * (i0 + 2 * u + 4)..][..16].as_chunks::<16>().0[0]);
                let v = _mm512_permutex2var_ps(lo, even, hi);
                acc[t % 4] = _mm512_fmadd_ps(w[t], v, acc[t % 4]);
                if t + 1 < taps {
                    let v = _mm512_permutex2var_ps(lo, odd, hi);
                    acc[(t + 1) % 4] = _mm512_fmadd_ps(w[t + 1], v, acc[(t + 1) % 4]);
                }
                t += 2;
            }
            let s = _mm512_add_ps(_mm512_add_ps(acc[0], acc[1]), _mm512_add_ps(acc[2], acc[3]));
            store(&mut dst[4 * x..][..16].as_chunks_mut::<16>().0[0], s);
            x += 4;
        }
        (p.x0, x)
    }

    /// The first `v.len()` (at most 16) lanes from `v`, the rest zero.
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn load_part(v: &[f32]) -> __m512 {
        let n = v.len().min(16);
        let mask: __mmask16 = ((1u32 << n) - 1) as u16;
        #[allow(unsafe_code)]
        // SAFETY: AVX-512 F is enabled (callers checked it); the mask
        // enables only the first `n ≤ v.len()` lanes, which are readable,
        // and masked-off lanes are not accessed (no fault).
        unsafe {
            _mm512_maskz_loadu_ps(mask, v.as_ptr())
        }
    }

    /// `tmp = Σ weight · row`, 64 values per step held in registers across
    /// all rows.
    #[target_feature(enable = "avx512f,fma")]
    fn vertical(rows: &[(&[f32], f32)], tmp: &mut [f32]) {
        const B: usize = 64;
        let full = tmp.len() / B * B;
        for (k, out) in tmp[..full].chunks_exact_mut(B).enumerate() {
            let mut acc = [_mm512_setzero_ps(); 4];
            for &(row, wt) in rows {
                let r: &[f32; B] = &row.as_chunks::<B>().0[k];
                let w = _mm512_set1_ps(wt);
                for (a, r16) in acc.iter_mut().zip(r.as_chunks::<16>().0) {
                    *a = _mm512_fmadd_ps(w, load(r16), *a);
                }
            }
            for (o, a) in out.as_chunks_mut::<16>().0.iter_mut().zip(acc) {
                store(o, a);
            }
        }
        let rest = tmp.len() - full;
        for (k, out) in tmp[full..].chunks_mut(16).enumerate() {
            let mut acc = _mm512_setzero_ps();
            for &(row, wt) in rows {
                let r = &row[full + 16 * k..][..out.len()];
                acc = _mm512_fmadd_ps(_mm512_set1_ps(wt), load_part(r), acc);
            }
            let mut buf = [0f32; 16];
            store(&mut buf, acc);
            out.copy_from_slice(&buf[..out.len()]);
        }
        let _ = rest;
    }

    /// One destination texel per step: the dot product of its contiguous
    /// run of `taps · CH` floats with its expanded weights, folded to the
    /// channels (see the module docs).
    #[target_feature(enable = "avx512f,avx512vl,avx512dq,fma")]
    fn horizontal<const CH: usize>(
        tmp: &[f32],
        dst: &mut [f32],
        wx: &AxisWeights,
        runs: &[Option<u32>],
        ex: &Expanded,
        xs: std::ops::Range<usize>,
    ) {
        let n = wx.taps * CH;
        let blocks = ex.pad / 16;
        let first = xs.start;
        for (x, d) in dst[CH * xs.start..CH * xs.end]
            .chunks_exact_mut(CH)
            .enumerate()
            .map(|(i, d)| (first + i, d))
        {
            let Some(i0) = runs[x] else {
                texel_by_index(tmp, d, wx, x, CH);
                continue;
            };
            let data = &tmp[i0 as usize * CH..][..n];
            let wv = &ex.weights[ex.pattern[x] as usize * ex.pad..][..ex.pad];
            let wv = wv.as_chunks::<16>().0;
            // Blocks k ≡ r (mod 3) share accumulator r: with three
            // channels, lane l of block k holds channel (16k + l) mod 3.
            let mut acc = [_mm512_setzero_ps(); 3];
            for k in 0..blocks {
                let v = load_part(&data[16 * k..]);
                acc[k % 3] = _mm512_fmadd_ps(v, load(&wv[k]), acc[k % 3]);
            }
            if CH == 3 {
                let mut buf = [[0f32; 16]; 3];
                for (b, a) in buf.iter_mut().zip(acc) {
                    store(b, a);
                }
                let flat = buf.as_flattened();
                let mut out = [0f32; 3];
                for (m, v) in flat.iter().enumerate() {
                    out[m % 3] += v;
                }
                d.copy_from_slice(&out[..CH]);
                continue;
            }
            let s = _mm512_add_ps(_mm512_add_ps(acc[0], acc[1]), acc[2]);
            if CH == 1 {
                d[0] = _mm512_reduce_add_ps(s);
                continue;
            }
            let lo = _mm512_castps512_ps256(s);
            let hi = _mm512_extractf32x8_ps::<1>(s);
            let h = _mm256_add_ps(lo, hi);
            let q = _mm_add_ps(_mm256_castps256_ps128(h), _mm256_extractf128_ps::<1>(h));
            let mut out = [0f32; 4];
            #[allow(unsafe_code)]
            // SAFETY: SSE is baseline on x86_64; `out` is 4 writable floats.
            unsafe {
                _mm_storeu_ps(out.as_mut_ptr(), q)
            };
            if CH == 2 {
                d[0] = out[0] + out[2];
                d[1] = out[1] + out[3];
            } else {
                d.copy_from_slice(&out[..CH]);
            }
        }
    }
}
