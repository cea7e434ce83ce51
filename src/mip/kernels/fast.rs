//! Fast paths for the commonest reduction: the 2×2 box of an even-sized
//! level (every level of a power-of-two chain).
//!
//! - u8, linear: exact integer average `(a + b + c + d + 2) >> 2` — the
//!   vertical pair sums go to a u16 scratch row (one widening add per byte,
//!   which vectorises), the horizontal pairs are summed from it.
//! - u8, sRGB: colour channels through a 256-entry decode table in 2^-24
//!   fixed point, summed in u32, and encoded by comparing against the exact
//!   sRGB decision thresholds (one look-up in a 4 Ki-bucket table, small
//!   enough for the L1 cache, gives the candidate code and the threshold
//!   inside the bucket; one comparison settles it). No `powf` per texel, and the result
//!   is the correctly rounded code except within ~1e-3 of a code of a tie.
//! - f32, linear: one fused pass reading the 2×2 block, no decode copy; for
//!   RGBA each texel is one SSE register, and the same pass notes whether
//!   any alpha differs and whether any output is non-finite (so neither
//!   needs a pass of its own).
//!
//! Straight alpha: when the four alphas of a block differ, colour is the
//! alpha-weighted average (integer arithmetic for u8, rounded to nearest);
//! when they are equal (the opaque case) the plain average is the same
//! value, so no weighting work is done. A block with all alpha 0 keeps the
//! plain colour average, as the separable path does.
//!
//! Every path here is compared with [`crate::mip::separable`] in
//! `tests/core/mip_fast_paths_match_plain.rs`.

use std::sync::OnceLock;

use rayon::prelude::*;

use crate::error::Result;
use crate::mip::{MipFilter, MipOptions, srgb_simd};
use crate::texel::{AlphaMode, ChannelType, ColorSpace, Format, Texels, srgb};
use crate::texture::Texture;

/// Destination bytes per parallel task (keeps rayon overhead negligible).
const TASK_BYTES: usize = 64 * 1024;

/// Reduce with a fast path if one applies; `Ok(None)` means "use the plain
/// path". The flag is true when the kernel saw every output value finite
/// (only the f32 RGBA kernel tracks it; it lets the deferred NaN check
/// skip its scan of level 1).
pub(crate) fn try_reduce(
    src: &Texture,
    w: u32,
    h: u32,
    options: &MipOptions,
) -> Result<Option<(Texture, bool)>> {
    let (sw, sh) = (src.width(), src.height());
    if options.filter != MipFilter::Box || sw != 2 * w || sh != 2 * h {
        return Ok(None);
    }
    let fmt = src.format();
    let straight = fmt
        .alpha_channel()
        .filter(|_| fmt.alpha == AlphaMode::Straight);
    let (texels, finite) = match (src.texels(), fmt.color_space) {
        (Texels::U8(s), ColorSpace::Linear) => (
            Texels::U8(box_u8(s, sw as usize, fmt, straight, false)),
            false,
        ),
        (Texels::U8(s), ColorSpace::Srgb) => (
            Texels::U8(box_u8(s, sw as usize, fmt, straight, true)),
            false,
        ),
        (Texels::F32(s), ColorSpace::Linear) => {
            let (v, finite) = box_f32(s, sw as usize, fmt, straight);
            (Texels::F32(v), finite)
        }
        _ => return Ok(None),
    };
    Texture::from_texels(w, h, fmt, texels).map(|t| Some((t, finite)))
}

/// The 2×2 box of an even-sized level of any stored type, to linear f32
/// (the unrounded level a chain reduces further): each pair of source rows
/// is decoded into per-thread scratch (or read in place when the level is
/// linear f32) and reduced with [`box_row_f32`], so no decoded copy of the
/// whole level exists. With `encode` an 8-bit format, each new row is also
/// encoded to it while in cache (the stored level: [`ReducedLinear::stored`]).
/// `None` when the box does not apply (another filter, or sizes that do
/// not halve exactly).
pub(crate) fn try_reduce_linear(
    src: &Texture,
    w: u32,
    h: u32,
    options: &MipOptions,
    encode: Option<Format>,
) -> Option<ReducedLinear> {
    let (sw, sh) = (src.width() as usize, src.height() as usize);
    if options.filter != MipFilter::Box || sw != 2 * w as usize || sh != 2 * h as usize {
        return None;
    }
    let fmt = src.format();
    let straight = fmt
        .alpha_channel()
        .filter(|_| fmt.alpha == AlphaMode::Straight);
    use std::sync::atomic::{AtomicBool, Ordering};
    let ch = fmt.channels as usize;
    let row = w as usize * ch;
    let src_row = sw * ch;
    let mut dst: Vec<f32> = crate::mem::zeroed(row * h as usize);
    let encode = encode.filter(|f| f.channel_type == ChannelType::U8 && f.channels == fmt.channels);
    let mut stored: Vec<u8> = match encode {
        Some(_) => crate::mem::zeroed(row * h as usize),
        None => Vec::new(),
    };
    let per = rows_per_task(row * 4);
    let finite = AtomicBool::new(ch == 4);
    let texels = src.texels();
    let in_place = match (texels, fmt.color_space) {
        (Texels::F32(v), ColorSpace::Linear) => Some(v.as_slice()),
        _ => None,
    };
    let mut stored_tasks: Vec<&mut [u8]> = if encode.is_some() {
        stored.chunks_mut(row * per).collect()
    } else {
        Vec::new()
    };
    type Task<'a> = (usize, (&'a mut [f32], Option<&'a mut [u8]>));
    let tasks: Vec<Task<'_>> = dst
        .chunks_mut(row * per)
        .zip(
            stored_tasks
                .drain(..)
                .map(Some)
                .chain(std::iter::repeat_with(|| None)),
        )
        .enumerate()
        .collect();
    tasks.into_par_iter().for_each_init(
        || vec![0f32; if in_place.is_some() { 0 } else { 2 * src_row }],
        |scratch, (task, (out, mut coded))| {
            for (i, d) in out.chunks_exact_mut(row).enumerate() {
                let y = task * per + i;
                let (r0, r1): (&[f32], &[f32]) = match in_place {
                    Some(v) => (
                        &v[2 * y * src_row..][..src_row],
                        &v[(2 * y + 1) * src_row..][..src_row],
                    ),
                    None => {
                        let (r0, r1) = scratch.split_at_mut(src_row);
                        crate::texel::decode_range_to_linear(&fmt, texels, 2 * y * src_row, r0);
                        crate::texel::decode_range_to_linear(
                            &fmt,
                            texels,
                            (2 * y + 1) * src_row,
                            r1,
                        );
                        (r0, r1)
                    }
                };
                if !box_row_f32(r0, r1, d, ch, straight) {
                    finite.store(false, Ordering::Relaxed);
                }
                if let (Some(f), Some(c)) = (&encode, coded.as_deref_mut()) {
                    crate::texel::encode_u8(f, d, &mut c[i * row..][..row]);
                }
            }
        },
    );
    Some(ReducedLinear {
        linear: dst,
        stored: encode.map(|_| Texels::U8(stored)),
        finite: finite.into_inner(),
    })
}

