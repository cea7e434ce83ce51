//! AVX-512 kernels for the 8-bit codec: codes to linear f32
//! ([`decode`]) and linear f32 to codes ([`encode`]), for any channel
//! layout, each channel sRGB or linear. Both give the scalar codec's
//! values bit for bit; they exist because the scalar loops were most of
//! the time of an 8-bit chain (issue 32: 40% of the sRGB box chain was
//! `encode_u8`, another 24% `decode_u8`).
//!
//! - **Decode**, sRGB lanes: 16 codes widened to dwords and looked up in
//!   the sRGB table held in 16 registers (eight two-register permutes and
//!   three blends); linear lanes: `code · (1/255)`. The same floats the
//!   scalar tables hold.
//! - **Encode**, linear lanes: `v · 255 + 0.5`, clamped, truncated, as
//!   [`super::unorm8`] does (NaN to 0; the two operations are not fused).
//! - **Encode**, sRGB lanes: the curve in f32, in 1/65536 of a code: the
//!   linear segment below 0.0031308, else `1.055·l^(5/12) − 0.055` with
//!   `l^(5/12)` as a per-octave scale (one `vpermps` from the exponent) times
//!   a degree-6 polynomial in the mantissa (`x86::PowerSegment`, which
//!   `mip/srgb_simd.rs` shares to encode its fixed-point sums). An
//!   offset of `AMBIGUITY` steps is added before rounding down; a lane
//!   whose fraction is below `2·AMBIGUITY` steps may be one code too high
//!   (about 1 value in 2000 of random data, far more on smooth gradients,
//!   where averages of neighbouring codes land next to a threshold): those
//!   lanes are settled in registers against the scalar thresholds of their
//!   codes (one more lookup, a compare and a masked subtract). Every lane
//!   is the scalar code: a unit test checks every f32 in [0, 1].
//!
//! Used when the CPU has AVX-512 F, BW, DQ, VL and VBMI
//! ([`crate::cpu::avx512_sample`], which `PARVO_NO_AVX` turns off);
//! otherwise, and for the last `len mod 16` values, the scalar loops run.

/// Offset, in 1/65536 of a code, added before rounding down; lanes whose
/// result lies less than `2·AMBIGUITY` steps above a code boundary are
/// redone exactly. It must exceed the f32 evaluation error (the
/// polynomial's bound is about 7 steps; 4 already passes the exhaustive
/// tests of both users, 16 leaves a margin and redoes about 1 value in
/// 2000).
const AMBIGUITY: u32 = 16;

/// `m^(5/12)` for `m` in [1, 2): the degree-6 Chebyshev interpolant,
/// expanded in powers of `m` (relative error 2.4e-7, 3.8e-7 evaluated in
/// f32; at most 1e-4 of a code after scaling by 255·1.055).
const POLY: [f32; 7] = [
    0.351_870_06,
    1.057_500_4,
    -0.676_159_26,
    0.379_771_56,
    -0.139_750_14,
    0.029_459_171,
    -0.002_691_525_7,
];

/// True when the kernels may run (the CPU has them and `PARVO_NO_AVX` is
/// not set).
pub(crate) fn available() -> bool {
    crate::cpu::avx512_sample()
}

/// Which of a texel's `ch` channels are sRGB (the first `cc`): lane masks
/// for a block of 16 values starting at value `o`, indexed by `o mod ch`.
fn srgb_masks(ch: usize, cc: usize) -> [u16; 4] {
    std::array::from_fn(|o| {
        (0..16).fold(0u16, |m, i| m | (u16::from((o + i) % ch.max(1) < cc) << i))
    })
}

