//! Every accumulator against brute-force loops on random images of awkward
//! sizes (fixed seeds): exact integer sums, float sums within the table's
//! own error bound, and averages over fractional rectangles.

use parvo::sat::{self, AccumulatorKind, Rect};
use parvo::texel::{AlphaMode, ChannelType, ColorSpace, Format};
use parvo::{Texture, Wrap, WrapMode};

/// splitmix64: a fixed-seed generator written out so the tests need no
/// crate and never change their data.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

const SIZES: [(u32, u32); 7] = [(1, 1), (1, 9), (9, 1), (3, 5), (12, 19), (100, 300), (6, 1)];

fn random_texture(rng: &mut Rng, w: u32, h: u32, fmt: Format) -> Texture {
    let n = (w * h) as usize * fmt.channels as usize;
    match fmt.channel_type {
        ChannelType::U8 => {
            Texture::from_u8(w, h, fmt, (0..n).map(|_| rng.below(256) as u8).collect()).unwrap()
        }
        ChannelType::U16 => {
            Texture::from_u16(w, h, fmt, (0..n).map(|_| rng.below(65536) as u16).collect()).unwrap()
        }
        _ => Texture::from_f32(
            w,
            h,
            fmt,
            (0..n).map(|_| (rng.unit() * 4.0 - 1.0) as f32).collect(),
        )
        .unwrap(),
    }
}

/// Integer codes of texel (x, y), channel c.
fn code(tex: &Texture, x: u32, y: u32, c: usize) -> u64 {
    let i = (y as usize * tex.width() as usize + x as usize) * tex.channels() + c;
    match tex.texels() {
        parvo::Texels::U8(v) => v[i] as u64,
        parvo::Texels::U16(v) => v[i] as u64,
        _ => unreachable!(),
    }
}

fn kinds_for(fmt: &Format) -> Vec<AccumulatorKind> {
    if fmt.channel_type.is_float() || fmt.color_space == ColorSpace::Srgb {
        vec![
            AccumulatorKind::F32,
            AccumulatorKind::OffsetF32,
            AccumulatorKind::F64,
        ]
    } else {
        AccumulatorKind::ALL.to_vec()
    }
}

fn formats() -> Vec<Format> {
    let mut v = Vec::new();
    for ty in [ChannelType::U8, ChannelType::U16, ChannelType::F32] {
        for ch in 1..=4 {
            v.push(Format::new(ch, ty, ColorSpace::Linear).with_alpha(AlphaMode::Premultiplied));
        }
        v.push(Format::new(4, ty, ColorSpace::Linear));
        v.push(Format::new(2, ty, ColorSpace::Linear));
    }
    v.push(Format::new(4, ChannelType::U8, ColorSpace::Srgb));
    v
}

/// Brute-force area-weighted linear average under clamp to edge of a
/// fractional rectangle (inside the level), with straight alpha weighting.
fn brute_average(tex: &Texture, lin: &[f32], r: Rect) -> [f64; 4] {
    let ch = tex.channels();
    let fmt = tex.format();
    let straight = fmt.has_alpha() && fmt.alpha == AlphaMode::Straight;
    let a = ch - 1;
    let int = !fmt.channel_type.is_float() && fmt.color_space == ColorSpace::Linear;
    let mut sum = [0f64; 4];
    let mut area = 0.0;
    for j in r.y0.floor() as i64..r.y1.ceil() as i64 {
        let wy = (r.y1.min(j as f64 + 1.0) - r.y0.max(j as f64)).max(0.0);
        for i in r.x0.floor() as i64..r.x1.ceil() as i64 {
            let wx = (r.x1.min(i as f64 + 1.0) - r.x0.max(i as f64)).max(0.0);
            let wt = wx * wy;
            let (x, y) = (i as u32, j as u32);
            let val = |c: usize| {
                if int {
                    let max = if fmt.channel_type == ChannelType::U8 {
                        255.0
                    } else {
                        65535.0
                    };
                    code(tex, x, y, c) as f64 / max
                } else {
                    lin[(y as usize * tex.width() as usize + x as usize) * ch + c] as f64
                }
            };
            let al = if straight { val(a) } else { 1.0 };
            for (c, s) in sum.iter_mut().enumerate().take(ch) {
                *s += wt
                    * if straight && c != a {
                        val(c) * al
                    } else {
                        val(c)
                    };
            }
            area += wt;
        }
    }
    let mut out = [0.0; 4];
    for c in 0..ch {
        out[c] = if straight && c != a {
            if sum[a] > 0.0 { sum[c] / sum[a] } else { 0.0 }
        } else {
            sum[c] / area
        };
    }
    out
}