/// What [`try_reduce_linear`] made.
pub(crate) struct ReducedLinear {
    /// The level in linear f32, unrounded.
    pub linear: Vec<f32>,
    /// The level encoded to the 8-bit format asked for, if any.
    pub stored: Option<Texels>,
    /// Every value came out finite (tracked by the RGBA kernel only;
    /// `false` means "not known").
    pub finite: bool,
}

fn rows_per_task(row_bytes: usize) -> usize {
    (TASK_BYTES / row_bytes.max(1)).max(1)
}

/// 2×2 box of an even-sized u8 level (linear or sRGB).
pub fn box_u8(src: &[u8], sw: usize, fmt: Format, straight: Option<usize>, srgb: bool) -> Vec<u8> {
    box_u8_with(src, sw, fmt, straight, srgb, srgb_simd::available())
}

/// [`box_u8`] with the sRGB RGBA8 kernel chosen by the caller: the AVX-512
/// one when `avx512` (the CPU must have it), else the scalar one. Lets the
/// tests compare both in one process without touching `PARVO_NO_AVX`.
fn box_u8_with(
    src: &[u8],
    sw: usize,
    fmt: Format,
    straight: Option<usize>,
    srgb: bool,
    avx512: bool,
) -> Vec<u8> {
    let ch = fmt.channels as usize;
    let (w, h) = (sw / 2, src.len() / (sw * ch) / 2);
    let row = w * ch;
    let mut dst: Vec<u8> = crate::mem::zeroed(row * h);
    let per = rows_per_task(row);
    let tables = srgb.then(fixed_tables);
    dst.par_chunks_mut(row * per).enumerate().for_each_init(
        || vec![0u16; sw * ch],
        |tmp, (task, out)| {
            for (i, d) in out.chunks_exact_mut(row).enumerate() {
                let y = task * per + i;
                let r0 = &src[2 * y * sw * ch..][..sw * ch];
                let r1 = &src[(2 * y + 1) * sw * ch..][..sw * ch];
                let constant_alpha = match (tables, ch) {
                    (None, 4) => simd::row_rgba8_dispatch(r0, r1, tmp, d),
                    (None, _) => {
                        match ch {
                            1 => row_u8_linear::<1>(r0, r1, tmp, d),
                            2 => row_u8_linear::<2>(r0, r1, tmp, d),
                            _ => row_u8_linear::<3>(r0, r1, tmp, d),
                        }
                        false
                    }
                    (Some(t), 4) => srgb_simd::row_rgba8(r0, r1, d, t, avx512),
                    (Some(t), _) => {
                        row_u8_srgb(r0, r1, d, fmt, t);
                        false
                    }
                };
                if let Some(a) = straight
                    && !constant_alpha
                    && !(r0[a] == r1[a]
                        && alpha_is_constant(r0, ch, a)
                        && alpha_is_constant(r1, ch, a))
                {
                    fix_straight_alpha_u8(r0, r1, d, ch, a, tables);
                }
            }
        },
    );
    dst
}

#[inline(always)]
fn row_u8_linear<const CH: usize>(r0: &[u8], r1: &[u8], tmp: &mut [u16], dst: &mut [u8]) {
    for ((t, &a), &b) in tmp.iter_mut().zip(r0).zip(r1) {
        *t = a as u16 + b as u16;
    }
    for (d, s) in dst.chunks_exact_mut(CH).zip(tmp.chunks_exact(2 * CH)) {
        for c in 0..CH {
            d[c] = ((s[c] + s[CH + c] + 2) >> 2) as u8;
        }
    }
}

