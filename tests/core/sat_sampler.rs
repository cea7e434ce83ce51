//! `SatSampler`: exact whole-texel averages on 16-bit 4096² input, the
//! documented behaviour at extremes, and the anisotropic variant against a
//! brute-force parallelogram average.

use parvo::sat::{AccumulatorKind, SatSampler};
use parvo::texel::{AlphaMode, ChannelType, ColorSpace, Format};
use parvo::wrap::wrap_index;
use parvo::{Texture, Wrap, WrapMode};

struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn unit(&mut self) -> f32 {
        (self.next() >> 40) as f32 / (1u64 << 24) as f32
    }
}

const MODES: [WrapMode; 5] = [
    WrapMode::Repeat,
    WrapMode::MirroredRepeat,
    WrapMode::ClampToEdge,
    WrapMode::ClampToBorder,
    WrapMode::MirrorClampToEdge,
];

#[test]
fn whole_texel_box_on_16bit_4096_squared_is_exact_to_f32_rounding() {
    let n = 4096u32;
    let mut rng = Rng(0x16B17);
    let codes: Vec<u16> = (0..n * n).map(|_| rng.next() as u16).collect();
    let fmt = Format::new(1, ChannelType::U16, ColorSpace::Linear);
    let tex = Texture::from_u16(n, n, fmt, codes.clone()).unwrap();
    let s = SatSampler::new(&tex, Wrap::default(), [0.0; 4]).unwrap();
    assert_eq!(s.table().kind(), AccumulatorKind::U64);
    let k = 1.0 / n as f32; // one texel in u or v, exact
    // (u, v, du/dx, dv/dy): centred, at the far corner, across the corner.
    for (u, v, du, dv) in [
        (0.5, 0.5, 1024.0 * k, 512.0 * k),
        (1.0 - 16.0 * k, 1.0 - 16.0 * k, 32.0 * k, 32.0 * k),
        (0.0, 1.0, 64.0 * k, 6.0 * k),
        (0.25, 0.75, 4096.0 * k, 4096.0 * k),
        (0.5 + 0.5 * k, 0.5 + 0.5 * k, 1.0 * k, 1.0 * k),
    ] {
        let got = s.sample(u, v, du, 0.0, 0.0, dv);
        // The box, in texels, and its exact integer sum by brute force.
        let (cx, cy) = (u as f64 * n as f64, v as f64 * n as f64);
        let (hx, hy) = (du as f64 * n as f64 / 2.0, dv as f64 * n as f64 / 2.0);
        let (x0, x1) = ((cx - hx) as i64, (cx + hx) as i64);
        let (y0, y1) = ((cy - hy) as i64, (cy + hy) as i64);
        assert_eq!(
            (x0 as f64, y0 as f64),
            (cx - hx, cy - hy),
            "box must be whole texels"
        );
        let mut sum = 0u64;
        for j in y0..y1 {
            let y = wrap_index(WrapMode::Repeat, j, n).unwrap() as usize;
            for i in x0..x1 {
                let x = wrap_index(WrapMode::Repeat, i, n).unwrap() as usize;
                sum += codes[y * n as usize + x] as u64;
            }
        }
        let count = ((x1 - x0) * (y1 - y0)) as u64;
        // One correctly rounded division, then the f32 rounding.
        let want = (sum as f64 / (count as f64 * 65535.0)) as f32;
        assert_eq!(got[0], want, "u={u} v={v}: sum {sum} over {count}");
        assert_eq!(got[3], 1.0);
        let exact = sum as f64 / (count as f64 * 65535.0);
        let ulp = f32::from_bits(got[0].to_bits() + 1) - got[0];
        assert!((got[0] as f64 - exact).abs() <= 0.5 * ulp as f64 * (1.0 + 1e-9));
    }
}

fn small_rgba() -> Texture {
    let mut rng = Rng(7);
    let v = (0..16 * 8 * 4).map(|_| (rng.next() >> 56) as u8).collect();
    let f =
        Format::new(4, ChannelType::U8, ColorSpace::Linear).with_alpha(AlphaMode::Premultiplied);
    Texture::from_u8(16, 8, f, v).unwrap()
}

