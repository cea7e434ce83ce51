//! AVX-512 lookups for the bilinear and trilinear filters and footprint
//! assembly (linear magnification and minification filters, mip mode
//! nearest or linear, no texel tracing), and for the isotropic nearest
//! filter ([`nearest`]: one texel per lookup, no blend within a level),
//! chosen at run time on CPUs with AVX-512 F, BW, DQ, VL and VBMI.
//! `PARVO_NO_AVX=1` turns them off.
//!
//! # Same answers, bit for bit
//! These paths perform the portable code's operations on the same values
//! in the same order — `f64` positions, the exponent-based nearest-mip
//! rule, the piecewise-quartic `log2`, `f32` blends as separate
//! multiplies and adds (no fused multiply-add) — so they return exactly
//! what the portable code returns; `tests/core/sampling_core/sample_simd.rs` compares the two
//! on random and extreme queries, and the unit tests below compare the
//! lane-wise `log2` and level plans with the portable ones directly (a
//! wrong level can hide behind the portable fallback). Only the way the
//! work is spread over registers differs:
//!
//! - **First pass, per block of 8 queries (or 8 probes)**, one lane
//!   each: the query fields transposed from the array of queries, the
//!   footprint, level choice, blend weight and address of the 2×2 block on
//!   each level, and whether that block lies inside its level, staged in
//!   memory for a chunk of blocks ([`Staged`]). Footprint assembly first
//!   sets up 8 queries at a time, then lays the probes of a chunk of
//!   queries end to end, so probes of different queries share a block.
//! - **Second pass, per 4 lanes**, one 512-bit register per corner of the
//!   block (lane `j` in 128-bit group `j`, RGBA `f32`): a packed RGBA8
//!   block is two 8-byte loads per lane, and the 64 codes of 4 lanes are
//!   decoded at once — `vpermi2b` looks each code up in the four byte
//!   planes of the decode table and unpacking interleaves the planes back
//!   into `f32`s; linear channels are converted and scaled instead. An
//!   `f32` block is two 32-byte loads per lane. Blocks of the other
//!   storages (1–3 channel `u8`, `u16`, `f16`, 1–3 channel `f32`) are
//!   decoded texel by texel with `Pixel::decode` and then blended in
//!   registers like the others. The bilinear blend and the
//!   level blend then run on 4 lanes per instruction and store 4 results
//!   at once. Footprint assembly then sums each query's probes in order.
//!
//! Two passes rather than one loop from query to colour: each loop's
//! iterations are short and independent, so the core overlaps them.
//!
//! No gathers: on the machines measured they cost about two cycles per
//! element, more than the loads and table look-ups above (the `log2` of
//! the trilinear level permutes its coefficients in registers).
//!
//! A lane whose block is not inside its level (NaN or huge coordinates,
//! edge crossings, a ρ² of zero or outside the normal `f64` range) reads a
//! block of zeros instead and is then handed to the portable code, which
//! handles every case; so are the queries of a slice's last, partial
//! block.

// Intrinsics: every `unsafe` block below says which features are enabled
// and why its memory accesses stay in bounds.
#![allow(unsafe_code)]

use std::arch::x86_64::*;

use super::aniso::Setup;
use super::bilinear::{Lin, Near};
use super::fetch::{Addressing, Chain, Lut8, Pixel};
use super::footprint::{LOG2_BITS, LOG2_POLY, Lod, Plan, UNBOUNDED_TEXELS};
use super::trilinear::{self, MIP_LINEAR, MIP_NEAREST};
use super::{Query, SamplerOptions, aniso};
use crate::trace::NoTrace;

/// True when the CPU has the features these paths need and
/// `PARVO_NO_AVX` is not set (checked once).
pub(crate) fn available() -> bool {
    crate::cpu::avx512_sample()
}

/// Most levels the per-lane level tables hold (a 32768-texel side).
const MAX_LEVELS: usize = 16;

/// True when `c` can take these paths: at most [`MAX_LEVELS`] levels, and
/// texels of at most 16 bytes; packed RGBA8 ones need colour channels
/// that share a decode table. RGBA8 and RGBA `f32` blocks are decoded in
/// registers; the other storages (1–3 channel `u8`, `u16`, `f16`, 1–3
/// channel `f32`) by `Pixel::decode` per texel ([`group_any`]), the rest
/// of the lookup in registers as for the others.
pub(crate) fn fits<P: Pixel>(c: &Chain<P>) -> bool {
    let texels_ok = match P::packed(&c.lut) {
        Some(l) => std::mem::size_of::<P>() == 4 && l.shared,
        None => std::mem::size_of::<P>() <= 16,
    };
    c.levels.len() <= MAX_LEVELS && texels_ok
}

/// Per-level constants as lane tables (index = level), two registers of
/// 8 levels each. The sizes as `f64`, `w − 1`, `h − 1` and the bytes per
/// row follow from `w` and `h` by a conversion, a subtract or a shift,
/// which run on either vector port, where more table look-ups would take
/// the shuffle port the texel decode needs.
struct Levels {
    w: [__m512i; 2],
    h: [__m512i; 2],
    /// Address of the level's first texel (its provenance exposed, see
    /// [`read`]).
    base: [__m512i; 2],
}

/// The per-level constants of a chain as plain arrays (index = level),
/// worked out once per sampler; [`Levels`] loads them into registers.
/// The addresses stay valid while the chain lives: the sampler that owns
/// this table owns the chain (through an `Arc`), whose level buffers never
/// move.
#[derive(Clone, Debug)]
pub(crate) struct LevelTable {
    /// `w`, `h`, the level's address.
    int: [[i64; 16]; 3],
}

impl LevelTable {
    /// The table of `c`, or `None` when these paths cannot run on it
    /// (not [`available`], or `c` does not [`fits`]).
    pub(crate) fn new<P: Pixel>(c: &Chain<P>) -> Option<LevelTable> {
        if !(available() && fits(c)) {
            return None;
        }
        // Entries past the last level read as 1 × 1 (no block fits), so a
        // level index beyond the chain could only send a lane to the
        // portable path; the plans clamp every index to the chain anyway.
        let mut t = LevelTable {
            int: [[1; 16], [1; 16], [0; 16]],
        };
        for (k, l) in c.levels.iter().enumerate() {
            // `blocks` converts these back: `wf` and `hf` are the sizes
            // as `f64`, exactly.
            debug_assert_eq!((l.wf, l.hf), (l.w as f64, l.h as f64));
            t.int[0][k] = l.w as i64;
            t.int[1][k] = l.h as i64;
            t.int[2][k] = l.texels.as_ptr().expose_provenance() as i64;
        }
        Some(t)
    }
}

impl Levels {
    #[inline]
    #[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
    fn new(t: &LevelTable) -> Levels {
        Levels {
            w: epi64x2(&t.int[0]),
            h: epi64x2(&t.int[1]),
            base: epi64x2(&t.int[2]),
        }
    }
}

/// 16 values as two registers.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
fn epi64x2(a: &[i64; 16]) -> [__m512i; 2] {
    // SAFETY: two unaligned 64-byte loads inside the 128-byte array.
    unsafe {
        [
            _mm512_loadu_epi64(a.as_ptr()),
            _mm512_loadu_epi64(a.as_ptr().add(8)),
        ]
    }
}

#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
fn look_epi64(t: &[__m512i; 2], idx: __m512i) -> __m512i {
    _mm512_permutex2var_epi64(t[0], idx, t[1])
}

/// Where the 2×2 blocks of 8 lanes lie on their levels `lvl`:
/// `bilinear::bilinear`'s fast path, lane-wise.
struct Blocks {
    /// Address of texel (i0, j0) and of (i0, j0 + 1).
    top: __m512i,
    bot: __m512i,
    /// Fractions α and β.
    al: __m256,
    be: __m256,
    /// Lanes whose block lies inside the level.
    inside: u8,
}

#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
fn blocks<P: Pixel>(ls: &Levels, lvl: __m512i, u: __m512d, v: __m512d) -> Blocks {
    let (w, h) = (look_epi64(&ls.w, lvl), look_epi64(&ls.h, lvl));
    let half = _mm512_set1_pd(0.5);
    let x = _mm512_sub_pd(_mm512_mul_pd(u, _mm512_cvtepi64_pd(w)), half);
    let y = _mm512_sub_pd(_mm512_mul_pd(v, _mm512_cvtepi64_pd(h)), half);
    // floor(x) as an integer in one conversion rounding down. NaN, ±∞
    // and values beyond i64 convert to i64::MIN: huge as unsigned, so
    // outside every level, as `floor_fast` makes them. For lanes inside a
    // level the integer converts back to floor(x) exactly.
    const FLOOR: i32 = _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC;
    let i0 = _mm512_cvt_roundpd_epi64::<FLOOR>(x);
    let j0 = _mm512_cvt_roundpd_epi64::<FLOOR>(y);
    let (fx, fy) = (_mm512_cvtepi64_pd(i0), _mm512_cvtepi64_pd(j0));
    let one = _mm512_set1_epi64(1);
    // A block's first index must be below w − 1 and h − 1.
    let inside = _mm512_cmplt_epu64_mask(i0, _mm512_sub_epi64(w, one))
        & _mm512_cmplt_epu64_mask(j0, _mm512_sub_epi64(h, one));
    // Lanes inside the level have 0 ≤ i0, j0 and w below 2^32, so a
    // 32 × 32 → 64-bit multiply gives j0·w (other lanes' addresses are
    // replaced before use). Bytes from texels: a shift for the sizes that
    // are powers of two, a multiply for 3, 6 and 12.
    let k = _mm512_add_epi64(_mm512_mul_epu32(j0, w), i0);
    let top = _mm512_add_epi64(look_epi64(&ls.base, lvl), bytes::<P>(k));
    Blocks {
        top,
        bot: _mm512_add_epi64(top, bytes::<P>(w)),
        al: _mm512_cvtpd_ps(_mm512_sub_pd(x, fx)),
        be: _mm512_cvtpd_ps(_mm512_sub_pd(y, fy)),
        inside,
    }
}