/// True when every texel of the row has the same alpha (the common opaque
/// case). Alpha-carrying layouts have 2 or 4 channels, so 8-byte words hold
/// whole texels: XOR each word with the first texel's alpha pattern, mask
/// the alpha bytes and OR everything together (vectorises to a few
/// instructions per 8 bytes).
fn alpha_is_constant(row: &[u8], ch: usize, a: usize) -> bool {
    debug_assert!(ch == 2 || ch == 4);
    let (mut mask, mut pattern) = (0u64, 0u64);
    for byte in (a..8).step_by(ch) {
        mask |= 0xFF << (8 * byte);
        pattern |= (row[a] as u64) << (8 * byte);
    }
    let (words, rest) = row.as_chunks::<8>();
    let acc = words.iter().fold(0u64, |acc, w| {
        acc | ((u64::from_le_bytes(*w) ^ pattern) & mask)
    });
    acc == 0 && rest.chunks_exact(ch).all(|px| px[a] == row[a])
}

/// SIMD kernels. SSE2 is part of the x86-64 baseline; loads and stores go
/// through arrays (`bytemuck::cast`), which compile to unaligned vector
/// moves, so the kernel itself is safe code. Other targets use the plain
/// loop.
mod simd {
    /// The RGBA8 row kernel for this target. Returns true when every alpha
    /// byte of both rows equals `r0[3]` (then no alpha weighting is needed).
    #[inline]
    pub fn row_rgba8_dispatch(r0: &[u8], r1: &[u8], tmp: &mut [u16], dst: &mut [u8]) -> bool {
        #[cfg(target_arch = "x86_64")]
        #[allow(unsafe_code)]
        // SAFETY: `row_rgba8` only requires SSE2, which every x86_64 CPU has
        // (it is in the target's baseline feature set).
        unsafe {
            row_rgba8(r0, r1, tmp, dst)
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            super::row_u8_linear::<4>(r0, r1, tmp, dst);
            r0[3] == r1[3]
                && super::alpha_is_constant(r0, 4, 3)
                && super::alpha_is_constant(r1, 4, 3)
        }
    }

    /// 2×2 averages of RGBA f32 texel pairs (`a`, `b` are two rows of
    /// `2 · d.len()` texels). Returns whether any alpha differs from the
    /// first alpha of `a`, and the largest `bits & 0x7fff_ffff` of an output
    /// value (≥ `0x7f80_0000` means a non-finite output). On x86_64 each
    /// texel is one SSE register (SSE2 is baseline, so the intrinsics are
    /// safe to call); LLVM's own vectoriser shuffles lanes across texels
    /// instead and is about twice as slow.
    /// With AVX-512 (detected once; `PARVO_NO_AVX` turns it off) four
    /// texels per register, the same operations in the same order: the
    /// same bits.
    #[inline]
    pub fn rgba_f32_box(a: &[[f32; 4]], b: &[[f32; 4]], d: &mut [[f32; 4]]) -> (bool, u32) {
        #[cfg(target_arch = "x86_64")]
        if d.len() >= 8 && crate::cpu::avx512_sample() {
            #[allow(unsafe_code)]
            // SAFETY: `avx512_sample()` confirmed AVX-512 F, the only
            // feature `rgba_f32_box_avx512` is compiled for.
            return unsafe { rgba_f32_box_avx512(a, b, d) };
        }
        #[cfg(target_arch = "x86_64")]
        #[allow(unsafe_code)]
        // SAFETY: `rgba_f32_box_sse2` only requires SSE2, which every x86_64
        // CPU has (it is in the target's baseline feature set).
        unsafe {
            rgba_f32_box_sse2(a, b, d)
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let first = a[0][3].to_bits();
            let (mut diff, mut top) = (0u32, 0u32);
            for ((o, p), q) in d.iter_mut().zip(a.chunks_exact(2)).zip(b.chunks_exact(2)) {
                for c in 0..4 {
                    o[c] = 0.25 * ((p[0][c] + p[1][c]) + (q[0][c] + q[1][c]));
                    top = top.max(o[c].to_bits() & 0x7fff_ffff);
                }
                diff |= [p[0][3], p[1][3], q[0][3], q[1][3]]
                    .iter()
                    .fold(0, |acc, v| acc | (v.to_bits() ^ first));
            }
            (diff != 0, top)
        }
    }

