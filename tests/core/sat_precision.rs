//! Float tables on a 4096² random image (the configuration of
//! `examples/03_sat_precision.rs`): f64 beats offset-f32, which beats f32,
//! for small boxes near the far corner, and every table stays within its
//! own stated bound.

use parvo::sat::{self, AccumulatorKind, Rect};
use parvo::texel::{ChannelType, ColorSpace, Format};
use parvo::{Texture, Wrap};

const N: u32 = 4096;
const REGION: u32 = 24;

#[test]
fn f64_beats_offset_f32_beats_f32_near_the_far_corner() {
    let mut s = 0x05EE_D5A7_u64;
    let values: Vec<f32> = (0..N * N)
        .map(|_| {
            s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = s;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^= z >> 31;
            ((z >> 11) as f64 / (1u64 << 53) as f64) as f32
        })
        .collect();
    let fmt = Format::new(1, ChannelType::F32, ColorSpace::Linear);
    let tex = Texture::from_f32(N, N, fmt, values.clone()).unwrap();
    let mut errors = Vec::new();
    for kind in [
        AccumulatorKind::F32,
        AccumulatorKind::OffsetF32,
        AccumulatorKind::F64,
    ] {
        let t = sat::build(&tex, Some(kind)).unwrap();
        let mut per_size = Vec::new();
        for k in 1..=4u32 {
            let mut worst = 0f64;
            for y0 in N - REGION..=N - k {
                for x0 in N - REGION..=N - k {
                    let mut want = 0f64;
                    for y in y0..y0 + k {
                        for x in x0..x0 + k {
                            want += values[(y * N + x) as usize] as f64;
                        }
                    }
                    let r = Rect::texels(x0 as i64, y0 as i64, (x0 + k) as i64, (y0 + k) as i64);
                    let s = t.sum_box(r, Wrap::default());
                    let err = (s.sum[0] - want).abs();
                    // Every query is within the bound the table states.
                    assert!(err <= s.error, "{kind} {k}x{k}: {err} > {}", s.error);
                    worst = worst.max(err / (k * k) as f64);
                }
            }
            per_size.push(worst);
        }
        errors.push(per_size);
    }
    for (k, ((&f32e, &off), &f64e)) in errors[0].iter().zip(&errors[1]).zip(&errors[2]).enumerate()
    {
        assert!(
            f64e < off && off < f32e,
            "{k}: f32 {f32e} offset {off} f64 {f64e}"
        );
        // f64: 4·2(w+h)·2⁻⁵³·Σ|v| ≤ 2⁻¹³ for a 1×1 box; measured ≪ that.
        assert!(f64e <= 2f64.powi(-13) / ((k + 1) * (k + 1)) as f64);
        assert!(f64e < 1e-8, "f64 error {f64e}");
        // The offset table is at least 1000× better than plain f32 here.
        assert!(off * 1000.0 < f32e);
    }
}