/// Bytes of `n` texels (below 2^32) per lane: a shift for the sizes that
/// are powers of two, a multiply for 3, 6 and 12.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
fn bytes<P: Pixel>(n: __m512i) -> __m512i {
    let size = std::mem::size_of::<P>();
    if size.is_power_of_two() {
        _mm512_sllv_epi64(n, _mm512_set1_epi64(size.trailing_zeros() as i64))
    } else {
        _mm512_mul_epu32(n, _mm512_set1_epi64(size as i64))
    }
}

/// Where the texels of 8 nearest lookups lie on their levels `lvl`:
/// `bilinear::nearest`'s fast path, lane-wise. The address of texel
/// `(floor(u·w), floor(v·h))` ([`ZEROS`] for lanes outside their level)
/// and the lanes inside.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
fn texels<P: Pixel>(ls: &Levels, lvl: __m512i, u: __m512d, v: __m512d) -> (__m512i, u8) {
    let (w, h) = (look_epi64(&ls.w, lvl), look_epi64(&ls.h, lvl));
    // floor as in `blocks` (NaN, ±∞ and huge values: i64::MIN, outside).
    const FLOOR: i32 = _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC;
    let i = _mm512_cvt_roundpd_epi64::<FLOOR>(_mm512_mul_pd(u, _mm512_cvtepi64_pd(w)));
    let j = _mm512_cvt_roundpd_epi64::<FLOOR>(_mm512_mul_pd(v, _mm512_cvtepi64_pd(h)));
    let inside = _mm512_cmplt_epu64_mask(i, w) & _mm512_cmplt_epu64_mask(j, h);
    // Inside lanes have 0 ≤ i < w < 2^32 and 0 ≤ j: j·w by a 32 × 32-bit
    // multiply, as in `blocks`.
    let k = _mm512_add_epi64(_mm512_mul_epu32(j, w), i);
    let at = _mm512_add_epi64(look_epi64(&ls.base, lvl), bytes::<P>(k));
    let zeros = _mm512_set1_epi64(ZEROS.as_ptr().expose_provenance() as i64);
    (_mm512_mask_blend_epi64(inside, zeros, at), inside)
}

/// 64 zero bytes that lanes outside their level read instead of texels
/// (their results are then replaced by the portable path's).
static ZEROS: [u64; 8] = [0; 8];

/// The block addresses of 8 lanes, with [`ZEROS`] for the lanes not in
/// `fast`.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
fn addresses(b: &Blocks, fast: u8) -> ([u64; 8], [u64; 8]) {
    let zeros = _mm512_set1_epi64(ZEROS.as_ptr().expose_provenance() as i64);
    let (mut top, mut bot) = ([0u64; 8], [0u64; 8]);
    // SAFETY: unaligned 64-byte stores into the 64-byte arrays.
    unsafe {
        _mm512_storeu_epi64(
            top.as_mut_ptr().cast(),
            _mm512_mask_blend_epi64(fast, zeros, b.top),
        );
        _mm512_storeu_epi64(
            bot.as_mut_ptr().cast(),
            _mm512_mask_blend_epi64(fast, zeros, b.bot),
        );
    }
    (top, bot)
}

/// Reads `T` at an address from [`addresses`].
///
/// # Safety
/// The address is a block address of a lane inside its level, or
/// [`ZEROS`], and `size_of::<T>()` bytes from it stay inside that
/// allocation (at most 32: two texels of at most 16 bytes, or
/// [`ZEROS`]).
#[inline(always)]
unsafe fn read<T: Copy>(addr: u64) -> T {
    // SAFETY: the caller's contract; the address came from
    // `expose_provenance` on an allocation the chain (or the static) keeps
    // alive.
    unsafe { std::ptr::with_exposed_provenance::<T>(addr as usize).read_unaligned() }
}

/// One 256-entry byte table look-up of 64 codes: `vpermi2b` covers 128
/// entries, the code's top bit (`top`) picks between two.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
fn look_bytes(codes: __m512i, top: u64, t: &[u8; 256]) -> __m512i {
    // SAFETY: four 64-byte loads inside the 256-byte table.
    let q = unsafe {
        let p = t.as_ptr().cast::<i8>();
        [
            _mm512_loadu_epi8(p),
            _mm512_loadu_epi8(p.add(64)),
            _mm512_loadu_epi8(p.add(128)),
            _mm512_loadu_epi8(p.add(192)),
        ]
    };
    let lo = _mm512_permutex2var_epi8(q[0], codes, q[1]);
    let hi = _mm512_permutex2var_epi8(q[2], codes, q[3]);
    _mm512_mask_blend_epi8(top, lo, hi)
}

/// Byte `b` of a 128-bit group alone in a 32-bit lane (`vpshufb` reads a
/// 0x80 byte as 0).
const fn dw(b: i32) -> i32 {
    b | (0x80 << 8) | (0x80 << 16) | (0x80 << 24)
}

/// The bytes `pattern` selects from each 128-bit group of `codes`, as
/// `f32` times 1/255 (`texel::decode_u8` for linear channels).
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
fn widen(codes: __m512i, pattern: [i32; 4]) -> __m512 {
    let pattern = _mm512_set4_epi32(pattern[3], pattern[2], pattern[1], pattern[0]);
    let v = _mm512_shuffle_epi8(codes, pattern);
    _mm512_mul_ps(_mm512_cvtepi32_ps(v), _mm512_set1_ps(1.0 / 255.0))
}

/// The 2×2 blocks of 4 lanes of a packed RGBA8 chain, decoded: register
/// `c` holds corner `c` (00, 10, 01, 11) of lane `j` in 128-bit group
/// `j`, as RGBA `f32` ([`decode_rgba8`] of the 16 texels).
///
/// # Safety
/// The addresses satisfy [`read`] for 8 bytes.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
unsafe fn group_rgba8(lut: &Lut8, top: &[u64], bot: &[u64]) -> [__m512; 4] {
    // SAFETY: the caller's contract (two adjacent 4-byte texels per row).
    let mut x = [_mm_setzero_si128(); 4];
    for (j, x) in x.iter_mut().enumerate() {
        // SAFETY: the caller's contract (two adjacent 4-byte texels per
        // row).
        *x = unsafe { _mm_set_epi64x(read::<i64>(bot[j]), read::<i64>(top[j])) };
    }
    let codes = _mm512_inserti64x4::<1>(
        _mm512_castsi256_si512(_mm256_set_m128i(x[1], x[0])),
        _mm256_set_m128i(x[3], x[2]),
    );
    decode_rgba8(lut, codes)
}