    /// [`rgba_f32_box`] four output texels at a time: the even and the odd
    /// source texels of each row gathered by 128-bit shuffles, then the
    /// SSE2 kernel's sums in its order; the tail by the SSE2 kernel.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f")]
    pub(super) fn rgba_f32_box_avx512(
        a: &[[f32; 4]],
        b: &[[f32; 4]],
        d: &mut [[f32; 4]],
    ) -> (bool, u32) {
        use crate::simd::{load_ps, store_ps};
        use std::arch::x86_64::*;
        let n = d.len() / 4 * 4;
        let quarter = _mm512_set1_ps(0.25);
        let first = _mm512_set1_epi32(a[0][3].to_bits() as i32);
        let abs = _mm512_set1_epi32(0x7fff_ffff);
        let (mut diff, mut top) = (_mm512_setzero_si512(), _mm512_setzero_si512());
        for ((o, p), q) in d[..n]
            .as_chunks_mut::<4>()
            .0
            .iter_mut()
            .zip(a.as_chunks::<8>().0)
            .zip(b.as_chunks::<8>().0)
        {
            let p: &[[f32; 16]; 2] = bytemuck::cast_ref(p);
            let q: &[[f32; 16]; 2] = bytemuck::cast_ref(q);
            let (p0, p1, q0, q1) = (
                load_ps(&p[0]),
                load_ps(&p[1]),
                load_ps(&q[0]),
                load_ps(&q[1]),
            );
            // Texels 0, 2, 4, 6 and 1, 3, 5, 7 of each row.
            let pe = _mm512_shuffle_f32x4::<0b10_00_10_00>(p0, p1);
            let po = _mm512_shuffle_f32x4::<0b11_01_11_01>(p0, p1);
            let qe = _mm512_shuffle_f32x4::<0b10_00_10_00>(q0, q1);
            let qo = _mm512_shuffle_f32x4::<0b11_01_11_01>(q0, q1);
            let s = _mm512_mul_ps(
                quarter,
                _mm512_add_ps(_mm512_add_ps(pe, po), _mm512_add_ps(qe, qo)),
            );
            store_ps(bytemuck::cast_mut(o), s);
            let x = |v: __m512| _mm512_xor_si512(_mm512_castps_si512(v), first);
            diff = _mm512_or_si512(
                diff,
                _mm512_or_si512(_mm512_or_si512(x(p0), x(p1)), _mm512_or_si512(x(q0), x(q1))),
            );
            top = _mm512_max_epu32(top, _mm512_and_si512(_mm512_castps_si512(s), abs));
        }
        let alpha_differs = _mm512_mask_test_epi32_mask(0x8888, diff, diff) != 0;
        let top = _mm512_reduce_max_epu32(top);
        if n == d.len() {
            return (alpha_differs, top);
        }
        // The tail compares with the row's first alpha too.
        let (ta, tb) = (&a[2 * n..], &b[2 * n..]);
        let first = a[0][3];
        let (tail_diff, tail_top) = rgba_f32_box_sse2_from(ta, tb, &mut d[n..], first);
        (alpha_differs || tail_diff, top.max(tail_top))
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "sse2")]
    pub(super) fn rgba_f32_box_sse2(
        a: &[[f32; 4]],
        b: &[[f32; 4]],
        d: &mut [[f32; 4]],
    ) -> (bool, u32) {
        rgba_f32_box_sse2_from(a, b, d, a[0][3])
    }

    /// The SSE2 kernel, alphas compared with `first`.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "sse2")]
    fn rgba_f32_box_sse2_from(
        a: &[[f32; 4]],
        b: &[[f32; 4]],
        d: &mut [[f32; 4]],
        first: f32,
    ) -> (bool, u32) {
        {
            use std::arch::x86_64::*;
            let ld = |t: &[f32; 4]| -> __m128 { bytemuck::cast(*t) };
            let quarter = _mm_set1_ps(0.25);
            let first = _mm_set1_epi32(first.to_bits() as i32);
            let abs = _mm_set1_epi32(0x7fff_ffff);
            let (mut diff, mut top) = (_mm_setzero_si128(), _mm_setzero_si128());
            for ((o, p), q) in d.iter_mut().zip(a.chunks_exact(2)).zip(b.chunks_exact(2)) {
                let (p0, p1, q0, q1) = (ld(&p[0]), ld(&p[1]), ld(&q[0]), ld(&q[1]));
                let s = _mm_mul_ps(quarter, _mm_add_ps(_mm_add_ps(p0, p1), _mm_add_ps(q0, q1)));
                *o = bytemuck::cast(s);
                let x = _mm_or_si128(
                    _mm_or_si128(
                        _mm_xor_si128(_mm_castps_si128(p0), first),
                        _mm_xor_si128(_mm_castps_si128(p1), first),
                    ),
                    _mm_or_si128(
                        _mm_xor_si128(_mm_castps_si128(q0), first),
                        _mm_xor_si128(_mm_castps_si128(q1), first),
                    ),
                );
                diff = _mm_or_si128(diff, x);
                // Magnitudes as integers: signed max is fine below 2^31.
                let m = _mm_and_si128(_mm_castps_si128(s), abs);
                let gt = _mm_cmpgt_epi32(m, top);
                top = _mm_or_si128(_mm_and_si128(gt, m), _mm_andnot_si128(gt, top));
            }
            let diff: [u32; 4] = bytemuck::cast(diff);
            let top: [u32; 4] = bytemuck::cast(top);
            (diff[3] != 0, top.into_iter().max().unwrap_or(0))
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "sse2")]
    fn row_rgba8(r0: &[u8], r1: &[u8], tmp: &mut [u16], dst: &mut [u8]) -> bool {
        use std::arch::x86_64::*;
        let load = |s: &[u8; 16]| -> __m128i { bytemuck::cast(*s) };
        let (zero, two) = (_mm_setzero_si128(), _mm_set1_epi16(2));
        let alpha_mask = _mm_set1_epi32(0xFF00_0000u32 as i32);
        let alpha_ref = _mm_set1_epi32(((r0[3] as u32) << 24) as i32);
        let mut diff = zero;
        let n = dst.len() / 16;
        // 32 source bytes (8 texels) of each row per step, as two loads.
        fn pairs(r: &[u8]) -> &[[[u8; 16]; 2]] {
            r.as_chunks::<16>().0.as_chunks::<2>().0
        }
        for ((d, [a0, a1]), [b0, b1]) in dst.chunks_exact_mut(16).zip(pairs(r0)).zip(pairs(r1)) {
            let (a0, a1) = (load(a0), load(a1));
            let (b0, b1) = (load(b0), load(b1));
            let any = _mm_or_si128(_mm_xor_si128(a0, alpha_ref), _mm_xor_si128(a1, alpha_ref));
            let any = _mm_or_si128(
                any,
                _mm_or_si128(_mm_xor_si128(b0, alpha_ref), _mm_xor_si128(b1, alpha_ref)),
            );
            diff = _mm_or_si128(diff, _mm_and_si128(any, alpha_mask));
            // Vertical sums of pixels 0-1, 2-3, 4-5, 6-7 as u16 lanes.
            let s0 = _mm_add_epi16(_mm_unpacklo_epi8(a0, zero), _mm_unpacklo_epi8(b0, zero));
            let s1 = _mm_add_epi16(_mm_unpackhi_epi8(a0, zero), _mm_unpackhi_epi8(b0, zero));
            let s2 = _mm_add_epi16(_mm_unpacklo_epi8(a1, zero), _mm_unpacklo_epi8(b1, zero));
            let s3 = _mm_add_epi16(_mm_unpackhi_epi8(a1, zero), _mm_unpackhi_epi8(b1, zero));
            // Horizontal pairs: low pixel + high pixel of each register.
            let o01 = _mm_add_epi16(_mm_unpacklo_epi64(s0, s1), _mm_unpackhi_epi64(s0, s1));
            let o23 = _mm_add_epi16(_mm_unpacklo_epi64(s2, s3), _mm_unpackhi_epi64(s2, s3));
            let o01 = _mm_srli_epi16(_mm_add_epi16(o01, two), 2);
            let o23 = _mm_srli_epi16(_mm_add_epi16(o23, two), 2);
            let out: [u8; 16] = bytemuck::cast(_mm_packus_epi16(o01, o23));
            d.copy_from_slice(&out);
        }
        let diff: [u64; 2] = bytemuck::cast(diff);
        let mut constant = diff == [0, 0];
        let done = n * 16;
        if done < dst.len() {
            let (t0, t1) = (&r0[2 * done..], &r1[2 * done..]);
            super::row_u8_linear::<4>(t0, t1, &mut tmp[2 * done..], &mut dst[done..]);
            constant &= t0
                .chunks_exact(4)
                .chain(t1.chunks_exact(4))
                .all(|p| p[3] == r0[3]);
        }
        constant
    }
}

