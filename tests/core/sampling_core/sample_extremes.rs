//! Defined behaviour at the extremes (see the `parvo::sample` module docs):
//! NaN/Inf/huge coordinates and derivatives, zero and collinear
//! derivatives, footprints that only the 1×1 level can serve, tiny
//! textures, texels near the top of the f32 range.

use parvo::sample::ewa::MAX_RADIUS;
use parvo::sample::{
    LinearChain, MipMode, Query, Sampler, SamplerOptions, TexelCounter, TexelRecorder,
};
use parvo::texel::{ChannelType, ColorSpace, Format};
use parvo::{MipChain, MipOptions, Texture, Wrap, WrapMode, mip};

const RGBA32: Format = Format::new(4, ChannelType::F32, ColorSpace::Linear);

fn noise(w: u32, h: u32, seed: u64) -> Texture {
    let mut s = seed | 1;
    let v: Vec<f32> = (0..w * h * 4)
        .map(|_| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 40) as f32 / (1u64 << 24) as f32
        })
        .collect();
    Texture::from_f32(w, h, RGBA32, v).unwrap()
}

fn chain(t: Texture) -> MipChain {
    mip::build(t, &MipOptions::default()).unwrap()
}

use crate::common;

fn presets() -> Vec<SamplerOptions> {
    common::sampler_presets(16)
}

const HUGE: [f32; 5] = [1e30, -1e30, f32::MAX, f32::INFINITY, f32::NAN];

#[test]
fn huge_derivatives_read_only_the_coarsest_level_at_constant_cost() {
    for (w, h) in [(1024u32, 1024u32), (1024, 16), (3, 700)] {
        let c = chain(noise(w, h, 1));
        let last = (c.len() - 1) as u32;
        for o in presets() {
            if o.method == parvo::sample::Method::Supersample {
                continue; // level 0 by definition
            }
            let s = Sampler::new(&c, o).unwrap();
            for d in HUGE {
                for q in [
                    Query::new(0.3, 0.6, d, 0.0, 0.0, d),
                    Query::new(0.3, 0.6, d, d, 0.0, 1e-3),
                    Query::new(0.3, 0.6, 1e-3, 0.0, 0.0, d),
                ] {
                    let mut rec = TexelRecorder::new();
                    let got = s.sample_traced(&q, &mut rec);
                    assert!(got.iter().all(|x| x.is_finite()), "{} {q:?}", o.name());
                    assert!(
                        rec.reads.iter().all(|r| r.level == last),
                        "{} {q:?} read {:?}",
                        o.name(),
                        &rec.reads[..rec.reads.len().min(8)]
                    );
                    assert!(
                        rec.reads.len() <= 16 * 4,
                        "{} {q:?}: {}",
                        o.name(),
                        rec.reads.len()
                    );
                }
            }
        }
    }
}

#[test]
fn ewa_work_is_bounded_when_the_lod_clamp_forces_level_zero() {
    let c = chain(noise(2048, 2048, 2));
    let linear = std::sync::Arc::new(LinearChain::new(&c));
    let bound = {
        let r = MAX_RADIUS + 2.0;
        2 * (std::f64::consts::PI * r * r + 4.0 * r) as u64
    };
    for o in [
        SamplerOptions {
            lod_max: 0.0,
            ..SamplerOptions::ewa()
        },
        SamplerOptions {
            mip: MipMode::None,
            ..SamplerOptions::ewa()
        },
        SamplerOptions {
            lod_bias: -20.0,
            ..SamplerOptions::ewa()
        },
        SamplerOptions {
            wrap: Wrap::both(WrapMode::ClampToBorder),
            ..SamplerOptions::ewa()
        },
    ] {
        let s = Sampler::from_linear(linear.clone(), o).unwrap();
        for d in [1e30f32, 10.0, 1.0, f32::INFINITY] {
            for q in [
                Query::new(0.5, 0.5, d, 0.0, 0.0, d),
                Query::new(0.5, 0.5, d, d, -d, d),
                Query::new(0.5, 0.5, d, d, 2.0 * d, 2.0 * d), // collinear
                Query::new(0.5, 0.5, d, 0.0, 0.0, 0.0),       // one zero vector
            ] {
                let mut n = TexelCounter::default();
                let got = s.sample_traced(&q, &mut n);
                assert!(got.iter().all(|x| x.is_finite()));
                assert!(
                    n.count <= bound,
                    "{q:?} read {} texels (bound {bound})",
                    n.count
                );
            }
        }
    }
}