/// 16 packed RGBA8 texels (one per 32-bit lane of `codes`), decoded:
/// register `c` holds texel `4j + c` in 128-bit group `j`, as RGBA `f32`.
/// The 64 codes are looked up in the four byte planes of the decode table
/// and the planes interleaved back into `f32`s (linear channels are
/// converted and scaled instead).
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
pub(crate) fn decode_rgba8(lut: &Lut8, codes: __m512i) -> [__m512; 4] {
    if lut.colour_linear && (lut.alpha_same || lut.alpha_linear) {
        return [
            widen(codes, [dw(0), dw(1), dw(2), dw(3)]),
            widen(codes, [dw(4), dw(5), dw(6), dw(7)]),
            widen(codes, [dw(8), dw(9), dw(10), dw(11)]),
            widen(codes, [dw(12), dw(13), dw(14), dw(15)]),
        ];
    }
    let top7 = _mm512_movepi8_mask(codes);
    // Bytes 3, 7, 11, … are alpha codes.
    const ALPHA: u64 = 0x8888_8888_8888_8888;
    let planes_alpha = !lut.alpha_same && !lut.alpha_linear;
    let mut p = [_mm512_setzero_si512(); 4];
    for (k, p) in p.iter_mut().enumerate() {
        *p = look_bytes(codes, top7, &lut.planes[0][k]);
        if planes_alpha {
            let a = look_bytes(codes, top7, &lut.planes[1][k]);
            *p = _mm512_mask_blend_epi8(ALPHA, *p, a);
        }
    }
    if lut.alpha_linear && !lut.alpha_same {
        // Linear alpha, `texel::decode_u8`: each texel's alpha code (its
        // top byte) as f32 times 1/255, in the texel's own 32 bits. Byte k
        // of that f32 goes to the alpha byte of plane k: shifted up by
        // 3 − k bytes, then blended (no shuffle-port work).
        let a = _mm512_castps_si512(_mm512_mul_ps(
            _mm512_cvtepi32_ps(_mm512_srli_epi32::<24>(codes)),
            _mm512_set1_ps(1.0 / 255.0),
        ));
        p[0] = _mm512_mask_blend_epi8(ALPHA, p[0], _mm512_slli_epi32::<24>(a));
        p[1] = _mm512_mask_blend_epi8(ALPHA, p[1], _mm512_slli_epi32::<16>(a));
        p[2] = _mm512_mask_blend_epi8(ALPHA, p[2], _mm512_slli_epi32::<8>(a));
        p[3] = _mm512_mask_blend_epi8(ALPHA, p[3], a);
    }
    // Within each 128-bit group (one lane's 16 codes): bytes 0-1 and 2-3
    // of each f32, then the f32s of codes 0-3, 4-7, 8-11 and 12-15.
    let a = _mm512_unpacklo_epi8(p[0], p[1]);
    let b = _mm512_unpackhi_epi8(p[0], p[1]);
    let c = _mm512_unpacklo_epi8(p[2], p[3]);
    let d = _mm512_unpackhi_epi8(p[2], p[3]);
    [
        _mm512_castsi512_ps(_mm512_unpacklo_epi16(a, c)),
        _mm512_castsi512_ps(_mm512_unpackhi_epi16(a, c)),
        _mm512_castsi512_ps(_mm512_unpacklo_epi16(b, d)),
        _mm512_castsi512_ps(_mm512_unpackhi_epi16(b, d)),
    ]
}

/// Two 32-byte rows in one register.
///
/// # Safety
/// The addresses satisfy [`read`] for 32 bytes.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
unsafe fn pair(a: u64, b: u64) -> __m512 {
    // SAFETY: the caller's contract.
    let (x, y) = unsafe { (read::<__m256>(a), read::<__m256>(b)) };
    _mm512_insertf32x8::<1>(_mm512_castps256_ps512(x), y)
}

/// [`group_rgba8`] for an RGBA `f32` chain: two 32-byte loads per lane.
///
/// # Safety
/// The addresses satisfy [`read`] for 32 bytes.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
unsafe fn group_f32(top: &[u64], bot: &[u64]) -> [__m512; 4] {
    // Two lanes' rows [t0 t1 | t0' t1'] per register.
    // SAFETY: the caller's contract.
    let (t01, t23, b01, b23) = unsafe {
        (
            pair(top[0], top[1]),
            pair(top[2], top[3]),
            pair(bot[0], bot[1]),
            pair(bot[2], bot[3]),
        )
    };
    [
        _mm512_shuffle_f32x4::<0b10_00_10_00>(t01, t23),
        _mm512_shuffle_f32x4::<0b11_01_11_01>(t01, t23),
        _mm512_shuffle_f32x4::<0b10_00_10_00>(b01, b23),
        _mm512_shuffle_f32x4::<0b11_01_11_01>(b01, b23),
    ]
}

/// The decoded blocks of lanes `4h … 4h + 3`.
///
/// # Safety
/// As [`group_rgba8`] or [`group_f32`].
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
unsafe fn group<P: Pixel>(lut: &P::Lut, top: &[u64; 8], bot: &[u64; 8], h: usize) -> [__m512; 4] {
    let (t, b) = (&top[4 * h..4 * h + 4], &bot[4 * h..4 * h + 4]);
    match P::packed(lut) {
        // SAFETY: the caller's contract.
        Some(l) => unsafe { group_rgba8(l, t, b) },
        // SAFETY: the caller's contract.
        None if P::RGBA_F32 => unsafe { group_f32(t, b) },
        // SAFETY: the caller's contract.
        None => unsafe { group_any::<P>(lut, t, b) },
    }
}

/// [`group_rgba8`] for the other storages: each lane's two texels per row
/// read and decoded by `Pixel::decode` (the portable code's decode, so
/// the same values), then loaded as the four corner registers.
///
/// # Safety
/// The addresses satisfy [`read`] for `2 · size_of::<P>()` bytes (at most
/// 32: [`fits`] admits texels of at most 16 bytes).
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
unsafe fn group_any<P: Pixel>(lut: &P::Lut, top: &[u64], bot: &[u64]) -> [__m512; 4] {
    // Corner c of lane j at d[c][j].
    let mut d = [[[0f32; 4]; 4]; 4];
    for j in 0..4 {
        // SAFETY: the caller's contract.
        let (t, b) = unsafe { (read::<[P; 2]>(top[j]), read::<[P; 2]>(bot[j])) };
        d[0][j] = t[0].decode(lut);
        d[1][j] = t[1].decode(lut);
        d[2][j] = b[0].decode(lut);
        d[3][j] = b[1].decode(lut);
    }
    // SAFETY: unaligned 64-byte loads of the 16-float corner arrays.
    d.map(|c| unsafe { _mm512_loadu_ps(c.as_ptr().cast()) })
}

/// Lane `4h + j` of an 8-lane vector in every float of 128-bit group `j`.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
fn spread(x: __m256, h: usize) -> __m512 {
    let b = 4 * h as i32;
    let idx = _mm512_set_epi32(
        b + 3,
        b + 3,
        b + 3,
        b + 3,
        b + 2,
        b + 2,
        b + 2,
        b + 2,
        b + 1,
        b + 1,
        b + 1,
        b + 1,
        b,
        b,
        b,
        b,
    );
    _mm512_permutexvar_ps(idx, _mm512_castps256_ps512(x))
}

/// `x·(1 − t) + y·t` with `omt` = 1 − t, as `fetch::lerp`.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
fn lerp16(x: __m512, y: __m512, omt: __m512, t: __m512) -> __m512 {
    _mm512_add_ps(_mm512_mul_ps(x, omt), _mm512_mul_ps(y, t))
}

/// The bilinear blend of the decoded blocks of lanes `4h … 4h + 3`:
/// `lerp(lerp(t00, t10, α), lerp(t01, t11, α), β)`, as `Pixel::bilerp`.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
fn bilerp(d: [__m512; 4], al8: __m256, be8: __m256, h: usize) -> __m512 {
    let one = _mm512_set1_ps(1.0);
    let (al, be) = (spread(al8, h), spread(be8, h));
    let (oma, omb) = (_mm512_sub_ps(one, al), _mm512_sub_ps(one, be));
    lerp16(
        lerp16(d[0], d[1], oma, al),
        lerp16(d[2], d[3], oma, al),
        omb,
        be,
    )
}

/// The 4 bits of `m` for lanes `4h … 4h + 3`, each repeated over the 4
/// floats of its group.
#[inline(always)]
fn group_mask(m: u8, h: usize) -> u16 {
    let m = (m >> (4 * h)) as u16;
    (0..4).fold(0, |acc, j| acc | ((m >> j & 1) * 0xF) << (4 * j))
}

/// Eight queries' fields as `f64` lanes: u, v, ∂u/∂x, ∂v/∂x, ∂u/∂y,
/// ∂v/∂y.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
fn fields(qs: &[Query; 8]) -> [__m512d; 6] {
    let p = qs.as_ptr().cast::<f32>();
    // SAFETY: `Query` is `repr(C)` with six `f32` fields, so 8 queries are
    // 48 floats: three 64-byte loads.
    let z = unsafe {
        [
            _mm512_loadu_ps(p),
            _mm512_loadu_ps(p.add(16)),
            _mm512_loadu_ps(p.add(32)),
        ]
    };
    let mut out = [_mm512_setzero_pd(); 6];
    for (f, out) in out.iter_mut().enumerate() {
        // SAFETY: a load of a 16-lane constant.
        let idx = unsafe { _mm512_loadu_epi32(FIELD_INDEX[f].as_ptr()) };
        let lo_part = _mm512_permutex2var_ps(z[0], idx, z[1]);
        let hi_part = _mm512_permutexvar_ps(idx, z[2]);
        let lanes = _mm512_mask_blend_ps(FIELD_HIGH[f], lo_part, hi_part);
        *out = _mm512_cvtps_pd(_mm512_castps512_ps256(lanes));
    }
    out
}

/// Lane i of field f is float 6i + f of eight queries: taken from the
/// first two registers (index mod 32) below 32, from the third above
/// ([`FIELD_HIGH`]).
const FIELD_INDEX: [[i32; 16]; 6] = {
    let mut t = [[0i32; 16]; 6];
    let mut f = 0;
    while f < 6 {
        let mut i = 0;
        while i < 8 {
            t[f][i] = ((6 * i + f) % 32) as i32;
            i += 1;
        }
        f += 1;
    }
    t
};

/// The lanes of each field taken from the third register.
const FIELD_HIGH: [u16; 6] = {
    let mut t = [0u16; 6];
    let mut f = 0;
    while f < 6 {
        let mut i = 0;
        while i < 8 {
            if 6 * i + f >= 32 {
                t[f] |= 1 << i;
            }
            i += 1;
        }
        f += 1;
    }
    t
};