/// Fixed-point sRGB tables: decode to 2^-24 units, thresholds in 2^-26
/// units (a sum of four decoded values), and the bucket index.
pub(crate) struct FixedSrgb {
    dec: [u32; 256],
    /// The decision thresholds themselves, kept for the exhaustive test.
    #[cfg(test)]
    thr: [u32; 256],
    /// Indexed by `s >> BUCKET_SHIFT` masked to the table size (so no
    /// bounds check); sums reach at most bucket 4096, the rest is padding.
    /// Each entry packs the code at the bucket's start (low 8 bits) and
    /// the offset within the bucket of the one threshold it may hold
    /// (2^14 when it holds none), so encoding is one look-up.
    bucket: Box<[u32; BUCKETS]>,
}

const BUCKETS: usize = 8192;

/// Bucket width 2^14 units: below the smallest threshold spacing (20369
/// units, in the linear segment near black), so a bucket holds at most one
/// threshold; the 4097 buckets in use (16 KiB) stay in the L1 cache.
const BUCKET_SHIFT: u32 = 14;

pub(crate) fn fixed_tables() -> &'static FixedSrgb {
    static T: OnceLock<FixedSrgb> = OnceLock::new();
    T.get_or_init(|| {
        let mut dec = [0u32; 256];
        for (c, d) in dec.iter_mut().enumerate() {
            *d = (srgb::decode_f64(c as f64 / 255.0) * (1u64 << 24) as f64).round() as u32;
        }
        let mut thr = [u32::MAX; 256];
        for (k, t) in thr.iter_mut().enumerate().take(255) {
            *t = (srgb::decode_f64((k as f64 + 0.5) / 255.0) * (1u64 << 26) as f64).ceil() as u32;
        }
        let mut bucket = Box::new([0u32; BUCKETS]);
        let mut code = 0usize;
        for (b, slot) in bucket.iter_mut().enumerate() {
            let lo = (b as u32) << BUCKET_SHIFT;
            while code < 255 && lo >= thr[code] {
                code += 1;
            }
            // thr[code] > lo here; it lies in this bucket if below the next.
            let offset = match thr[code].checked_sub(lo) {
                Some(o) if o < 1 << BUCKET_SHIFT => o,
                _ => 1 << BUCKET_SHIFT,
            };
            *slot = code as u32 | offset << 8;
        }
        FixedSrgb {
            dec,
            #[cfg(test)]
            thr,
            bucket,
        }
    })
}

impl FixedSrgb {
    /// Decoded value of each code, 2^-24 units (code 255 is exactly 2^24).
    pub(super) fn dec(&self) -> &[u32; 256] {
        &self.dec
    }

    /// The 255 decision thresholds (2^-26 units), then `u32::MAX`.
    #[cfg(test)]
    pub(super) fn thr(&self) -> &[u32; 256] {
        &self.thr
    }

    /// Code of a sum of four decoded values (2^-26 units of linear light).
    ///
    /// Thresholds are at least 20369 units apart (the steepest part of
    /// the curve, near 0) and buckets 16384 wide, so the bucket's code is
    /// at most one below the answer: one comparison, no loop.
    #[inline(always)]
    pub(super) fn encode4(&self, s: u32) -> u8 {
        let e = self.bucket[(s >> BUCKET_SHIFT) as usize & (BUCKETS - 1)];
        let within = s & ((1 << BUCKET_SHIFT) - 1);
        e as u8 + u8::from(within >= e >> 8)
    }
}

