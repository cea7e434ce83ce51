//! The sampler against SPEC.md, formula by formula. Each reference below is
//! written plainly from the spec text, not from the library's code.

use parvo::mip::{self, MipChain, level_size};
use parvo::sample::{
    Filter, MipMode, Query, Sampler, SamplerOptions, TexelCounter, TexelFilter, TexelRecorder,
    footprint, mip_linear, mip_nearest,
};
use parvo::texel::{ChannelType, ColorSpace, Format};
use parvo::{MipOptions, Texture, Wrap, WrapMode};

const RGBA32: Format = Format::new(4, ChannelType::F32, ColorSpace::Linear);

/// Small deterministic generator (xorshift64*), fixed seeds.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn f(&mut self) -> f32 {
        (self.next() >> 40) as f32 / (1u64 << 24) as f32
    }
}

fn texture(w: u32, h: u32, f: impl Fn(u32, u32) -> [f32; 4]) -> Texture {
    let mut v = Vec::with_capacity((w * h * 4) as usize);
    for y in 0..h {
        for x in 0..w {
            v.extend_from_slice(&f(x, y));
        }
    }
    Texture::from_f32(w, h, RGBA32, v).unwrap()
}

fn random_texture(w: u32, h: u32, seed: u64) -> Texture {
    let mut r = Rng(seed);
    let v: Vec<f32> = (0..w * h * 4).map(|_| r.f()).collect();
    Texture::from_f32(w, h, RGBA32, v).unwrap()
}

/// A chain whose level k is the constant k (all channels).
fn level_index_chain(w: u32, h: u32) -> MipChain {
    let n = mip::level_count(w, h, mip::Rounding::Down, None);
    let levels = (0..n)
        .map(|k| {
            let (lw, lh) = level_size(w, h, k, mip::Rounding::Down);
            texture(lw, lh, |_, _| [k as f32; 4])
        })
        .collect();
    MipChain::from_levels(levels, MipOptions::default()).unwrap()
}

fn single(t: Texture) -> MipChain {
    MipChain::from_levels(vec![t], MipOptions::default()).unwrap()
}

fn sampler(chain: &MipChain, o: SamplerOptions) -> Sampler {
    Sampler::new(chain, o).unwrap()
}

fn close(a: [f32; 4], b: [f32; 4], tol: f32) -> bool {
    a.iter().zip(&b).all(|(x, y)| (x - y).abs() <= tol)
}

fn texel(t: &Texture, x: u32, y: u32) -> [f32; 4] {
    t.texel_linear(x, y)
}