/// ρx² and ρy² per lane: the squared lengths of the derivative vectors
/// in level-0 texels, as `square_len` in `footprint`.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
fn square_lens(lod: &Lod, f: &[__m512d; 6]) -> (__m512d, __m512d) {
    let (wf, hf) = (_mm512_set1_pd(lod.wf), _mm512_set1_pd(lod.hf));
    let (ax, ay) = (_mm512_mul_pd(f[2], wf), _mm512_mul_pd(f[3], hf));
    let (bx, by) = (_mm512_mul_pd(f[4], wf), _mm512_mul_pd(f[5], hf));
    (
        _mm512_add_pd(_mm512_mul_pd(ax, ax), _mm512_mul_pd(ay, ay)),
        _mm512_add_pd(_mm512_mul_pd(bx, bx), _mm512_mul_pd(by, by)),
    )
}

/// Lanes that blend a second level: δ > 0 and a level `lo` other than
/// `hi` (as `trilinear::probe`).
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
fn blends_two(delta: __m256, hi: __m512i, lo: __m512i) -> u8 {
    _mm256_cmp_ps_mask::<_CMP_GT_OQ>(delta, _mm256_setzero_ps()) & _mm512_cmpneq_epi64_mask(lo, hi)
}

/// ρmax² per lane, as `Lod::rho2`.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
fn rho2(lod: &Lod, f: &[__m512d; 6]) -> __m512d {
    let (rx2, ry2) = square_lens(lod, f);
    let s = _mm512_add_pd(rx2, ry2);
    // NaN or above f64::MAX in one compare ("not ≤", true when unordered).
    let bad = _mm512_cmp_pd_mask::<_CMP_NLE_UQ>(s, _mm512_set1_pd(f64::MAX));
    // `vmaxpd a, b` is `a > b ? a : b`: `rx2 >= ry2 ? rx2 : ry2` for the
    // lanes kept (neither is NaN there).
    let m = _mm512_max_pd(ry2, rx2);
    _mm512_mask_blend_pd(bad, m, _mm512_set1_pd(UNBOUNDED_TEXELS * UNBOUNDED_TEXELS))
}

/// `x < lo ? lo : x` then `x > hi ? hi : x` (`f64::clamp` for non-NaN
/// bounds; NaN passes through): `vmaxpd lo, x` is `lo > x ? lo : x` and
/// returns x when either is NaN, and `vminpd` likewise.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
fn clamp_pd(x: __m512d, lo: f64, hi: f64) -> __m512d {
    let x = _mm512_max_pd(_mm512_set1_pd(lo), x);
    _mm512_min_pd(_mm512_set1_pd(hi), x)
}

/// `footprint::log2` per lane, and the lanes it covers (normal, finite
/// x); the others need the library `log2`. The coefficients of each
/// lane's interval come from one in-register permute per table.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
fn log2(x: __m512d) -> (__m512d, u8) {
    let ok = _mm512_cmp_pd_mask::<_CMP_GE_OQ>(x, _mm512_set1_pd(f64::MIN_POSITIVE))
        & _mm512_cmp_pd_mask::<_CMP_LE_OQ>(x, _mm512_set1_pd(f64::MAX));
    let bits = _mm512_castpd_si512(x);
    let e = _mm512_cvtepi64_pd(_mm512_sub_epi64(
        _mm512_srli_epi64::<52>(bits),
        _mm512_set1_epi64(1023),
    ));
    let mant = _mm512_and_si512(bits, _mm512_set1_epi64((1 << 52) - 1));
    // The interval, 0 … 7: `permutexvar` reads the low 3 bits of each
    // 64-bit index.
    let i = _mm512_srli_epi64::<{ 52 - LOG2_BITS }>(mant);
    let f = _mm512_mul_pd(
        _mm512_cvtepi64_pd(_mm512_and_si512(
            mant,
            _mm512_set1_epi64((1 << (52 - LOG2_BITS)) - 1),
        )),
        _mm512_set1_pd(1.0 / (1u64 << (52 - LOG2_BITS)) as f64),
    );
    // Estrin's scheme, as `footprint::log2`.
    let f2 = _mm512_mul_pd(f, f);
    let lo = _mm512_add_pd(coefficient(0, i), _mm512_mul_pd(coefficient(1, i), f));
    let mid = _mm512_add_pd(coefficient(2, i), _mm512_mul_pd(coefficient(3, i), f));
    let hi = _mm512_add_pd(mid, _mm512_mul_pd(coefficient(4, i), f2));
    let p = _mm512_add_pd(lo, _mm512_mul_pd(f2, hi));
    // `if p < 1.0 { p } else { 1.0 }`: p is never NaN here.
    let r = _mm512_add_pd(e, _mm512_min_pd(p, _mm512_set1_pd(1.0)));
    (r, ok)
}

/// `LOG2_POLY[k][i]` per lane.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
fn coefficient(k: usize, i: __m512i) -> __m512d {
    // SAFETY: a 64-byte load of an 8-entry `f64` array.
    _mm512_permutexvar_pd(i, unsafe { _mm512_loadu_pd(LOG2_POLY[k].as_ptr()) })
}

/// The plan of 8 isotropic lookups, as `trilinear::plan::<Lin, MIP>`:
/// levels `hi` and `lo` and the blend δ per lane, and the lanes whose
/// plan this computes exactly (the others take the portable path).
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
fn plans<const MIP: u8>(
    lod: &Lod,
    o: &SamplerOptions,
    f: &[__m512d; 6],
) -> (__m512i, __m512i, __m256, u8) {
    let r2 = rho2(lod, f);
    if MIP == MIP_NEAREST {
        // `Lod::plan_nearest`'s level, with y clamped to [near_min,
        // near_max] ⊆ [1, 4^q] so that c ∈ [0, 2q] and d = c >> 1 needs no
        // clamp (the same level: see `Lod::near_min`).
        let y = clamp_pd(
            _mm512_mul_pd(r2, _mm512_set1_pd(lod.scale)),
            lod.near_min,
            lod.near_max,
        );
        let e = _mm512_srli_epi64::<52>(_mm512_add_epi64(
            _mm512_castpd_si512(y),
            _mm512_set1_epi64((1 << 52) - 1),
        ));
        let d = _mm512_srli_epi64::<1>(_mm512_sub_epi64(e, _mm512_set1_epi64(1023)));
        (d, d, _mm256_setzero_ps(), 0xFF)
    } else {
        // `Lod::lambda`, then `Plan::at(λ, q, Linear)`.
        let (l2, ok) = log2(r2);
        let base = _mm512_add_pd(
            _mm512_mul_pd(_mm512_set1_pd(0.5), l2),
            _mm512_set1_pd(o.lod_bias as f64),
        );
        let lambda = _mm512_cvtpd_ps(clamp_pd(base, o.lod_min as f64, o.lod_max as f64));
        let (h, lo, delta) = levels::<MIP_LINEAR>(lambda, lod.q);
        (h, lo, delta, ok)
    }
}

/// `Plan::at(λ, q, mip)` per lane, for mip mode `MIP` nearest or linear:
/// levels `hi` and `lo` and the blend δ; λ ≤ 0 (or NaN) is
/// magnification, level 0 alone.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
fn levels<const MIP: u8>(lambda: __m256, q: usize) -> (__m512i, __m512i, __m256) {
    let zero = _mm256_setzero_ps();
    let minify = _mm256_cmp_ps_mask::<_CMP_GT_OQ>(lambda, zero);
    let qi = _mm256_set1_epi32(q as i32);
    // d' = clamp(λ, 0, q).
    let d = _mm256_min_ps(_mm256_max_ps(lambda, zero), _mm256_set1_ps(q as f32));
    if MIP == MIP_NEAREST {
        // `mip_nearest`: ceil(d' + 0.5) − 1 as trunc(x) − [x integral].
        let x = _mm256_add_ps(d, _mm256_set1_ps(0.5));
        let t = _mm256_cvttps_epi32(x);
        let whole = _mm256_cmp_ps_mask::<_CMP_EQ_OQ>(_mm256_cvtepi32_ps(t), x);
        let t = _mm256_mask_sub_epi32(t, whole, t, _mm256_set1_epi32(1));
        let h = _mm256_min_epi32(_mm256_max_epi32(t, _mm256_setzero_si256()), qi);
        let h = _mm512_cvtepi32_epi64(_mm256_maskz_mov_epi32(minify, h));
        (h, h, zero)
    } else {
        // `mip_linear`.
        let h = _mm256_min_epi32(_mm256_cvttps_epi32(d), qi);
        let lo = _mm256_min_epi32(_mm256_add_epi32(h, _mm256_set1_epi32(1)), qi);
        let delta = _mm256_maskz_mov_ps(minify, _mm256_sub_ps(d, _mm256_cvtepi32_ps(h)));
        (
            _mm512_cvtepi32_epi64(_mm256_maskz_mov_epi32(minify, h)),
            _mm512_cvtepi32_epi64(_mm256_maskz_mov_epi32(minify, lo)),
            delta,
        )
    }
}