#[test]
fn zero_and_degenerate_derivative_pairs_are_finite_for_ewa_and_aniso() {
    let c = chain(noise(64, 48, 3));
    for o in [
        SamplerOptions::ewa(),
        SamplerOptions::aniso(16),
        SamplerOptions::aniso(2),
    ] {
        let s = Sampler::new(&c, o).unwrap();
        for a in [0.0f32, 1e-30, 1e-6, 0.01, 0.3, 5.0] {
            for q in [
                Query::new(0.2, 0.9, a, 0.0, 2.0 * a, 0.0),
                Query::new(0.2, 0.9, a, a, -a, -a),
                Query::new(0.2, 0.9, 0.0, a, 0.0, 0.0),
                Query::new(0.2, 0.9, 0.0, 0.0, 0.0, 0.0),
            ] {
                let got = s.sample(&q);
                assert!(
                    got.iter()
                        .all(|x| x.is_finite() && (-1e-6..=1.0 + 1e-6).contains(x)),
                    "{} {q:?} {got:?}",
                    o.name()
                );
            }
        }
    }
    // Collinear EWA: the minor axis is lengthened to major/max_aniso, so the
    // level follows log2(major/16), not log2(0).
    let lc = chain(noise(256, 256, 4));
    let s = Sampler::new(&lc, SamplerOptions::ewa()).unwrap();
    let d = 64.0 / 256.0; // 64 texels, major = 64·√5
    let mut rec = TexelRecorder::new();
    s.sample_traced(&Query::new(0.5, 0.5, d, 0.0, 2.0 * d, 0.0), &mut rec);
    let lam = (64.0f64 * 5f64.sqrt() / 16.0).log2(); // ≈ 3.16
    assert!(
        rec.reads
            .iter()
            .all(|r| r.level == lam.floor() as u32 || r.level == lam.floor() as u32 + 1)
    );
}

#[test]
fn nan_coordinates_read_as_zero_and_infinite_ones_are_finite() {
    let c = chain(noise(16, 8, 5));
    for o in presets() {
        let s = Sampler::new(&c, o).unwrap();
        let q = Query::new(0.0, 0.7, 0.01, 0.0, 0.0, 0.02);
        assert_eq!(s.sample(&q.at(f32::NAN, 0.7)), s.sample(&q), "{}", o.name());
        assert_eq!(
            s.sample(&q.at(0.0, f32::NAN)),
            s.sample(&q.at(0.0, 0.0)),
            "{}",
            o.name()
        );
        for u in [f32::INFINITY, f32::NEG_INFINITY, 1e30, -1e30, f32::MAX] {
            for w in [
                WrapMode::Repeat,
                WrapMode::MirroredRepeat,
                WrapMode::ClampToEdge,
                WrapMode::ClampToBorder,
                WrapMode::MirrorClampToEdge,
            ] {
                let s = Sampler::new(
                    &c,
                    SamplerOptions {
                        wrap: Wrap::both(w),
                        ..o
                    },
                )
                .unwrap();
                let got = s.sample(&q.at(u, -u));
                assert!(got.iter().all(|x| x.is_finite()), "{} {w} u={u}", o.name());
            }
        }
    }
}

#[test]
fn one_by_one_one_by_n_and_n_by_one_textures() {
    for (w, h) in [(1u32, 1u32), (1, 17), (17, 1), (1, 2), (2, 1)] {
        let t = noise(w, h, 6);
        let c = chain(t.clone());
        for o in presets() {
            let s = Sampler::new(&c, o).unwrap();
            for q in [
                Query::point(0.5, 0.5),
                Query::new(0.1, 0.9, 0.3, 0.0, 0.0, 0.001),
                Query::new(-7.3, 12.1, 1e30, 0.0, 0.0, 1e30),
                Query::new(0.5, 0.5, f32::NAN, 0.0, 0.0, 0.0),
            ] {
                let got = s.sample(&q);
                assert!(
                    got.iter()
                        .all(|x| x.is_finite() && (-1e-6..=1.0 + 1e-6).contains(x)),
                    "{w}x{h} {} {q:?}",
                    o.name()
                );
                if (w, h) == (1, 1) {
                    let want = t.texel_linear(0, 0);
                    assert!(
                        got.iter().zip(&want).all(|(a, b)| (a - b).abs() < 1e-6),
                        "1x1 {}",
                        o.name()
                    );
                }
            }
        }
    }
}

