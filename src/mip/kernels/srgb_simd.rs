//! AVX-512 kernel for the sRGB RGBA8 2×2 box, bit-exact with the scalar
//! table kernel in [`crate::mip::fast`].
//!
//! The scalar kernel spends its time on table look-ups (twelve decodes and
//! three encode buckets per output texel), and AVX2 gathers are slow on the
//! machines we measure on. This kernel does no gathers:
//!
//! - **Decode by byte shuffles.** Each decoded value (2^-24 units) is split
//!   into three byte planes; a 256-entry plane is four zmm registers, and
//!   four `vpermb` (one per quarter, each merged into the codes at or above
//!   its start) look it up for 64 codes. Code 255 (exactly 2^24, one bit
//!   too many) is stored as 2^24 − 1; see `encode` for why that is exact.
//! - **Sum with VNNI.** The source bytes are first permuted (`vpermi2b`) so
//!   that each dword holds one channel of the four source texels of one
//!   output texel; `vpdpbusd` then sums a plane of the four in one
//!   instruction, and two shifts combine the planes into the `u32` sum `s`
//!   of the scalar code.
//! - **Encode by formula, settled exactly.** `s` (2^-26 units) goes through
//!   the sRGB encode in f32: the linear segment near black (exact there),
//!   else `1.055·x^(5/12) − 0.055` with `x^(5/12)` as a per-octave scale
//!   (one `vpermps` from the float exponent) times a degree-6 polynomial in
//!   the mantissa (the codec's `PowerSegment`, `texel/codec8.rs`). The
//!   code is rounded down in 1/65536 steps after adding `AMBIGUITY` steps,
//!   so a result whose fraction is below `2·AMBIGUITY` steps may be one
//!   code too high: those lanes (1 in 2000 of all sums) are
//!   redone with the scalar [`FixedSrgb::encode4`]. Every other lane is the
//!   scalar code, which a unit test checks for every `s` in 0..=2^26.
//! - Alpha is the rounded linear average `(a + b + c + d + 2) >> 2`, and the
//!   kernel notes whether any alpha differs from the row's first alpha, so
//!   the straight-alpha fix-up needs no scan of its own.
//! - The loop is software-pipelined: the sums of one block of 16 output
//!   texels are formed while the previous block is encoded (each half is a
//!   long dependency chain; the overlap is worth about 10%).
//!
//! Used when the CPU has AVX-512 F/BW/VBMI/VNNI (detected once at run
//! time) and `PARVO_NO_AVX` is not set; otherwise the scalar kernel runs.
//! Rows narrower than one block, and the last `width mod 16` texels of a
//! row, use the scalar kernel too.

use crate::mip::fast::{FixedSrgb, row_u8_srgb_n};

/// True when the AVX-512 kernel may run: the CPU has the features and
/// `PARVO_NO_AVX` is not set (read once).
pub fn available() -> bool {
    crate::cpu::simd_allowed() && supported()
}

/// True when this CPU has what the AVX-512 kernel needs (whatever
/// `PARVO_NO_AVX` says).
pub fn supported() -> bool {
    #[cfg(target_arch = "x86_64")]
    return crate::cpu::avx512_vnni_detected();
    #[cfg(not(target_arch = "x86_64"))]
    false
}

/// One output row of the sRGB RGBA8 box: `r0`, `r1` are the two source rows
/// (`2 · dst.len()` bytes each). With `avx512` the AVX-512 kernel runs (it
/// panics if the CPU lacks it: see [`supported`]); otherwise the scalar
/// kernel. Returns true when every alpha of both rows equals `r0[3]` (only
/// the AVX-512 kernel reports it; the scalar path returns false, "not
/// known").
pub fn row_rgba8(r0: &[u8], r1: &[u8], dst: &mut [u8], t: &FixedSrgb, avx512: bool) -> bool {
    #[cfg(target_arch = "x86_64")]
    if avx512 {
        assert!(supported(), "AVX-512 kernel requested on a CPU without it");
        #[allow(unsafe_code)]
        // SAFETY: the assert above (`supported()`) confirmed AVX-512 F, BW,
        // VBMI and VNNI, the features `x86::row_with` is compiled for. The
        // kernel reads and writes only through slices (64-byte arrays).
        return unsafe { x86::row_with(r0, r1, dst, None, t, x86::tables(t)) };
    }
    let _ = avx512;
    row_u8_srgb_n::<4, 3>(r0, r1, dst, t);
    false
}