/// `aniso::setup` of 8 queries into `out`: the footprint (`footprint_f64`)
/// lane-wise; lanes with a non-finite derivative or a ρmax²/η² of zero or
/// outside the normal `f64` range take the portable setup.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
fn setups<const MIP: u8>(lod: &Lod, o: &SamplerOptions, q8: &[Query; 8], out: &mut [Setup]) {
    let f = fields(q8);
    let max = _mm512_set1_pd(f64::MAX);
    let mut fin = 0xFFu8;
    for x in &f[2..6] {
        fin &= _mm512_cmp_pd_mask::<_CMP_LE_OQ>(_mm512_abs_pd(*x), max);
    }
    let (rx2, ry2) = square_lens(lod, &f);
    let (rho_x, rho_y) = (_mm512_sqrt_pd(rx2), _mm512_sqrt_pd(ry2));
    let ge = _mm512_cmp_pd_mask::<_CMP_GE_OQ>(rx2, ry2);
    let max2 = _mm512_mask_blend_pd(ge, ry2, rx2);
    let rho_max = _mm512_mask_blend_pd(ge, rho_y, rho_x);
    let rho_min = _mm512_mask_blend_pd(ge, rho_x, rho_y);
    let major_u = _mm512_mask_blend_pd(ge, f[4], f[2]);
    let major_v = _mm512_mask_blend_pd(ge, f[5], f[3]);
    // η = min(ρmax/ρmin, n); n when ρmin = 0; 1 when ρmax = 0.
    let n = _mm512_set1_pd(o.max_aniso.clamp(1, 16) as f64);
    let zero = _mm512_setzero_pd();
    let eta = _mm512_min_pd(_mm512_div_pd(rho_max, rho_min), n);
    let eta = _mm512_mask_blend_pd(_mm512_cmp_pd_mask::<_CMP_EQ_OQ>(rho_min, zero), eta, n);
    let eta = _mm512_mask_blend_pd(
        _mm512_cmp_pd_mask::<_CMP_EQ_OQ>(rho_max, zero),
        eta,
        _mm512_set1_pd(1.0),
    );
    let (l2, ok) = log2(_mm512_div_pd(max2, _mm512_mul_pd(eta, eta)));
    let base = _mm512_add_pd(
        _mm512_mul_pd(_mm512_set1_pd(0.5), l2),
        _mm512_set1_pd(o.lod_bias as f64),
    );
    let lambda = _mm512_cvtpd_ps(clamp_pd(base, o.lod_min as f64, o.lod_max as f64));
    let minify = _mm256_cmp_ps_mask::<_CMP_GT_OQ>(lambda, _mm256_setzero_ps());
    let (hi, lo, delta) = levels::<MIP>(lambda, lod.q);
    const CEIL: i32 = _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC;
    let probes = _mm512_cvttpd_epi32(_mm512_roundscale_pd::<CEIL>(eta));
    let (mut hs, mut ls, mut ds, mut ns) = ([0i64; 8], [0i64; 8], [0f32; 8], [0i32; 8]);
    let (mut mu, mut mv) = ([0f64; 8], [0f64; 8]);
    // SAFETY: unaligned stores of whole registers into arrays of their size.
    unsafe {
        _mm512_storeu_epi64(hs.as_mut_ptr(), hi);
        _mm512_storeu_epi64(ls.as_mut_ptr(), lo);
        _mm256_storeu_ps(ds.as_mut_ptr(), delta);
        _mm256_storeu_si256(ns.as_mut_ptr().cast(), probes);
        _mm512_storeu_pd(mu.as_mut_ptr(), major_u);
        _mm512_storeu_pd(mv.as_mut_ptr(), major_v);
    }
    let exact = fin & ok;
    for (i, (q, s)) in q8.iter().zip(out.iter_mut()).enumerate() {
        *s = if exact >> i & 1 == 1 {
            let (u, v) = lod.reduce(q);
            Setup {
                plan: Plan {
                    magnify: minify >> i & 1 == 0,
                    hi: hs[i] as usize,
                    lo: ls[i] as usize,
                    delta: ds[i],
                },
                probes: ns[i] as u32,
                u,
                v,
                major: [mu[i], mv[i]],
            }
        } else {
            aniso::setup::<Lin, MIP>(lod, o, q)
        };
    }
}

/// What the first pass leaves for the second about one block of 8 lanes:
/// the addresses of each lane's 2×2 block on its one or two levels
/// ([`ZEROS`] for lanes that are not read there), the fractions and the
/// level blend.
///
/// Splitting the work in two passes keeps each loop's iterations short
/// and independent, so the core overlaps many of them; one long loop from
/// query to colour was bound by its own latency.
#[derive(Clone, Copy)]
struct Staged {
    top: [u64; 8],
    bot: [u64; 8],
    top2: [u64; 8],
    bot2: [u64; 8],
    /// α, β on level `hi`; α, β on level `lo`; δ.
    w: [[f32; 8]; 5],
    /// Lanes read here (the others take the portable path).
    fast: u8,
    /// Lanes that blend a second level.
    two: u8,
}

impl Staged {
    const EMPTY: Staged = Staged {
        top: [0; 8],
        bot: [0; 8],
        top2: [0; 8],
        bot2: [0; 8],
        w: [[0.0; 8]; 5],
        fast: 0,
        two: 0,
    };
}

/// Blocks staged per chunk of the isotropic path.
const CHUNK: usize = 8;

/// The addresses and weights of `b` (and `b2` for `two`) into `s`.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
fn stage(s: &mut Staged, b: &Blocks, b2: Option<&Blocks>, delta: __m256, fast: u8, two: u8) {
    (s.top, s.bot) = addresses(b, fast);
    // SAFETY: unaligned 32-byte stores into 8-float arrays.
    unsafe {
        _mm256_storeu_ps(s.w[0].as_mut_ptr(), b.al);
        _mm256_storeu_ps(s.w[1].as_mut_ptr(), b.be);
        _mm256_storeu_ps(s.w[4].as_mut_ptr(), delta);
    }
    if let Some(b2) = b2 {
        (s.top2, s.bot2) = addresses(b2, two);
        // SAFETY: as above.
        unsafe {
            _mm256_storeu_ps(s.w[2].as_mut_ptr(), b2.al);
            _mm256_storeu_ps(s.w[3].as_mut_ptr(), b2.be);
        }
    }
    s.fast = fast;
    s.two = two;
}

/// Loads a staged `[f32; 8]`.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
fn ps8(x: &[f32; 8]) -> __m256 {
    // SAFETY: an unaligned 32-byte load of the 8-float array.
    unsafe { _mm256_loadu_ps(x.as_ptr()) }
}

/// The colours of lanes `4h … 4h + 3` of a staged block: the bilinear
/// blend on level `hi`, blended with level `lo` for the lanes in `two`
/// when `MIP` is linear.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
fn colours<P: Pixel, const MIP: u8>(c: &Chain<P>, s: &Staged, h: usize) -> __m512 {
    // SAFETY: lanes in `fast` are inside their level, the others read
    // `ZEROS` (`addresses`).
    let d = unsafe { group::<P>(&c.lut, &s.top, &s.bot, h) };
    let r = bilerp(d, ps8(&s.w[0]), ps8(&s.w[1]), h);
    let m = group_mask(s.two, h);
    if MIP != MIP_LINEAR || m == 0 {
        return r;
    }
    // SAFETY: as above, with the lanes in `two`.
    let d2 = unsafe { group::<P>(&c.lut, &s.top2, &s.bot2, h) };
    let r2 = bilerp(d2, ps8(&s.w[2]), ps8(&s.w[3]), h);
    // 1 − δ after spreading: one permute fewer, the same values.
    let delta = spread(ps8(&s.w[4]), h);
    let omd = _mm512_sub_ps(_mm512_set1_ps(1.0), delta);
    let mixed = lerp16(r, r2, omd, delta);
    _mm512_mask_blend_ps(m, r, mixed)
}