fn row_u8_srgb(r0: &[u8], r1: &[u8], dst: &mut [u8], fmt: Format, t: &FixedSrgb) {
    match fmt.channels {
        1 => row_u8_srgb_n::<1, 1>(r0, r1, dst, t),
        2 => row_u8_srgb_n::<2, 1>(r0, r1, dst, t),
        3 => row_u8_srgb_n::<3, 3>(r0, r1, dst, t),
        _ => row_u8_srgb_n::<4, 3>(r0, r1, dst, t),
    }
}

/// `CH` channels of which the first `CC` are colour (the rest, if any, is
/// a linear alpha channel).
#[inline(always)]
pub(super) fn row_u8_srgb_n<const CH: usize, const CC: usize>(
    r0: &[u8],
    r1: &[u8],
    dst: &mut [u8],
    t: &FixedSrgb,
) {
    let dec = &t.dec;
    for ((d, a), b) in dst
        .chunks_exact_mut(CH)
        .zip(r0.chunks_exact(2 * CH))
        .zip(r1.chunks_exact(2 * CH))
    {
        for c in 0..CC {
            let s = dec[a[c] as usize]
                + dec[a[CH + c] as usize]
                + dec[b[c] as usize]
                + dec[b[CH + c] as usize];
            d[c] = t.encode4(s);
        }
        for c in CC..CH {
            let s = a[c] as u16 + a[CH + c] as u16 + b[c] as u16 + b[CH + c] as u16;
            d[c] = ((s + 2) >> 2) as u8;
        }
    }
}

/// Re-do the colour of blocks whose alphas differ as an alpha-weighted
/// average (the plain average already written is right for equal alphas).
fn fix_straight_alpha_u8(
    r0: &[u8],
    r1: &[u8],
    dst: &mut [u8],
    ch: usize,
    a: usize,
    srgb: Option<&FixedSrgb>,
) {
    for (x, d) in dst.chunks_exact_mut(ch).enumerate() {
        let (i0, i1) = (2 * x * ch, (2 * x + 1) * ch);
        let al = [r0[i0 + a], r0[i1 + a], r1[i0 + a], r1[i1 + a]];
        if al[0] == al[1] && al[0] == al[2] && al[0] == al[3] {
            continue;
        }
        let sa: u64 = al.iter().map(|&v| v as u64).sum();
        let px = [
            &r0[i0..i0 + ch],
            &r0[i1..i1 + ch],
            &r1[i0..i0 + ch],
            &r1[i1..i1 + ch],
        ];
        for c in (0..ch).filter(|&c| c != a) {
            match srgb {
                None => {
                    let num: u64 = (0..4).map(|k| al[k] as u64 * px[k][c] as u64).sum();
                    d[c] = ((2 * num + sa) / (2 * sa)) as u8;
                }
                Some(t) => {
                    let num: u64 = (0..4)
                        .map(|k| al[k] as u64 * t.dec[px[k][c] as usize] as u64)
                        .sum();
                    // Weighted mean in 2^-24 units, times 4 for encode4.
                    let s4 = (4 * num + sa / 2) / sa;
                    d[c] = t.encode4(s4 as u32);
                }
            }
        }
    }
}

/// 2×2 box of an even-sized linear f32 level, one fused pass. Returns the
/// level and whether every output value is finite (tracked by the RGBA
/// kernel only; `false` means "not known").
pub fn box_f32(src: &[f32], sw: usize, fmt: Format, straight: Option<usize>) -> (Vec<f32>, bool) {
    use std::sync::atomic::{AtomicBool, Ordering};
    let ch = fmt.channels as usize;
    let (w, h) = (sw / 2, src.len() / (sw * ch) / 2);
    let row = w * ch;
    let mut dst: Vec<f32> = crate::mem::zeroed(row * h);
    let per = rows_per_task(row * 4);
    let finite = AtomicBool::new(ch == 4);
    dst.par_chunks_mut(row * per)
        .enumerate()
        .for_each(|(task, out)| {
            for (i, d) in out.chunks_exact_mut(row).enumerate() {
                let y = task * per + i;
                let r0 = &src[2 * y * sw * ch..][..sw * ch];
                let r1 = &src[(2 * y + 1) * sw * ch..][..sw * ch];
                if !box_row_f32(r0, r1, d, ch, straight) {
                    finite.store(false, Ordering::Relaxed);
                }
            }
        });
    (dst, finite.load(Ordering::Relaxed))
}

/// One destination row of [`box_f32`] from source rows `r0` and `r1`
/// (`2·w·ch` values each; `d` gets `w·ch`);
/// false when the RGBA kernel saw a non-finite output (the other kernels
/// do not track it and return true only for RGBA's flag's sake: the
/// caller starts from `ch == 4`).
#[inline]
pub fn box_row_f32(
    r0: &[f32],
    r1: &[f32],
    d: &mut [f32],
    ch: usize,
    straight: Option<usize>,
) -> bool {
    match (ch, straight) {
        (4, _) => {
            let (alpha_differs, bad) = row_f32x4(r0, r1, d);
            // Alpha weighting changes nothing when every alpha of both
            // rows is the same (the opaque case).
            if let Some(a) = straight
                && alpha_differs
            {
                row_f32_straight(r0, r1, d, 4, a);
            }
            !bad || all_finite(d)
        }
        (3, _) => {
            row_f32::<3>(r0, r1, d);
            true
        }
        (2, None) => {
            row_f32::<2>(r0, r1, d);
            true
        }
        (1, _) => {
            row_f32::<1>(r0, r1, d);
            true
        }
        (2, Some(a)) => {
            row_f32::<2>(r0, r1, d);
            if !f32_alpha_constant::<2>(r0, r1, a) {
                row_f32_straight(r0, r1, d, 2, a);
            }
            true
        }
        _ => unreachable!("channel count is validated to 1..=4"),
    }
}

