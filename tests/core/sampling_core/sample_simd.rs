//! The SIMD lookups (AVX-512, taken by untraced bilinear, trilinear and
//! footprint-assembly lookups on CPUs that have it) against the portable
//! code, bit for bit.
//!
//! A lookup with a tracing sink always runs the portable code (it reports
//! texels one by one), so `sample_slice` and `sample_slice_traced` on the
//! same queries compare the two paths. On a CPU without AVX-512 both run
//! the portable code and the comparison holds trivially; the test says
//! which it ran (`Sampler::uses_simd`).

use parvo::sample::{Query, Sampler, SamplerOptions, TexelCounter};
use parvo::texel::{ChannelType, ColorSpace, Format};
use parvo::{MipOptions, Wrap, WrapMode, mip};

use crate::common;
use common::Rng;

/// Random queries over a few periods, with edge, NaN, infinite, huge and
/// zero values mixed in.
fn queries(r: &mut Rng, n: usize) -> Vec<Query> {
    let odd = [
        0.0,
        -0.0,
        1.0,
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        1e30,
        -1e30,
        1e-30,
        1e6,
    ];
    (0..n)
        .map(|_| {
            let mut v = [
                r.f() * 3.0 - 1.0,
                r.f() * 3.0 - 1.0,
                (r.f() - 0.5) * 0.3,
                (r.f() - 0.5) * 0.05,
                (r.f() - 0.5) * 0.05,
                (r.f() - 0.5) * 0.2,
            ];
            // Grazing: one derivative vector much longer than the other.
            if r.next_u64().is_multiple_of(4) {
                v[2] *= 0.01;
                v[3] *= 0.01;
            }
            if r.next_u64().is_multiple_of(8) {
                let k = (r.next_u64() % 6) as usize;
                v[k] = odd[(r.next_u64() % odd.len() as u64) as usize];
            }
            Query::new(v[0], v[1], v[2], v[3], v[4], v[5])
        })
        .collect()
}

fn options() -> Vec<SamplerOptions> {
    let mut v = Vec::new();
    for base in [
        SamplerOptions::bilinear(),
        SamplerOptions::trilinear(),
        SamplerOptions::aniso(4),
        SamplerOptions::aniso(16),
        SamplerOptions {
            mip: parvo::sample::MipMode::Nearest,
            ..SamplerOptions::aniso(8)
        },
    ] {
        v.push(base);
        v.push(SamplerOptions {
            lod_bias: 0.75,
            lod_min: 0.5,
            lod_max: 3.0,
            wrap: Wrap {
                u: WrapMode::MirroredRepeat,
                v: WrapMode::ClampToBorder,
            },
            border: [0.25, 0.5, 0.75, 1.0],
            ..base
        });
        v.push(SamplerOptions {
            lod_bias: -1.5,
            wrap: Wrap {
                u: WrapMode::ClampToEdge,
                v: WrapMode::MirrorClampToEdge,
            },
            ..base
        });
        // Clamps that pin every lookup: below level 0 (magnification
        // only) and beyond the last level of every chain here.
        v.push(SamplerOptions {
            lod_min: -3.0,
            lod_max: -0.25,
            ..base
        });
        v.push(SamplerOptions {
            lod_min: 20.0,
            lod_max: 40.0,
            lod_bias: 2.5,
            ..base
        });
    }
    v
}

