//! Summed-area tables of a small texture of arbitrary size, channels,
//! type and texels, with every accumulator kind, queried with rectangles
//! of arbitrary f64 bit patterns (NaN, infinities, huge, swapped) under
//! every wrap mode: building either succeeds or refuses, a query never
//! panics, and on ordinary rectangles (finite, within a few periods, at
//! least a quarter texel in area) the average equals brute force over the
//! wrapped texels.
//!
//! The body of `fuzz/fuzz_targets/sat.rs`, shared with the replay test
//! (`tests/core/fuzz_replay.rs` or `tests/cli/fuzz_replay.rs`), which runs it
//! over `fuzz/seeds/sat` and every kept artifact in the checks-on test build.

use parvo::sat::{self, AccumulatorKind, Rect};
use parvo::texel::{ChannelType, ColorSpace, Format};
use parvo::texture::Texture;
use parvo::wrap::wrap_index;
use parvo::{Wrap, WrapMode};

const BORDER: [f32; 4] = [0.25, 0.5, 0.75, 1.0];

/// Area-weighted average over the wrapped plane, texel by texel (the
/// first `ch` channels of the linear texels).
fn brute(lin: &[f32], w: u32, h: u32, ch: usize, r: Rect, wrap: Wrap) -> [f64; 4] {
    let mut sum = [0f64; 4];
    let mut area = 0.0;
    for j in r.y0.floor() as i64..r.y1.ceil() as i64 {
        let wy = r.y1.min(j as f64 + 1.0) - r.y0.max(j as f64);
        for i in r.x0.floor() as i64..r.x1.ceil() as i64 {
            let wx = r.x1.min(i as f64 + 1.0) - r.x0.max(i as f64);
            for c in 0..ch {
                let t = match (wrap_index(wrap.u, i, w), wrap_index(wrap.v, j, h)) {
                    (Some(x), Some(y)) => lin[(y as usize * w as usize + x as usize) * ch + c],
                    _ => BORDER[c],
                };
                sum[c] += wx * wy * t as f64;
            }
            area += wx * wy;
        }
    }
    sum.map(|s| s / area)
}

/// One input of the `sat` target: any outcome but a panic (or a failed
/// assertion below) is a pass.
pub fn run(data: &[u8]) {
    if data.len() < 8 {
        return;
    }
    let (w, h) = (1 + data[0] as u32 % 20, 1 + data[1] as u32 % 20);
    // Grey or RGB: no alpha, so the table sums the values
    // themselves and brute force needs no premultiplication.
    let ch = if data[2] & 1 == 0 { 1 } else { 3 };
    let cs = if data[3] & 1 == 1 {
        ColorSpace::Srgb
    } else {
        ColorSpace::Linear
    };
    let wide = data[3] & 2 == 2;
    let kinds = AccumulatorKind::ALL;
    let kind = (data[4] as usize % (kinds.len() + 1))
        .checked_sub(1)
        .map(|k| kinds[k]);
    let modes = WrapMode::ALL;
    let wrap = Wrap {
        u: modes[data[5] as usize % modes.len()],
        v: modes[data[6] as usize % modes.len()],
    };
    let n = (w * h * ch as u32) as usize;
    let body = &data[8..];
    let tex = if wide {
        if body.len() < 2 * n {
            return;
        }
        let v = body[..2 * n]
            .chunks_exact(2)
            .map(|b| u16::from_le_bytes([b[0], b[1]]))
            .collect();
        Texture::from_u16(w, h, Format::new(ch, ChannelType::U16, cs), v)
    } else {
        if body.len() < n {
            return;
        }
        Texture::from_u8(
            w,
            h,
            Format::new(ch, ChannelType::U8, cs),
            body[..n].to_vec(),
        )
    };
    let Ok(tex) = tex else { return };
    let Ok(table) = sat::build(&tex, kind) else {
        return;
    };
    let lin = tex.to_linear();
    let rest = &body[if wide { 2 * n } else { n }..];
    for r in rest.chunks_exact(32).take(16) {
        let e = |k: usize| f64::from_le_bytes(r[8 * k..8 * k + 8].try_into().unwrap());
        let rect = Rect::new(e(0), e(1), e(2), e(3));
        let got = table.average(rect, wrap, BORDER);
        let s = rect.sanitized();
        let ordinary = [rect.x0, rect.y0, rect.x1, rect.y1]
            .iter()
            .all(|v| v.is_finite() && v.abs() < 64.0)
            && s.area() >= 0.25;
        if !ordinary {
            continue;
        }
        let want = brute(&lin, w, h, ch as usize, s, wrap);
        // Integer and f64 tables are exact up to the final division; f32
        // tables lose about 2⁻²⁴ of the largest sum they hold.
        let tol = if matches!(
            kind,
            Some(AccumulatorKind::F32 | AccumulatorKind::OffsetF32)
        ) || table.kind() == AccumulatorKind::F32
            || table.kind() == AccumulatorKind::OffsetF32
        {
            2e-3
        } else {
            1e-5
        };
        for c in 0..ch as usize {
            assert!(
                (got[c] as f64 - want[c]).abs() <= tol,
                "{} {wrap} {rect:?} ch{c}: {} vs brute force {}",
                table.kind(),
                got[c],
                want[c]
            );
        }
    }
}