/// Decode 8-bit values (`ch` channels, the first `cc` sRGB) to linear f32
/// with the AVX-512 kernel, or `false` (nothing written) when it may not
/// run.
pub(crate) fn decode(i: &[u8], o: &mut [f32], ch: usize, cc: usize) -> bool {
    #[cfg(target_arch = "x86_64")]
    if available() {
        #[allow(unsafe_code)]
        // SAFETY: `available()` confirmed AVX-512 F, BW, DQ, VL (and VBMI),
        // a superset of what `x86::decode` is compiled for.
        unsafe {
            x86::decode(i, o, ch, cc)
        };
        return true;
    }
    let _ = (i, o, ch, cc);
    false
}

/// Encode linear f32 (`ch` channels, the first `cc` sRGB) to 8-bit values
/// with the AVX-512 kernel, or `false` (nothing written) when it may not
/// run.
pub(crate) fn encode(i: &[f32], o: &mut [u8], ch: usize, cc: usize) -> bool {
    #[cfg(target_arch = "x86_64")]
    if available() {
        #[allow(unsafe_code)]
        // SAFETY: `available()` confirmed AVX-512 F, BW, DQ, VL (and VBMI),
        // a superset of what `x86::encode` is compiled for.
        unsafe {
            x86::encode(i, o, ch, cc)
        };
        return true;
    }
    let _ = (i, o, ch, cc);
    false
}

/// The scalar codec, value by value (the tails, and the reference).
fn decode_scalar(i: &[u8], o: &mut [f32], start: usize, ch: usize, cc: usize) {
    let t = &super::srgb::tables().decode8;
    for (k, (o, &c)) in o.iter_mut().zip(i).enumerate() {
        *o = if (start + k) % ch < cc {
            t[c as usize]
        } else {
            c as f32 * (1.0 / 255.0)
        };
    }
}

fn encode_scalar(i: &[f32], o: &mut [u8], start: usize, ch: usize, cc: usize) {
    let t = super::srgb::tables();
    for (k, (o, &v)) in o.iter_mut().zip(i).enumerate() {
        *o = if (start + k) % ch < cc {
            super::srgb::encode_u8_with(t, v)
        } else {
            super::unorm8(v)
        };
    }
}

#[cfg(target_arch = "x86_64")]
pub(crate) mod x86 {
    use std::arch::x86_64::*;
    use std::sync::OnceLock;

    use super::{AMBIGUITY, POLY, decode_scalar, encode_scalar, srgb_masks};
    use crate::simd::{load_ps, store_ps};

