//! Numerical and size extremes of chain building.

use crate::common;
use common::*;
use half::f16;
use parvo::mip::{self, MipFilter, MipOptions};
use parvo::{ChannelType, ColorSpace, Format, Texels, Texture};

#[test]
fn long_thin_textures_65536x1_and_1x65536_build_full_chains() {
    let mut rng = Rng(0x10_0000);
    for (w, h) in [(65536u32, 1u32), (1, 65536)] {
        let f = Format::new(2, ChannelType::U8, ColorSpace::Srgb);
        let tex = random_texture(&mut rng, w, h, f);
        for filter in [MipFilter::Box, MipFilter::Kaiser] {
            let chain = mip::build(tex.clone(), &MipOptions::with_filter(filter)).unwrap();
            assert_eq!(chain.len(), 17);
            for (k, lvl) in chain.levels().iter().enumerate() {
                assert_eq!(
                    (lvl.width(), lvl.height()),
                    ((w >> k).max(1), (h >> k).max(1))
                );
            }
            // Check the last few levels against the reference chain
            // (each level from the unrounded one before it).
            let sizes: Vec<(u32, u32)> = chain
                .levels()
                .iter()
                .map(|l| (l.width(), l.height()))
                .collect();
            let reference = reference_chain(
                &chain.levels()[0],
                &sizes,
                filter.name(),
                "repeat",
                "repeat",
            );
            for k in 12..17 {
                let (lvl, want) = (&chain.levels()[k], &reference[k - 1]);
                assert!(max_error(lvl, want) <= tolerance(ChannelType::U8));
            }
        }
    }
}

#[test]
fn f16_values_near_65504_do_not_overflow_when_averaged() {
    let f = Format::new(1, ChannelType::F16, ColorSpace::Linear);
    let mut rng = Rng(0xf16);
    // Constant maximum, and random values in the top of the range.
    let max = vec![f16::MAX; 64 * 64];
    let top: Vec<f16> = (0..64 * 64)
        .map(|_| f16::from_f64(60000.0 + rng.unit() * 5504.0))
        .collect();
    for v in [max, top] {
        let tex = Texture::from_f16(64, 64, f, v).unwrap();
        for filter in MipFilter::ALL {
            let chain = mip::build(tex.clone(), &MipOptions::with_filter(filter)).unwrap();
            for lvl in chain.levels() {
                let Texels::F16(t) = lvl.texels() else {
                    unreachable!()
                };
                assert!(
                    t.iter().all(|x| x.is_finite() && x.to_f32() >= 59000.0),
                    "{filter}: overflow or collapse"
                );
            }
        }
    }
    // Odd-sized even-valued pair: (65504 + 65504) / 2 in the fast path of
    // f32 too.
    let f32f = Format::new(1, ChannelType::F32, ColorSpace::Linear);
    let tex = Texture::from_f32(2, 2, f32f, vec![f32::MAX; 4]).unwrap();
    let chain = mip::build(tex, &MipOptions::default()).unwrap();
    assert_eq!(raw(&chain.levels()[1])[0], f32::MAX as f64);
}

#[test]
fn subnormal_values_average_without_flushing() {
    let tiny = f32::from_bits(1000); // subnormal
    let f = Format::new(1, ChannelType::F32, ColorSpace::Linear);
    let tex = Texture::from_f32(2, 2, f, vec![tiny, tiny, tiny, tiny]).unwrap();
    for fast in [true, false] {
        let chain = mip::build(
            tex.clone(),
            &MipOptions {
                fast_paths: fast,
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(raw(&chain.levels()[1])[0], tiny as f64, "fast {fast}");
    }
    let h = f16::from_bits(3); // f16 subnormal
    let fh = Format::new(1, ChannelType::F16, ColorSpace::Linear);
    let tex =
        Texture::from_f16(2, 2, fh, vec![h, h, f16::from_bits(1), f16::from_bits(1)]).unwrap();
    let chain = mip::build(tex, &MipOptions::default()).unwrap();
    let Texels::F16(t) = chain.levels()[1].texels() else {
        unreachable!()
    };
    assert_eq!(t[0], f16::from_bits(2));
}

#[test]
fn u16_full_range_averages_exactly() {
    let f = Format::new(1, ChannelType::U16, ColorSpace::Linear);
    let tex = Texture::from_u16(2, 2, f, vec![0, 65535, 65535, 65535]).unwrap();
    let chain = mip::build(tex, &MipOptions::default()).unwrap();
    // 3·65535/4 = 49151.25
    assert_eq!(chain.levels()[1].texels(), &Texels::U16(vec![49151]));
    let tex = Texture::from_u16(2, 1, f, vec![0, 65535]).unwrap();
    let chain = mip::build(tex, &MipOptions::default()).unwrap();
    assert_eq!(chain.levels()[1].texels(), &Texels::U16(vec![32768]));
    let all = Texture::from_u16(4, 4, f, vec![65535; 16]).unwrap();
    for filter in MipFilter::ALL {
        let chain = mip::build(all.clone(), &MipOptions::with_filter(filter)).unwrap();
        assert!(
            chain
                .levels()
                .iter()
                .all(|l| raw(l).iter().all(|&v| v == 65535.0))
        );
    }
}

#[test]
fn one_by_one_is_a_single_level_chain() {
    let tex = Texture::from_u8(1, 1, Format::default(), vec![1, 2, 3, 4]).unwrap();
    let chain = mip::build(tex.clone(), &MipOptions::default()).unwrap();
    assert_eq!(chain.len(), 1);
    assert_eq!(chain.levels()[0], tex);
}

#[test]
fn nan_anywhere_is_reported_exactly_whatever_the_filter_and_level_count() {
    // The Error policy defers its scan to level 1; a NaN or Inf in any
    // texel, channel or position must still be found and named.
    let f = Format::new(4, ChannelType::F32, ColorSpace::Linear);
    let mut rng = Rng(0xba1d);
    for filter in MipFilter::ALL {
        for &(w, h) in &[(1u32, 1u32), (7, 1), (16, 16), (13, 9)] {
            for max_levels in [None, Some(1), Some(2)] {
                for _ in 0..4 {
                    let mut v: Vec<f32> = (0..w * h * 4).map(|_| rng.unit() as f32).collect();
                    let i = (rng.next_u64() % v.len() as u64) as usize;
                    v[i] = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY][i % 3];
                    let tex = Texture::from_f32(w, h, f, v).unwrap();
                    let opts = MipOptions {
                        max_levels,
                        ..MipOptions::with_filter(filter)
                    };
                    match mip::build(tex.clone(), &opts) {
                        Err(parvo::Error::NonFinite { x, y, channel, .. }) => {
                            assert_eq!(((y * w + x) * 4 + channel as u32) as usize, i);
                        }
                        other => panic!(
                            "{filter} {w}x{h} {max_levels:?}: {:?}",
                            other.map(|c| c.len())
                        ),
                    }
                    assert!(mip::build_reduced_levels(&tex, &opts).is_err());
                }
            }
        }
    }
}
