//! The fast separable chains (issue 32: band-by-band decode, the AVX-512
//! row kernel, the level encoded while in cache) against the plain
//! separable path (`fast_paths: false`, itself checked against the
//! brute-force reference in `mip_filters_match_reference.rs`): every level
//! within one code, for Kaiser, Lanczos3, Mitchell and triangle, 8- and
//! 16-bit, linear and sRGB, one to four channels, straight alpha (random,
//! so the weighted rows run, and opaque, so the plain rows run),
//! premultiplied alpha, odd sizes and every wrap mode, on seeded noise and
//! on a real photo (Pillow's `hopper.png`, and its `pil123rgba.png` for
//! real alpha).

use crate::common;
use common::*;
use parvo::mip::{self, MipFilter, MipOptions};
use parvo::wrap::{Wrap, WrapMode};
use parvo::{AlphaMode, ChannelType, ColorSpace, Format, Texels, Texture};

const FILTERS: [MipFilter; 4] = [
    MipFilter::Kaiser,
    MipFilter::Lanczos3,
    MipFilter::Mitchell,
    MipFilter::Triangle,
];

/// Largest difference in stored codes between two textures of one format.
fn max_code_diff(a: &Texture, b: &Texture) -> f64 {
    assert_eq!(a.format(), b.format());
    assert_eq!((a.width(), a.height()), (b.width(), b.height()));
    match (a.texels(), b.texels()) {
        (Texels::U8(x), Texels::U8(y)) => x
            .iter()
            .zip(y)
            .map(|(p, q)| (*p as f64 - *q as f64).abs())
            .fold(0.0, f64::max),
        (Texels::U16(x), Texels::U16(y)) => x
            .iter()
            .zip(y)
            .map(|(p, q)| (*p as f64 - *q as f64).abs())
            .fold(0.0, f64::max),
        _ => panic!("integer formats only"),
    }
}

/// Build `tex`'s chain both ways and compare every level; returns the
/// largest code difference seen.
fn check(tex: &Texture, options: MipOptions, what: &str) -> f64 {
    let fast = mip::build(
        tex.clone(),
        &MipOptions {
            fast_paths: true,
            ..options
        },
    )
    .unwrap();
    let plain = mip::build(
        tex.clone(),
        &MipOptions {
            fast_paths: false,
            ..options
        },
    )
    .unwrap();
    assert_eq!(fast.len(), plain.len(), "{what}");
    let mut worst = 0.0f64;
    for (k, (f, p)) in fast.levels().iter().zip(plain.levels()).enumerate() {
        let d = max_code_diff(f, p);
        assert!(
            d <= 1.0,
            "{what}: level {k} ({}x{}) differs by {d} codes",
            f.width(),
            f.height()
        );
        worst = worst.max(d);
    }
    worst
}

#[test]
fn fast_separable_chains_match_the_plain_path_on_noise() {
    let mut rng = Rng(0x5e9a_0032);
    for ty in [ChannelType::U8, ChannelType::U16] {
        for ch in 1..=4u8 {
            for cs in [ColorSpace::Srgb, ColorSpace::Linear] {
                for alpha in [AlphaMode::Straight, AlphaMode::Premultiplied] {
                    let f = Format::new(ch, ty, cs).with_alpha(alpha);
                    for &(w, h) in &[(257u32, 131u32), (1, 1000), (3, 5), (64, 64)] {
                        let tex = random_texture(&mut rng, w, h, f);
                        for filter in FILTERS {
                            let what = format!("{f} {w}x{h} {filter}");
                            check(&tex, MipOptions::with_filter(filter), &what);
                        }
                    }
                }
            }
        }
    }
}

/// Opaque (and constant-alpha) sources take the unweighted rows of the
/// straight-alpha path; a source with one transparent corner mixes both.
#[test]
fn fast_separable_chains_match_on_opaque_and_partly_transparent_sources() {
    let mut rng = Rng(0x0a9e);
    for ch in [2u8, 4] {
        let f = Format::new(ch, ChannelType::U8, ColorSpace::Srgb);
        let (w, h) = (300u32, 77u32);
        let mut tex = random_texture(&mut rng, w, h, f);
        if let Texels::U8(v) = tex.texels_mut() {
            for (i, t) in v.chunks_exact_mut(ch as usize).enumerate() {
                let (x, y) = (i as u32 % w, i as u32 / w);
                t[ch as usize - 1] = if x < 20 && y < 10 { 0 } else { 255 };
            }
        }
        for filter in FILTERS {
            check(
                &tex,
                MipOptions::with_filter(filter),
                &format!("{f} {filter}"),
            );
        }
    }
}