    /// `65536 · 255 · 1.055 · 2^(5(E − 127)/12)` at index `E mod 16` for the
    /// biased float exponents E = 118..=127 of the power segment.
    fn scales() -> &'static [f32; 16] {
        static T: OnceLock<[f32; 16]> = OnceLock::new();
        T.get_or_init(|| {
            let mut s = [0f32; 16];
            for e in 118..=127i32 {
                s[(e % 16) as usize] =
                    (65536.0 * 255.0 * 1.055 * (5.0 * (e - 127) as f64 / 12.0).exp2()) as f32;
            }
            s
        })
    }

    /// Decode 16 values per step: the sRGB lanes by a 256-entry lookup in
    /// registers ([`lookup256`]; a gather of 16 floats cost about 20
    /// cycles on Zen 4, a fifth of the Kaiser chain), the linear lanes as
    /// `code · (1/255)` (the same float operation as the table's).
    #[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl")]
    pub(crate) fn decode(i: &[u8], o: &mut [f32], ch: usize, cc: usize) {
        let masks = srgb_masks(ch, cc);
        let rows = crate::texel::srgb::tables().decode8.as_chunks::<16>().0;
        let lut: [__m512; 16] = std::array::from_fn(|r| load_ps(&rows[r]));
        let scale = _mm512_set1_ps(1.0 / 255.0);
        let n = i.len().min(o.len()) / 16 * 16;
        for (k, (src, dst)) in i[..n]
            .as_chunks::<16>()
            .0
            .iter()
            .zip(o[..n].as_chunks_mut::<16>().0)
            .enumerate()
        {
            let bytes: __m128i = bytemuck::cast(*src);
            let idx = _mm512_cvtepu8_epi32(bytes);
            let linear = _mm512_mul_ps(_mm512_cvtepi32_ps(idx), scale);
            // No sRGB channel (a linear image): no lookup.
            let v = if cc == 0 {
                linear
            } else {
                _mm512_mask_blend_ps(masks[(16 * k) % ch], linear, lookup256(&lut, idx))
            };
            store_ps(dst, v);
        }
        decode_scalar(&i[n..], &mut o[n..], n, ch, cc);
    }

    /// `lut[idx / 16][idx % 16]` per lane for indices below 256: eight
    /// two-register permutes (indices mod 32), then a blend per higher
    /// index bit.
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn lookup256(lut: &[__m512; 16], idx: __m512i) -> __m512 {
        let bit = |b: i32| _mm512_test_epi32_mask(idx, _mm512_set1_epi32(b));
        let (b5, b6, b7) = (bit(32), bit(64), bit(128));
        let pair = |g: usize| {
            let lo = _mm512_permutex2var_ps(lut[4 * g], idx, lut[4 * g + 1]);
            let hi = _mm512_permutex2var_ps(lut[4 * g + 2], idx, lut[4 * g + 3]);
            _mm512_mask_blend_ps(b5, lo, hi)
        };
        let low = _mm512_mask_blend_ps(b6, pair(0), pair(1));
        let high = _mm512_mask_blend_ps(b6, pair(2), pair(3));
        _mm512_mask_blend_ps(b7, low, high)
    }

    /// The constants of [`encode16`], as registers.
    struct Consts {
        power: PowerSegment,
        lin_m: __m512,
        lin_k: __m512,
        split: __m512,
        zero: __m512,
        one: __m512,
        c255: __m512,
        half: __m512,
    }

    #[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl")]
    fn consts() -> Consts {
        let off = 32768.0 + AMBIGUITY as f64;
        Consts {
            power: PowerSegment::new(scales()),
            lin_m: _mm512_set1_ps((65536.0 * 255.0 * 12.92) as f32),
            lin_k: _mm512_set1_ps(off as f32),
            split: _mm512_set1_ps(0.003_130_8),
            zero: _mm512_setzero_ps(),
            one: _mm512_set1_ps(1.0),
            c255: _mm512_set1_ps(255.0),
            half: _mm512_set1_ps(0.5),
        }
    }

    /// The power segment of the sRGB encode, `255·(1.055·x^(5/12) −
    /// 0.055)`, in 1/65536 of a code, plus `32768 + AMBIGUITY` (a half
    /// code to round, and the offset the [`ambiguous`](Self::ambiguous)
    /// test needs), in f32: `x^(5/12)` is a per-octave scale (one
    /// `vpermps` from the float exponent) times a degree-6 polynomial in
    /// the mantissa. Shared by this codec (values in [0, 1]) and the sRGB
    /// box kernel of `mip/srgb_simd.rs` (fixed-point sums), which differ
    /// only in their scale tables.
    #[derive(Clone, Copy)]
    pub(crate) struct PowerSegment {
        poly: [__m512; 7],
        scale: __m512,
        pow_k: __m512,
        ambiguous: __m512i,
    }

    impl PowerSegment {
        /// `scale[E mod 16]` is `65536 · 255 · 1.055 · X_E^(5/12)`, where
        /// `X_E` is the value, in the caller's units, of the float whose
        /// biased exponent is E and mantissa 1 (for every E the segment
        /// meets).
        #[target_feature(enable = "avx512f")]
        pub(crate) fn new(scale: &[f32; 16]) -> PowerSegment {
            let off = 32768.0 + AMBIGUITY as f64;
            PowerSegment {
                poly: POLY.map(|c| _mm512_set1_ps(c)),
                scale: load_ps(scale),
                pow_k: _mm512_set1_ps((off - 65536.0 * 255.0 * 0.055) as f32),
                ambiguous: _mm512_set1_epi32((0xFFFF & !(2 * AMBIGUITY - 1)) as i32),
            }
        }

        /// The segment at each (positive, in range) lane of `f`, not yet
        /// rounded: round it down and shift right by 16 for the code.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub(crate) fn eval(&self, f: __m512) -> __m512 {
            let m = _mm512_getmant_ps::<_MM_MANT_NORM_1_2, _MM_MANT_SIGN_SRC>(f);
            let c = &self.poly;
            let m2 = _mm512_mul_ps(m, m);
            let p01 = _mm512_fmadd_ps(c[1], m, c[0]);
            let p23 = _mm512_fmadd_ps(c[3], m, c[2]);
            let p45 = _mm512_fmadd_ps(c[5], m, c[4]);
            let p456 = _mm512_fmadd_ps(c[6], m2, p45);
            let p0123 = _mm512_fmadd_ps(p23, m2, p01);
            let m4 = _mm512_mul_ps(m2, m2);
            let p = _mm512_fmadd_ps(p456, m4, p0123);
            let sc =
                _mm512_permutexvar_ps(_mm512_srli_epi32::<23>(_mm512_castps_si512(f)), self.scale);
            _mm512_fmadd_ps(sc, p, self.pow_k)
        }

        /// The lanes of `mask` whose rounded-down [`eval`](Self::eval)
        /// `n` lies less than `2·AMBIGUITY` steps above a code boundary:
        /// their code may be one too high, and is to be redone exactly.
        #[inline]
        #[target_feature(enable = "avx512f")]
        pub(crate) fn ambiguous(&self, mask: __mmask16, n: __m512i) -> __mmask16 {
            _mm512_mask_testn_epi32_mask(mask, n, self.ambiguous)
        }
    }

    /// 16 values to linear codes: `(v · 255 + 0.5) as u8` (NaN and below
    /// 0 to 0).
    #[inline]
    #[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl")]
    fn linear16(k: &Consts, v: __m512) -> __m512i {
        let u = _mm512_add_ps(_mm512_mul_ps(v, k.c255), k.half);
        let u = _mm512_min_ps(_mm512_max_ps(u, k.zero), k.c255);
        _mm512_cvttps_epi32(u)
    }

    /// 16 values to codes: sRGB in the lanes of `srgb`, linear elsewhere;
    /// and the mask of sRGB lanes that may be one code too high.
    #[inline]
    #[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl")]
    fn encode16(k: &Consts, v: __m512, srgb: __mmask16) -> (__m512i, __mmask16) {
        let lin_code = linear16(k, v);
        // sRGB lanes. `max` gives its second operand for NaN: NaN to 0.
        let l = _mm512_min_ps(_mm512_max_ps(v, k.zero), k.one);
        let pow = k.power.eval(l);
        let lin = _mm512_fmadd_ps(l, k.lin_m, k.lin_k);
        let power = _mm512_cmp_ps_mask::<_CMP_GE_OQ>(l, k.split);
        let x = _mm512_mask_blend_ps(power, lin, pow);
        let n = _mm512_cvt_roundps_epi32::<{ _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC }>(x);
        let ambiguous = k.power.ambiguous(srgb, n);
        let code = _mm512_mask_blend_epi32(srgb, lin_code, _mm512_srli_epi32::<16>(n));
        (code, ambiguous)
    }

    #[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl")]
    pub(crate) fn encode(i: &[f32], o: &mut [u8], ch: usize, cc: usize) {
        let k = consts();
        let masks = srgb_masks(ch, cc);
        let floors: [__m512; 16] = std::array::from_fn(|r| load_ps(&floors()[r]));
        let n = i.len().min(o.len()) / 16 * 16;
        for (b, (src, dst)) in i[..n]
            .as_chunks::<16>()
            .0
            .iter()
            .zip(o[..n].as_chunks_mut::<16>().0)
            .enumerate()
        {
            let v = load_ps(src);
            if cc == 0 {
                // A linear image: no sRGB lane.
                *dst = bytemuck::cast(_mm512_cvtepi32_epi8(linear16(&k, v)));
                continue;
            }
            let (mut code, ambiguous) = encode16(&k, v, masks[(16 * b) % ch]);
            if ambiguous != 0 {
                code = settle(&floors, v, code, ambiguous);
            }
            *dst = bytemuck::cast(_mm512_cvtepi32_epi8(code));
        }
        encode_scalar(&i[n..], &mut o[n..], n, ch, cc);
    }

    /// The smallest value of each code: `floors[c / 16][c % 16]` is the
    /// scalar threshold between codes c − 1 and c (−∞ for code 0).
    fn floors() -> &'static [[f32; 16]; 16] {
        static T: OnceLock<[[f32; 16]; 16]> = OnceLock::new();
        T.get_or_init(|| {
            let thr = &crate::texel::srgb::tables().thresholds;
            std::array::from_fn(|r| {
                std::array::from_fn(|i| match 16 * r + i {
                    0 => f32::NEG_INFINITY,
                    c => thr[c - 1],
                })
            })
        })
    }

    /// The lanes of `mask` (sRGB lanes whose `code` may be one too high)
    /// settled exactly: one lower where the clamped value lies below the
    /// code's scalar threshold, so every lane is the scalar code (the
    /// scalar encode counts the thresholds at or below the value).
    #[inline(never)]
    #[target_feature(enable = "avx512f")]
    fn settle(floors: &[__m512; 16], v: __m512, code: __m512i, mask: __mmask16) -> __m512i {
        // The clamp of `encode16` (NaN to 0).
        let l = _mm512_min_ps(_mm512_max_ps(v, _mm512_setzero_ps()), _mm512_set1_ps(1.0));
        let low = _mm512_mask_cmp_ps_mask::<_CMP_LT_OQ>(mask, l, lookup256(floors, code));
        _mm512_mask_sub_epi32(code, low, code, _mm512_set1_epi32(1))
    }

    /// [`encode16`] for the exhaustive test: every lane sRGB; the codes
    /// and the ambiguous mask.
    #[cfg(test)]
    #[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl")]
    pub(crate) fn encode16_srgb(v: &[f32; 16]) -> ([u8; 16], u16) {
        let k = consts();
        let (code, amb) = encode16(&k, load_ps(v), 0xFFFF);
        (bytemuck::cast(_mm512_cvtepi32_epi8(code)), amb)
    }
}