fn all_finite(v: &[f32]) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// The RGBA f32 row kernel: one pass that averages each 2×2 block (texels
/// as `[f32; 4]`, so each block is three vector adds and a multiply),
/// notes whether any alpha differs from the row's first alpha, and whether
/// any output is non-finite. Sums that overflow to infinity from finite
/// input are redone in f64. Returns `(alpha differs, non-finite seen)`.
fn row_f32x4(r0: &[f32], r1: &[f32], dst: &mut [f32]) -> (bool, bool) {
    let a4: &[[f32; 4]] = bytemuck::cast_slice(r0);
    let b4: &[[f32; 4]] = bytemuck::cast_slice(r1);
    let d4: &mut [[f32; 4]] = bytemuck::cast_slice_mut(dst);
    let (diff, top) = simd::rgba_f32_box(a4, b4, d4);
    let bad = top >= 0x7f80_0000;
    if bad {
        overflow_fixup::<4>(r0, r1, dst);
    }
    (diff, bad)
}

#[inline(always)]
fn row_f32<const CH: usize>(r0: &[f32], r1: &[f32], dst: &mut [f32]) {
    for ((d, a), b) in dst
        .chunks_exact_mut(CH)
        .zip(r0.chunks_exact(2 * CH))
        .zip(r1.chunks_exact(2 * CH))
    {
        for c in 0..CH {
            d[c] = 0.25 * ((a[c] + a[CH + c]) + (b[c] + b[CH + c]));
        }
    }
    if dst.iter().fold(false, |acc, v| acc | v.is_infinite()) {
        overflow_fixup::<CH>(r0, r1, dst);
    }
}

/// The f32 sum overflows only for values near f32::MAX; redo those few
/// texels in f64 so a finite input never averages to infinity.
fn overflow_fixup<const CH: usize>(r0: &[f32], r1: &[f32], dst: &mut [f32]) {
    for (x, d) in dst.chunks_exact_mut(CH).enumerate() {
        for (c, v) in d.iter_mut().enumerate() {
            if v.is_infinite() {
                let i = 2 * x * CH + c;
                let s = (r0[i] as f64 + r0[i + CH] as f64) + (r1[i] as f64 + r1[i + CH] as f64);
                *v = (0.25 * s) as f32;
            }
        }
    }
}

/// Every alpha of both rows equal (bitwise): weighting would cancel.
fn f32_alpha_constant<const CH: usize>(r0: &[f32], r1: &[f32], a: usize) -> bool {
    let first = r0[a].to_bits();
    let diff = |row: &[f32]| {
        row.chunks_exact(CH)
            .fold(0u32, |acc, t| acc | (t[a].to_bits() ^ first))
    };
    (diff(r0) | diff(r1)) == 0
}

