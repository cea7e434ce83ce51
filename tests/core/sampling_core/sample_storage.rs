//! The samplers' fast paths against their general ones: every storage
//! (1–4 channels of u8, u16, f16 and f32, decoded at fetch) against the
//! same levels widened to RGBA `f32` up front, and its memory; lookups
//! inside a level against the same lookups whole wrap periods away, and
//! the logarithm-free nearest-mip rule against SPEC's λ rule.

use std::sync::Arc;

use half::f16;
use parvo::mip::MipChain;
use parvo::sample::{
    LinearChain, MipMode, Query, Sampler, SamplerOptions, TexelFilter, TexelRecorder, footprint,
    mip_nearest,
};
use parvo::texel::{AlphaMode, ChannelType, ColorSpace, Format, Texels};
use parvo::{MipOptions, Texture, Wrap, WrapMode, mip};

use crate::common;
use common::Rng;

fn presets() -> Vec<SamplerOptions> {
    let mut v = common::sampler_presets(8);
    v.push(SamplerOptions {
        mag: TexelFilter::Nearest,
        mip: MipMode::None,
        ..SamplerOptions::trilinear()
    });
    v
}

fn query(r: &mut Rng) -> Query {
    let d = |r: &mut Rng, s: f32| (r.f() - 0.5) * s;
    Query::new(
        r.f() * 3.0 - 1.0,
        r.f() * 3.0 - 1.0,
        d(r, 0.3),
        d(r, 0.05),
        d(r, 0.05),
        d(r, 0.2),
    )
}

/// Every storage the samplers read: 1–4 channels of each type, linear and
/// sRGB, and for 2 and 4 channels with the last one as data (sRGB there
/// too) rather than alpha.
fn storage_formats() -> Vec<Format> {
    let mut v = Vec::new();
    for ty in [
        ChannelType::U8,
        ChannelType::U16,
        ChannelType::F16,
        ChannelType::F32,
    ] {
        for ch in 1u8..=4 {
            for cs in [ColorSpace::Linear, ColorSpace::Srgb] {
                v.push(Format::new(ch, ty, cs));
                if ch % 2 == 0 {
                    v.push(Format::new(ch, ty, cs).with_alpha(AlphaMode::None));
                }
            }
        }
    }
    v
}

/// A random `w × h` texture of `f`: any code for the integer types; for
/// `f16` any finite code (subnormals, negatives and 65504 included), for
/// `f32` values in [−1, 4).
fn random_level(r: &mut Rng, w: u32, h: u32, f: Format) -> Texture {
    let n = (w * h) as usize * f.channels as usize;
    let texels = match f.channel_type {
        ChannelType::U8 => Texels::U8((0..n).map(|_| r.next_u64() as u8).collect()),
        ChannelType::U16 => Texels::U16((0..n).map(|_| r.next_u64() as u16).collect()),
        ChannelType::F16 => Texels::F16(
            (0..n)
                .map(|_| {
                    loop {
                        let h = f16::from_bits(r.next_u64() as u16);
                        if h.is_finite() {
                            break h;
                        }
                    }
                })
                .collect(),
        ),
        ChannelType::F32 => Texels::F32((0..n).map(|_| r.f() * 5.0 - 1.0).collect()),
    };
    Texture::from_texels(w, h, f, texels).unwrap()
}

/// A chain of random levels of `f` (random at every level, so every level
/// holds every kind of value).
fn random_chain(r: &mut Rng, w: u32, h: u32, f: Format) -> MipChain {
    let n = mip::level_count(w, h, mip::Rounding::Down, None);
    let levels = (0..n)
        .map(|k| {
            let (lw, lh) = mip::level_size(w, h, k, mip::Rounding::Down);
            random_level(r, lw, lh, f)
        })
        .collect();
    MipChain::from_levels(levels, MipOptions::default()).unwrap()
}