#[cfg(test)]
mod tests {
    use super::{decode_scalar, encode_scalar};

    fn can_test() -> bool {
        if super::available() {
            return true;
        }
        eprintln!("skipped: no AVX-512 F/BW/DQ/VL/VBMI (or PARVO_NO_AVX set)");
        false
    }

    /// Every layout: 1–4 channels, any number of leading sRGB channels.
    fn layouts() -> Vec<(usize, usize)> {
        (1..=4)
            .flat_map(|ch| (0..=ch).map(move |cc| (ch, cc)))
            .collect()
    }

    #[test]
    fn decode_equals_the_scalar_tables_for_every_code_in_every_lane() {
        if !can_test() {
            return;
        }
        for (ch, cc) in layouts() {
            // The last input has every code in every lane of a block under
            // every channel (lane l of block b holds b + 17·l: 768 blocks).
            let every: Vec<u8> = (0..16 * 256 * 3)
                .map(|k| (k / 16 + 17 * (k % 16)) as u8)
                .collect();
            let mixed = |len: usize| (0..len).map(|k| (k * 7 + k / 256) as u8).collect();
            let inputs = [0usize, 5, 16, 48, 256 * 4 + 7, 3 * 256 * 4].map(mixed);
            for i in inputs.into_iter().chain([every.clone()]) {
                let len = i.len();
                let mut want = vec![0f32; len];
                decode_scalar(&i, &mut want, 0, ch, cc);
                let mut got = vec![f32::NAN; len];
                assert!(super::decode(&i, &mut got, ch, cc));
                let same = want
                    .iter()
                    .zip(&got)
                    .all(|(a, b)| a.to_bits() == b.to_bits());
                assert!(same, "{ch} channels, {cc} sRGB, {len} values");
            }
        }
    }