#[test]
fn texels_near_the_top_of_the_f32_range_never_give_nan_or_inf() {
    let v: Vec<f32> = (0..8 * 8 * 4)
        .map(|i| if i % 3 == 0 { 1e38 } else { -1e38 })
        .collect();
    let t = Texture::from_f32(8, 8, RGBA32, v).unwrap();
    // Build the chain from levels that keep the extreme values (box mips of
    // ±1e38 are fine in f32, but go through the library to be honest).
    let c = chain(t);
    for o in presets() {
        let s = Sampler::new(&c, o).unwrap();
        for q in [
            Query::new(0.37, 0.61, 0.2, 0.0, 0.0, 0.01),
            Query::new(0.37, 0.61, 0.0, 0.0, 0.0, 0.0),
            Query::new(0.37, 0.61, 1e30, 0.0, 0.0, 1e30),
        ] {
            let got = s.sample(&q);
            assert!(
                got.iter().all(|x| x.is_finite()),
                "{} {q:?} {got:?}",
                o.name()
            );
        }
    }
}

#[test]
fn every_storage_type_and_channel_count_samples_the_same_linear_values() {
    // The same linear image stored as u16/f16/f32 (1–4 channels) samples
    // to within the storage precision; sRGB u8 decodes before filtering.
    let base: Vec<f32> = (0..12 * 10)
        .map(|i| ((i * 37) % 101) as f32 / 100.0)
        .collect();
    let q = Query::new(0.33, 0.71, 0.13, 0.02, -0.01, 0.09);
    for ch in 1u8..=4 {
        let lin: Vec<f32> = base
            .iter()
            .flat_map(|&g| std::iter::repeat_n(g, ch as usize))
            .collect();
        let mut results = vec![];
        for ty in [ChannelType::U16, ChannelType::F16, ChannelType::F32] {
            let f = Format::new(ch, ty, ColorSpace::Linear);
            let t = Texture::from_linear(12, 10, f, &lin).unwrap();
            let s = Sampler::new(&chain(t), SamplerOptions::aniso(8)).unwrap();
            results.push(s.sample(&q));
        }
        for r in &results[1..] {
            assert!(
                r.iter().zip(&results[0]).all(|(a, b)| (a - b).abs() < 2e-3),
                "{ch} channels: {results:?}"
            );
        }
        // Grey replicated, missing alpha 1.
        let r = results[2];
        assert!((r[0] - r[1]).abs() < 1e-6 && (r[0] - r[2]).abs() < 1e-6);
        if ch == 1 || ch == 3 {
            assert_eq!(r[3], 1.0);
        }
    }
}

#[test]
fn batch_results_match_single_queries_in_order() {
    let c = chain(noise(100, 60, 8));
    let qs: Vec<Query> = (0..5000)
        .map(|i| {
            let t = i as f32 * 0.37;
            Query::new(
                t.sin() * 2.0,
                t.cos() * 3.0,
                0.01 * (t * 0.3).sin(),
                0.002,
                0.001,
                0.03 * (t * 0.7).cos(),
            )
        })
        .collect();
    for o in presets() {
        let s = Sampler::new(&c, o).unwrap();
        let mut par = vec![[0f32; 4]; qs.len()];
        let mut ser = vec![[0f32; 4]; qs.len()];
        s.sample_batch(&qs, &mut par).unwrap();
        s.sample_slice(&qs, &mut ser).unwrap();
        assert_eq!(par, ser, "{}", o.name());
        let mut traced = vec![[0f32; 4]; qs.len()];
        let sinks = s
            .sample_batch_traced(&qs, &mut traced, |_| TexelCounter::default())
            .unwrap();
        assert_eq!(traced, ser);
        let mut whole = TexelCounter::default();
        s.sample_slice_traced(&qs, &mut ser, &mut whole).unwrap();
        assert_eq!(sinks.iter().map(|(_, c)| c.count).sum::<u64>(), whole.count);
        assert!(sinks.windows(2).all(|w| w[0].0 < w[1].0));
        assert!(s.sample_batch(&qs, &mut par[1..]).is_err());
    }
}