/// [`row_rgba8`] with the AVX-512 kernel (the CPU must have it: see
/// [`available`]), also writing each output texel unrounded in linear f32
/// to `lin` (`dst.len()` floats): colour `s · 2^-26` of the kernel's sum,
/// alpha the exact average of the four codes over 255. The fused first
/// level of the box chain that rounds once (`mip/stream.rs`): level 0's
/// codes are read once, and no f32 copy of level 0 is made. Returns the
/// constant-alpha report of [`row_rgba8`] (always known here).
pub fn row_rgba8_linear(
    r0: &[u8],
    r1: &[u8],
    dst: &mut [u8],
    lin: &mut [f32],
    t: &FixedSrgb,
) -> bool {
    assert!(lin.len() == dst.len(), "one float per output value");
    #[cfg(target_arch = "x86_64")]
    {
        assert!(supported(), "AVX-512 kernel requested on a CPU without it");
        #[allow(unsafe_code)]
        // SAFETY: the assert above (`supported()`) confirmed AVX-512 F, BW,
        // VBMI and VNNI, the features `x86::row_with` is compiled for. The
        // kernel reads and writes only through slices.
        return unsafe { x86::row_with(r0, r1, dst, Some(lin), t, x86::tables(t)) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let _ = (r0, r1, dst, lin, t);
        unreachable!("AVX-512 kernel requested on a CPU without it")
    }
}

/// The scalar unrounded values of [`row_rgba8_linear`] for output values
/// from `from` on (the tail of a row), the kernel's own: the same sums
/// (code 255 counting 2^24 − 1, see `x86::sum4`), the same conversions.
fn linear_tail(r0: &[u8], r1: &[u8], lin: &mut [f32], from: usize, t: &FixedSrgb) {
    let dec = t.dec();
    let d = |c: u8| dec[c as usize] - u32::from(c == 255);
    let unit = 1.0 / (1u64 << 26) as f32;
    for (x, o) in lin.chunks_exact_mut(4).enumerate().skip(from / 4) {
        let (p, q) = (8 * x, 8 * x + 4);
        for c in 0..3 {
            let s = d(r0[p + c]) + d(r0[q + c]) + d(r1[p + c]) + d(r1[q + c]);
            o[c] = s as f32 * unit;
        }
        let a = r0[p + 3] as u32 + r0[q + 3] as u32 + r1[p + 3] as u32 + r1[q + 3] as u32;
        o[3] = a as f32 / 1020.0;
    }
}

/// The smallest sum (2^-26 units) that holds a code 255, as the kernel
/// sums it (2^24 − 1, see `x86::sum4`).
const SHORT_FROM: u32 = (1 << 24) - 1;

/// Sums below this (2^-26 units, x ≤ 0.0031308) use the linear segment.
/// Any split between the thresholds of codes 9 and 10 (about 193 500 and
/// 213 500) would do: both formulas agree closely around it.
const LINEAR_BELOW: u32 = 210_105;

#[cfg(target_arch = "x86_64")]
mod x86 {
    use std::arch::x86_64::*;
    use std::sync::OnceLock;

    use super::{FixedSrgb, LINEAR_BELOW, SHORT_FROM, linear_tail, row_u8_srgb_n};
    use crate::texel::codec8::x86::PowerSegment;

    /// Byte planes of the decode table and the per-octave scales.
    pub struct Tables {
        /// Low, middle and high byte of `dec[c]`, except for code 255:
        /// its 2^24 needs 25 bits, so it is stored as 2^24 − 1 (see
        /// `encode` for why the sum may be up to 4 short).
        plane: [[u8; 256]; 3],
        /// `65536 · 255 · 1.055 · 2^(5(E − 26)/12)` at index `E − 17` for
        /// the float exponents E = 17..=26 of the power segment (the index
        /// is the low four bits of the biased exponent).
        scale: [f32; 16],
    }

    pub fn tables(t: &FixedSrgb) -> &'static Tables {
        static T: OnceLock<Tables> = OnceLock::new();
        T.get_or_init(|| {
            let dec = t.dec();
            let mut plane = [[0u8; 256]; 3];
            for (c, &d) in dec.iter().enumerate() {
                let d = if c == 255 {
                    assert_eq!(d, 1 << 24, "decode of code 255 is exactly 2^24");
                    d - 1
                } else {
                    assert!(d < SHORT_FROM, "decoded values below 255 stay below");
                    d
                };
                plane[0][c] = d as u8;
                plane[1][c] = (d >> 8) as u8;
                plane[2][c] = (d >> 16) as u8;
            }
            let mut scale = [0f32; 16];
            for (i, s) in scale.iter_mut().enumerate().take(10) {
                let e = i as f64 + 17.0;
                *s = (65536.0 * 255.0 * 1.055 * (5.0 * (e - 26.0) / 12.0).exp2()) as f32;
            }
            Tables { plane, scale }
        })
    }

    #[inline]
    #[target_feature(enable = "avx512f")]
    fn load(b: &[u8; 64]) -> __m512i {
        #[allow(unsafe_code)]
        // SAFETY: AVX-512 F is enabled for this function (its callers
        // checked it); `b` is 64 readable bytes, exactly one unaligned load.
        unsafe {
            _mm512_loadu_si512(b.as_ptr().cast())
        }
    }

    #[inline]
    #[target_feature(enable = "avx512f")]
    fn store(d: &mut [u8; 64], v: __m512i) {
        #[allow(unsafe_code)]
        // SAFETY: AVX-512 F is enabled for this function (its callers
        // checked it); `d` is 64 writable bytes, exactly one unaligned store.
        unsafe {
            _mm512_storeu_si512(d.as_mut_ptr().cast(), v)
        }
    }

    /// The constants of the kernel, as registers.
    #[derive(Clone, Copy)]
    struct Consts {
        planes: [[__m512i; 4]; 3],
        /// The power segment (its scale in this kernel's units).
        power: PowerSegment,
        /// The linear segment, `65536·255·12.92·s/2^26 + 65536·0.5`: no
        /// offset, as it is never flagged (see `encode`).
        lin_m: __m512,
        lin_k: __m512,
        split: __m512i,
        ones: __m512i,
        bit6: __m512i,
    }

    #[target_feature(enable = "avx512f,avx512bw,avx512vbmi,avx512vnni")]
    fn consts(tab: &Tables) -> Consts {
        let mut planes = [[_mm512_setzero_si512(); 4]; 3];
        for (regs, table) in planes.iter_mut().zip(&tab.plane) {
            for (r, part) in regs.iter_mut().zip(table.as_chunks::<64>().0) {
                *r = load(part);
            }
        }
        Consts {
            planes,
            power: PowerSegment::new(&tab.scale),
            lin_m: _mm512_set1_ps((65536.0 * 255.0 * 12.92 / (1u64 << 26) as f64) as f32),
            lin_k: _mm512_set1_ps(32768.0),
            split: _mm512_set1_epi32(LINEAR_BELOW as i32),
            ones: _mm512_set1_epi8(1),
            bit6: _mm512_set1_epi8(0x40),
        }
    }

    /// One 256-entry byte table (four registers) looked up for 64 codes:
    /// `vpermb` on the low six bits, each quarter of the table merged
    /// into the codes at or above its start (`from`).
    #[inline]
    #[target_feature(enable = "avx512f,avx512bw,avx512vbmi")]
    fn look_up(table: &[__m512i; 4], codes: __m512i, from: [__mmask64; 3]) -> __m512i {
        let r = _mm512_permutexvar_epi8(codes, table[0]);
        let r = _mm512_mask_permutexvar_epi8(r, from[0], codes, table[1]);
        let r = _mm512_mask_permutexvar_epi8(r, from[1], codes, table[2]);
        _mm512_mask_permutexvar_epi8(r, from[2], codes, table[3])
    }

    /// Sum of the decoded values of the four bytes of each dword (2^-24
    /// units per value), as the scalar kernel sums them except that each
    /// code 255 counts 2^24 − 1: three byte planes hold 24 bits, and a
    /// fourth plane (or per-lane weights) would cost two more instructions
    /// per register for what `encode` absorbs for free.
    #[inline]
    #[target_feature(enable = "avx512f,avx512bw,avx512vbmi,avx512vnni")]
    fn sum4(k: &Consts, q: __m512i) -> __m512i {
        let b7 = _mm512_movepi8_mask(q);
        let b6 = _mm512_test_epi8_mask(q, k.bit6);
        // Codes from 64, from 128, from 192: each look-up overwrites.
        let quarters = [b7 | b6, b7, b7 & b6];
        let lo = look_up(&k.planes[0], q, quarters);
        let mid = look_up(&k.planes[1], q, quarters);
        let hi = look_up(&k.planes[2], q, quarters);
        // (Σhigh·2^8 + Σmid)·2^8 + Σlow.
        let s = _mm512_dpbusd_epi32(_mm512_setzero_si512(), hi, k.ones);
        let s = _mm512_dpbusd_epi32(_mm512_slli_epi32::<8>(s), mid, k.ones);
        _mm512_dpbusd_epi32(_mm512_slli_epi32::<8>(s), lo, k.ones)
    }

    /// `65536 · code + fraction` of each sum `s` (the code is byte 2), and
    /// the mask of lanes where the code may be one too high.
    ///
    /// A sum holding `k` codes 255 arrives `k` (at most 4) short; it is at
    /// least `SHORT_FROM`, where 4 units move the code by less than 2^-16,
    /// so a decision threshold within the gap leaves the lane flagged. The
    /// exhaustive test checks exactly this: every unflagged `s` from
    /// `SHORT_FROM` on has the scalar code of `s + 1` to `s + 4` too.
    ///
    /// Lanes in the linear segment are never flagged: there the f32 value
    /// is within 0.04 of a step of the exact one, no integer sum comes
    /// closer than 0.08 steps to a threshold (the same exhaustive test),
    /// and sums of dark codes often tie exactly in linear light (codes 0,
    /// 1, 0, 1 average to 0.5), which a window would send to the scalar
    /// encode a quarter of the time.
    #[inline]
    #[target_feature(enable = "avx512f,avx512bw,avx512vbmi,avx512vnni")]
    fn encode(k: &Consts, s: __m512i) -> (__m512i, __mmask16) {
        let f = _mm512_cvtepi32_ps(s);
        let pow = k.power.eval(f);
        let lin = _mm512_fmadd_ps(f, k.lin_m, k.lin_k);
        let power = _mm512_cmpge_epi32_mask(s, k.split);
        let v = _mm512_mask_blend_ps(power, lin, pow);
        let n = _mm512_cvt_roundps_epi32::<{ _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC }>(v);
        (n, k.power.ambiguous(power, n))
    }

    /// 16 codes of `encode` for the exhaustive test: `(code, ambiguous)`.
    #[cfg(test)]
    #[target_feature(enable = "avx512f,avx512bw,avx512vbmi,avx512vnni")]
    pub fn encode16(t: &FixedSrgb, s: &[u32; 16]) -> ([u32; 16], u16) {
        let k = consts(tables(t));
        let (n, amb) = encode(&k, load(bytemuck::cast_ref(s)));
        let mut out = [0u32; 16];
        store(bytemuck::cast_mut(&mut out), _mm512_srli_epi32::<16>(n));
        (out, amb)
    }

    /// Shuffle indices and masks. A block is 16 output texels from 32 source
    /// texels of each row, loaded as `a0`, `a1` (row 0) and `b0`, `b1`
    /// (row 1); output texels 0..8 read (a0, b0), 8..16 read (a1, b1).
    /// The 48 colour values, numbered `3·texel + channel`, go to three
    /// registers of 16 dwords, the 16 alphas to a fourth; each dword holds
    /// the four source bytes of its value. A register that needs both
    /// pairs takes two masked `vpermi2b`: lanes in the mask read (a0, b0),
    /// the others keep their index byte for the second shuffle from
    /// (a1, b1).
    const fn gather(reg: usize) -> ([u8; 64], u64) {
        let (mut idx, mut first_pair) = ([0u8; 64], 0u64);
        let mut i = 0;
        while i < 64 {
            let (lane, k) = (i / 4, i % 4);
            let (texel, channel) = if reg < 3 {
                ((16 * reg + lane) / 3, (16 * reg + lane) % 3)
            } else {
                (lane, 3)
            };
            let source = 2 * (texel % 8) + (k & 1);
            idx[i] = ((k >> 1) * 64 + 4 * source + channel) as u8;
            if texel < 8 {
                first_pair |= 1 << i;
            }
            i += 1;
        }
        (idx, first_pair)
    }

    /// Output byte `i` (texel `i / 4`, channel `i % 4`) from the merged
    /// register of `row`: dword `l` holds lane `l` of colour register 1 in
    /// byte 0, of the alpha register in byte 1, of colour register 0 in
    /// byte 2 and of colour register 2 in byte 3.
    const fn pack() -> [u8; 64] {
        let mut idx = [0u8; 64];
        let mut i = 0;
        while i < 64 {
            let (texel, channel) = (i / 4, i % 4);
            let (lane, byte) = if channel < 3 {
                let v = 3 * texel + channel;
                (v % 16, [2, 0, 3][v / 16])
            } else {
                (texel, 1)
            };
            idx[i] = (4 * lane + byte) as u8;
            i += 1;
        }
        idx
    }

    const GATHER: [([u8; 64], u64); 4] = [gather(0), gather(1), gather(2), gather(3)];
    const PACK: [u8; 64] = pack();

    /// Gather indices and the alpha constants, as registers.
    struct Gather {
        idx: [__m512i; 4],
        first: [u64; 2],
        sixty_four: __m512i,
        alpha_round: __m512i,
        alpha_ref: __m512i,
    }

    impl Gather {
        #[inline]
        #[target_feature(enable = "avx512f,avx512bw,avx512vbmi,avx512vnni")]
        fn new(alpha: u8) -> Gather {
            Gather {
                idx: [
                    load(&GATHER[0].0),
                    load(&GATHER[1].0),
                    load(&GATHER[2].0),
                    load(&GATHER[3].0),
                ],
                first: [GATHER[1].1, GATHER[3].1],
                sixty_four: _mm512_set1_epi8(64),
                alpha_round: _mm512_set1_epi32(128),
                alpha_ref: _mm512_set1_epi8(alpha as i8),
            }
        }
    }

    /// The first half of a block: the three colour registers of sums (see
    /// `sum4`) and the alpha register (`64·Σa + 128`, so byte 1 is
    /// `(Σa + 2) >> 2`); ORs into `diff` where alphas differ from the
    /// reference (in the alpha register's bytes).
    #[inline]
    #[target_feature(enable = "avx512f,avx512bw,avx512vbmi,avx512vnni")]
    fn sums(
        k: &Consts,
        g: &Gather,
        a: &[[u8; 64]],
        b: &[[u8; 64]],
        diff: &mut __m512i,
    ) -> [__m512i; 4] {
        let (a0, a1) = (load(&a[0]), load(&a[1]));
        let (b0, b1) = (load(&b[0]), load(&b[1]));
        let c0 = _mm512_permutex2var_epi8(a0, g.idx[0], b0);
        let c1 = _mm512_mask2_permutex2var_epi8(a0, g.idx[1], g.first[0], b0);
        let c1 = _mm512_mask2_permutex2var_epi8(a1, c1, !g.first[0], b1);
        let c2 = _mm512_permutex2var_epi8(a1, g.idx[2], b1);
        let al = _mm512_mask2_permutex2var_epi8(a0, g.idx[3], g.first[1], b0);
        let al = _mm512_mask2_permutex2var_epi8(a1, al, !g.first[1], b1);
        *diff = _mm512_ternarylogic_epi32::<0xF6>(*diff, al, g.alpha_ref);
        [
            sum4(k, c0),
            sum4(k, c1),
            sum4(k, c2),
            _mm512_dpbusd_epi32(g.alpha_round, al, g.sixty_four),
        ]
    }

    /// Index of the four RGBA output registers of a block of unrounded
    /// values: lane `i` of register `j` is texel `4j + i / 4`, channel
    /// `i % 4`; colour value `v = 3·texel + channel` is lane `v mod 16` of
    /// colour register `v / 16`, and register `j` reads the pair
    /// (`j / 2`, `j / 2 + 1`) of colour registers (bit 4 picks the second).
    /// Alpha lanes hold the texel's index in the alpha register.
    const fn interleave(j: usize) -> [u32; 16] {
        let mut idx = [0u32; 16];
        let mut i = 0;
        while i < 16 {
            let (texel, channel) = (4 * j + i / 4, i % 4);
            idx[i] = if channel < 3 {
                let v = 3 * texel + channel;
                ((v / 16 - j / 2) * 16 + v % 16) as u32
            } else {
                texel as u32
            };
            i += 1;
        }
        idx
    }

    const INTERLEAVE: [[u32; 16]; 4] = [interleave(0), interleave(1), interleave(2), interleave(3)];

    /// The 64 unrounded values of one block into `out` (see
    /// [`super::row_rgba8_linear`]) from the sums of [`sums`].
    #[inline]
    #[target_feature(enable = "avx512f,avx512bw,avx512vbmi,avx512vnni")]
    fn unrounded(s: [__m512i; 4], idx: &[__m512i; 4], out: &mut [f32; 64]) {
        let unit = _mm512_set1_ps(1.0 / (1u64 << 26) as f32);
        let c = [0, 1, 2].map(|r| _mm512_mul_ps(_mm512_cvtepi32_ps(s[r]), unit));
        // 64·Σa + 128 back to Σa, over 4·255.
        let sum_a = _mm512_sub_epi32(_mm512_srli_epi32::<6>(s[3]), _mm512_set1_epi32(2));
        let a = _mm512_div_ps(_mm512_cvtepi32_ps(sum_a), _mm512_set1_ps(1020.0));
        for (j, o) in out.as_chunks_mut::<16>().0.iter_mut().enumerate() {
            let pair = j / 2;
            let v = _mm512_permutex2var_ps(c[pair], idx[j], c[pair + 1]);
            let v = _mm512_mask_permutexvar_ps(v, 0x8888, idx[j], a);
            #[allow(unsafe_code)]
            // SAFETY: AVX-512 F is enabled (callers checked it); `o` is 16
            // writable floats, one unaligned store.
            unsafe {
                _mm512_storeu_ps(o.as_mut_ptr(), v)
            };
        }
    }

    /// The kernel behind [`super::row_rgba8`] and (with `lin`)
    /// [`super::row_rgba8_linear`]: blocks of 16 output texels, then the
    /// scalar kernel for the rest of the row.
    #[target_feature(enable = "avx512f,avx512bw,avx512vbmi,avx512vnni")]
    pub fn row_with(
        r0: &[u8],
        r1: &[u8],
        dst: &mut [u8],
        mut lin: Option<&mut [f32]>,
        t: &FixedSrgb,
        tab: &Tables,
    ) -> bool {
        let k = consts(tab);
        let idx = INTERLEAVE.map(|i| load(bytemuck::cast_ref(&i)));
        let g = Gather::new(r0[3]);
        let pack = load(&PACK);
        let mut diff = _mm512_setzero_si512();

        let a_blocks = r0.as_chunks::<64>().0;
        let b_blocks = r1.as_chunks::<64>().0;
        let d_blocks = dst.as_chunks_mut::<64>().0;
        let n = d_blocks
            .len()
            .min(a_blocks.len() / 2)
            .min(b_blocks.len() / 2);
        // Software pipeline: the sums of block i + 1 are computed while
        // block i is encoded, so the two long dependency chains overlap.
        let pair = |i: usize| (&a_blocks[2 * i..2 * i + 2], &b_blocks[2 * i..2 * i + 2]);
        let mut next = [_mm512_setzero_si512(); 4];
        if n > 0 {
            let (a, b) = pair(0);
            next = sums(&k, &g, a, b, &mut diff);
        }
        for (i, d) in d_blocks[..n].iter_mut().enumerate() {
            let [s0, s1, s2, na] = next;
            if let Some(l) = lin.as_deref_mut() {
                unrounded(next, &idx, &mut l.as_chunks_mut::<64>().0[i]);
            }
            if i + 1 < n {
                let (a, b) = pair(i + 1);
                next = sums(&k, &g, a, b, &mut diff);
            }
            let (n0, m0) = encode(&k, s0);
            let (n1, m1) = encode(&k, s1);
            let (n2, m2) = encode(&k, s2);
            // One register of dwords [code 1, alpha, code 0, code 2] (codes
            // are byte 2 of n, alpha byte 1 of na), then one shuffle.
            let x = _mm512_mask_blend_epi8(0x1111_1111_1111_1111, n0, _mm512_srli_epi32::<16>(n1));
            let x = _mm512_mask_blend_epi8(0x2222_2222_2222_2222, x, na);
            let x = _mm512_mask_blend_epi8(0x8888_8888_8888_8888, x, _mm512_slli_epi32::<8>(n2));
            let out = _mm512_permutexvar_epi8(pack, x);
            store(d, out);
            if m0 | m1 | m2 != 0 {
                let ambiguous = m0 as u64 | (m1 as u64) << 16 | (m2 as u64) << 32;
                let (a, b) = pair(i);
                redo_ambiguous(a.as_flattened(), b.as_flattened(), d, ambiguous, t);
            }
        }
        let done = 64 * n;
        let mut constant = _mm512_test_epi32_mask(diff, diff) == 0;
        if done < dst.len() {
            let (t0, t1) = (&r0[2 * done..], &r1[2 * done..]);
            row_u8_srgb_n::<4, 3>(t0, t1, &mut dst[done..], t);
            if let Some(l) = lin {
                linear_tail(r0, r1, l, done, t);
            }
            constant &= t0
                .chunks_exact(4)
                .chain(t1.chunks_exact(4))
                .all(|p| p[3] == r0[3]);
        }
        constant
    }

    /// The scalar code for the values flagged ambiguous: bit `v` of `mask`
    /// is colour value `v` (texel `v / 3`, channel `v % 3`) of the 16
    /// output texels in `d`.
    #[cold]
    #[inline(never)]
    fn redo_ambiguous(a: &[u8], b: &[u8], d: &mut [u8], mut mask: u64, t: &FixedSrgb) {
        let dec = t.dec();
        while mask != 0 {
            let v = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            let (x, c) = (v / 3, v % 3);
            let (p, q) = (8 * x + c, 8 * x + 4 + c);
            let s =
                dec[a[p] as usize] + dec[a[q] as usize] + dec[b[p] as usize] + dec[b[q] as usize];
            d[4 * x + c] = t.encode4(s);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::row_rgba8;
    use crate::mip::fast::{FixedSrgb, fixed_tables, row_u8_srgb_n};

    /// Whether this machine can run the AVX-512 kernel (else the tests
    /// that need it pass vacuously, saying so).
    fn can_test() -> bool {
        if super::supported() {
            return true;
        }
        eprintln!("skipped: no AVX-512 F/BW/VBMI/VNNI on this CPU");
        false
    }

    /// xorshift64*: a fixed-seed stream of bytes.
    struct Rng(u64);
    impl Rng {
        fn byte(&mut self) -> u8 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 56) as u8
        }
    }

    /// Run both kernels on two source rows and compare every byte and the
    /// constant-alpha report against a direct check.
    fn check_rows(r0: &[u8], r1: &[u8], what: &str) {
        let t = fixed_tables();
        let mut want = vec![0u8; r0.len() / 2];
        row_u8_srgb_n::<4, 3>(r0, r1, &mut want, t);
        let mut got = vec![0xA5u8; r0.len() / 2];
        let constant = row_rgba8(r0, r1, &mut got, t, true);
        // The fused variant: the same codes and report, and unrounded
        // values equal to the scalar sums' (blocks and tail alike).
        let mut got2 = vec![0x5Au8; r0.len() / 2];
        let mut lin = vec![f32::NAN; r0.len() / 2];
        let constant2 = super::row_rgba8_linear(r0, r1, &mut got2, &mut lin, t);
        assert!(got2 == got && constant2 == constant, "{what}: fused codes");
        let mut want_lin = vec![0f32; lin.len()];
        super::linear_tail(r0, r1, &mut want_lin, 0, t);
        if let Some(i) = (0..lin.len()).find(|&i| lin[i].to_bits() != want_lin[i].to_bits()) {
            panic!("{what}: value {i}: {} (scalar {})", lin[i], want_lin[i]);
        }
        if let Some(i) = (0..want.len()).find(|&i| got[i] != want[i]) {
            let (x, c) = (i / 4, i % 4);
            let codes = [
                r0[8 * x + c],
                r0[8 * x + 4 + c],
                r1[8 * x + c],
                r1[8 * x + 4 + c],
            ];
            panic!(
                "{what}: width {}, texel {x} channel {c}: codes {codes:?} give {} (scalar {})",
                r0.len() / 4,
                got[i],
                want[i]
            );
        }
        let expect = r0
            .chunks_exact(4)
            .chain(r1.chunks_exact(4))
            .all(|p| p[3] == r0[3]);
        assert_eq!(constant, expect, "{what}: constant-alpha report");
    }

    #[test]
    fn avx512_row_matches_scalar_on_random_rows() {
        if !can_test() {
            return;
        }
        let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
        for width in [2, 6, 32, 34, 64, 130, 258, 2048, 4098] {
            for opaque in [false, true] {
                let mut row = || -> Vec<u8> {
                    (0..4 * width)
                        .map(|i| {
                            if opaque && i % 4 == 3 {
                                255
                            } else {
                                rng.byte()
                            }
                        })
                        .collect()
                };
                let (r0, r1) = (row(), row());
                check_rows(&r0, &r1, "random");
            }
        }
    }

    #[test]
    fn avx512_row_matches_scalar_on_every_code_in_every_position() {
        if !can_test() {
            return;
        }
        // Each of the 4 source positions of a block (row 0/1, left/right)
        // and each channel sees all 256 codes, against shifted partners.
        for shift in [0usize, 1, 77, 128, 255] {
            for width in [512usize, 514] {
                let code = |x: usize, c: usize, off: usize| ((x + 61 * c + off) % 256) as u8;
                let r0: Vec<u8> = (0..4 * width).map(|i| code(i / 4, i % 4, 0)).collect();
                let r1: Vec<u8> = (0..4 * width).map(|i| code(i / 4, i % 4, shift)).collect();
                check_rows(&r0, &r1, "every code");
                // Constant planes (all four codes equal) of every code.
                let same: Vec<u8> = (0..4 * width).map(|i| code(i / 8, i % 4, shift)).collect();
                check_rows(&same, &same, "equal blocks");
            }
        }
    }

    /// Four codes per decision threshold whose decoded sum is the largest
    /// below it, and four whose sum is the smallest at or above it.
    fn blocks_next_to_thresholds(t: &FixedSrgb) -> Vec<[u8; 4]> {
        let dec = t.dec();
        let mut pairs: Vec<(u32, u8, u8)> = (0..256)
            .flat_map(|a| (a..256).map(move |b| (a, b)))
            .map(|(a, b)| (dec[a] + dec[b], a as u8, b as u8))
            .collect();
        pairs.sort_unstable();
        let mut out = Vec::new();
        for &thr in &t.thr()[..255] {
            let (mut below, mut above) = (None::<(u32, [u8; 4])>, None::<(u32, [u8; 4])>);
            for &(p, a, b) in &pairs {
                if p > thr {
                    break;
                }
                // The smallest partner sum reaching the threshold, and the
                // one before it.
                let i = pairs.partition_point(|&(q, _, _)| p + q < thr);
                if let Some(&(q, c, d)) = pairs.get(i)
                    && above.is_none_or(|(s, _)| p + q < s)
                {
                    above = Some((p + q, [a, b, c, d]));
                }
                if let Some(&(q, c, d)) = i.checked_sub(1).map(|j| &pairs[j])
                    && below.is_none_or(|(s, _)| p + q > s)
                {
                    below = Some((p + q, [a, b, c, d]));
                }
            }
            out.extend(below.into_iter().chain(above).map(|(_, q)| q));
        }
        out
    }

    #[test]
    fn avx512_row_matches_scalar_next_to_every_threshold() {
        if !can_test() {
            return;
        }
        let t = fixed_tables();
        let blocks = blocks_next_to_thresholds(t);
        assert!(blocks.len() >= 500, "{} blocks", blocks.len());
        // Each block fills one colour value; shifting the start moves every
        // block through every channel and lane of the kernel.
        for start in 0..3 {
            let texels = (start + blocks.len()).div_ceil(3).next_multiple_of(16) + 3;
            let (mut r0, mut r1) = (vec![200u8; 8 * texels], vec![90u8; 8 * texels]);
            for (i, q) in blocks.iter().enumerate() {
                let (x, ch) = ((start + i) / 3, (start + i) % 3);
                let (p, r) = (8 * x + ch, 8 * x + 4 + ch);
                (r0[p], r0[r], r1[p], r1[r]) = (q[0], q[1], q[2], q[3]);
            }
            check_rows(&r0, &r1, "next to a threshold");
            // And with the two rows (and the two texels) swapped.
            check_rows(&r1, &r0, "next to a threshold, rows swapped");
        }
    }

    /// Dark noise (codes in the linear segment) ties exactly in linear
    /// light a quarter of the time; those ties must not be sent to the
    /// scalar encode, or dark images would run at scalar speed.
    #[test]
    #[cfg(target_arch = "x86_64")]
    fn dark_blocks_rarely_take_the_scalar_encode() {
        if !can_test() {
            return;
        }
        let t = fixed_tables();
        let dec = t.dec();
        let sums: Vec<u32> = (0..11usize.pow(4))
            .map(|i| (0..4).map(|k| dec[i / 11usize.pow(k) % 11]).sum())
            .collect();
        let mut flagged = 0;
        for chunk in sums.chunks(16) {
            let mut s = [0u32; 16];
            s[..chunk.len()].copy_from_slice(chunk);
            #[allow(unsafe_code)]
            // SAFETY: `can_test()` confirmed the features `encode16` needs.
            let (_, amb) = unsafe { super::x86::encode16(t, &s) };
            flagged += (amb & ((1u32 << chunk.len()) - 1) as u16).count_ones();
        }
        assert!(
            flagged * 1000 < sums.len() as u32,
            "{flagged} of {} flagged",
            sums.len()
        );
    }

    #[test]
    #[cfg(target_arch = "x86_64")]
    fn vector_encode_equals_the_scalar_encode_for_every_sum() {
        use super::x86;
        if !can_test() {
            return;
        }
        let t = fixed_tables();
        let top = 1u32 << 26;
        let (mut ambiguous, mut s) = (0u64, [0u32; 16]);
        let mut base = 0u32;
        while base <= top {
            for (k, v) in s.iter_mut().enumerate() {
                *v = (base + k as u32).min(top);
            }
            #[allow(unsafe_code)]
            // SAFETY: `can_test()` confirmed the features `encode16` needs.
            let (codes, amb) = unsafe { x86::encode16(t, &s) };
            for k in 0..16 {
                if amb >> k & 1 == 1 {
                    ambiguous += 1;
                    continue;
                }
                assert_eq!(codes[k], t.encode4(s[k]) as u32, "s = {}", s[k]);
                // A sum with codes 255 arrives one unit short per 255.
                if s[k] >= super::SHORT_FROM {
                    for short in 1..=4 {
                        let full = (s[k] + short).min(top);
                        assert_eq!(codes[k], t.encode4(full) as u32, "s = {full} - {short}");
                    }
                }
            }
            base += 16;
        }
        // About 2·2·AMBIGUITY/65536 of all sums: the fall-back stays rare.
        assert!(
            ambiguous < (top / 1000) as u64,
            "{ambiguous} ambiguous sums"
        );
        eprintln!("{ambiguous} of {top} sums take the scalar encode");
    }
}