/// Isotropic bilinear or trilinear lookups (`Lin` filters, mip mode
/// `MIP` nearest or linear) of `queries` into `out`: what
/// `trilinear::plan` and `trilinear::probe` compute, 8 queries at a time,
/// in two passes over chunks of [`CHUNK`] blocks (see [`Staged`]).
///
/// # Safety
/// `table` is `LevelTable::new(c)` (which is `Some` only when the CPU has
/// the features).
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
pub(crate) unsafe fn isotropic<P: Pixel, const MIP: u8>(
    c: &Chain<P>,
    table: &LevelTable,
    a: &Addressing,
    lod: &Lod,
    opts: &SamplerOptions,
    queries: &[Query],
    out: &mut [[f32; 4]],
) {
    const N: usize = 8 * CHUNK;
    let ls = Levels::new(table);
    let mut staged = [Staged::EMPTY; CHUNK];
    let mut planned = Probes::<N>::EMPTY;
    let mut ok = [0u8; CHUNK];
    let whole = queries.len() / 8 * 8;
    for (qc, oc) in queries[..whole].chunks(N).zip(out[..whole].chunks_mut(N)) {
        let nb = qc.len() / 8;
        // The footprints and levels first, then the blocks: two short
        // loops overlap better than one with the whole dependent chain from
        // query to address (ρ², log2, clamps, levels, then the blocks).
        for (b, (q8, ok)) in qc.as_chunks::<8>().0.iter().zip(&mut ok).enumerate() {
            let f = fields(q8);
            let (hi, lo, delta, lanes) = plans::<MIP>(lod, opts, &f);
            let (u, v) = (
                reduce_lanes(f[0], lod.wrap_u),
                reduce_lanes(f[1], lod.wrap_v),
            );
            planned.store(8 * b, u, v, hi, lo, delta);
            *ok = lanes;
        }
        for (b, (s, ok)) in staged[..nb].iter_mut().zip(&ok).enumerate() {
            stage_probes::<P, MIP, N>(&ls, &planned, 8 * b, *ok, s);
        }
        for (s, o8) in staged[..nb].iter().zip(oc.chunks_exact_mut(8)) {
            for h in 0..2 {
                let r = colours::<P, MIP>(c, s, h);
                // SAFETY: one unaligned 64-byte store into 4 RGBA values.
                unsafe { _mm512_storeu_ps(o8[4 * h..].as_mut_ptr().cast(), r) };
            }
        }
        for (b, (s, o8)) in staged[..nb].iter().zip(oc.chunks_exact_mut(8)).enumerate() {
            if s.fast != 0xFF {
                let q8 = &qc[8 * b..8 * b + 8];
                for (i, (q, o)) in q8.iter().zip(o8.iter_mut()).enumerate() {
                    if s.fast >> i & 1 == 0 {
                        *o = portable::<P, MIP>(c, a, lod, opts, q);
                    }
                }
            }
        }
    }
    for (q, o) in queries[whole..].iter().zip(&mut out[whole..]) {
        *o = portable::<P, MIP>(c, a, lod, opts, q);
    }
}

/// One isotropic lookup the portable way.
#[inline(never)]
fn portable<P: Pixel, const MIP: u8>(
    c: &Chain<P>,
    a: &Addressing,
    lod: &Lod,
    o: &SamplerOptions,
    q: &Query,
) -> [f32; 4] {
    let p = trilinear::plan::<Lin, MIP>(lod, o, q);
    let (u, v) = lod.reduce(q);
    trilinear::probe(c, Lin, &p, u, v, a, &mut NoTrace)
}

/// Isotropic nearest lookups (`Near` filters, mip mode `MIP` nearest or
/// linear) of `queries` into `out`: what `trilinear::plan` and
/// `trilinear::probe` compute, 16 queries at a time. The plans and texel
/// addresses of 8 lanes at once (the plans as [`isotropic`]'s, the texel
/// as `bilinear::nearest`'s fast path), then the 16 texels read: packed
/// RGBA8 ones decoded at once in registers ([`decode_rgba8`]), the other
/// storages by `Pixel::decode` (the portable code's decode); with mip
/// mode linear, the lanes that blend a second level blend its texel by
/// `fetch::lerp` as the portable code does. Lanes outside their level, a
/// plan this cannot compute and the last partial 16 take the portable
/// path.
///
/// # Safety
/// As [`isotropic`].
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
pub(crate) unsafe fn nearest<P: Pixel, const MIP: u8>(
    c: &Chain<P>,
    table: &LevelTable,
    a: &Addressing,
    lod: &Lod,
    opts: &SamplerOptions,
    queries: &[Query],
    out: &mut [[f32; 4]],
) {
    let ls = Levels::new(table);
    let (q16s, _) = queries.as_chunks::<16>();
    let whole = q16s.len() * 16;
    let (o16s, _) = out.as_chunks_mut::<16>();
    for (q16, o16) in q16s.iter().zip(o16s.iter_mut()) {
        let mut at = [0u64; 16];
        let mut at2 = [0u64; 16];
        let mut delta = [0f32; 16];
        let (mut fast, mut two) = (0u16, 0u16);
        for (h, q8) in q16.as_chunks::<8>().0.iter().enumerate() {
            let f = fields(q8);
            let (hi, lo, d, ok) = plans::<MIP>(lod, opts, &f);
            let u = reduce_lanes(f[0], lod.wrap_u);
            let v = reduce_lanes(f[1], lod.wrap_v);
            let (t, inside) = texels::<P>(&ls, hi, u, v);
            // Coordinates of 2^51 and more take the portable path: there
            // `Lod::reduce` saturates (`fast_floor`) where `reduce_lanes`
            // is exact, and the bilinear paths' accident (an exact 0 is
            // outside a 2×2 block) does not protect a single texel.
            let limit = _mm512_set1_pd(REDUCE_EXACT);
            let small = _mm512_cmp_pd_mask::<_CMP_LT_OQ>(_mm512_abs_pd(f[0]), limit)
                & _mm512_cmp_pd_mask::<_CMP_LT_OQ>(_mm512_abs_pd(f[1]), limit);
            let mut fast8 = ok & inside & small;
            // SAFETY: 64-byte stores of 8 entries inside the 16-entry
            // arrays (h is 0 or 1).
            unsafe { _mm512_storeu_epi64(at[8 * h..].as_mut_ptr().cast(), t) };
            if MIP == MIP_LINEAR {
                let two8 = blends_two(d, hi, lo) & fast8;
                if two8 != 0 {
                    let (t2, inside2) = texels::<P>(&ls, lo, u, v);
                    fast8 &= !two8 | inside2;
                    two |= ((two8 & fast8) as u16) << (8 * h);
                    // SAFETY: as above.
                    unsafe {
                        _mm512_storeu_epi64(at2[8 * h..].as_mut_ptr().cast(), t2);
                        _mm256_storeu_ps(delta[8 * h..].as_mut_ptr(), d);
                    }
                }
            }
            fast |= (fast8 as u16) << (8 * h);
        }
        // SAFETY: every address is a texel inside its level or `ZEROS`
        // (`texels`), and the texels are at most 16 bytes (`fits`).
        unsafe { texels16::<P>(c, &at, o16) };
        if MIP == MIP_LINEAR && two != 0 {
            for (i, o) in o16.iter_mut().enumerate() {
                if two >> i & 1 != 0 {
                    // SAFETY: a lane in `two` has its second texel inside
                    // its level.
                    let t2 = unsafe { read::<P>(at2[i]) }.decode(&c.lut);
                    *o = super::fetch::lerp(*o, t2, delta[i]);
                }
            }
        }
        if fast != 0xFFFF {
            for (i, (q, o)) in q16.iter().zip(o16.iter_mut()).enumerate() {
                if fast >> i & 1 == 0 {
                    *o = portable_nearest::<P, MIP>(c, a, lod, opts, q);
                }
            }
        }
    }
    for (q, o) in queries[whole..].iter().zip(&mut out[whole..]) {
        *o = portable_nearest::<P, MIP>(c, a, lod, opts, q);
    }
}

/// The level plans and wrapped coordinates of 8 isotropic lookups, for
/// tracing their reads without their texels
/// ([`crate::cache::isotropic::AddressOnly`]): per lane `(u, v)` as
/// `Lod::reduce` moves them, the levels `hi` and `lo` and the blend δ as
/// `Lod::plan_nearest` (`MIP` nearest) or `Plan::at(Lod::lambda, …)`
/// (`MIP` linear) give them, and the lanes computed exactly here (a
/// normal ρ², coordinates below 2^51); the others need the portable
/// plan. Whether a lane magnifies is not given: the caller's
/// magnification and minification filters are the same.
pub(crate) struct Plans8 {
    pub u: [f64; 8],
    pub v: [f64; 8],
    pub hi: [i64; 8],
    pub lo: [i64; 8],
    pub delta: [f32; 8],
    pub exact: u8,
}

/// Proof that the CPU has the features of [`available`]: the safe way to
/// [`Planner::plans8`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct Planner(());

impl Planner {
    /// A planner when the CPU has the features (and `PARVO_NO_AVX` is not
    /// set).
    pub(crate) fn new() -> Option<Planner> {
        available().then_some(Planner(()))
    }

    /// [`Plans8`] of `q8` for `linear` (else nearest) mip mode.
    #[inline]
    pub(crate) fn plans8(
        self,
        lod: &Lod,
        o: &SamplerOptions,
        linear: bool,
        q8: &[Query; 8],
    ) -> Plans8 {
        // SAFETY: a `Planner` exists only on CPUs with the features.
        unsafe { plans8(lod, o, linear, q8) }
    }
}