#[test]
fn nearest_and_bilinear_return_exact_texels_at_texel_centres() {
    for (w, h) in [(8, 4), (1, 16), (32, 1), (16, 16)] {
        let t = random_texture(w, h, 7 + w as u64);
        let chain = single(t.clone());
        let near = sampler(&chain, SamplerOptions::nearest());
        let bil = sampler(&chain, SamplerOptions::bilinear());
        for y in 0..h {
            for x in 0..w {
                let q = Query::point((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
                assert_eq!(
                    near.sample(&q),
                    texel(&t, x, y),
                    "nearest {w}x{h} ({x},{y})"
                );
                assert_eq!(
                    bil.sample(&q),
                    texel(&t, x, y),
                    "bilinear {w}x{h} ({x},{y})"
                );
            }
        }
    }
    // Awkward sizes: (i + 0.5)/w is not exact in f32, so allow rounding.
    for (w, h) in [(5, 3), (7, 13), (1, 1)] {
        let t = random_texture(w, h, 99);
        let bil = sampler(&single(t.clone()), SamplerOptions::bilinear());
        for y in 0..h {
            for x in 0..w {
                let q = Query::point((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
                assert!(
                    close(bil.sample(&q), texel(&t, x, y), 1e-5),
                    "{w}x{h} ({x},{y})"
                );
            }
        }
    }
}

/// SPEC "Texel filtering", linear: i0 = floor(u·w − 0.5), α = frac, ...,
/// with repeat wrapping, written out in f64.
fn reference_bilinear(t: &Texture, u: f64, v: f64) -> [f32; 4] {
    let (w, h) = (t.width() as i64, t.height() as i64);
    let x = u * w as f64 - 0.5;
    let y = v * h as f64 - 0.5;
    let (i0, j0) = (x.floor() as i64, y.floor() as i64);
    let (a, b) = (x - x.floor(), y - y.floor());
    let tx = |i: i64, j: i64| texel(t, i.rem_euclid(w) as u32, j.rem_euclid(h) as u32);
    let mut out = [0f32; 4];
    for (c, o) in out.iter_mut().enumerate() {
        let v = (1.0 - a) * (1.0 - b) * tx(i0, j0)[c] as f64
            + a * (1.0 - b) * tx(i0 + 1, j0)[c] as f64
            + (1.0 - a) * b * tx(i0, j0 + 1)[c] as f64
            + a * b * tx(i0 + 1, j0 + 1)[c] as f64;
        *o = v as f32;
    }
    out
}

#[test]
fn bilinear_matches_the_spec_formula_and_averages_at_midpoints() {
    for (w, h) in [(8, 8), (5, 3), (1, 7), (12, 19)] {
        let t = random_texture(w, h, 3 * w as u64 + h as u64);
        let bil = sampler(&single(t.clone()), SamplerOptions::bilinear());
        // Midpoints between texel centres: exact averages.
        for y in 0..h {
            for x in 0..w {
                let q = Query::point((x + 1) as f32 / w as f32, (y as f32 + 0.5) / h as f32);
                let (a, b) = (texel(&t, x, y), texel(&t, (x + 1) % w, y));
                let want = [0, 1, 2, 3].map(|c| 0.5 * (a[c] + b[c]));
                assert!(close(bil.sample(&q), want, 2e-6), "{w}x{h} ({x},{y})");
            }
        }
        let mut r = Rng(5);
        for _ in 0..500 {
            let (u, v) = (r.f() * 6.0 - 3.0, r.f() * 6.0 - 3.0);
            let got = bil.sample(&Query::point(u, v));
            assert!(
                close(got, reference_bilinear(&t, u as f64, v as f64), 2e-6),
                "{w}x{h} at ({u},{v})"
            );
        }
    }
}

#[test]
fn lod_selects_exact_level_at_power_of_two_footprints() {
    let (w, h) = (64, 64);
    let chain = level_index_chain(w, h);
    for k in 0..=6 {
        let d = (1u32 << k) as f32 / w as f32; // ρ = 2^k texels
        let q = Query::isotropic(0.4, 0.6, d);
        let fp = footprint(&q, w, h, &SamplerOptions::trilinear());
        assert_eq!(fp.lambda, k as f32);
        assert_eq!(
            (fp.rho_x, fp.rho_y, fp.eta),
            ((1u32 << k) as f64, (1u32 << k) as f64, 1.0)
        );
        for o in [
            SamplerOptions::bilinear(),
            SamplerOptions::trilinear(),
            SamplerOptions::nearest(),
        ] {
            let s = sampler(&chain, o);
            assert_eq!(s.sample(&q), [k as f32; 4], "{} at ρ = 2^{k}", o.name());
            let mut rec = TexelRecorder::new();
            s.sample_traced(&q, &mut rec);
            assert!(
                rec.reads.iter().all(|r| r.level == k),
                "{} reads {:?}",
                o.name(),
                rec.reads
            );
        }
    }
    // Beyond the chain: the last level.
    let q = Query::isotropic(0.4, 0.6, 1000.0);
    assert_eq!(
        sampler(&chain, SamplerOptions::trilinear()).sample(&q),
        [6.0; 4]
    );
}

#[test]
fn nearest_mip_picks_level_k_at_lambda_k_plus_half() {
    // The rule itself.
    assert_eq!(mip_nearest(0.5, 6), 0);
    assert_eq!(mip_nearest(0.500_001, 6), 1);
    assert_eq!(mip_nearest(1.5, 6), 1);
    assert_eq!(mip_nearest(1.499, 6), 1);
    assert_eq!(mip_nearest(2.0, 6), 2);
    assert_eq!(mip_nearest(2.51, 6), 3);
    assert_eq!(mip_nearest(100.0, 6), 6);
    for k in 0..6u32 {
        let lam = k as f32 + 0.5;
        // d = ceil(d' + 0.5) − 1
        assert_eq!(mip_nearest(lam, 6), ((lam + 0.5).ceil() - 1.0) as usize);
    }
    // Through the sampler: ρ = 2^k and a bias of exactly 0.5.
    let chain = level_index_chain(64, 64);
    for k in 0..6 {
        let q = Query::isotropic(0.3, 0.3, (1u32 << k) as f32 / 64.0);
        let at = |bias: f32| {
            let o = SamplerOptions {
                lod_bias: bias,
                ..SamplerOptions::bilinear()
            };
            sampler(&chain, o).sample(&q)[0]
        };
        assert_eq!(at(0.5), k as f32, "λ = {k}.5 picks level {k}");
        assert_eq!(at(0.5 + 1.0 / 64.0), (k + 1) as f32);
        assert_eq!(at(0.5 - 1.0 / 64.0), k as f32);
    }
}

#[test]
fn linear_mip_blends_the_two_levels_by_the_lod_fraction() {
    assert_eq!(mip_linear(2.25, 6), (2, 3, 0.25));
    assert_eq!(mip_linear(6.0, 6), (6, 6, 0.0));
    assert_eq!(mip_linear(9.0, 6), (6, 6, 0.0));
    let chain = level_index_chain(64, 64);
    for k in 0..6 {
        for delta in [0.125f32, 0.25, 0.5, 0.75, 0.875] {
            let q = Query::isotropic(0.7, 0.2, (1u32 << k) as f32 / 64.0);
            let o = SamplerOptions {
                lod_bias: delta,
                ..SamplerOptions::trilinear()
            };
            let got = sampler(&chain, o).sample(&q)[0];
            let want = (1.0 - delta) * k as f32 + delta * (k + 1) as f32;
            assert!(
                (got - want).abs() < 1e-6,
                "λ = {k} + {delta}: {got} vs {want}"
            );
        }
    }
}

#[test]
fn lod_clamp_and_magnification_threshold() {
    let chain = level_index_chain(64, 64);
    let q = Query::isotropic(0.5, 0.5, 16.0 / 64.0); // λ = 4
    let with = |o: SamplerOptions| sampler(&chain, o).sample(&q)[0];
    let t = SamplerOptions::trilinear();
    assert_eq!(with(SamplerOptions { lod_max: 2.0, ..t }), 2.0);
    assert_eq!(with(SamplerOptions { lod_min: 5.0, ..t }), 5.0);
    assert_eq!(
        with(SamplerOptions {
            lod_bias: -10.0,
            ..t
        }),
        0.0
    );
    // λ ≤ 0 uses the magnification filter: nearest mag reads 1 texel,
    // linear min is never used.
    let o = SamplerOptions {
        mag: TexelFilter::Nearest,
        ..t
    };
    let mut c = TexelCounter::default();
    sampler(&chain, o).sample_traced(&Query::isotropic(0.5, 0.5, 0.5 / 64.0), &mut c);
    assert_eq!(c.count, 1);
    // λ exactly 0 is magnification too.
    let mut c = TexelCounter::default();
    sampler(&chain, o).sample_traced(&Query::isotropic(0.5, 0.5, 1.0 / 64.0), &mut c);
    assert_eq!(c.count, 1);
    // mip none: minification on level 0 only.
    let o = SamplerOptions {
        mip: MipMode::None,
        ..t
    };
    assert_eq!(with(o), 0.0);
}

/// SPEC "Wrap modes", on integer texel indices.
fn reference_wrap(mode: WrapMode, i: i64, size: i64) -> Option<i64> {
    let mirror = |n: i64| if n >= 0 { n } else { -(1 + n) };
    let md = |a: i64, b: i64| ((a % b) + b) % b;
    match mode {
        WrapMode::Repeat => Some(md(i, size)),
        WrapMode::MirroredRepeat => Some((size - 1) - mirror(md(i, 2 * size) - size)),
        WrapMode::ClampToEdge => Some(i.clamp(0, size - 1)),
        WrapMode::ClampToBorder => (0..size).contains(&i).then_some(i),
        WrapMode::MirrorClampToEdge => Some(mirror(i).clamp(0, size - 1)),
    }
}

#[test]
fn every_wrap_mode_matches_the_spec_at_negative_and_large_coordinates() {
    let modes = WrapMode::ALL;
    let border = [0.25, 0.5, 0.75, 1.0];
    let (w, h) = (4u32, 2u32); // (i + 0.5)/4 is exact in f32 up to |i| ~ 2^21
    let t = random_texture(w, h, 11);
    for mu in modes {
        for mv in modes {
            let o = SamplerOptions {
                wrap: Wrap { u: mu, v: mv },
                border,
                ..SamplerOptions::nearest()
            };
            let s = sampler(&single(t.clone()), o);
            let is: Vec<i64> = (-13..13)
                .chain([-1_000_001, 999_999, 1 << 20, -(1 << 20)])
                .collect();
            for &i in &is {
                for &j in &[-5i64, -1, 0, 1, 2, 3, 7, 1 << 19, -(1 << 19) - 1] {
                    let q = Query::point((i as f32 + 0.5) / w as f32, (j as f32 + 0.5) / h as f32);
                    let want = match (
                        reference_wrap(mu, i, w as i64),
                        reference_wrap(mv, j, h as i64),
                    ) {
                        (Some(x), Some(y)) => texel(&t, x as u32, y as u32),
                        _ => border,
                    };
                    assert_eq!(s.sample(&q), want, "{mu},{mv} at texel ({i},{j})");
                }
            }
        }
    }
}

#[test]
fn repeat_keeps_subtexel_precision_at_u_one_million() {
    let t = random_texture(4, 4, 21);
    let s = sampler(&single(t.clone()), SamplerOptions::bilinear());
    // u = 1e6 + 0.125 is exact in f32; x = 4e6 + 0.5 is the centre of
    // texel 4e6 ≡ 0 (mod 4).
    let got = s.sample(&Query::point(1e6 + 0.125, 0.125));
    assert_eq!(got, texel(&t, 0, 0));
    // u = 1e6 + 0.25: x − 0.5 = 4e6 + 0.5, halfway between texels 0 and 1.
    let got = s.sample(&Query::point(1e6 + 0.25, 0.125));
    let (a, b) = (texel(&t, 0, 0), texel(&t, 1, 0));
    assert!(close(got, [0, 1, 2, 3].map(|c| 0.5 * (a[c] + b[c])), 1e-6));
    // Negative: u = −1e6 + 0.625 → x = −4e6 + 2.5 → texel 2.
    assert_eq!(
        s.sample(&Query::point(-1e6 + 0.625, 0.125)),
        texel(&t, 2, 0)
    );
}

#[test]
fn aniso_with_eta_one_equals_trilinear() {
    let t = random_texture(128, 128, 5);
    let chain = mip::build(t, &MipOptions::default()).unwrap();
    let tri = sampler(&chain, SamplerOptions::trilinear());
    let mut r = Rng(77);
    for n in [2, 4, 8, 16] {
        let an = sampler(&chain, SamplerOptions::aniso(n));
        for _ in 0..300 {
            let (u, v) = (r.f() * 3.0 - 1.0, r.f() * 3.0 - 1.0);
            let d = r.f() * 0.1;
            // Exactly equal lengths: (d, 0)/(0, d) and (d, d)/(−d, d).
            for q in [
                Query::new(u, v, d, 0.0, 0.0, d),
                Query::new(u, v, d, d, -d, d),
                Query::point(u, v),
            ] {
                assert_eq!(an.footprint(&q).probes, 1);
                assert_eq!(an.sample(&q), tri.sample(&q), "aniso{n} {q:?}");
            }
        }
    }
}

#[test]
fn probe_count_is_ceil_eta_capped_at_max_aniso_and_probes_sit_at_the_ext_positions() {
    let w = 1024u32;
    let t = random_texture(w, w, 9);
    let chain = single(t);
    for n in [1u32, 2, 3, 4, 7, 16] {
        let o = SamplerOptions {
            mag: TexelFilter::Nearest,
            min: TexelFilter::Nearest,
            mip: MipMode::None,
            ..SamplerOptions::aniso(n)
        };
        let s = sampler(&chain, o);
        for ratio in [1.0f32, 1.5, 2.0, 2.0001, 3.2, 5.0, 12.5, 16.0, 40.0] {
            // Major along y this time (ρy > ρx): 0.5 texel across, ratio·0.5 along.
            let minor = 0.5 / w as f32;
            let q = Query::new(0.31, 0.47, minor, 0.0, 0.0, minor * ratio);
            let fp = s.footprint(&q);
            let eta = (ratio as f64).min(n as f64);
            let want = eta.ceil() as u32;
            assert_eq!(fp.probes, want, "n={n} ratio={ratio}");
            // The longer vector; dx when the lengths tie (ρx ≥ ρy).
            let major = if ratio > 1.0 {
                [0.0, (minor * ratio) as f64]
            } else {
                [minor as f64, 0.0]
            };
            assert_eq!(fp.major, major);
            let mut rec = TexelRecorder::new();
            s.sample_traced(&q, &mut rec);
            assert_eq!(rec.reads.len() as u32, want);
            // Probe i at (u, v + (i/(N+1) − 1/2)·dvdy), nearest texel.
            for (i, r) in rec.reads.iter().enumerate() {
                let t = (i as f64 + 1.0) / (want as f64 + 1.0) - 0.5;
                let u = 0.31f32 as f64 + t * major[0];
                let v = 0.47f32 as f64 + t * major[1];
                let y = (v * w as f64).floor().rem_euclid(w as f64) as u32;
                let x = (u * w as f64).floor().rem_euclid(w as f64) as u32;
                assert_eq!((r.x, r.y), (x, y), "n={n} ratio={ratio} probe {i}");
            }
        }
    }
}

#[test]
fn anisotropic_footprint_follows_the_spec_formulas() {
    let o = SamplerOptions::aniso(8);
    let (w, h) = (256u32, 64u32);
    let q = Query::new(0.5, 0.5, 3.0 / 256.0, 4.0 / 64.0, -1.0 / 256.0, 0.5 / 64.0);
    let fp = footprint(&q, w, h, &o);
    let (rx, ry) = (5.0f64, (1.0f64 + 0.25).sqrt());
    assert!((fp.rho_x - rx).abs() < 1e-12 && (fp.rho_y - ry).abs() < 1e-12);
    let eta = (rx / ry).min(8.0);
    assert!((fp.eta - eta).abs() < 1e-12);
    assert!((fp.lambda as f64 - (rx / eta).log2()).abs() < 1e-6);
    assert_eq!(fp.probes, eta.ceil() as u32);
    // ρmin = 0 < ρmax: η = maxAniso; both 0: η = 1, magnification.
    let fp = footprint(&Query::new(0.5, 0.5, 0.1, 0.0, 0.0, 0.0), w, h, &o);
    assert_eq!((fp.eta, fp.probes), (8.0, 8));
    let fp = footprint(&Query::point(0.5, 0.5), w, h, &o);
    assert_eq!(fp.eta, 1.0);
    assert!(fp.lambda <= 0.0);
}

#[test]
fn ewa_of_a_constant_texture_is_the_constant() {
    for (w, h) in [(37, 23), (1, 1), (1, 9), (16, 1), (64, 64)] {
        let c = [0.3, 0.6, 0.9, 0.45];
        let t = texture(w, h, |_, _| c);
        let chain = mip::build(t, &MipOptions::default()).unwrap();
        let mut r = Rng(w as u64 * 31 + h as u64);
        for max_aniso in [1, 4, 16] {
            let o = SamplerOptions {
                max_aniso,
                ..SamplerOptions::ewa()
            };
            let s = sampler(&chain, o);
            for _ in 0..200 {
                let q = Query::new(
                    r.f() * 4.0 - 2.0,
                    r.f() * 4.0 - 2.0,
                    (r.f() - 0.5) * 0.5,
                    (r.f() - 0.5) * 0.05,
                    (r.f() - 0.5) * 0.02,
                    (r.f() - 0.5) * 0.5,
                );
                assert!(close(s.sample(&q), c, 1e-6), "{w}x{h} {q:?}");
            }
        }
    }
}

#[test]
fn every_filter_weights_sum_to_one() {
    // On a constant texture every filter returns the constant iff its
    // weights sum to 1 (borders read the same constant).
    // Every preset (aniso at 4 and 16), and anisotropy 2, 3 and 8 too.
    let presets: Vec<SamplerOptions> = crate::common::sampler_presets(16)
        .into_iter()
        .chain([2, 3, 8].map(SamplerOptions::aniso))
        .collect();
    for c in [1.0f32, 0.3, 7.25] {
        let cc = [c, c * 0.5, c * 0.25, c];
        let t = texture(24, 10, |_, _| cc);
        let chain = mip::build(t, &MipOptions::default()).unwrap();
        for base in &presets {
            for wrap in [
                WrapMode::Repeat,
                WrapMode::MirroredRepeat,
                WrapMode::ClampToBorder,
            ] {
                let o = SamplerOptions {
                    wrap: Wrap::both(wrap),
                    border: cc,
                    ..*base
                };
                let s = sampler(&chain, o);
                let mut r = Rng(3);
                for _ in 0..200 {
                    let q = Query::new(
                        r.f() * 3.0 - 1.0,
                        r.f() * 3.0 - 1.0,
                        (r.f() - 0.5) * 0.8,
                        (r.f() - 0.5) * 0.1,
                        (r.f() - 0.5) * 0.1,
                        (r.f() - 0.5) * 0.3,
                    );
                    let got = s.sample(&q);
                    assert!(
                        close(got, cc, 4e-6 * c),
                        "{} {wrap}: {got:?} {q:?}",
                        o.name()
                    );
                }
            }
        }
    }
}

#[test]
fn srgb_textures_are_decoded_to_linear_before_filtering() {
    // Codes 0 and 255 side by side: bilinear at the midpoint is the linear
    // average 0.5, which re-encodes to sRGB code 188 (SPEC "Colour").
    let f = Format::new(4, ChannelType::U8, ColorSpace::Srgb);
    let t = Texture::from_u8(2, 1, f, vec![0, 0, 0, 255, 255, 255, 255, 255]).unwrap();
    let s = sampler(&single(t), SamplerOptions::bilinear());
    let got = s.sample(&Query::point(0.5, 0.5));
    assert_eq!(got, [0.5, 0.5, 0.5, 1.0]);
    assert_eq!(parvo::texel::srgb::encode_u8(got[0]), 188);
}

#[test]
fn option_names_round_trip_and_bad_options_are_errors() {
    for f in Filter::ALL {
        assert_eq!(f.name().parse::<Filter>().unwrap(), f);
    }
    assert!("bogus".parse::<Filter>().is_err());
    assert_eq!(SamplerOptions::aniso(16).name(), "aniso16");
    assert_eq!(SamplerOptions::bilinear().name(), "bilinear");
    assert_eq!(SamplerOptions::nearest().name(), "nearest");
    assert_eq!(SamplerOptions::trilinear().name(), "trilinear");
    assert_eq!(SamplerOptions::ewa().name(), "ewa");
    assert_eq!(
        "linear".parse::<TexelFilter>().unwrap(),
        TexelFilter::Linear
    );
    assert_eq!("none".parse::<MipMode>().unwrap(), MipMode::None);
    let chain = single(random_texture(4, 4, 1));
    let bad = [
        SamplerOptions::aniso(0),
        SamplerOptions::aniso(17),
        SamplerOptions {
            lod_bias: f32::NAN,
            ..Default::default()
        },
        SamplerOptions {
            lod_min: 3.0,
            lod_max: 1.0,
            ..Default::default()
        },
        SamplerOptions {
            border: [f32::INFINITY, 0.0, 0.0, 0.0],
            ..Default::default()
        },
        SamplerOptions::supersample(0),
    ];
    for o in bad {
        assert!(Sampler::new(&chain, o).is_err(), "{o:?}");
    }
    // `sat` builds its table from level 0 as stored, which a prepared
    // chain keeps (`LinearChain::source`): the same sampler either way.
    let lin = std::sync::Arc::new(parvo::sample::LinearChain::new(&chain));
    let from_lin = Sampler::from_linear(lin, SamplerOptions::sat()).unwrap();
    let own = Sampler::new(&chain, SamplerOptions::sat()).unwrap();
    let q = Query::new(0.3, 0.6, 0.05, 0.01, -0.02, 0.04);
    assert_eq!(from_lin.sample(&q), own.sample(&q));
    // Options key caches: equal options hash equally.
    use std::collections::HashSet;
    let set: HashSet<SamplerOptions> = [
        SamplerOptions::aniso(4),
        SamplerOptions::aniso(4),
        SamplerOptions::ewa(),
    ]
    .into_iter()
    .collect();
    assert_eq!(set.len(), 2);
}

#[test]
fn ewa_matches_a_brute_force_scan_of_the_spec_formula() {
    // Level 0 only, anisotropy below the clamp: the ellipse is exactly
    // SPEC's A, B, C from the raw derivative vectors.
    let (w, h) = (32u32, 24u32);
    let t = random_texture(w, h, 17);
    let o = SamplerOptions {
        mip: MipMode::None,
        ..SamplerOptions::ewa()
    };
    let s = sampler(&single(t.clone()), o);
    let mut r = Rng(23);
    let mut checked = 0;
    while checked < 300 {
        let (s0, t0) = ((r.f() - 0.5) * 12.0, (r.f() - 0.5) * 12.0);
        let (s1, t1) = ((r.f() - 0.5) * 12.0, (r.f() - 0.5) * 12.0);
        // Singular values of [[s0, s1], [t0, t1]]: skip clamped ratios.
        let (a, b, c) = (s0 * s0 + s1 * s1, s0 * t0 + s1 * t1, t0 * t0 + t1 * t1);
        let root = (((a - c) * 0.5).powi(2) + b * b).sqrt();
        let (big, small) = ((a + c) * 0.5 + root, (a + c) * 0.5 - root);
        if small <= 0.0 || (big / small).sqrt() > 15.0 {
            continue;
        }
        checked += 1;
        let (u, v) = (r.f() * 2.0 - 0.5, r.f() * 2.0 - 0.5);
        let q = Query::new(
            u,
            v,
            s0 / w as f32,
            t0 / h as f32,
            s1 / w as f32,
            t1 / h as f32,
        );
        // The query's f32 derivatives, back in texels, in f64.
        let ds0 = q.dudx as f64 * w as f64;
        let dt0 = q.dvdx as f64 * h as f64;
        let ds1 = q.dudy as f64 * w as f64;
        let dt1 = q.dvdy as f64 * h as f64;
        let mut qa = dt0 * dt0 + dt1 * dt1 + 1.0;
        let mut qb = -2.0 * (ds0 * dt0 + ds1 * dt1);
        let mut qc = ds0 * ds0 + ds1 * ds1 + 1.0;
        let f = qa * qc - qb * qb / 4.0;
        qa /= f;
        qb /= f;
        qc /= f;
        let (sc, tc) = (u as f64 * w as f64 - 0.5, v as f64 * h as f64 - 0.5);
        let mut sum = [0f64; 4];
        let mut wsum = 0.0;
        for j in (tc as i64 - 30)..(tc as i64 + 30) {
            for i in (sc as i64 - 30)..(sc as i64 + 30) {
                let (ss, tt) = (i as f64 - sc, j as f64 - tc);
                let r2 = qa * ss * ss + qb * ss * tt + qc * tt * tt;
                if r2 < 1.0 {
                    let wt = (-2.0 * r2).exp() - (-2.0f64).exp();
                    let tx = texel(
                        &t,
                        i.rem_euclid(w as i64) as u32,
                        j.rem_euclid(h as i64) as u32,
                    );
                    for ch in 0..4 {
                        sum[ch] += wt * tx[ch] as f64;
                    }
                    wsum += wt;
                }
            }
        }
        let want = sum.map(|x| (x / wsum) as f32);
        assert!(
            close(s.sample(&q), want, 2e-5),
            "{q:?}: {:?} vs {want:?}",
            s.sample(&q)
        );
    }
}
