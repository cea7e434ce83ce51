//! The sRGB transfer function (IEC 61966-2-1), exact piecewise curve.
//!
//! Decoding 8-bit codes goes through a 256-entry table. Encoding linear
//! values to 8-bit codes is *exactly* `round(encode(v) * 255)`: instead of
//! evaluating `powf` per value we compare against the 255 decision
//! thresholds `decode((k + 0.5) / 255)` (computed in f64), starting from a
//! coarse bucket table so at most a couple of comparisons are needed. The
//! result equals the formula's rounding except where `v` lies within one f32
//! ulp of a threshold, i.e. at exact ties.

use std::sync::OnceLock;

/// sRGB-encoded value in [0, 1] to linear light (exact curve, f64).
pub fn decode_f64(c: f64) -> f64 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear light in [0, 1] to sRGB-encoded (exact curve, f64).
pub fn encode_f64(l: f64) -> f64 {
    if l <= 0.0031308 {
        l * 12.92
    } else {
        1.055 * l.powf(1.0 / 2.4) - 0.055
    }
}

/// sRGB-encoded value to linear light (f32).
#[inline]
pub fn decode(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear light to sRGB-encoded value (f32).
#[inline]
pub fn encode(l: f32) -> f32 {
    if l <= 0.003_130_8 {
        l * 12.92
    } else {
        1.055 * l.powf(1.0 / 2.4) - 0.055
    }
}

/// Number of buckets in the coarse encode index over linear [0, 1].
const BUCKETS: usize = 4096;

pub(crate) struct Tables {
    /// Linear value of each 8-bit code.
    pub decode8: [f32; 256],
    /// `thresholds[k]`: smallest linear value that encodes to code k + 1.
    pub thresholds: [f32; 256],
    /// For each bucket of linear [0, 1], the code of its lower edge.
    pub bucket: Box<[u8; BUCKETS + 1]>,
}

pub(crate) fn tables() -> &'static Tables {
    static T: OnceLock<Tables> = OnceLock::new();
    T.get_or_init(|| {
        let mut decode8 = [0f32; 256];
        for (k, d) in decode8.iter_mut().enumerate() {
            *d = decode_f64(k as f64 / 255.0) as f32;
        }
        let mut thresholds = [f32::INFINITY; 256];
        for (k, t) in thresholds.iter_mut().enumerate().take(255) {
            // Round up to the next f32 so that `v >= t` means the exact
            // value is at or above the midpoint in sRGB space.
            let exact = decode_f64((k as f64 + 0.5) / 255.0);
            let mut f = exact as f32;
            if (f as f64) < exact {
                f = f32::from_bits(f.to_bits() + 1);
            }
            *t = f;
        }
        let mut bucket = Box::new([0u8; BUCKETS + 1]);
        let mut code = 0usize;
        for (b, slot) in bucket.iter_mut().enumerate() {
            let lo = b as f32 / BUCKETS as f32;
            while code < 255 && lo >= thresholds[code] {
                code += 1;
            }
            *slot = code as u8;
        }
        Tables {
            decode8,
            thresholds,
            bucket,
        }
    })
}

/// Linear value to the nearest 8-bit sRGB code (NaN maps to 0).
#[inline]
pub fn encode_u8(l: f32) -> u8 {
    let t = tables();
    encode_u8_with(t, l)
}

/// [`encode_u8`] with the tables at hand. Branch-free: the clamp maps
/// NaN and values ≤ 0 to bucket 0 (code 0) and values ≥ 1 to the last
/// bucket (code 255); the thresholds are at least 0.000303 apart (the
/// linear toe's step) and the buckets 1/4096 = 0.000244 wide, so a bucket
/// holds at most one threshold and one comparison settles the code.
#[inline]
pub(crate) fn encode_u8_with(t: &Tables, l: f32) -> u8 {
    // `max` returns the other operand for NaN (`clamp` would keep it).
    #[allow(clippy::manual_clamp)]
    let l = l.max(0.0).min(1.0);
    let code = t.bucket[((l * BUCKETS as f32) as usize).min(BUCKETS)];
    code + u8::from(l >= t.thresholds[code as usize])
}

/// 8-bit sRGB code to linear light.
#[inline]
pub fn decode_u8(c: u8) -> f32 {
    tables().decode8[c as usize]
}

/// Linear value of each 16-bit sRGB code (256 KiB, built on first use).
pub(crate) fn decode16() -> &'static [f32] {
    static T: OnceLock<Vec<f32>> = OnceLock::new();
    T.get_or_init(|| {
        (0..=u16::MAX)
            .map(|c| decode_f64(c as f64 / 65535.0) as f32)
            .collect()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encode_u8_matches_formula_rounding_on_a_dense_sweep() {
        for i in 0..=200_000u32 {
            let l = i as f32 / 200_000.0;
            let want = (encode_f64(l as f64) * 255.0).round() as u8;
            assert_eq!(encode_u8(l), want, "l = {l}");
        }
    }

    #[test]
    fn encode_u8_is_exact_next_to_every_threshold_and_at_the_extremes() {
        let t = tables();
        for k in 0..255usize {
            let th = t.thresholds[k];
            let below = f32::from_bits(th.to_bits() - 1);
            assert_eq!(encode_u8(th), k as u8 + 1, "at threshold {k}");
            assert_eq!(encode_u8(below), k as u8, "below threshold {k}");
            // The loop the tables were made with agrees.
            let mut code = 0usize;
            while code < 255 && below >= t.thresholds[code] {
                code += 1;
            }
            assert_eq!(code, k);
        }
        for (l, want) in [
            (f32::NAN, 0),
            (-1.0, 0),
            (f32::NEG_INFINITY, 0),
            (0.0, 0),
            (1.0, 255),
            (1.5, 255),
            (f32::INFINITY, 255),
        ] {
            assert_eq!(encode_u8(l), want, "l = {l}");
        }
    }

    #[test]
    fn every_code_round_trips() {
        for c in 0..=255u8 {
            assert_eq!(encode_u8(decode_u8(c)), c);
        }
    }
}