/// `chain` widened to RGBA `f32` linear light by the texture functions
/// alone (`Texture::texel_linear`: decode, then grey replicated and
/// missing alpha 1): what every storage must sample like.
fn widened(chain: &MipChain) -> MipChain {
    let rgba = Format::new(4, ChannelType::F32, ColorSpace::Linear).with_alpha(AlphaMode::None);
    let levels = chain
        .levels()
        .iter()
        .map(|t| {
            let mut v = Vec::new();
            for y in 0..t.height() {
                for x in 0..t.width() {
                    v.extend(t.texel_linear(x, y));
                }
            }
            Texture::from_f32(t.width(), t.height(), rgba, v).unwrap()
        })
        .collect();
    MipChain::from_levels(levels, *chain.options()).unwrap()
}

/// The per-chain decode table of an 8-bit chain (6 KiB): the one part of
/// a prepared chain that does not scale with the texels.
fn table_bytes(f: &Format) -> usize {
    if f.channel_type == ChannelType::U8 {
        6144
    } else {
        0
    }
}

fn stored_bytes(c: &MipChain) -> usize {
    c.levels().iter().map(|t| t.byte_len()).sum()
}

#[test]
fn every_storage_samples_like_the_chain_widened_to_rgba_f32() {
    let modes = [
        WrapMode::Repeat,
        WrapMode::MirroredRepeat,
        WrapMode::ClampToEdge,
        WrapMode::ClampToBorder,
    ];
    for (n, f) in storage_formats().into_iter().enumerate() {
        let mut r = Rng(1000 + n as u64);
        let chain = random_chain(&mut r, 37, 23, f);
        let wide = widened(&chain);
        for base in presets() {
            let exact = base.mag == TexelFilter::Nearest && base.min == TexelFilter::Nearest;
            for (i, &m) in modes.iter().enumerate() {
                let o = SamplerOptions {
                    wrap: Wrap {
                        u: m,
                        v: modes[(i + 1) % modes.len()],
                    },
                    border: [0.1, 0.2, 0.3, 0.4],
                    ..base
                };
                let a = Sampler::new(&chain, o).unwrap();
                let b = Sampler::new(&wide, o).unwrap();
                // The AVX-512 path (where the CPU has it) and the portable
                // one give the same bits on every storage.
                let mut portable = a.clone();
                portable.set_simd(false);
                let stored = stored_bytes(&chain);
                let prepared = a.chain().memory_bytes();
                assert!(
                    prepared as f64 <= 1.1 * stored as f64 + table_bytes(&f) as f64,
                    "{f}: {prepared} prepared bytes for {stored} stored"
                );
                let qs: Vec<Query> = (0..40).map(|_| query(&mut r)).collect();
                let mut simd = vec![[0f32; 4]; qs.len()];
                let mut plain = vec![[0f32; 4]; qs.len()];
                a.sample_slice(&qs, &mut simd).unwrap();
                portable.sample_slice(&qs, &mut plain).unwrap();
                if o.method != parvo::sample::Method::Ewa {
                    let bits = |v: &[[f32; 4]]| -> Vec<[u32; 4]> {
                        v.iter().map(|c| c.map(f32::to_bits)).collect()
                    };
                    assert_eq!(bits(&simd), bits(&plain), "{f} {}", o.name());
                }
                for (&q, &x) in qs.iter().zip(&simd) {
                    let y = b.sample(&q);
                    let close = |p: f32, q: f32| {
                        if exact {
                            p.to_bits() == q.to_bits()
                        } else {
                            (p - q).abs() <= 1e-6 * q.abs().max(1.0)
                        }
                    };
                    assert!(
                        x.iter().zip(&y).all(|(p, q)| close(*p, *q)),
                        "{f} {} {m}: {x:?} vs {y:?} at {q:?}",
                        o.name()
                    );
                }
            }
        }
        // Every texel of every level, as `load` returns it.
        let (a, b) = (
            Sampler::new(&chain, SamplerOptions::nearest()).unwrap(),
            Sampler::new(&wide, SamplerOptions::nearest()).unwrap(),
        );
        for (k, t) in chain.levels().iter().enumerate() {
            for y in 0..t.height() as i64 {
                for x in 0..t.width() as i64 {
                    let (p, q) = (a.load(x, y, k as u32), b.load(x, y, k as u32));
                    assert_eq!(
                        p.map(|v| v.map(f32::to_bits)),
                        q.map(|v| v.map(f32::to_bits))
                    );
                }
            }
        }
    }
}

