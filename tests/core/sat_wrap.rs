//! Rectangles crossing every edge and corner, under every wrap mode,
//! against brute force over the wrapped texels; many periods at constant
//! cost.

use parvo::sat::{self, AccumulatorKind, Rect};
use parvo::texel::{ChannelType, ColorSpace, Format};
use parvo::wrap::wrap_index;
use parvo::{Texture, Wrap, WrapMode};

const MODES: [WrapMode; 5] = [
    WrapMode::Repeat,
    WrapMode::MirroredRepeat,
    WrapMode::ClampToEdge,
    WrapMode::ClampToBorder,
    WrapMode::MirrorClampToEdge,
];

const BORDER: [f32; 4] = [0.25, 0.5, 0.75, 1.0];

fn texture(w: u32, h: u32) -> Texture {
    let mut s = 0x1234_5678u32;
    let v = (0..w * h * 3)
        .map(|_| {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            (s >> 8) as u16
        })
        .collect();
    Texture::from_u16(
        w,
        h,
        Format::new(3, ChannelType::U16, ColorSpace::Linear),
        v,
    )
    .unwrap()
}

/// Area-weighted average over the wrapped plane, texel by texel.
fn brute(tex: &Texture, r: Rect, wrap: Wrap) -> [f64; 3] {
    let lin = tex.to_linear();
    let (w, h) = (tex.width(), tex.height());
    let mut sum = [0f64; 3];
    let mut area = 0.0;
    for j in r.y0.floor() as i64..r.y1.ceil() as i64 {
        let wy = r.y1.min(j as f64 + 1.0) - r.y0.max(j as f64);
        for i in r.x0.floor() as i64..r.x1.ceil() as i64 {
            let wx = r.x1.min(i as f64 + 1.0) - r.x0.max(i as f64);
            let t = match (wrap_index(wrap.u, i, w), wrap_index(wrap.v, j, h)) {
                (Some(x), Some(y)) => {
                    let k = (y as usize * w as usize + x as usize) * 3;
                    [lin[k] as f64, lin[k + 1] as f64, lin[k + 2] as f64]
                }
                _ => [BORDER[0] as f64, BORDER[1] as f64, BORDER[2] as f64],
            };
            for c in 0..3 {
                sum[c] += wx * wy * t[c];
            }
            area += wx * wy;
        }
    }
    sum.map(|s| s / area)
}

#[test]
fn queries_wrapping_every_edge_and_corner_match_brute_force() {
    let (w, h) = (5u32, 7u32);
    let tex = texture(w, h);
    let tables = [
        sat::build(&tex, None).unwrap(),
        sat::build(&tex, Some(AccumulatorKind::F64)).unwrap(),
        sat::build(&tex, Some(AccumulatorKind::OffsetF32)).unwrap(),
    ];
    // Centres on every corner and edge midpoint, and outside them.
    let xs = [0.0, 2.5, 5.0, -1.25, 6.5];
    let ys = [0.0, 3.5, 7.0, -2.75, 9.0];
    // Half sizes: inside one texel, across one edge, more than a period.
    let halves = [
        (0.3, 0.4),
        (1.0, 1.0),
        (1.75, 2.25),
        (6.0, 8.5),
        (13.2, 3.0),
    ];
    for mu in MODES {
        for mv in MODES {
            let wrap = Wrap { u: mu, v: mv };
            for &cx in &xs {
                for &cy in &ys {
                    for &(hx, hy) in &halves {
                        let r = Rect::new(cx - hx, cy - hy, cx + hx, cy + hy);
                        let want = brute(&tex, r, wrap);
                        for t in &tables {
                            let got = t.average(r, wrap, BORDER);
                            for c in 0..3 {
                                assert!(
                                    (got[c] as f64 - want[c]).abs() < 2e-6,
                                    "{} {wrap} {r:?} ch{c}: {} vs {}",
                                    t.kind(),
                                    got[c],
                                    want[c]
                                );
                            }
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn whole_texel_wrapped_rectangles_are_exact_in_integer_tables() {
    let tex = texture(5, 7);
    let sat::AnySat::U32(t) = sat::build(&tex, None).unwrap() else {
        panic!("16-bit 5x7 needs 22 bits: u32")
    };
    let code = |x: u32, y: u32, c: usize| match tex.texels() {
        parvo::Texels::U16(v) => v[(y as usize * 5 + x as usize) * 3 + c] as f64,
        _ => unreachable!(),
    };
    for mode in MODES.into_iter().filter(|&m| m != WrapMode::ClampToBorder) {
        let wrap = Wrap::both(mode);
        for (x0, y0, x1, y1) in [
            (-3, -4, 2, 1),
            (3, 5, 12, 16),
            (-11, 2, -6, 30),
            (0, 0, 5, 7),
        ] {
            let s = t.sum_box(Rect::texels(x0, y0, x1, y1), wrap);
            let mut want = [0f64; 3];
            for j in y0..y1 {
                for i in x0..x1 {
                    let (x, y) = (
                        wrap_index(mode, i, 5).unwrap(),
                        wrap_index(mode, j, 7).unwrap(),
                    );
                    for (c, w) in want.iter_mut().enumerate() {
                        *w += code(x, y, c);
                    }
                }
            }
            assert_eq!(&s.sum[..3], &want, "{mode} ({x0},{y0})-({x1},{y1})");
            assert_eq!(s.error, 0.0);
        }
    }
}

#[test]
fn a_million_periods_cost_what_one_does_and_average_the_level() {
    let tex = texture(5, 7);
    let t = sat::build(&tex, None).unwrap();
    let whole = t.average(Rect::texels(0, 0, 5, 7), Wrap::default(), BORDER);
    // 1e6 whole periods plus a partial one on each axis.
    let big = Rect::new(-2.5e6, -3.5e6, 2.5e6 + 2.5, 3.5e6 + 3.25);
    let got = t.sum_box(big, Wrap::default());
    // Columns: 1e6 periods + 2.5 texels; rows: 1e6 periods + 3.25 texels.
    assert!((got.area - (5e6 + 2.5) * (7e6 + 3.25)).abs() < 1.0);
    let avg = t.average(big, Wrap::default(), BORDER);
    for c in 0..3 {
        assert!(
            (avg[c] - whole[c]).abs() < 1e-5,
            "{} vs {}",
            avg[c],
            whole[c]
        );
    }
    // Mirrored repeat averages the level over whole double periods too.
    let avg = t.average(big, Wrap::both(WrapMode::MirroredRepeat), BORDER);
    for c in 0..3 {
        assert!((avg[c] - whole[c]).abs() < 1e-5);
    }
}

#[test]
fn clamp_to_border_far_away_reads_only_the_border() {
    let tex = texture(5, 7);
    let t = sat::build(&tex, None).unwrap();
    let avg = t.average(
        Rect::new(100.0, 100.0, 120.5, 130.0),
        Wrap::both(WrapMode::ClampToBorder),
        BORDER,
    );
    assert_eq!(&avg[..3], &BORDER[..3]);
    // A huge box centred on the level tends to the border colour.
    let avg = t.average(
        Rect::new(-1e12, -1e12, 1e12, 1e12),
        Wrap::both(WrapMode::ClampToBorder),
        BORDER,
    );
    for c in 0..3 {
        assert!((avg[c] - BORDER[c]).abs() < 1e-6);
    }
}