#[test]
fn fast_separable_chains_match_under_every_wrap_mode() {
    let mut rng = Rng(0x3a9);
    let f = Format::new(4, ChannelType::U8, ColorSpace::Srgb);
    let tex = random_texture(&mut rng, 131, 257, f);
    for mode in [
        WrapMode::Repeat,
        WrapMode::ClampToEdge,
        WrapMode::MirroredRepeat,
        WrapMode::ClampToBorder,
    ] {
        for filter in FILTERS {
            let options = MipOptions {
                wrap: Wrap {
                    u: mode,
                    v: WrapMode::MirroredRepeat,
                },
                ..MipOptions::with_filter(filter)
            };
            check(&tex, options, &format!("{mode:?} {filter}"));
        }
    }
}

fn photo(name: &str) -> Texture {
    let path = format!(
        "{}/tests/data/peer/pillow/{name}",
        env!("CARGO_MANIFEST_DIR")
    );
    let l = parvo::io::load(&path, &parvo::io::Limits::default()).unwrap();
    l.base().clone()
}

#[test]
fn fast_separable_chains_match_on_real_photos() {
    for name in ["hopper.png", "pil123rgba.png"] {
        let tex = photo(name);
        assert_eq!(tex.channel_type(), ChannelType::U8, "{name}");
        // The photo as stored, and cut to an odd size.
        let (w, h) = (tex.width(), tex.height());
        let odd = {
            let f = tex.format();
            let ch = f.channels as usize;
            let Texels::U8(v) = tex.texels() else {
                unreachable!()
            };
            let (ow, oh) = (w - 1 - (w % 2), h - 3 + (h % 2));
            let mut out = Vec::new();
            for y in 0..oh as usize {
                out.extend_from_slice(&v[y * w as usize * ch..][..ow as usize * ch]);
            }
            Texture::from_u8(ow, oh, f, out).unwrap()
        };
        for t in [&tex, &odd] {
            for filter in FILTERS {
                let what = format!("{name} {}x{} {filter}", t.width(), t.height());
                check(t, MipOptions::with_filter(filter), &what);
            }
        }
    }
}

/// Levels 1 and 2 of 8- and 16-bit chains are made together, band by
/// band, level 1 never whole in f32: level 1 must be the level a one-level
/// chain (made the two-pass way) stores, bit for bit, and every level must
/// be the same whatever the bands are (1, 2 and 3 threads cut the levels
/// differently; rows near band edges are made by both neighbours).
#[test]
fn levels_made_together_equal_the_two_pass_levels_for_any_bands() {
    let mut rng = Rng(0x32_f05e);
    let pools: Vec<rayon::ThreadPool> = [1, 2, 3]
        .map(|n| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .unwrap()
        })
        .into();
    for (ty, ch, alpha) in [
        (ChannelType::U8, 4u8, AlphaMode::Straight),
        (ChannelType::U8, 2, AlphaMode::Straight),
        (ChannelType::U8, 3, AlphaMode::Straight),
        (ChannelType::U16, 4, AlphaMode::Premultiplied),
        (ChannelType::U8, 1, AlphaMode::Straight),
    ] {
        let f = Format::new(ch, ty, ColorSpace::Srgb).with_alpha(alpha);
        for &(w, h) in &[(203u32, 517u32), (64, 64), (2, 300)] {
            let tex = random_texture(&mut rng, w, h, f);
            for (filter, mode) in [
                (MipFilter::Kaiser, WrapMode::Repeat),
                (MipFilter::Lanczos3, WrapMode::ClampToEdge),
                (MipFilter::Mitchell, WrapMode::MirroredRepeat),
                (MipFilter::Triangle, WrapMode::ClampToBorder),
            ] {
                let what = format!("{f} {w}x{h} {filter} {mode:?}");
                let options = MipOptions {
                    wrap: Wrap { u: mode, v: mode },
                    ..MipOptions::with_filter(filter)
                };
                let one = mip::build(
                    tex.clone(),
                    &MipOptions {
                        max_levels: Some(2),
                        ..options
                    },
                )
                .unwrap();
                let chains: Vec<_> = pools
                    .iter()
                    .map(|p| p.install(|| mip::build(tex.clone(), &options).unwrap()))
                    .collect();
                assert_eq!(
                    chains[0].levels()[1].texels(),
                    one.levels()[1].texels(),
                    "{what}: level 1"
                );
                for c in &chains[1..] {
                    for (k, (a, b)) in c.levels().iter().zip(chains[0].levels()).enumerate() {
                        assert_eq!(a.texels(), b.texels(), "{what}: level {k}");
                    }
                }
            }
        }
    }
}