#[test]
fn prepared_chains_stay_within_a_tenth_of_the_stored_bytes() {
    for (n, f) in storage_formats().into_iter().enumerate() {
        let mut r = Rng(2000 + n as u64);
        // 384 × 256: the smallest chain (1-channel u8) is 131,069 bytes,
        // so the 6 KiB table of 8-bit chains fits in the tenth.
        let chain = random_chain(&mut r, 384, 256, f);
        let stored = stored_bytes(&chain);
        let s = Sampler::new(&chain, SamplerOptions::trilinear()).unwrap();
        let prepared = s.chain().memory_bytes();
        assert!(
            prepared as f64 <= 1.1 * stored as f64,
            "{f}: {prepared} prepared bytes for {stored} stored"
        );
        assert_eq!(prepared, stored + table_bytes(&f), "{f}");
    }
}

#[test]
fn shared_samplers_read_the_callers_chain_without_a_copy() {
    for (n, f) in storage_formats().into_iter().enumerate() {
        let mut r = Rng(3000 + n as u64);
        let chain = Arc::new(random_chain(&mut r, 37, 23, f));
        let copied = Sampler::new(&chain, SamplerOptions::trilinear()).unwrap();
        let s = Sampler::shared(chain.clone(), SamplerOptions::trilinear()).unwrap();
        assert!(Arc::ptr_eq(s.chain().source(), &chain), "{f}");
        // Only the decode table is added; sRGB f32 is decoded to a copy.
        let srgb_float = f.channel_type == ChannelType::F32 && f.color_space == ColorSpace::Srgb;
        let added = s.chain().added_bytes();
        if srgb_float {
            assert_eq!(added, stored_bytes(&chain), "{f}");
        } else {
            assert_eq!(added, table_bytes(&f), "{f}");
        }
        for _ in 0..50 {
            let q = query(&mut r);
            assert_eq!(s.sample(&q), copied.sample(&q), "{f} {q:?}");
        }
    }
}

#[test]
fn sat_and_mip_samplers_share_one_prepared_chain_and_table() {
    let f = Format::new(3, ChannelType::U16, ColorSpace::Srgb);
    let mut r = Rng(77);
    let chain = Arc::new(random_chain(&mut r, 61, 40, f));
    let lin = Arc::new(LinearChain::shared(chain.clone()));
    let mip = Sampler::from_linear(lin.clone(), SamplerOptions::trilinear()).unwrap();
    // The table built from the shared chain's level 0 …
    let sat = Sampler::from_linear(lin.clone(), SamplerOptions::sat()).unwrap();
    assert!(Arc::ptr_eq(mip.chain(), sat.chain()));
    // … is the one `Sampler::new` builds from the chain.
    let own = Sampler::new(&chain, SamplerOptions::sat()).unwrap();
    // A built table is shared as it is.
    let table = Arc::new(
        parvo::sat::SatSampler::new(chain.level(0).unwrap(), Wrap::default(), [0.0; 4]).unwrap(),
    );
    let shared =
        Sampler::from_linear_with_sat(lin.clone(), SamplerOptions::sat(), table.clone()).unwrap();
    assert!(std::ptr::eq(shared.sat().unwrap(), &*table));
    assert!(Arc::ptr_eq(shared.chain(), &lin));
    for _ in 0..200 {
        let q = query(&mut r);
        let want = own.sample(&q);
        assert_eq!(sat.sample(&q), want, "{q:?}");
        assert_eq!(shared.sample(&q), want, "{q:?}");
    }
    // The mip sampler's answers do not depend on the sat sampler's.
    let alone = Sampler::new(&chain, SamplerOptions::trilinear()).unwrap();
    let q = query(&mut r);
    assert_eq!(mip.sample(&q), alone.sample(&q));
}