#[test]
fn simd_lookups_equal_the_portable_lookups_bit_for_bit() {
    let formats = [
        Format::new(4, ChannelType::U8, ColorSpace::Srgb),
        Format::new(4, ChannelType::U8, ColorSpace::Linear),
        Format::new(3, ChannelType::U8, ColorSpace::Srgb),
        Format::new(2, ChannelType::U8, ColorSpace::Srgb),
        Format::new(1, ChannelType::U8, ColorSpace::Linear),
        Format::new(4, ChannelType::F16, ColorSpace::Linear),
        Format::new(4, ChannelType::F32, ColorSpace::Linear),
    ];
    let mut r = Rng(0x51_3d);
    let mut simd_seen = false;
    for format in formats {
        for (w, h) in common::AWKWARD {
            let tex = common::random_texture(&mut r, w, h, format);
            let chain = mip::build(tex, &MipOptions::default()).unwrap();
            // 333 queries: not a multiple of the 8-query blocks.
            let qs = queries(&mut r, 333);
            for o in options() {
                let s = Sampler::new(&chain, o).unwrap();
                simd_seen |= s.uses_simd();
                let mut fast = vec![[0f32; 4]; qs.len()];
                let mut plain = vec![[0f32; 4]; qs.len()];
                s.sample_slice(&qs, &mut fast).unwrap();
                let mut sink = TexelCounter::default();
                s.sample_slice_traced(&qs, &mut plain, &mut sink).unwrap();
                for (i, (a, b)) in fast.iter().zip(&plain).enumerate() {
                    assert_eq!(
                        a.map(f32::to_bits),
                        b.map(f32::to_bits),
                        "{format:?} {w}x{h} {} query {:?}: {a:?} vs {b:?}",
                        o.name(),
                        qs[i]
                    );
                }
                // With the SIMD path forbidden, the portable one.
                let mut portable = s.clone();
                portable.set_simd(false);
                assert!(!portable.uses_simd());
                let mut off = vec![[0f32; 4]; qs.len()];
                portable.sample_slice(&qs, &mut off).unwrap();
                assert!(
                    off.iter()
                        .zip(&plain)
                        .all(|(a, b)| a.map(f32::to_bits) == b.map(f32::to_bits))
                );
                portable.set_simd(true);
                assert_eq!(portable.uses_simd(), s.uses_simd());
                // One query at a time takes the same path as a slice.
                for (q, want) in qs.iter().zip(&plain).step_by(37) {
                    assert_eq!(s.sample(q).map(f32::to_bits), want.map(f32::to_bits));
                }
            }
        }
    }
    eprintln!("SIMD path taken: {simd_seen}");
    #[cfg(target_arch = "x86_64")]
    if std::env::var_os("PARVO_NO_AVX").is_none()
        && std::arch::is_x86_feature_detected!("avx512f")
        && std::arch::is_x86_feature_detected!("avx512bw")
        && std::arch::is_x86_feature_detected!("avx512dq")
        && std::arch::is_x86_feature_detected!("avx512vl")
        && std::arch::is_x86_feature_detected!("avx512vbmi")
    {
        assert!(simd_seen, "the CPU has AVX-512 but no sampler used it");
    }
}

/// Queries for the nearest path: coordinates far outside [0, 1) (up to
/// ±1e5 periods, where `f64` positions still keep sub-texel bits), tiny
/// and huge derivatives (magnification and every level), and now and then
/// a NaN, infinite or huge field.
fn far_queries(r: &mut Rng, n: usize) -> Vec<Query> {
    let odd = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 1e30, -1e30, 0.0];
    (0..n)
        .map(|_| {
            let reach = [1.0, 30.0, 1e5][(r.next_u64() % 3) as usize];
            let scale = [1e-4, 0.01, 0.2, 3.0][(r.next_u64() % 4) as usize];
            let mut v = [
                (r.f() * 2.0 - 1.0) * reach,
                (r.f() * 2.0 - 1.0) * reach,
                (r.f() - 0.5) * scale,
                (r.f() - 0.5) * scale * 0.3,
                (r.f() - 0.5) * scale * 0.3,
                (r.f() - 0.5) * scale,
            ];
            if r.next_u64().is_multiple_of(16) {
                let k = (r.next_u64() % 6) as usize;
                v[k] = odd[(r.next_u64() % odd.len() as u64) as usize];
            }
            Query::new(v[0], v[1], v[2], v[3], v[4], v[5])
        })
        .collect()
}