#[test]
fn integer_tables_equal_brute_force_sums_exactly() {
    let mut rng = Rng(0x5A7_0001);
    for fmt in formats().into_iter().filter(|f| !f.channel_type.is_float()) {
        if fmt.color_space == ColorSpace::Srgb {
            continue;
        }
        for (w, h) in SIZES {
            let tex = random_texture(&mut rng, w, h, fmt);
            for kind in [
                AccumulatorKind::U32,
                AccumulatorKind::U64,
                AccumulatorKind::U128,
            ] {
                let t = match sat::build(&tex, Some(kind)) {
                    Ok(t) => t,
                    Err(_) => {
                        // Only a too-narrow kind may refuse.
                        let need = sat::required_bits(sat::value_bits(&fmt), w, h);
                        assert!(need > kind.integer_bits().unwrap(), "{kind} {fmt} {w}x{h}");
                        continue;
                    }
                };
                let straight = fmt.has_alpha() && fmt.alpha == AlphaMode::Straight;
                let a = fmt.channels as usize - 1;
                for _ in 0..40 {
                    let (x0, x1) = {
                        let a = rng.below(w as u64 + 1) as u32;
                        let b = rng.below(w as u64 + 1) as u32;
                        (a.min(b), a.max(b))
                    };
                    let (y0, y1) = {
                        let a = rng.below(h as u64 + 1) as u32;
                        let b = rng.below(h as u64 + 1) as u32;
                        (a.min(b), a.max(b))
                    };
                    let mut want = [0u64; 4];
                    for y in y0..y1 {
                        for x in x0..x1 {
                            for (c, s) in want.iter_mut().enumerate().take(tex.channels()) {
                                *s += if straight && c != a {
                                    code(&tex, x, y, c) * code(&tex, x, y, a)
                                } else {
                                    code(&tex, x, y, c)
                                };
                            }
                        }
                    }
                    let got: [u64; 4] = match &t {
                        sat::AnySat::U32(t) => t.raw_sum(x0, y0, x1, y1).map(|v| v as u64),
                        sat::AnySat::U64(t) => t.raw_sum(x0, y0, x1, y1),
                        sat::AnySat::U128(t) => t.raw_sum(x0, y0, x1, y1).map(|v| v as u64),
                        _ => unreachable!(),
                    };
                    assert_eq!(got, want, "{kind} {fmt} {w}x{h} [{x0},{x1})x[{y0},{y1})");
                    let bs = t.sum_box(
                        Rect::texels(x0 as i64, y0 as i64, x1 as i64, y1 as i64),
                        Wrap::default(),
                    );
                    assert_eq!(bs.sum.map(|v| v as u64), want);
                }
            }
        }
    }
}