#[test]
fn lookups_whole_wrap_periods_apart_are_identical() {
    // u = m/64 + k is exact in f32 for |k| < 2^17, so the texel-space
    // positions differ by whole periods exactly: the in-level fast path and
    // the wrapping path must give the same bits.
    let f = Format::new(4, ChannelType::U8, ColorSpace::Srgb);
    let mut r = Rng(41);
    let v: Vec<u8> = (0..64 * 32 * 4).map(|_| r.next_u64() as u8).collect();
    let chain = mip::build(
        Texture::from_u8(64, 32, f, v).unwrap(),
        &MipOptions::default(),
    )
    .unwrap();
    for (mode, period) in [(WrapMode::Repeat, 1i32), (WrapMode::MirroredRepeat, 2)] {
        for base in presets() {
            let o = SamplerOptions {
                wrap: Wrap::both(mode),
                ..base
            };
            let s = Sampler::new(&chain, o).unwrap();
            for _ in 0..200 {
                let (m, n) = ((r.next_u64() % 64) as f32, (r.next_u64() % 64) as f32);
                let q = query(&mut r).at(m / 64.0, n / 64.0);
                let mut want_reads = TexelRecorder::new();
                let want = s.sample_traced(&q, &mut want_reads);
                for k in [-1000, -3, -1, 1, 2, 7, 12345] {
                    let k = (k * period) as f32;
                    let moved = q.at(q.u + k, q.v - k);
                    let mut reads = TexelRecorder::new();
                    let got = s.sample_traced(&moved, &mut reads);
                    assert_eq!(got, want, "{} {mode} {q:?} moved by {k}", o.name());
                    assert_eq!(reads.reads, want_reads.reads, "{} {mode}", o.name());
                }
            }
        }
    }
}

#[test]
fn nearest_mip_level_matches_the_lambda_rule_for_random_footprints() {
    // SPEC: λ = clamp(log2(ρmax) + bias), d = ceil(clamp(λ, 0, q) + 0.5) − 1,
    // magnification when λ ≤ 0. The sampler picks the level without a
    // logarithm; away from the rounding thresholds it must agree.
    let (w, h) = (512u32, 128u32);
    let n = mip::level_count(w, h, mip::Rounding::Down, None) as usize;
    let levels: Vec<Texture> = (0..n)
        .map(|k| {
            let (lw, lh) = mip::level_size(w, h, k as u32, mip::Rounding::Down);
            let f = Format::new(1, ChannelType::F32, ColorSpace::Linear);
            Texture::from_f32(lw, lh, f, vec![k as f32; (lw * lh) as usize]).unwrap()
        })
        .collect();
    let chain = MipChain::from_levels(levels, MipOptions::default()).unwrap();
    let mut r = Rng(5);
    let mut checked = 0;
    for _ in 0..4000 {
        let bias = [0.0, 0.5, -1.25, 2.0, (r.f() - 0.5) * 6.0][(r.next_u64() % 5) as usize];
        let (lod_min, lod_max) = match r.next_u64() % 3 {
            0 => (-1000.0, 1000.0),
            1 => (1.5, 3.0),
            _ => (-2.0, 0.75),
        };
        let o = SamplerOptions {
            lod_bias: bias,
            lod_min,
            lod_max,
            ..SamplerOptions::nearest()
        };
        let s = Sampler::new(&chain, o).unwrap();
        // Derivative lengths from 2^-4 to 2^12 texels.
        let len = 2f32.powf(r.f() * 16.0 - 4.0);
        let ang = r.f() * std::f32::consts::TAU;
        let q = Query::new(
            0.37,
            0.61,
            len * ang.cos() / w as f32,
            len * ang.sin() / h as f32,
            -0.3 * len * ang.sin() / w as f32,
            0.3 * len * ang.cos() / h as f32,
        );
        let lambda = footprint(&q, w, h, &o).lambda;
        let frac = (lambda - lambda.floor() - 0.5).abs();
        if lambda.abs() < 1e-4 || frac < 1e-4 {
            continue; // on a threshold: either side is a correct rounding
        }
        let want = if lambda <= 0.0 {
            0
        } else {
            mip_nearest(lambda, n - 1)
        };
        let mut rec = TexelRecorder::new();
        let got = s.sample_traced(&q, &mut rec)[0];
        assert_eq!(got, want as f32, "λ = {lambda}, bias {bias}");
        assert!(rec.reads.iter().all(|t| t.level as usize == want));
        checked += 1;
    }
    assert!(checked > 3500, "{checked}");
}