fn row_f32_straight(r0: &[f32], r1: &[f32], dst: &mut [f32], ch: usize, a: usize) {
    for ((d, p), q) in dst
        .chunks_exact_mut(ch)
        .zip(r0.chunks_exact(2 * ch))
        .zip(r1.chunks_exact(2 * ch))
    {
        let al = [p[a] as f64, p[ch + a] as f64, q[a] as f64, q[ch + a] as f64];
        let sa = (al[0] + al[1]) + (al[2] + al[3]);
        for c in 0..ch {
            let v = [p[c] as f64, p[ch + c] as f64, q[c] as f64, q[ch + c] as f64];
            d[c] = if c == a {
                0.25 * sa
            } else if 0.25 * sa > 1e-7 {
                ((al[0] * v[0] + al[1] * v[1]) + (al[2] * v[2] + al[3] * v[3])) / sa
            } else {
                0.25 * ((v[0] + v[1]) + (v[2] + v[3]))
            } as f32;
        }
        if 0.25 * sa <= 1e-7 && d[a] < 0.0 && d[a].is_finite() {
            d[a] = 0.0;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texel::ChannelType;

    /// Every level of a box chain, reduced with the AVX-512 sRGB kernel or
    /// the scalar one (the same choice `PARVO_NO_AVX` makes, without the
    /// environment).
    fn box_chain(level0: &[u8], w: usize, h: usize, fmt: Format, avx512: bool) -> Vec<Vec<u8>> {
        let straight = fmt
            .alpha_channel()
            .filter(|_| fmt.alpha == AlphaMode::Straight);
        let (mut levels, mut w, mut h) = (vec![level0.to_vec()], w, h);
        while w % 2 == 0 && h % 2 == 0 && w * h > 1 {
            let src = levels.last().expect("level 0");
            levels.push(box_u8_with(src, w, fmt, straight, true, avx512));
            (w, h) = (w / 2, h / 2);
        }
        levels
    }

    #[test]
    fn avx512_and_scalar_srgb_box_chains_are_identical() {
        if !srgb_simd::supported() {
            eprintln!("skipped: no AVX-512 F/BW/VBMI/VNNI on this CPU");
            return;
        }
        let mut state = 0x2545_F491_4F6C_DD1Du64;
        let mut byte = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 32) as u8
        };
        // Random colour; alpha opaque in the top third, random in the
        // middle, constant per 8×8 tile below (so some rows have constant,
        // non-255 alpha and some blocks straddle tiles).
        for (w, h) in [(512usize, 256usize), (260, 24), (2, 2), (96, 2)] {
            let mut level0 = vec![0u8; w * h * 4];
            for (i, px) in level0.chunks_exact_mut(4).enumerate() {
                let (x, y) = (i % w, i / w);
                px[..3].iter_mut().for_each(|c| *c = byte());
                px[3] = match 3 * y / h {
                    0 => 255,
                    1 => byte(),
                    _ => (x / 8 * 37 + y / 8 * 101) as u8,
                };
            }
            for alpha in [AlphaMode::Straight, AlphaMode::Premultiplied] {
                let fmt = Format {
                    alpha,
                    ..Format::new(4, ChannelType::U8, ColorSpace::Srgb)
                };
                let fast = box_chain(&level0, w, h, fmt, true);
                let plain = box_chain(&level0, w, h, fmt, false);
                assert!(fast.len() > 1, "{w}×{h} has a reduced level");
                for (k, (a, b)) in fast.iter().zip(&plain).enumerate() {
                    assert!(a == b, "{w}×{h} {alpha:?}: level {k} differs");
                }
            }
        }
    }

    /// The RGBA f32 box by its formula, texel by texel: `(outputs, alpha
    /// differs from the first, largest magnitude bits)`.
    fn f32_box_reference(a: &[[f32; 4]], b: &[[f32; 4]]) -> (Vec<[f32; 4]>, bool, u32) {
        let first = a[0][3].to_bits();
        let (mut out, mut diff, mut top) = (Vec::new(), false, 0u32);
        for (p, q) in a.chunks_exact(2).zip(b.chunks_exact(2)) {
            let o: [f32; 4] =
                std::array::from_fn(|c| 0.25 * ((p[0][c] + p[1][c]) + (q[0][c] + q[1][c])));
            top = o.iter().fold(top, |t, v| t.max(v.to_bits() & 0x7fff_ffff));
            diff |= [p[0][3], p[1][3], q[0][3], q[1][3]]
                .iter()
                .any(|v| v.to_bits() != first);
            out.push(o);
        }
        (out, diff, top)
    }

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn f32_box_kernels_equal_the_formula_bit_for_bit() {
        let avx512 = crate::cpu::avx512_sample();
        if !avx512 {
            eprintln!("skipped the AVX-512 kernel: no AVX-512 (or PARVO_NO_AVX set)");
        }
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for n in [1usize, 3, 4, 7, 8, 9, 15, 16, 17, 31, 64, 333, 1001] {
            // 0: colour random, alpha constant; 1: one alpha differs, at
            // a random place (often in the tail); 2: huge values (sums
            // overflow); 3: a NaN; 4: everything random.
            for case in 0..5 {
                for _ in 0..4 {
                    let mut rows = vec![[0f32; 4]; 4 * n];
                    for t in rows.iter_mut() {
                        for c in &mut t[..3] {
                            *c = (next() >> 40) as f32 / (1u64 << 24) as f32;
                        }
                        t[3] = 0.75;
                    }
                    let at = (next() % (4 * n as u64)) as usize;
                    match case {
                        1 => rows[at][3] = 0.5,
                        2 => rows[at][(next() % 4) as usize] = 3.0e38,
                        3 => rows[at][(next() % 4) as usize] = f32::NAN,
                        4 => rows.iter_mut().for_each(|t| {
                            *t = std::array::from_fn(|_| f32::from_bits(next() as u32))
                        }),
                        _ => {}
                    }
                    let (a, b) = rows.split_at(2 * n);
                    let (want, want_diff, want_top) = f32_box_reference(a, b);
                    // NaN payloads depend on operand order, which the
                    // compiler may swap in the formula: any NaN is NaN.
                    let bits = |v: &[[f32; 4]]| -> Vec<u32> {
                        v.iter()
                            .flatten()
                            .map(|x| if x.is_nan() { u32::MAX } else { x.to_bits() })
                            .collect()
                    };
                    let check = |d: &[[f32; 4]], got: (bool, u32), which: &str| {
                        assert_eq!(bits(d), bits(&want), "{which}: n {n}, case {case}");
                        assert_eq!(got, (want_diff, want_top), "{which}: n {n}, case {case}");
                    };
                    let mut d = vec![[0f32; 4]; n];
                    #[allow(unsafe_code)]
                    // SAFETY: SSE2 is in the x86_64 baseline.
                    let got = unsafe { simd::rgba_f32_box_sse2(a, b, &mut d) };
                    check(&d, got, "sse2");
                    if avx512 {
                        let mut e = vec![[0f32; 4]; n];
                        #[allow(unsafe_code)]
                        // SAFETY: `avx512_sample()` confirmed AVX-512 F.
                        let got = unsafe { simd::rgba_f32_box_avx512(a, b, &mut e) };
                        check(&e, got, "avx512");
                        // The two kernels: the same bits, NaN payloads too.
                        let raw = |v: &[[f32; 4]]| -> Vec<u32> {
                            v.iter().flatten().map(|x| x.to_bits()).collect()
                        };
                        assert_eq!(raw(&e), raw(&d), "avx512 against sse2: n {n}, case {case}");
                    }
                }
            }
        }
    }

    #[test]
    fn one_step_encode_equals_the_threshold_count_everywhere() {
        let t = fixed_tables();
        let count = |s: u32| t.thr.iter().filter(|&&x| s >= x).count() as u8;
        let mut probes: Vec<u32> = (0..=(1u32 << 26)).step_by(4099).collect();
        for &x in &t.thr[..255] {
            probes.extend([x.saturating_sub(1), x, x + 1]);
        }
        probes.push(1 << 26);
        for s in probes {
            assert_eq!(t.encode4(s), count(s), "s = {s}");
        }
    }
}