/// [`Plans8`] of `q8` for `linear` (else nearest) mip mode.
///
/// # Safety
/// The CPU has the features of [`available`].
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
unsafe fn plans8(lod: &Lod, o: &SamplerOptions, linear: bool, q8: &[Query; 8]) -> Plans8 {
    let f = fields(q8);
    let (hi, lo, delta, ok) = if linear {
        plans::<MIP_LINEAR>(lod, o, &f)
    } else {
        plans::<MIP_NEAREST>(lod, o, &f)
    };
    let limit = _mm512_set1_pd(REDUCE_EXACT);
    let small = _mm512_cmp_pd_mask::<_CMP_LT_OQ>(_mm512_abs_pd(f[0]), limit)
        & _mm512_cmp_pd_mask::<_CMP_LT_OQ>(_mm512_abs_pd(f[1]), limit);
    let mut p = Plans8 {
        u: [0.0; 8],
        v: [0.0; 8],
        hi: [0; 8],
        lo: [0; 8],
        delta: [0.0; 8],
        exact: ok & small,
    };
    // SAFETY: unaligned stores of whole registers into arrays of their
    // size.
    unsafe {
        _mm512_storeu_pd(p.u.as_mut_ptr(), reduce_lanes(f[0], lod.wrap_u));
        _mm512_storeu_pd(p.v.as_mut_ptr(), reduce_lanes(f[1], lod.wrap_v));
        _mm512_storeu_epi64(p.hi.as_mut_ptr(), hi);
        _mm512_storeu_epi64(p.lo.as_mut_ptr(), lo);
        _mm256_storeu_ps(p.delta.as_mut_ptr(), delta);
    }
    p
}

/// Below this magnitude `reduce_lanes` equals `Lod::reduce` (both floors
/// exact): 2^51.
const REDUCE_EXACT: f64 = 2_251_799_813_685_248.0;

/// The 16 texels at `at`, decoded into `out`: packed RGBA8 in registers
/// (the codes loaded transposed, so that each register holds 4
/// consecutive results), the others by `Pixel::decode`.
///
/// # Safety
/// Every address satisfies [`read`] for `size_of::<P>()` bytes.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
unsafe fn texels16<P: Pixel>(c: &Chain<P>, at: &[u64; 16], out: &mut [[f32; 4]; 16]) {
    if let Some(lut) = P::packed(&c.lut) {
        // `decode_rgba8` puts the code of 32-bit lane 4j + r into group j
        // of register r: lane 4j + r takes texel 4r + j, and register r
        // then holds texels 4r … 4r + 3 in order.
        let mut codes = [0u32; 16];
        for (l, code) in codes.iter_mut().enumerate() {
            let (j, r) = (l / 4, l % 4);
            // SAFETY: the caller's contract (`fits` makes packed texels 4
            // bytes).
            *code = unsafe { read::<u32>(at[4 * r + j]) };
        }
        // SAFETY: a 64-byte load of the 16 codes.
        let codes = unsafe { _mm512_loadu_epi32(codes.as_ptr().cast()) };
        let d = decode_rgba8(lut, codes);
        for (r, d) in d.into_iter().enumerate() {
            // SAFETY: a 64-byte store into 4 RGBA values.
            unsafe { _mm512_storeu_ps(out[4 * r..].as_mut_ptr().cast(), d) };
        }
    } else {
        for (o, &t) in out.iter_mut().zip(at) {
            // SAFETY: the caller's contract.
            *o = unsafe { read::<P>(t) }.decode(&c.lut);
        }
    }
}

/// One isotropic nearest lookup the portable way.
#[inline(never)]
fn portable_nearest<P: Pixel, const MIP: u8>(
    c: &Chain<P>,
    a: &Addressing,
    lod: &Lod,
    o: &SamplerOptions,
    q: &Query,
) -> [f32; 4] {
    let p = trilinear::plan::<Near, MIP>(lod, o, q);
    let (u, v) = lod.reduce(q);
    trilinear::probe(c, Near, &p, u, v, a, &mut NoTrace)
}

/// [`Lod::reduce`] on 8 lanes: `x − floor(x)` (repeat) or
/// `x − 2·floor(x/2)` (mirror), the same exact `f64` operations; lanes
/// whose coordinate is NaN or infinite come out NaN, which is never
/// inside a level, so the portable code takes them (it reduces NaN to 0
/// and keeps infinities).
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
fn reduce_lanes(x: __m512d, mode: crate::wrap::WrapMode) -> __m512d {
    use crate::wrap::WrapMode;
    const FLOOR: i32 = _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC;
    match mode {
        WrapMode::Repeat => _mm512_sub_pd(x, _mm512_roundscale_pd::<FLOOR>(x)),
        WrapMode::MirroredRepeat => {
            let half = _mm512_mul_pd(x, _mm512_set1_pd(0.5));
            let k = _mm512_roundscale_pd::<FLOOR>(half);
            _mm512_sub_pd(x, _mm512_mul_pd(_mm512_set1_pd(2.0), k))
        }
        _ => x,
    }
}

/// Footprint-assembly lookups (`Lin` filters, mip mode `MIP`) of
/// `queries` into `out`: `aniso::setup` per query as the portable code
/// does it, then the probes of a chunk of queries packed 8 to a block
/// (probes of different queries share a block, so lanes are not wasted
/// on queries with few probes), staged before they are read (see
/// [`Staged`]), and finally each query's probes summed in probe order.
///
/// # Safety
/// As [`isotropic`].
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
pub(crate) unsafe fn anisotropic<P: Pixel, const MIP: u8>(
    c: &Chain<P>,
    table: &LevelTable,
    a: &Addressing,
    lod: &Lod,
    opts: &SamplerOptions,
    queries: &[Query],
    out: &mut [[f32; 4]],
) {
    // At most 16 probes per query.
    const MAX_PROBES: usize = 16 * super::BLOCK;
    const MAX_BLOCKS: usize = MAX_PROBES / 8;
    for (qs, os) in queries
        .chunks(super::BLOCK)
        .zip(out.chunks_mut(super::BLOCK))
    {
        let mut st = [Setup::EMPTY; super::BLOCK];
        let (q8s, rest) = qs.as_chunks::<8>();
        for (q8, s) in q8s.iter().zip(st.chunks_exact_mut(8)) {
            setups::<MIP>(lod, opts, q8, s);
        }
        let done = qs.len() - rest.len();
        for (s, q) in st[done..].iter_mut().zip(rest) {
            *s = aniso::setup::<Lin, MIP>(lod, opts, q);
        }
        // SAFETY: as this function's.
        unsafe {
            probes_of::<P, MIP, MAX_PROBES, MAX_BLOCKS>(c, table, a, &st[..qs.len()], os);
        }
    }
}

/// The probes of the footprint-assembly lookups set up in `st` (at most
/// `NP / 16` of them; `NB = NP / 8`), into `out`: packed 8 to a block
/// (probes of different lookups share a block, so lanes are not wasted
/// on lookups with few probes), staged before they are read (see
/// [`Staged`]), then each lookup's probes summed in probe order. The
/// batch path runs it 16 lookups at a time, `Sampler::sample` on one and
/// `Sampler::sample_quad` on a quad's four.
///
/// # Safety
/// As [`isotropic`].
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
pub(crate) unsafe fn probes_of<P: Pixel, const MIP: u8, const NP: usize, const NB: usize>(
    c: &Chain<P>,
    table: &LevelTable,
    a: &Addressing,
    st: &[Setup],
    out: &mut [[f32; 4]],
) {
    let ls = Levels::new(table);
    let mut staged = [Staged::EMPTY; NB];
    let mut probes = Probes {
        u: [0.0; NP],
        v: [0.0; NP],
        hi: [0; NP],
        lo: [0; NP],
        delta: [0.0; NP],
    };
    let mut colour = [[0f32; 4]; NP];
    {
        let os = out;
        let mut np = 0;
        for s in st {
            let n = s.probes.max(1);
            let step = 1.0 / (n as f64 + 1.0);
            for i in 1..=n {
                let (u, v) = if n == 1 {
                    (s.u, s.v)
                } else {
                    s.probe_at(i, step)
                };
                probes.u[np] = u;
                probes.v[np] = v;
                probes.hi[np] = s.plan.hi as i64;
                probes.lo[np] = s.plan.lo as i64;
                probes.delta[np] = s.plan.delta;
                np += 1;
            }
        }
        let nb = np.div_ceil(8);
        for (k, s) in staged[..nb].iter_mut().enumerate() {
            let live = if 8 * k + 8 <= np {
                0xFF
            } else {
                ((1u16 << (np - 8 * k)) - 1) as u8
            };
            stage_probes::<P, MIP, NP>(&ls, &probes, 8 * k, live, s);
        }
        for (s, col) in staged[..nb].iter().zip(colour.chunks_exact_mut(8)) {
            for h in 0..2 {
                if s.fast >> (4 * h) & 0xF == 0 {
                    continue;
                }
                let r = colours::<P, MIP>(c, s, h);
                // SAFETY: one unaligned 64-byte store into 4 RGBA values.
                unsafe { _mm512_storeu_ps(col[4 * h..].as_mut_ptr().cast(), r) };
            }
        }
        let mut k = 0;
        for (s, o) in st.iter().zip(os.iter_mut()) {
            let n = s.probes.max(1) as usize;
            // Probes the first pass left out, the portable way.
            for i in k..k + n {
                if staged[i / 8].fast >> (i % 8) & 1 == 0 {
                    colour[i] = trilinear::probe(
                        c,
                        Lin,
                        &s.plan,
                        probes.u[i],
                        probes.v[i],
                        a,
                        &mut NoTrace,
                    );
                }
            }
            *o = if n == 1 {
                colour[k]
            } else {
                let inv = 1.0 / n as f32;
                let mut acc = [0f32; 4];
                for p in &colour[k..k + n] {
                    for c in 0..4 {
                        acc[c] += p[c] * inv;
                    }
                }
                acc
            };
            k += n;
        }
    }
}