/// Issue 31: the isotropic nearest lookups have a SIMD path (before it,
/// `nearest` ran the portable code and was slower than `bilinear`), and
/// it returns what the portable nearest returns, bit for bit: every
/// storage, every wrap mode on each axis, mip modes nearest and linear,
/// LOD clamps and biases, awkward sizes, coordinates far outside [0, 1),
/// slices that are not a multiple of the 16-query blocks.
#[test]
fn simd_nearest_equals_the_portable_nearest_bit_for_bit() {
    use parvo::sample::{MipMode, TexelFilter};
    let formats = [
        Format::new(4, ChannelType::U8, ColorSpace::Srgb),
        Format::new(4, ChannelType::U8, ColorSpace::Linear),
        Format::new(3, ChannelType::U8, ColorSpace::Srgb),
        Format::new(2, ChannelType::U8, ColorSpace::Linear),
        Format::new(1, ChannelType::U8, ColorSpace::Srgb),
        Format::new(4, ChannelType::U16, ColorSpace::Linear),
        Format::new(3, ChannelType::U16, ColorSpace::Srgb),
        Format::new(4, ChannelType::F16, ColorSpace::Linear),
        Format::new(2, ChannelType::F16, ColorSpace::Linear),
        Format::new(4, ChannelType::F32, ColorSpace::Linear),
        Format::new(3, ChannelType::F32, ColorSpace::Linear),
        Format::new(1, ChannelType::F32, ColorSpace::Linear),
    ];
    let modes = [
        WrapMode::Repeat,
        WrapMode::MirroredRepeat,
        WrapMode::ClampToEdge,
        WrapMode::ClampToBorder,
        WrapMode::MirrorClampToEdge,
    ];
    let mut r = Rng(0x0e_a5_31);
    let mut simd_seen = false;
    for format in formats {
        for (w, h) in common::AWKWARD.into_iter().chain([(64, 64), (100, 3)]) {
            let tex = common::random_texture(&mut r, w, h, format);
            let chain = mip::build(tex, &MipOptions::default()).unwrap();
            // 1001 queries: not a multiple of 16.
            let qs = far_queries(&mut r, 1001);
            for (k, (mip, (u, v))) in [MipMode::Nearest, MipMode::Linear]
                .into_iter()
                .flat_map(|m| modes.iter().flat_map(move |&u| modes.map(|v| (m, (u, v)))))
                .enumerate()
            {
                let o = SamplerOptions {
                    mag: TexelFilter::Nearest,
                    min: TexelFilter::Nearest,
                    mip,
                    wrap: Wrap { u, v },
                    border: [0.25, 0.5, 0.75, 1.0],
                    lod_bias: [0.0, 0.75, -1.5][k % 3],
                    lod_min: [-1000.0, 0.5, -3.0][k % 3],
                    lod_max: [1000.0, 3.0, 40.0][k % 3],
                    ..SamplerOptions::nearest()
                };
                let s = Sampler::new(&chain, o).unwrap();
                simd_seen |= s.uses_simd();
                let mut fast = vec![[0f32; 4]; qs.len()];
                let mut plain = vec![[0f32; 4]; qs.len()];
                s.sample_slice(&qs, &mut fast).unwrap();
                s.sample_slice_traced(&qs, &mut plain, &mut TexelCounter::default())
                    .unwrap();
                let mut portable = s.clone();
                portable.set_simd(false);
                let mut off = vec![[0f32; 4]; qs.len()];
                portable.sample_slice(&qs, &mut off).unwrap();
                for (i, ((a, b), c)) in fast.iter().zip(&plain).zip(&off).enumerate() {
                    assert_eq!(
                        a.map(f32::to_bits),
                        b.map(f32::to_bits),
                        "{format:?} {w}x{h} {} query {:?}: {a:?} vs {b:?}",
                        o.name(),
                        qs[i]
                    );
                    assert_eq!(b.map(f32::to_bits), c.map(f32::to_bits));
                }
            }
        }
    }
    eprintln!("SIMD nearest taken: {simd_seen}");
    #[cfg(target_arch = "x86_64")]
    if std::env::var_os("PARVO_NO_AVX").is_none()
        && std::arch::is_x86_feature_detected!("avx512f")
        && std::arch::is_x86_feature_detected!("avx512bw")
        && std::arch::is_x86_feature_detected!("avx512dq")
        && std::arch::is_x86_feature_detected!("avx512vl")
        && std::arch::is_x86_feature_detected!("avx512vbmi")
    {
        assert!(
            simd_seen,
            "the CPU has AVX-512 but no nearest sampler used it"
        );
    }
}
