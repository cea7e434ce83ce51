//! Properties every chain must have, whatever the filter, type or wrap.

use crate::common;
use common::*;
use half::f16;
use parvo::mip::{self, MipFilter, MipOptions, NanPolicy, weights};
use parvo::{AlphaMode, ChannelType, ColorSpace, Error, Format, Texels, Texture, Wrap, WrapMode};

const WRAPS: [WrapMode; 5] = [
    WrapMode::Repeat,
    WrapMode::MirroredRepeat,
    WrapMode::ClampToEdge,
    WrapMode::ClampToBorder,
    WrapMode::MirrorClampToEdge,
];

fn constant(w: u32, h: u32, f: Format, rng: &mut Rng) -> Texture {
    let one = random_texture(rng, 1, 1, f);
    let ch = f.channels as usize;
    let n = w as usize * h as usize * ch;
    // Repeat the one random texel n / ch times, whatever the storage type.
    fn tile<T: Copy>(v: &[T], n: usize) -> Vec<T> {
        v.iter().cycle().take(n).copied().collect()
    }
    let texels = match one.texels() {
        Texels::U8(v) => Texels::U8(tile(v, n)),
        Texels::U16(v) => Texels::U16(tile(v, n)),
        Texels::F16(v) => Texels::F16(tile(v, n)),
        Texels::F32(v) => Texels::F32(tile(v, n)),
    };
    Texture::from_texels(w, h, f, texels).unwrap()
}

