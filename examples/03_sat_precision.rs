//! How wrong is each float summed-area table? Prints the markdown table
//! in the README: the largest absolute error of box averages for small
//! boxes near the far corner of a 4096² random image (where the entries
//! are largest and the subtraction cancels most), per float accumulator.
//!
//! ```text
//! cargo run --release --example 03_sat_precision
//! ```
//!
//! The image is one channel of f32 values uniform in [0, 1) with full
//! mantissas (fixed seed). The reference sums each box's texels in f64 by
//! a loop (error below 1e-15).

use parvo::sat::{self, AccumulatorKind, Rect};
use parvo::texel::{ChannelType, ColorSpace, Format};
use parvo::{Texture, Wrap};

const N: u32 = 4096;
/// Boxes whose corner lies in the last `REGION × REGION` texels.
const REGION: u32 = 64;
const SIZES: [u32; 4] = [1, 2, 3, 4];

fn main() -> parvo::Result<()> {
    let mut s = 0x05EE_D5A7_u64;
    let values: Vec<f32> = (0..N * N)
        .map(|_| {
            // splitmix64
            s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = s;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^= z >> 31;
            ((z >> 11) as f64 / (1u64 << 53) as f64) as f32
        })
        .collect();
    let fmt = Format::new(1, ChannelType::F32, ColorSpace::Linear);
    let tex = Texture::from_f32(N, N, fmt, values.clone())?;
    println!(
        "Max abs error of box averages, boxes with a corner in the last {REGION}x{REGION} texels \
         of a {N}x{N} random image (values in [0, 1)):\n"
    );
    print!("| accumulator | bytes/entry |");
    for k in SIZES {
        print!(" {k}x{k} |");
    }
    println!(" 1x1 near origin | bound, 1x1 |");
    print!("|---|---|");
    for _ in SIZES {
        print!("---|");
    }
    println!("---|---|");
    for kind in [
        AccumulatorKind::F32,
        AccumulatorKind::OffsetF32,
        AccumulatorKind::F64,
    ] {
        let t = sat::build(&tex, Some(kind))?;
        let query = |r: Rect| {
            let s = t.sum_box(r, Wrap::default());
            s.sum[0] / s.area
        };
        print!("| {kind} | {} |", kind.bytes());
        for k in SIZES {
            print!(" {:.2e} |", max_error(&query, &values, k, N - REGION));
        }
        print!(" {:.2e} |", max_error(&query, &values, 1, 0));
        println!(" {:.2e} |", 4.0 * t.max_entry_error());
    }
    // For contrast: an f32 table summed in f32 (the plain two-pass prefix
    // sum), which adds the rounding of every running sum to the storage
    // rounding parvo's f32 table has.
    let w = N as usize + 1;
    let mut plain = vec![0f32; w * w];
    for y in 0..N as usize {
        for x in 0..N as usize {
            plain[(y + 1) * w + x + 1] = plain[(y + 1) * w + x] + values[y * N as usize + x];
        }
    }
    for y in 1..w {
        for x in 0..w {
            plain[y * w + x] += plain[(y - 1) * w + x];
        }
    }
    let query = |r: Rect| {
        let (x0, y0, x1, y1) = (r.x0 as usize, r.y0 as usize, r.x1 as usize, r.y1 as usize);
        let e = |x: usize, y: usize| plain[y * w + x] as f64;
        (e(x1, y1) - e(x0, y1) - e(x1, y0) + e(x0, y0)) / r.area()
    };
    print!("| f32, summed in f32 (plain) | 4 |");
    for k in SIZES {
        print!(" {:.2e} |", max_error(&query, &values, k, N - REGION));
    }
    println!(" {:.2e} | |", max_error(&query, &values, 1, 0));
    Ok(())
}

/// Largest |error| of the box average over k×k boxes whose corner lies in
/// `[start, start + REGION)²`.
fn max_error(query: &dyn Fn(Rect) -> f64, values: &[f32], k: u32, start: u32) -> f64 {
    let mut worst = 0f64;
    for y0 in start..=start + REGION - k {
        for x0 in start..=start + REGION - k {
            let mut want = 0f64;
            for y in y0..y0 + k {
                for x in x0..x0 + k {
                    want += values[(y * N + x) as usize] as f64;
                }
            }
            want /= (k * k) as f64;
            let r = Rect::texels(x0 as i64, y0 as i64, (x0 + k) as i64, (y0 + k) as i64);
            // The error of the table, before the f32 rounding of a result.
            let got = query(r);
            worst = worst.max((got - want).abs());
        }
    }
    worst
}