    #[test]
    fn encode_equals_the_scalar_codec_in_every_layout() {
        if !can_test() {
            return;
        }
        let mut s = 0x9E37_79B9u32;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            s
        };
        let specials = [
            f32::NAN,
            -f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            -0.0,
            0.0,
            -1.0,
            1.0,
            1.0000001,
            2.0,
            f32::MIN_POSITIVE,
            1e-40,
            0.003_130_8,
            0.5,
        ];
        // Values at and next to every sRGB threshold: the lanes the
        // polynomial flags as ambiguous.
        let thr = &crate::texel::srgb::tables().thresholds;
        let near: Vec<f32> = thr[..255]
            .iter()
            .flat_map(|&t| [t.next_down(), t, t.next_up()])
            .collect();
        for (ch, cc) in layouts() {
            for len in [0usize, 7, 16, 33, 4096 + 5] {
                let i: Vec<f32> = (0..len)
                    .map(|k| match k % 6 {
                        0 => specials[(next() as usize) % specials.len()],
                        1 => f32::from_bits(next() % 0x3F80_0001),
                        2 => near[(next() as usize) % near.len()],
                        _ => (next() >> 8) as f32 / (1u32 << 24) as f32 * 1.1 - 0.05,
                    })
                    .collect();
                let mut want = vec![0u8; len];
                encode_scalar(&i, &mut want, 0, ch, cc);
                let mut got = vec![0xA5u8; len];
                assert!(super::encode(&i, &mut got, ch, cc));
                assert_eq!(got, want, "{ch} channels, {cc} sRGB, {len} values");
            }
        }
    }

    /// Every f32 from 0 to 1 (and so every value the clamp can give):
    /// each lane not flagged ambiguous is the scalar code, and few are.
    #[test]
    #[cfg(target_arch = "x86_64")]
    fn srgb_encode_equals_the_scalar_code_for_every_f32_in_0_1() {
        if !can_test() {
            return;
        }
        let t = crate::texel::srgb::tables();
        let top = 1f32.to_bits();
        let (mut flagged, mut bits) = (0u64, 0u32);
        while bits <= top {
            let v: [f32; 16] = std::array::from_fn(|k| f32::from_bits((bits + k as u32).min(top)));
            #[allow(unsafe_code)]
            // SAFETY: `can_test()` confirmed the features `encode16_srgb`
            // needs.
            let (codes, amb) = unsafe { super::x86::encode16_srgb(&v) };
            if amb != 0 {
                // The whole encode settles the flagged lanes exactly.
                let mut out = [0u8; 16];
                assert!(super::encode(&v, &mut out, 1, 1));
                for k in 0..16 {
                    let want = crate::texel::srgb::encode_u8_with(t, v[k]);
                    assert_eq!(
                        out[k],
                        want,
                        "l = {:e} ({:#x}), settled",
                        v[k],
                        v[k].to_bits()
                    );
                }
            }
            for k in 0..16 {
                if amb >> k & 1 == 1 {
                    flagged += 1;
                } else if codes[k] != crate::texel::srgb::encode_u8_with(t, v[k]) {
                    panic!(
                        "l = {:e} ({:#x}): {} (scalar {})",
                        v[k],
                        v[k].to_bits(),
                        codes[k],
                        crate::texel::srgb::encode_u8_with(t, v[k])
                    );
                }
            }
            bits += 16;
        }
        assert!(flagged < (top / 1000) as u64, "{flagged} flagged");
        eprintln!("{flagged} of {top} values take the scalar encode");
    }
}
