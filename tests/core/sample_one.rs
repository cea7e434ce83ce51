//! The one-query and quad calls a rasterizer makes (`Sampler::sample`,
//! `sample_quad`, `sample_bias`) against the batch path on the same
//! queries: they take their own monomorphised paths (`sample/one.rs`),
//! and must return what `sample_slice` returns, bit for bit, for every
//! preset, storage, wrap mode and coordinates far outside [0, 1).

use parvo::sample::{Query, Sampler, SamplerOptions, quad_queries};
use parvo::texel::{ChannelType, ColorSpace, Format};
use parvo::{MipOptions, Wrap, WrapMode, mip};

use crate::common;
use common::Rng;

fn bits(c: &[f32; 4]) -> [u32; 4] {
    c.map(f32::to_bits)
}

/// Quads of a tiled plane: corners anywhere in ±40 periods (and a few
/// beyond 2^20), pixel steps from magnifying to strongly minifying and
/// anisotropic.
fn quads(r: &mut Rng, n: usize) -> Vec<[[f32; 2]; 4]> {
    (0..n)
        .map(|i| {
            let span = if i % 17 == 0 { 3.0e6 } else { 80.0 };
            let (u, v) = ((r.f() - 0.5) * span, (r.f() - 0.5) * span);
            let s = 10f32.powf(-4.0 + 3.0 * r.f());
            let dx = [s * (r.f() - 0.5), s * (r.f() - 0.5) * 0.2];
            let dy = [s * (r.f() - 0.5) * 0.3, s * (r.f() - 0.5) * 4.0];
            [
                [u, v],
                [u + dx[0], v + dx[1]],
                [u + dy[0], v + dy[1]],
                [u + dx[0] + dy[0], v + dx[1] + dy[1]],
            ]
        })
        .collect()
}

fn options() -> Vec<SamplerOptions> {
    let mut v = Vec::new();
    for base in common::sampler_presets(8) {
        v.push(base);
        v.push(SamplerOptions {
            wrap: Wrap {
                u: WrapMode::MirroredRepeat,
                v: WrapMode::ClampToBorder,
            },
            border: [0.25, 0.5, 0.75, 1.0],
            lod_bias: 0.5,
            ..base
        });
        v.push(SamplerOptions {
            mag: parvo::sample::TexelFilter::Nearest,
            wrap: Wrap {
                u: WrapMode::ClampToEdge,
                v: WrapMode::MirrorClampToEdge,
            },
            ..base
        });
    }
    v
}

#[test]
fn single_and_quad_calls_equal_the_batch_path_bit_for_bit() {
    let formats = [
        Format::new(4, ChannelType::U8, ColorSpace::Srgb),
        Format::new(1, ChannelType::U8, ColorSpace::Linear),
        Format::new(3, ChannelType::F16, ColorSpace::Linear),
        Format::new(4, ChannelType::F32, ColorSpace::Linear),
    ];
    let mut r = Rng(0x0e_51);
    for format in formats {
        for (w, h) in [(37, 23), (1, 9), (64, 64)] {
            let tex = common::random_texture(&mut r, w, h, format);
            let chain = mip::build(tex, &MipOptions::default()).unwrap();
            let qs4 = quads(&mut r, 150);
            let flat: Vec<Query> = qs4.iter().flat_map(quad_queries).collect();
            for o in options() {
                let s = Sampler::new(&chain, o).unwrap();
                let mut all = vec![[0f32; 4]; flat.len()];
                s.sample_slice(&flat, &mut all).unwrap();
                let name = o.name();
                for (i, (q, want)) in flat.iter().zip(&all).enumerate() {
                    assert_eq!(
                        bits(&s.sample(q)),
                        bits(want),
                        "{format:?} {w}x{h} {name}: sample({q:?})"
                    );
                    if i % 4 == 0 {
                        let quad = s.sample_quad(&qs4[i / 4]);
                        for k in 0..4 {
                            assert_eq!(
                                bits(&quad[k]),
                                bits(&all[i + k]),
                                "{format:?} {w}x{h} {name}: sample_quad({:?})[{k}]",
                                qs4[i / 4]
                            );
                        }
                    }
                }
            }
        }
    }
}

/// `sample_bias(q, b)` of an isotropic or footprint-assembly sampler is
/// the sampler with `lod_bias + b` (the shader's bias adds to the
/// sampler's, GL 4.6 §8.14.1); EWA and the reference scale the footprint
/// by 2^b instead, which is the same λ shift.
#[test]
fn a_call_bias_equals_the_sampler_bias() {
    let mut r = Rng(0xb1a5);
    let format = Format::new(4, ChannelType::U8, ColorSpace::Srgb);
    let tex = common::random_texture(&mut r, 45, 29, format);
    let chain = mip::build(tex, &MipOptions::default()).unwrap();
    let qs: Vec<Query> = quads(&mut r, 100).iter().flat_map(quad_queries).collect();
    for base in common::sampler_presets(8) {
        if !matches!(base.method, parvo::sample::Method::Texel) {
            continue;
        }
        for b in [-1.25f32, 0.5, 2.0] {
            let s = Sampler::new(&chain, base).unwrap();
            let biased = Sampler::new(
                &chain,
                SamplerOptions {
                    lod_bias: base.lod_bias + b,
                    ..base
                },
            )
            .unwrap();
            for q in &qs {
                assert_eq!(
                    bits(&s.sample_bias(q, b)),
                    bits(&biased.sample(q)),
                    "{} bias {b} at {q:?}",
                    base.name()
                );
            }
        }
    }
}

/// `sample_rgba8` is `sample` encoded in the texture's colour space:
/// against the sRGB formula in f64 (IEC 61966-2-1) for the colour of an
/// sRGB texture, x·255 for alpha and linear textures, rounded to nearest
/// after clamping to [0, 1] (values within 1e-4 of a rounding tie are
/// skipped: f32 against f64).
#[test]
fn encoded_output_is_the_colour_space_formula() {
    let mut r = Rng(0x8b17);
    for format in [
        Format::new(4, ChannelType::U8, ColorSpace::Srgb),
        Format::new(4, ChannelType::F32, ColorSpace::Linear),
    ] {
        let tex = common::random_texture(&mut r, 33, 17, format);
        let chain = mip::build(tex, &MipOptions::default()).unwrap();
        let s = Sampler::new(&chain, SamplerOptions::trilinear()).unwrap();
        let srgb = format.color_space == ColorSpace::Srgb;
        let mut checked = 0;
        for q in quads(&mut r, 500).iter().flat_map(quad_queries) {
            let lin = s.sample(&q);
            let enc = s.sample_rgba8(&q);
            for k in 0..4 {
                let x = (lin[k] as f64).clamp(0.0, 1.0);
                let e = if srgb && k < 3 {
                    common::srgb_encode(x)
                } else {
                    x
                } * 255.0;
                if (e - e.floor() - 0.5).abs() < 1e-4 {
                    continue;
                }
                assert_eq!(enc[k], e.round() as u8, "{format:?} channel {k} of {lin:?}");
                checked += 1;
            }
        }
        assert!(checked > 7000, "{checked}");
    }
}
