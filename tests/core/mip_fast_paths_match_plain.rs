//! The fast box paths agree with the plain separable path (and so with the
//! brute-force reference): u8 linear and sRGB in every channel layout and
//! alpha mode, and linear f32.

use crate::common;
use common::*;
use parvo::mip::{self, MipOptions};
use parvo::{AlphaMode, ChannelType, ColorSpace, Format};

#[test]
fn fast_box_paths_match_the_plain_path_and_the_reference() {
    let mut rng = Rng(0xfa57);
    for ty in [ChannelType::U8, ChannelType::F32] {
        for ch in 1..=4u8 {
            for cs in [ColorSpace::Linear, ColorSpace::Srgb] {
                for alpha in [AlphaMode::Straight, AlphaMode::Premultiplied] {
                    let f = Format::new(ch, ty, cs).with_alpha(alpha);
                    for &(w, h) in &[(2u32, 2u32), (64, 32), (36, 200)] {
                        let tex = random_texture(&mut rng, w, h, f);
                        let fast = mip::build(tex.clone(), &MipOptions::default()).unwrap();
                        let plain = mip::build(
                            tex,
                            &MipOptions {
                                fast_paths: false,
                                ..Default::default()
                            },
                        )
                        .unwrap();
                        assert_eq!(fast.len(), plain.len());
                        let sizes: Vec<(u32, u32)> = fast
                            .levels()
                            .iter()
                            .map(|l| (l.width(), l.height()))
                            .collect();
                        let reference =
                            reference_chain(&fast.levels()[0], &sizes, "box", "repeat", "repeat");
                        let tol = tolerance(ty);
                        // A single reduction (`mip::reduce`, the stored
                        // type's own kernels) both ways, too.
                        let (w1, h1) = sizes.get(1).copied().unwrap_or((1, 1));
                        if sizes.len() > 1 {
                            let one = |fast_paths| {
                                mip::reduce(
                                    &fast.levels()[0],
                                    w1,
                                    h1,
                                    &MipOptions {
                                        fast_paths,
                                        ..Default::default()
                                    },
                                )
                                .unwrap()
                            };
                            for (name, l) in [("fast", one(true)), ("plain", one(false))] {
                                assert!(
                                    max_error(&l, &reference[0]) <= tol,
                                    "{name} reduce {f} {w}x{h}: {}",
                                    max_error(&l, &reference[0])
                                );
                            }
                        }
                        for k in 1..fast.len() {
                            let (a, b) = (&fast.levels()[k], &plain.levels()[k]);
                            // Both within rounding of the exact value...
                            let want = &reference[k - 1];
                            assert!(
                                max_error(a, want) <= tol,
                                "fast {f} {w}x{h} level {k}: {}",
                                max_error(a, want)
                            );
                            assert!(max_error(b, want) <= tol, "plain {f} {w}x{h} level {k}");
                            // ...and identical apart from exact ties.
                            let diff = raw(a)
                                .iter()
                                .zip(raw(b))
                                .filter(|(x, y)| {
                                    (*x - y).abs()
                                        > if ty == ChannelType::F32 {
                                            y.abs() * 1e-6
                                        } else {
                                            0.0
                                        }
                                })
                                .count();
                            assert!(
                                diff * 100 <= raw(a).len().max(100),
                                "{f} {w}x{h} level {k}: {diff} differences"
                            );
                        }
                    }
                }
            }
        }
    }
}

/// Largest difference in 8-bit codes between two textures.
#[cfg(feature = "io")]
fn max_code_diff(a: &parvo::Texture, b: &parvo::Texture) -> u8 {
    let (parvo::Texels::U8(x), parvo::Texels::U8(y)) = (a.texels(), b.texels()) else {
        panic!("8-bit textures only")
    };
    x.iter()
        .zip(y)
        .map(|(p, q)| p.abs_diff(*q))
        .max()
        .unwrap_or(0)
}

/// The RGBA8 sRGB box chain (level 1 fused from the codes where AVX-512
/// runs) within one code of the plain path at every level, on real photos
/// (opaque `hopper.png`, and `pil123rgba.png` with real alpha) cut to
/// sizes whose rows end in a partial block of the kernel and whose levels
/// stop halving early, and to odd sizes.
#[test]
#[cfg(feature = "io")]
fn rgba8_srgb_box_chains_match_the_plain_path_on_real_photos() {
    for name in ["hopper.png", "pil123rgba.png"] {
        let path = format!(
            "{}/tests/data/peer/pillow/{name}",
            env!("CARGO_MANIFEST_DIR")
        );
        let l = parvo::io::load(&path, &parvo::io::Limits::default()).unwrap();
        let tex = l.base();
        let (w, h, ch) = (
            tex.width() as usize,
            tex.height() as usize,
            tex.format().channels as usize,
        );
        let parvo::Texels::U8(v) = tex.texels() else {
            panic!("{name} is 8-bit")
        };
        let rgba: Vec<u8> = v
            .chunks_exact(ch)
            .flat_map(|t| match ch {
                4 => [t[0], t[1], t[2], t[3]],
                3 => [t[0], t[1], t[2], 255],
                _ => panic!("{name}: {ch} channels"),
            })
            .collect();
        let f = Format::new(4, ChannelType::U8, ColorSpace::Srgb);
        for (cw, chh) in [
            (w, h),
            (w - w % 4 - 28, 48),
            (w - 1 - w % 2, h - 2 + h % 2),
            (36, 24),
        ] {
            let mut cut = Vec::new();
            for y in 0..chh {
                cut.extend_from_slice(&rgba[y * w * 4..][..cw * 4]);
            }
            let t = parvo::Texture::from_u8(cw as u32, chh as u32, f, cut).unwrap();
            let fast = mip::build(t.clone(), &MipOptions::default()).unwrap();
            let plain = mip::build(
                t,
                &MipOptions {
                    fast_paths: false,
                    ..Default::default()
                },
            )
            .unwrap();
            assert_eq!(fast.len(), plain.len());
            for (k, (a, b)) in fast.levels().iter().zip(plain.levels()).enumerate() {
                let d = max_code_diff(a, b);
                assert!(d <= 1, "{name} {cw}x{chh} level {k}: {d} codes");
            }
        }
    }
}