#[test]
fn zero_area_footprints_return_the_texel_under_the_centre() {
    let tex = small_rgba();
    for mode in MODES {
        let s = SatSampler::new(&tex, Wrap::both(mode), [0.0; 4]).unwrap();
        for &(u, v) in &[(0.03f32, 0.9f32), (0.5, 0.5), (0.99, 0.01), (0.2, 0.6)] {
            let got = s.sample(u, v, 0.0, 0.0, 0.0, 0.0);
            let (x, y) = ((u * 16.0).floor() as u32, (v * 8.0).floor() as u32);
            let want = tex.texel_linear(x, y);
            for c in 0..4 {
                assert!((got[c] - want[c]).abs() < 1e-6, "{mode} ({u},{v})");
            }
        }
    }
    // A footprint that is a horizontal line averages along its row.
    let s = SatSampler::new(&tex, Wrap::default(), [0.0; 4]).unwrap();
    let got = s.sample(0.5, 0.3, 1.0, 0.0, 0.0, 0.0);
    let y = (0.3f32 * 8.0).floor() as u32;
    let mut want = [0f32; 4];
    for x in 0..16 {
        let t = tex.texel_linear(x, y);
        for c in 0..4 {
            want[c] += t[c] / 16.0;
        }
    }
    for c in 0..4 {
        assert!((got[c] - want[c]).abs() < 1e-5);
    }
}

