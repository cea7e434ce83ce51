//! Every filter, every storage type and channel layout, several wrap modes:
//! each level of the chain equals a brute-force reference reduction of the
//! level above it (SPEC.md formulas restated in `common`), to the type's
//! precision (unorm: correctly rounded to within 0.01 code).

use crate::common;
use common::*;
use parvo::mip::{self, MipFilter, MipOptions, Rounding};
use parvo::{AlphaMode, ChannelType, ColorSpace, Format, Wrap};

fn check_chain(tex: parvo::Texture, opts: &MipOptions, label: &str) {
    let chain = mip::build(tex, opts).unwrap();
    let f = chain.levels()[0].format();
    // Every level from the unrounded level before it (rounded once).
    let sizes: Vec<(u32, u32)> = chain
        .levels()
        .iter()
        .map(|l| (l.width(), l.height()))
        .collect();
    let reference = reference_chain(
        &chain.levels()[0],
        &sizes,
        opts.filter.name(),
        opts.wrap.u.name(),
        opts.wrap.v.name(),
    );
    for k in 1..chain.len() {
        let lvl = &chain.levels()[k];
        let want = &reference[k - 1];
        let err = max_error(lvl, want);
        assert!(
            err <= tolerance(f.channel_type),
            "{label}: level {k} ({}x{}) error {err} (format {f})",
            lvl.width(),
            lvl.height()
        );
    }
}

#[test]
fn every_filter_matches_brute_force_on_awkward_sizes() {
    let mut rng = Rng(0x5eed_0001);
    for filter in MipFilter::ALL {
        for &(w, h) in &AWKWARD {
            for wrap in ["repeat", "clamp", "mirror", "border", "mirror-clamp,repeat"] {
                let opts = MipOptions {
                    wrap: wrap.parse::<Wrap>().unwrap(),
                    ..MipOptions::with_filter(filter)
                };
                let f = Format::new(4, ChannelType::F32, ColorSpace::Linear)
                    .with_alpha(AlphaMode::Premultiplied);
                let tex = random_texture(&mut rng, w, h, f);
                check_chain(tex, &opts, &format!("{filter} {w}x{h} {wrap}"));
            }
        }
    }
}

#[test]
fn every_type_and_layout_matches_brute_force() {
    let mut rng = Rng(0x5eed_0002);
    for filter in MipFilter::ALL {
        for f in all_formats() {
            // Negative-lobe kernels with straight alpha divide by small
            // filtered alphas; that is checked with box and triangle.
            let negative_lobes = !matches!(filter, MipFilter::Box | MipFilter::Triangle);
            if negative_lobes && f.has_alpha() && f.alpha == AlphaMode::Straight {
                continue;
            }
            for &(w, h) in &[(12u32, 19u32), (257, 129)] {
                let tex = random_texture(&mut rng, w, h, f);
                check_chain(
                    tex,
                    &MipOptions::with_filter(filter),
                    &format!("{filter} {w}x{h}"),
                );
            }
        }
    }
}

#[test]
fn rounding_up_matches_the_area_box_reference() {
    let mut rng = Rng(0x5eed_0003);
    for filter in MipFilter::ALL {
        for &(w, h) in &AWKWARD {
            let opts = MipOptions {
                rounding: Rounding::Up,
                ..MipOptions::with_filter(filter)
            };
            let f = Format::new(3, ChannelType::F32, ColorSpace::Linear);
            let tex = random_texture(&mut rng, w, h, f);
            check_chain(tex, &opts, &format!("up {filter} {w}x{h}"));
        }
    }
}

#[test]
fn straight_alpha_box_and_triangle_match_reference_in_u8_srgb() {
    let mut rng = Rng(0x5eed_0004);
    for filter in [MipFilter::Box, MipFilter::Triangle] {
        for &(w, h) in &[(64u32, 64u32), (63, 33), (2, 2)] {
            let tex = random_texture(
                &mut rng,
                w,
                h,
                Format::new(4, ChannelType::U8, ColorSpace::Srgb),
            );
            check_chain(
                tex,
                &MipOptions::with_filter(filter),
                &format!("straight {filter} {w}x{h}"),
            );
        }
    }
}

#[test]
fn level_sizes_follow_the_spec() {
    use parvo::mip::{level_count, level_sizes};
    assert_eq!(level_count(1, 1, Rounding::Down, None), 1);
    assert_eq!(level_count(4096, 1, Rounding::Down, None), 13);
    assert_eq!(level_count(257, 129, Rounding::Down, None), 9);
    assert_eq!(
        level_sizes(5, 3, Rounding::Down, None),
        vec![(5, 3), (2, 1), (1, 1)]
    );
    assert_eq!(
        level_sizes(5, 3, Rounding::Up, None),
        vec![(5, 3), (3, 2), (2, 1), (1, 1)]
    );
    assert_eq!(level_sizes(64, 64, Rounding::Down, Some(3)).len(), 3);
    for w in 1..300u32 {
        for h in [1u32, 7, 64, 299] {
            let s = level_sizes(w, h, Rounding::Down, None);
            let m = w.max(h) as f64;
            assert_eq!(s.len(), m.log2().floor() as usize + 1);
            for (k, &(lw, lh)) in s.iter().enumerate() {
                assert_eq!(lw, ((w >> k).max(1)));
                assert_eq!(lh, ((h >> k).max(1)));
            }
            assert_eq!(*s.last().unwrap(), (1, 1));
        }
    }
}

#[test]
fn opaque_straight_alpha_takes_the_unweighted_path_and_matches_reference() {
    // Constant alpha (opaque, and a constant 0.5) lets the filters skip
    // alpha weighting; the result must still equal the weighted reference.
    let mut rng = Rng(0x5eed_0005);
    for filter in MipFilter::ALL {
        for (ty, alpha) in [
            (ChannelType::F32, 1.0f64),
            (ChannelType::F32, 0.5),
            (ChannelType::U8, 1.0),
        ] {
            for &(w, h) in &[(64u32, 32u32), (12, 19)] {
                let f = Format::new(4, ty, ColorSpace::Linear);
                let tex = random_texture(&mut rng, w, h, f);
                let texels = match tex.texels().clone() {
                    parvo::Texels::F32(mut v) => {
                        v.iter_mut()
                            .skip(3)
                            .step_by(4)
                            .for_each(|a| *a = alpha as f32);
                        parvo::Texels::F32(v)
                    }
                    parvo::Texels::U8(mut v) => {
                        v.iter_mut()
                            .skip(3)
                            .step_by(4)
                            .for_each(|a| *a = (alpha * 255.0) as u8);
                        parvo::Texels::U8(v)
                    }
                    _ => unreachable!(),
                };
                let tex = parvo::Texture::from_texels(w, h, f, texels).unwrap();
                check_chain(
                    tex,
                    &MipOptions::with_filter(filter),
                    &format!("opaque {filter} {ty} {w}x{h}"),
                );
            }
        }
    }
}