#[test]
fn constant_images_stay_constant_at_every_level_for_every_filter_wrap_and_type() {
    let mut rng = Rng(0xc0_57a7);
    for filter in MipFilter::ALL {
        for wrap in WRAPS {
            for f in all_formats() {
                for &(w, h) in &[(13u32, 7u32), (16, 16), (1, 6)] {
                    let tex = constant(w, h, f, &mut rng);
                    let want = raw(&tex)[..f.channels as usize].to_vec();
                    let opts = MipOptions {
                        wrap: Wrap::both(wrap),
                        ..MipOptions::with_filter(filter)
                    };
                    let chain = mip::build(tex, &opts).unwrap();
                    for (k, lvl) in chain.levels().iter().enumerate() {
                        for (i, v) in raw(lvl).iter().enumerate() {
                            let w0 = want[i % want.len()];
                            // f32 sums of weights that add to 1 only to
                            // within rounding, and straight alpha divides
                            // two such sums: allow 5 ulp per level (each
                            // level is filtered from the one above). Every
                            // other type must come back exactly.
                            let tol = if f.channel_type == ChannelType::F32 {
                                w0.abs() * 6e-7 * k as f64
                            } else {
                                0.0
                            };
                            assert!(
                                (v - w0).abs() <= tol,
                                "{filter} {wrap} {f} {w}x{h} level {k}: {v} != {w0}"
                            );
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn kernel_weights_sum_to_one() {
    for filter in MipFilter::ALL {
        for wrap in WRAPS {
            for src in [1u32, 2, 3, 5, 8, 19, 64, 257] {
                for dst in [src / 2, src.div_ceil(2)] {
                    let dst = dst.max(1);
                    let exact = weights::exact(filter, src, dst, wrap);
                    assert_eq!(exact.len(), dst as usize);
                    for t in &exact {
                        let s: f64 = t.iter().map(|p| p.1).sum();
                        assert!((s - 1.0).abs() < 1e-12, "{filter} {wrap} {src}->{dst}: {s}");
                        assert!(t.iter().all(|p| p.0 < src));
                    }
                    let flat = weights::axis(filter, src, dst, wrap);
                    for x in 0..dst as usize {
                        let s: f32 = flat.of(x).map(|p| p.1).sum();
                        assert!((s - 1.0).abs() < 1e-6, "{filter} flat {src}->{dst}: {s}");
                    }
                }
            }
        }
    }
}

#[test]
fn box_on_odd_sizes_is_the_spec_polyphase_box() {
    for n in 1..20u32 {
        let wts = weights::exact(MipFilter::Box, 2 * n + 1, n, WrapMode::Repeat);
        for (x, t) in wts.iter().enumerate() {
            let d = (2 * n + 1) as f64;
            let want = [
                (2 * x as u32, (n as f64 - x as f64) / d),
                (2 * x as u32 + 1, n as f64 / d),
                (2 * x as u32 + 2, (x as f64 + 1.0) / d),
            ];
            let got: Vec<_> = t.iter().filter(|p| p.1 > 0.0).copied().collect();
            let want: Vec<_> = want.into_iter().filter(|p| p.1 > 0.0).collect();
            assert_eq!(got.len(), want.len());
            for (g, w) in got.iter().zip(&want) {
                assert_eq!(g.0, w.0);
                assert!((g.1 - w.1).abs() < 1e-12);
            }
        }
        // No source texel is dropped or favoured: each one's total weight
        // over all destination texels is n / (2n + 1).
        let mut cover = vec![0.0; (2 * n + 1) as usize];
        for t in &wts {
            for &(i, w) in t {
                cover[i as usize] += w;
            }
        }
        for c in cover {
            assert!((c - n as f64 / (2 * n + 1) as f64).abs() < 1e-12);
        }
    }
}

#[test]
fn srgb_codes_0_and_255_average_to_188() {
    for fast in [true, false] {
        for (w, h, v) in [(2u32, 1u32, vec![0u8, 255]), (2, 2, vec![0, 255, 255, 0])] {
            let f = Format::new(1, ChannelType::U8, ColorSpace::Srgb);
            let tex = Texture::from_u8(w, h, f, v).unwrap();
            let opts = MipOptions {
                fast_paths: fast,
                ..Default::default()
            };
            let chain = mip::build(tex, &opts).unwrap();
            assert_eq!(
                chain.levels()[1].texels(),
                &Texels::U8(vec![188]),
                "fast {fast}"
            );
        }
        // Linear data averages to the middle code (127.5 rounds up).
        let f = Format::new(1, ChannelType::U8, ColorSpace::Linear);
        let tex = Texture::from_u8(2, 1, f, vec![0, 255]).unwrap();
        let opts = MipOptions {
            fast_paths: fast,
            ..Default::default()
        };
        let chain = mip::build(tex, &opts).unwrap();
        assert_eq!(chain.levels()[1].texels(), &Texels::U8(vec![128]));
    }
}

#[test]
fn alpha_weighting_keeps_the_colour_of_opaque_texels_next_to_transparent_ones() {
    // Left half opaque orange, right half fully transparent with a hidden
    // blue colour: no filter may pull blue (or black) into the orange.
    for fast in [true, false] {
        for filter in [MipFilter::Box, MipFilter::Triangle] {
            for cs in [ColorSpace::Linear, ColorSpace::Srgb] {
                let (w, h) = (16u32, 8u32);
                let mut v = Vec::new();
                for _y in 0..h {
                    for x in 0..w {
                        v.extend_from_slice(if x < 7 {
                            &[230, 120, 20, 255]
                        } else {
                            &[0, 0, 255, 0]
                        });
                    }
                }
                let tex = Texture::from_u8(w, h, Format::new(4, ChannelType::U8, cs), v).unwrap();
                let opts = MipOptions {
                    fast_paths: fast,
                    ..MipOptions::with_filter(filter)
                };
                let chain = mip::build(tex, &opts).unwrap();
                for (k, lvl) in chain.levels().iter().enumerate().skip(1) {
                    let Texels::U8(t) = lvl.texels() else {
                        unreachable!()
                    };
                    for px in t.chunks_exact(4).filter(|p| p[3] > 0) {
                        assert_eq!(
                            &px[..3],
                            &[230, 120, 20],
                            "{filter} {cs} fast={fast} level {k}: {px:?}"
                        );
                    }
                }
            }
        }
    }
    // The simplest case, exactly: two opaque red and two transparent black.
    let f = Format::new(4, ChannelType::U8, ColorSpace::Srgb);
    let tex = Texture::from_u8(
        2,
        2,
        f,
        vec![255, 0, 0, 255, 0, 0, 0, 0, 255, 0, 0, 255, 0, 0, 0, 0],
    )
    .unwrap();
    let chain = mip::build(tex, &MipOptions::default()).unwrap();
    assert_eq!(
        chain.levels()[1].texels(),
        &Texels::U8(vec![255, 0, 0, 128])
    );
    // Premultiplied data is averaged as is.
    let tex = Texture::from_u8(
        2,
        1,
        f.with_alpha(AlphaMode::Premultiplied),
        vec![200, 0, 0, 255, 0, 0, 0, 0],
    )
    .unwrap();
    let chain = mip::build(
        tex,
        &MipOptions {
            fast_paths: false,
            ..Default::default()
        },
    )
    .unwrap();
    let Texels::U8(t) = chain.levels()[1].texels() else {
        unreachable!()
    };
    let want = (srgb_encode(srgb_decode(200.0 / 255.0) / 2.0) * 255.0).round() as u8;
    assert_eq!(t, &vec![want, 0, 0, 128]);
}

#[test]
fn alpha_coverage_option_keeps_level_0_coverage_at_every_level() {
    // Foliage-like alpha: smooth noise thresholded around the reference.
    let (w, h) = (256u32, 256u32);
    let mut rng = Rng(0xa1fa);
    let blobs: Vec<(f64, f64, f64)> = (0..40)
        .map(|_| {
            (
                rng.unit() * 256.0,
                rng.unit() * 256.0,
                4.0 + rng.unit() * 20.0,
            )
        })
        .collect();
    let mut v = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let a: f64 = blobs
                .iter()
                .map(|&(bx, by, r)| {
                    let d2 = (x as f64 - bx).powi(2) + (y as f64 - by).powi(2);
                    (-d2 / (r * r)).exp()
                })
                .sum::<f64>()
                .min(1.0);
            v.extend_from_slice(&[40, 160, 30, (a * 255.0) as u8]);
        }
    }
    let f = Format::new(4, ChannelType::U8, ColorSpace::Srgb);
    let tex = Texture::from_u8(w, h, f, v).unwrap();
    let reference = 0.5;
    let c0 = mip::alpha::coverage(&tex, reference);
    assert!(c0 > 0.1 && c0 < 0.9, "test texture coverage {c0}");
    let plain = mip::build(tex.clone(), &MipOptions::default()).unwrap();
    let opts = MipOptions {
        alpha_coverage: Some(reference),
        ..Default::default()
    };
    let chain = mip::build(tex, &opts).unwrap();
    let mut plain_drift: f32 = 0.0;
    for (k, lvl) in chain.levels().iter().enumerate() {
        let n = lvl.texel_count() as f32;
        let c = mip::alpha::coverage(lvl, reference);
        // Within 1%, or the best a level of n texels can do (1/(2n)) plus
        // one texel of u8 quantisation.
        let tol = 0.01f32.max(1.5 / n);
        assert!(
            (c - c0).abs() <= tol,
            "level {k} coverage {c} vs {c0} (tol {tol})"
        );
        plain_drift =
            plain_drift.max((mip::alpha::coverage(&plain.levels()[k], reference) - c0).abs());
    }
    // The option matters: without it, coverage drifts.
    assert!(plain_drift > 0.01, "plain chain drift {plain_drift}");
}

#[test]
fn normal_maps_are_renormalised_per_level() {
    let mut rng = Rng(0x4e4f);
    let (w, h) = (32u32, 32u32);
    let mut v = Vec::new();
    for _ in 0..w * h {
        let (x, y) = (rng.unit() * 1.6 - 0.8, rng.unit() * 1.6 - 0.8);
        let z = (1.0 - x * x - y * y).max(0.0).sqrt();
        let l = (x * x + y * y + z * z).sqrt();
        v.extend_from_slice(&[(x / l) as f32, (y / l) as f32, (z / l) as f32]);
    }
    let f = Format::new(3, ChannelType::F32, ColorSpace::Linear);
    let tex = Texture::from_f32(w, h, f, v).unwrap();
    let chain = mip::build(
        tex,
        &MipOptions {
            normal_map: true,
            ..Default::default()
        },
    )
    .unwrap();
    for lvl in chain.levels() {
        let Texels::F32(t) = lvl.texels() else {
            unreachable!()
        };
        for n in t.chunks_exact(3) {
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            assert!((len - 1.0).abs() < 1e-5, "length {len}");
        }
    }
    let srgb = Texture::new(4, 4, Format::new(3, ChannelType::U8, ColorSpace::Srgb)).unwrap();
    assert!(
        mip::build(
            srgb,
            &MipOptions {
                normal_map: true,
                ..Default::default()
            }
        )
        .is_err()
    );
}

#[test]
fn nan_policies_refuse_blacken_or_fill_from_neighbours() {
    let f = Format::new(1, ChannelType::F32, ColorSpace::Linear);
    let mut v = vec![1.0f32; 16];
    v[6] = f32::NAN; // (2, 1)
    v[9] = f32::INFINITY; // (1, 2)
    let tex = Texture::from_f32(4, 4, f, v).unwrap();
    match mip::build(tex.clone(), &MipOptions::default()) {
        Err(Error::NonFinite {
            x: 2,
            y: 1,
            channel: 0,
            ..
        }) => {}
        other => panic!("expected NonFinite at (2,1), got {other:?}"),
    }
    let black = mip::build(
        tex.clone(),
        &MipOptions {
            nan_policy: NanPolicy::Black,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(raw(&black.levels()[0])[6], 0.0);
    assert_eq!(raw(&black.levels()[0])[9], 0.0);
    let nb = mip::build(
        tex,
        &MipOptions {
            nan_policy: NanPolicy::Neighbors,
            ..Default::default()
        },
    )
    .unwrap();
    for lvl in nb.levels() {
        assert!(
            raw(lvl).iter().all(|&x| x == 1.0),
            "neighbours of a constant are the constant"
        );
    }
    // Half floats too.
    let f16f = Format::new(1, ChannelType::F16, ColorSpace::Linear);
    let tex = Texture::from_f16(2, 1, f16f, vec![f16::NAN, f16::ONE]).unwrap();
    assert!(matches!(
        mip::build(tex, &MipOptions::default()),
        Err(Error::NonFinite { x: 0, y: 0, .. })
    ));
}

#[test]
fn progress_reports_every_level_in_order() {
    let tex = parvo::builtin::load("builtin:checker:64").unwrap();
    let mut seen = Vec::new();
    mip::build_with_progress(tex, &MipOptions::default(), &mut |p| seen.push(p)).unwrap();
    assert_eq!(seen.len(), 7);
    assert!(
        seen.windows(2)
            .all(|w| w[0].levels_done + 1 == w[1].levels_done)
    );
    let last = seen.last().unwrap();
    assert_eq!(last.texels_done, last.texels_total);
    assert_eq!(
        last.texels_total,
        (32 * 32 + 16 * 16 + 64 + 16 + 4 + 1) as u64
    );
}

#[test]
fn bad_options_are_errors_not_panics() {
    let tex = parvo::builtin::load("builtin:checker:8").unwrap();
    for opts in [
        MipOptions {
            alpha_coverage: Some(1.5),
            ..Default::default()
        },
        MipOptions {
            alpha_coverage: Some(f32::NAN),
            ..Default::default()
        },
        MipOptions {
            max_levels: Some(0),
            ..Default::default()
        },
    ] {
        assert!(mip::build(tex.clone(), &opts).is_err());
    }
    let grey = Texture::new(4, 4, Format::new(1, ChannelType::U8, ColorSpace::Linear)).unwrap();
    assert!(
        mip::build(
            grey,
            &MipOptions {
                alpha_coverage: Some(0.5),
                ..Default::default()
            }
        )
        .is_err()
    );
}