/// The probes of a chunk of footprint-assembly lookups (or the lookups of
/// a chunk of isotropic ones), one entry per probe: position, levels and
/// blend.
struct Probes<const N: usize> {
    u: [f64; N],
    v: [f64; N],
    hi: [i64; N],
    lo: [i64; N],
    delta: [f32; N],
}

impl<const N: usize> Probes<N> {
    const EMPTY: Probes<N> = Probes {
        u: [0.0; N],
        v: [0.0; N],
        hi: [0; N],
        lo: [0; N],
        delta: [0.0; N],
    };

    /// Entries `first … first + 7` from registers.
    #[inline]
    #[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
    fn store(
        &mut self,
        first: usize,
        u: __m512d,
        v: __m512d,
        hi: __m512i,
        lo: __m512i,
        delta: __m256,
    ) {
        let end = first + 8;
        // SAFETY: 64- and 32-byte stores of 8 entries inside the arrays
        // (the slices are 8 long, or the indexing panics first).
        unsafe {
            _mm512_storeu_pd(self.u[first..end].as_mut_ptr(), u);
            _mm512_storeu_pd(self.v[first..end].as_mut_ptr(), v);
            _mm512_storeu_epi64(self.hi[first..end].as_mut_ptr(), hi);
            _mm512_storeu_epi64(self.lo[first..end].as_mut_ptr(), lo);
            _mm256_storeu_ps(self.delta[first..end].as_mut_ptr(), delta);
        }
    }
}

/// Stages probes `first … first + 7` (the lanes in `live`) into `s`.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
fn stage_probes<P: Pixel, const MIP: u8, const N: usize>(
    ls: &Levels,
    p: &Probes<N>,
    first: usize,
    live: u8,
    s: &mut Staged,
) {
    let end = first + 8;
    // SAFETY: 64- and 32-byte loads of 8 entries inside the arrays (the
    // chunk holds whole blocks of 8).
    let (u, v, hi, lo, delta) = unsafe {
        (
            _mm512_loadu_pd(p.u[first..end].as_ptr()),
            _mm512_loadu_pd(p.v[first..end].as_ptr()),
            _mm512_loadu_epi64(p.hi[first..end].as_ptr()),
            _mm512_loadu_epi64(p.lo[first..end].as_ptr()),
            _mm256_loadu_ps(p.delta[first..end].as_ptr()),
        )
    };
    let bh = blocks::<P>(ls, hi, u, v);
    let fast = live & bh.inside;
    if MIP == MIP_LINEAR {
        let two = blends_two(delta, hi, lo) & fast;
        if two != 0 {
            let bl = blocks::<P>(ls, lo, u, v);
            let fast = fast & (!two | bl.inside);
            stage(s, &bh, Some(&bl), delta, fast, two & fast);
            return;
        }
    }
    stage(s, &bh, None, delta, fast, 0);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sample::footprint;

    /// A xorshift generator (fixed seed per test).
    struct Rng(u64);

    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            self.0
        }
    }

    #[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
    fn log2_lanes(x: &[f64; 8]) -> ([f64; 8], u8) {
        // SAFETY: a 64-byte load of 8 `f64`s and a store into 8.
        let (r, ok) = log2(unsafe { _mm512_loadu_pd(x.as_ptr()) });
        let mut out = [0f64; 8];
        // SAFETY: as above.
        unsafe { _mm512_storeu_pd(out.as_mut_ptr(), r) };
        (out, ok)
    }

    /// Every lane it covers equals `footprint::log2` bit for bit: powers
    /// of two and their neighbours (where the cap acts), both sides of
    /// every interval join, random bit patterns; and it covers exactly the
    /// normal finite values.
    #[test]
    fn log2_lanes_equal_the_portable_log2() {
        if !available() {
            return;
        }
        let mut xs = Vec::new();
        for k in -1022..=1023 {
            let p = 2f64.powi(k).to_bits();
            xs.extend([p - 2, p - 1, p, p + 1].map(f64::from_bits));
        }
        for k in [-40, 0, 7] {
            for i in 1..8 {
                let join = (2f64.powi(k) * (1.0 + i as f64 / 8.0)).to_bits();
                xs.extend((join - 3..=join + 3).map(f64::from_bits));
            }
        }
        let mut r = Rng(0x9e37_79b9_7f4a_7c15);
        xs.extend((0..200_000).map(|_| f64::from_bits(r.next() >> 1)));
        xs.extend([0.0, -1.0, f64::MIN_POSITIVE / 2.0, f64::INFINITY, f64::NAN]);
        while xs.len() % 8 != 0 {
            xs.push(1.0);
        }
        for c in xs.chunks_exact(8) {
            let c: &[f64; 8] = c.try_into().unwrap();
            // SAFETY: `available()` checked the CPU features.
            let (got, ok) = unsafe { log2_lanes(c) };
            for i in 0..8 {
                let normal = (f64::MIN_POSITIVE..=f64::MAX).contains(&c[i]);
                assert_eq!(ok >> i & 1 == 1, normal, "{:e}", c[i]);
                if normal {
                    let want = footprint::log2(c[i]);
                    assert_eq!(got[i].to_bits(), want.to_bits(), "{:e}", c[i]);
                }
            }
        }
    }

    #[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
    fn plan_lanes<const MIP: u8>(
        lod: &Lod,
        o: &SamplerOptions,
        q8: &[Query; 8],
    ) -> ([i64; 8], [i64; 8], [f32; 8], u8) {
        let (hi, lo, delta, ok) = plans::<MIP>(lod, o, &fields(q8));
        let (mut h, mut l, mut d) = ([0i64; 8], [0i64; 8], [0f32; 8]);
        // SAFETY: stores of whole registers into arrays of their size.
        unsafe {
            _mm512_storeu_epi64(h.as_mut_ptr(), hi);
            _mm512_storeu_epi64(l.as_mut_ptr(), lo);
            _mm256_storeu_ps(d.as_mut_ptr(), delta);
        }
        (h, l, d, ok)
    }

    /// The lane-wise plans equal `trilinear::plan` (levels and blend) for
    /// chains of 1 to 16 levels, LOD clamps below level 0, beyond the last
    /// level and in between, biases, and derivatives from 0 to ∞ and NaN,
    /// including exact powers of two (the level thresholds).
    #[test]
    fn plans_equal_the_portable_plans() {
        if !available() {
            return;
        }
        let mut r = Rng(0x2545_f491_4f6c_dd1d);
        let clamps = [
            (-1000.0, 1000.0, 0.0),
            (-3.0, -0.25, 0.0),
            (20.0, 40.0, 2.5),
            (0.5, 3.0, 0.75),
            (-1000.0, 1000.0, -1.5),
            (1.5, 1.5, 0.0),
            (0.0, 0.0, 0.5),
        ];
        for levels in [1usize, 2, 5, 12, 16] {
            let (w, h) = (1u64 << (levels - 1), 1u64 << (levels / 2));
            for (lod_min, lod_max, lod_bias) in clamps {
                let o = SamplerOptions {
                    lod_min,
                    lod_max,
                    lod_bias,
                    ..SamplerOptions::trilinear()
                };
                let lod = Lod::new(&o, w as f64, h as f64, levels);
                for _ in 0..400 {
                    let q8: [Query; 8] = std::array::from_fn(|_| {
                        let mut d = || -> f32 {
                            match r.next() % 8 {
                                0 => 0.0,
                                1 => f32::NAN,
                                2 => f32::INFINITY,
                                // Exact powers of two over texel sizes.
                                3 | 4 => {
                                    let k = (r.next() % 40) as i32 - 20;
                                    2f32.powi(k) / w as f32
                                }
                                _ => {
                                    let m = (r.next() % 10_000) as f32 / 5000.0 - 1.0;
                                    m * 2f32.powi((r.next() % 50) as i32 - 30)
                                }
                            }
                        };
                        Query::new(0.5, 0.5, d(), d(), d(), d())
                    });
                    // SAFETY: `available()` checked the CPU features.
                    let near = unsafe { plan_lanes::<MIP_NEAREST>(&lod, &o, &q8) };
                    // SAFETY: as above.
                    let lin = unsafe { plan_lanes::<MIP_LINEAR>(&lod, &o, &q8) };
                    for (i, q) in q8.iter().enumerate() {
                        let want = trilinear::plan::<Lin, MIP_NEAREST>(&lod, &o, q);
                        assert_eq!(near.3, 0xFF);
                        assert_eq!((near.0[i], near.1[i]), (want.hi as i64, want.lo as i64));
                        if lin.3 >> i & 1 == 1 {
                            let want = trilinear::plan::<Lin, MIP_LINEAR>(&lod, &o, q);
                            let got = (lin.0[i], lin.1[i], lin.2[i].to_bits());
                            let exp = (want.hi as i64, want.lo as i64, want.delta.to_bits());
                            assert_eq!(got, exp, "{q:?} levels {levels} {o:?}");
                        }
                    }
                }
            }
        }
    }
}