#[test]
fn float_tables_stay_within_their_error_bound() {
    let mut rng = Rng(0x5A7_0002);
    for fmt in formats() {
        for (w, h) in SIZES {
            let tex = random_texture(&mut rng, w, h, fmt);
            let lin = tex.to_linear();
            for kind in kinds_for(&fmt).into_iter().filter(|k| !k.is_integer()) {
                let t = sat::build(&tex, Some(kind)).unwrap();
                let bound = t.max_entry_error();
                for _ in 0..40 {
                    let x0 = rng.below(w as u64) as i64;
                    let y0 = rng.below(h as u64) as i64;
                    let x1 = x0 + 1 + rng.below((w as i64 - x0) as u64) as i64;
                    let y1 = y0 + 1 + rng.below((h as i64 - y0) as u64) as i64;
                    let r = Rect::texels(x0, y0, x1, y1);
                    // Reference: the same summands, summed in f64 by a loop.
                    let want = brute_average(&tex, &lin, r);
                    let got = t.sum_box(r, Wrap::default());
                    let area = ((x1 - x0) * (y1 - y0)) as f64;
                    let u = t.units().unit;
                    assert!((got.area - area).abs() < 1e-9);
                    let avg = t.average(r, Wrap::default(), [0.0; 4]);
                    for c in 0..tex.channels() {
                        // Average error ≤ 4·bound/area (+ f32 output rounding).
                        let tol = 4.0 * bound / (area * u) + 2e-6 * want[c].abs().max(1.0);
                        let a = tex.channels() - 1;
                        let tol = if fmt.has_alpha() && fmt.alpha == AlphaMode::Straight && c != a {
                            // Colour is divided by the covered alpha.
                            2.0 * tol / want[a].abs().max(1e-3)
                        } else {
                            tol
                        };
                        assert!(
                            (avg[c] as f64 - want[c]).abs() <= tol,
                            "{kind} {fmt} {w}x{h} {r:?} ch{c}: {} vs {} (tol {tol})",
                            avg[c],
                            want[c]
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn fractional_rectangles_weight_partial_texels_by_area() {
    let mut rng = Rng(0x5A7_0003);
    for fmt in formats() {
        for (w, h) in SIZES {
            let tex = random_texture(&mut rng, w, h, fmt);
            let lin = tex.to_linear();
            for kind in kinds_for(&fmt) {
                let Ok(t) = sat::build(&tex, Some(kind)) else {
                    continue;
                };
                for _ in 0..30 {
                    let (a, b) = (rng.unit() * w as f64, rng.unit() * w as f64);
                    let (c, d) = (rng.unit() * h as f64, rng.unit() * h as f64);
                    let r = Rect::new(a.min(b), c.min(d), a.max(b), c.max(d));
                    if r.area() < 1e-3 {
                        continue;
                    }
                    let want = brute_average(&tex, &lin, r);
                    for wrap in [WrapMode::ClampToEdge, WrapMode::Repeat] {
                        let got = t.average(r, Wrap::both(wrap), [0.0; 4]);
                        for ch in 0..tex.channels() {
                            let tol = 2e-6 * want[ch].abs().max(1.0)
                                + 8.0 * t.max_entry_error() / (r.area() * t.units().unit);
                            let a = tex.channels() - 1;
                            let tol =
                                if fmt.has_alpha() && fmt.alpha == AlphaMode::Straight && ch != a {
                                    2.0 * tol / want[a].abs().max(1e-3)
                                } else {
                                    tol
                                };
                            assert!(
                                (got[ch] as f64 - want[ch]).abs() <= tol,
                                "{kind} {fmt} {w}x{h} {r:?} ch{ch}: {} vs {}",
                                got[ch],
                                want[ch]
                            );
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn one_by_one_tables_hold_their_texel() {
    let fmt = Format::new(1, ChannelType::U8, ColorSpace::Linear);
    let tex = Texture::from_u8(1, 1, fmt, vec![200]).unwrap();
    for kind in AccumulatorKind::ALL {
        let t = sat::build(&tex, Some(kind)).unwrap();
        let avg = t.average(Rect::texels(0, 0, 1, 1), Wrap::default(), [0.0; 4]);
        assert!((avg[0] - 200.0 / 255.0).abs() < 1e-6, "{kind}");
        // Under repeat every rectangle of a 1x1 level is that texel.
        let avg = t.average(Rect::new(-3.3, 7.1, 12.9, 8.0), Wrap::default(), [0.0; 4]);
        assert!((avg[0] - 200.0 / 255.0).abs() < 1e-6, "{kind}");
        assert_eq!(t.memory_bytes(), 4 * kind.bytes());
    }
}