/// The storage formats of the README's prepared-bytes table: every channel
/// count of every type, 8-bit as sRGB (what images hold), the others
/// linear, plus the sRGB 16-bit and float cases.
fn table_formats() -> Vec<Format> {
    let mut v = Vec::new();
    for (ty, cs) in [
        (ChannelType::U8, ColorSpace::Srgb),
        (ChannelType::U16, ColorSpace::Linear),
        (ChannelType::F16, ColorSpace::Linear),
        (ChannelType::F32, ColorSpace::Linear),
    ] {
        for ch in 1..=4 {
            v.push(Format::new(ch, ty, cs));
        }
    }
    for ty in [ChannelType::U16, ChannelType::F16, ChannelType::F32] {
        v.push(Format::new(4, ty, ColorSpace::Srgb));
    }
    v
}

/// A smooth 1024² texture with noise in `f`, and its full box chain.
fn rate_chain(f: Format) -> MipChain {
    let n = 1024u32;
    let ch = f.channels as usize;
    let mut r = Rng(7);
    let mut lin = Vec::with_capacity((n * n) as usize * ch);
    for y in 0..n {
        for x in 0..n {
            for c in 0..ch {
                let s = ((x as f32 * 0.013 + c as f32).sin() * (y as f32 * 0.021).cos()) * 0.4;
                lin.push((0.5 + s + (r.f() - 0.5) * 0.1).clamp(0.0, 1.0));
            }
        }
    }
    let t = Texture::from_linear(n, n, f, &lin).unwrap();
    mip::build(t, &MipOptions::default()).unwrap()
}

/// The benchmark's `incache` queries at 1024²: a 200×200 block minified
/// by 1.2 and rotated by 10°.
fn rate_queries() -> Vec<Query> {
    let s = 1.2 / 1024.0;
    let (sn, cs) = 10f64.to_radians().sin_cos();
    let mut v = Vec::new();
    for py in 0..200 {
        for px in 0..200 {
            let (x, y) = (px as f64, py as f64);
            let u = 0.3 + (x * cs - y * sn) * s;
            let w = 0.3 + (x * sn + y * cs) * s;
            let d = [cs * s, sn * s, -sn * s, cs * s].map(|x| x as f32);
            v.push(Query::new(u as f32, w as f32, d[0], d[1], d[2], d[3]));
        }
    }
    v
}

/// Best of five runs of `f` over `n` queries, in millions per second.
fn mqps(n: usize, mut f: impl FnMut()) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let t = std::time::Instant::now();
        let mut reps = 0;
        while t.elapsed().as_secs_f64() < 0.15 {
            f();
            reps += 1;
        }
        best = best.min(t.elapsed().as_secs_f64() / reps as f64);
    }
    n as f64 / best / 1e6
}

/// The README table: prepared bytes per storage format and the one-thread
/// slice rate of bilinear and trilinear lookups. A measurement, run on
/// demand: `cargo test --release --test core -- --ignored
/// --nocapture storage_table`. It asserts what the table claims: the
/// prepared chain is at most 1.1× the stored one.
#[test]
#[ignore]
fn storage_table() {
    let qs = rate_queries();
    let mut out = vec![[0f32; 4]; qs.len()];
    println!("| format | stored bytes | prepared bytes | ratio | bilinear Mq/s | trilinear Mq/s |");
    println!("|---|---:|---:|---:|---:|---:|");
    for f in table_formats() {
        let chain = rate_chain(f);
        let stored: usize = chain.levels().iter().map(|t| t.byte_len()).sum();
        let lin = Arc::new(parvo::sample::LinearChain::new(&chain));
        let prepared = lin.memory_bytes();
        let mut rates = Vec::new();
        for o in [SamplerOptions::bilinear(), SamplerOptions::trilinear()] {
            let s = Sampler::from_linear(lin.clone(), o).unwrap();
            rates.push(mqps(qs.len(), || s.sample_slice(&qs, &mut out).unwrap()));
        }
        println!(
            "| {} {} {}ch | {stored} | {prepared} | {:.2} | {:.1} | {:.1} |",
            f.channel_type,
            f.color_space,
            f.channels,
            prepared as f64 / stored as f64,
            rates[0],
            rates[1]
        );
    }
}