#[test]
fn extreme_queries_are_defined_and_never_nan() {
    let tex = small_rgba();
    let vals = [
        0.0f32,
        -0.0,
        0.5,
        -1.5,
        1e-40,
        1e30,
        -1e30,
        1e6,
        f32::MAX,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NAN,
    ];
    for mu in MODES {
        for mv in [
            WrapMode::Repeat,
            WrapMode::ClampToBorder,
            WrapMode::MirrorClampToEdge,
        ] {
            let s = SatSampler::new(&tex, Wrap { u: mu, v: mv }, [0.1, 0.2, 0.3, 0.4]).unwrap();
            for &u in &vals {
                for &d in &vals {
                    for q in [
                        s.sample(u, 0.3, d, 0.0, 0.0, d),
                        s.sample(0.3, u, 0.0, d, d, 0.0),
                        s.sample(u, u, d, d, d, d),
                        s.sample_aniso(u, 0.3, d, 0.01, 0.0, 0.01, 8),
                    ] {
                        for c in q {
                            assert!(
                                c.is_finite() && (-1e-6..=1.0 + 1e-6).contains(&c),
                                "{mu},{mv} u={u} d={d}: {q:?}"
                            );
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn footprints_larger_than_the_texture_average_the_level_under_repeat() {
    let tex = small_rgba();
    let s = SatSampler::new(&tex, Wrap::default(), [0.0; 4]).unwrap();
    let mut whole = [0f64; 4];
    for y in 0..8 {
        for x in 0..16 {
            let t = tex.texel_linear(x, y);
            for c in 0..4 {
                whole[c] += t[c] as f64 / 128.0;
            }
        }
    }
    for d in [1e3f32, 1e6, 1e30, f32::INFINITY] {
        for u in [0.1f32, -7.3, 1e6] {
            let got = s.sample(u, 0.4, d, 0.0, 0.0, d);
            for c in 0..4 {
                assert!(
                    (got[c] as f64 - whole[c]).abs() < 1e-3,
                    "d={d} u={u}: {got:?} vs {whole:?}"
                );
            }
        }
    }
}

#[test]
fn coordinates_a_million_periods_away_sample_like_their_base() {
    let tex = small_rgba();
    let s = SatSampler::new(&tex, Wrap::default(), [0.0; 4]).unwrap();
    // Dyadic coordinates: u + 1e6 is exact in f32, so the results match.
    for (u, v) in [(0.3125f32, 0.625f32), (0.0625, 0.5)] {
        let base = s.sample(u, v, 0.125, 0.0, 0.0, 0.25);
        for k in [1e6f32, -1e6, 999_999.0] {
            let far = s.sample(u + k, v - k, 0.125, 0.0, 0.0, 0.25);
            assert_eq!(far, base, "k={k}");
        }
    }
}

#[test]
fn grey_expands_and_straight_alpha_weights_colour() {
    let g = Texture::from_u8(
        2,
        1,
        Format::new(1, ChannelType::U8, ColorSpace::Linear),
        vec![0, 255],
    )
    .unwrap();
    let s = SatSampler::new(&g, Wrap::default(), [0.0; 4]).unwrap();
    assert_eq!(s.sample(0.5, 0.5, 1.0, 0.0, 0.0, 1.0), [0.5, 0.5, 0.5, 1.0]);
    // Straight alpha: an opaque white texel beside a transparent black one
    // averages to white at half alpha (no dark fringe).
    let f = Format::new(2, ChannelType::U8, ColorSpace::Linear);
    let ga = Texture::from_u8(2, 1, f, vec![255, 255, 0, 0]).unwrap();
    let s = SatSampler::new(&ga, Wrap::default(), [0.0; 4]).unwrap();
    assert_eq!(s.sample(0.5, 0.5, 1.0, 0.0, 0.0, 1.0), [1.0, 1.0, 1.0, 0.5]);
    // sRGB data goes through linear light: codes 0 and 255 average to
    // linear 0.5 (code 188 when encoded), not to code 127.5.
    let f = Format::new(1, ChannelType::U8, ColorSpace::Srgb);
    let srgb = Texture::from_u8(2, 1, f, vec![0, 255]).unwrap();
    let s = SatSampler::new(&srgb, Wrap::default(), [0.0; 4]).unwrap();
    assert_eq!(s.table().kind(), AccumulatorKind::F64);
    assert_eq!(s.sample(0.5, 0.5, 1.0, 0.0, 0.0, 1.0)[0], 0.5);
}

/// Brute-force average over the footprint parallelogram: a dense grid of
/// points inside it, each reading the texel it falls in (repeat).
fn parallelogram_reference(tex: &Texture, lin: &[f32], q: [f32; 6]) -> f64 {
    let (w, h) = (tex.width() as f64, tex.height() as f64);
    let [u, v, dudx, dvdx, dudy, dvdy] = q.map(|x| x as f64);
    let n = 400;
    let mut sum = 0.0;
    for a in 0..n {
        for b in 0..n {
            let s = (a as f64 + 0.5) / n as f64 - 0.5;
            let t = (b as f64 + 0.5) / n as f64 - 0.5;
            let x = (u + s * dudx + t * dudy) * w;
            let y = (v + s * dvdx + t * dvdy) * h;
            let i = wrap_index(WrapMode::Repeat, x.floor() as i64, w as u32).unwrap();
            let j = wrap_index(WrapMode::Repeat, y.floor() as i64, h as u32).unwrap();
            sum += lin[j as usize * w as usize + i as usize] as f64;
        }
    }
    sum / (n * n) as f64
}

#[test]
fn anisotropic_slices_beat_one_box_on_diagonal_footprints() {
    // Diagonal stripes: what a thin diagonal footprint along them sees is
    // nearly constant, while its bounding box mixes every stripe.
    let n = 256u32;
    let v: Vec<u8> = (0..n * n)
        .map(|i| {
            let (x, y) = (i % n, i / n);
            if ((x + y) / 8) % 2 == 0 { 255 } else { 0 }
        })
        .collect();
    let tex =
        Texture::from_u8(n, n, Format::new(1, ChannelType::U8, ColorSpace::Linear), v).unwrap();
    let lin = tex.to_linear();
    let s = SatSampler::new(&tex, Wrap::default(), [0.0; 4]).unwrap();
    let mut rng = Rng(99);
    let (mut e1, mut e8) = (0.0, 0.0);
    let trials = 40;
    for _ in 0..trials {
        let (u, v) = (rng.unit(), rng.unit());
        // Major axis along the stripes (x = -y direction), 16:1.
        let len = 0.25 * (0.5 + rng.unit());
        let q = [u, v, len, -len, 0.04 * len, 0.04 * len];
        let want = parallelogram_reference(&tex, &lin, q);
        let one = s.sample(q[0], q[1], q[2], q[3], q[4], q[5])[0] as f64;
        let many = s.sample_aniso(q[0], q[1], q[2], q[3], q[4], q[5], 16)[0] as f64;
        e1 += (one - want).abs() / trials as f64;
        e8 += (many - want).abs() / trials as f64;
    }
    println!("mean abs error vs parallelogram: 1 box {e1:.4}, up to 16 slices {e8:.4}");
    assert!(e8 < 0.5 * e1, "aniso {e8} vs single {e1}");
}

#[test]
fn anisotropic_slices_of_an_axis_aligned_footprint_tile_its_box() {
    let tex = small_rgba();
    let s = SatSampler::new(&tex, Wrap::default(), [0.0; 4]).unwrap();
    for (dudx, dvdy) in [(0.5f32, 0.0625f32), (0.03, 0.4), (2.5, 0.01)] {
        let one = s.sample(0.3, 0.6, dudx, 0.0, 0.0, dvdy);
        let many = s.sample_aniso(0.3, 0.6, dudx, 0.0, 0.0, dvdy, 16);
        for c in 0..4 {
            assert!((one[c] - many[c]).abs() < 1e-5, "{one:?} vs {many:?}");
        }
    }
}
