//! EXR reading: scanline files, grey (`Y`) and layer-prefixed channels,
//! and the size limits checked on the header before any pixel is decoded.

use exr::prelude::*;
use parvo::io::{self, Limits};
use parvo::texel::{AlphaMode, ChannelType};

fn write_scanline(path: &std::path::Path, channels: &[(&str, Vec<f32>)], w: usize, h: usize) {
    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = channels
        .iter()
        .map(|(n, v)| AnyChannel::new(*n, FlatSamples::F32(v.clone())))
        .collect();
    let layer = Layer::new(
        (w, h),
        LayerAttributes::default(),
        Encoding {
            compression: Compression::ZIP16,
            blocks: Blocks::ScanLines,
            line_order: LineOrder::Increasing,
        },
        AnyChannels::sort(list),
    );
    Image::from_layer(layer).write().to_file(path).unwrap();
}

#[test]
fn scanline_grey_and_prefixed_rgba_exr_load_with_their_channels() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("y.exr");
    let y: Vec<f32> = (0..12).map(|i| i as f32 / 4.0).collect();
    write_scanline(&p, &[("Y", y.clone())], 4, 3);
    let l = io::load(p.to_str().unwrap(), &Limits::default()).unwrap();
    assert_eq!(l.base().channels(), 1);
    assert_eq!(l.base().channel_type(), ChannelType::F32);
    assert_eq!(l.base().to_linear(), y);
    assert_eq!(l.info.tile, None);
    assert!(!l.info.own_mips);

    let p = dir.path().join("rgba.exr");
    let ch = |k: f32| (0..6).map(|i| i as f32 + k).collect::<Vec<_>>();
    write_scanline(
        &p,
        &[
            ("diffuse.R", ch(0.0)),
            ("diffuse.G", ch(10.0)),
            ("diffuse.B", ch(20.0)),
            ("diffuse.A", vec![1.0; 6]),
        ],
        3,
        2,
    );
    let l = io::load(p.to_str().unwrap(), &Limits::default()).unwrap();
    assert_eq!(
        l.info.channel_names,
        ["diffuse.R", "diffuse.G", "diffuse.B", "diffuse.A"]
    );
    assert_eq!(l.base().format().alpha, AlphaMode::Premultiplied);
    assert_eq!(
        &l.base().to_linear()[..8],
        &[0.0, 10.0, 20.0, 1.0, 1.0, 11.0, 21.0, 1.0]
    );
}

#[test]
fn exr_header_sizes_are_checked_against_the_limits() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("big.exr");
    write_scanline(&p, &[("Y", vec![0.5; 64 * 64])], 64, 64);
    let small = Limits {
        max_width: 32,
        max_height: 32,
        max_alloc: 1 << 30,
    };
    let e = io::load(p.to_str().unwrap(), &small).unwrap_err();
    assert!(matches!(e, parvo::Error::Limits(_)), "{e}");
    let tight = Limits {
        max_alloc: 1000,
        ..Limits::default()
    };
    let e = io::load(p.to_str().unwrap(), &tight).unwrap_err();
    assert!(
        e.to_string()
            .contains(&parvo::setting::Setting::MaxAlloc.to_string()),
        "{e}"
    );
    assert!(io::load(p.to_str().unwrap(), &Limits::default()).is_ok());
}

#[test]
fn load_chain_returns_the_files_own_levels_or_builds_box_mips() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("y.exr");
    write_scanline(&p, &[("Y", vec![0.25; 8 * 4])], 8, 4);
    let c = io::load_chain(p.to_str().unwrap(), &Limits::default()).unwrap();
    assert_eq!(c.len(), 4, "8x4 -> 4x2 -> 2x1 -> 1x1");
    assert!(
        c.levels()
            .iter()
            .all(|l| l.to_linear().iter().all(|&v| v == 0.25))
    );
    let c = io::load_chain("builtin:checker:16", &Limits::default()).unwrap();
    assert_eq!(c.len(), 5);
}

#[test]
fn every_lossless_compression_round_trips_exactly() {
    use parvo::io::exr::ExrCompression;
    use parvo::io::{OutputKind, SaveOptions};
    use parvo::mip::{MipOptions, Rounding};
    use parvo::texel::{ColorSpace, Format};
    let dir = tempfile::tempdir().unwrap();
    // Fixed-seed noise (incompressible: exercises the raw-tile fallback)
    // next to a smooth ramp (compressible), 70x33 so edge tiles are partial.
    let mut s = 99u64;
    let v: Vec<f32> = (0..70 * 33 * 4)
        .map(|i| {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            if i % 8 < 4 {
                (s >> 40) as f32 / (1u64 << 24) as f32
            } else {
                (i % 280) as f32 / 280.0
            }
        })
        .collect();
    let f =
        Format::new(4, ChannelType::F32, ColorSpace::Linear).with_alpha(AlphaMode::Premultiplied);
    let base = parvo::Texture::from_f32(70, 33, f, v).unwrap();
    for ty in [ChannelType::F32, ChannelType::F16] {
        let t = base
            .convert(Format {
                channel_type: ty,
                ..f
            })
            .unwrap();
        let chain = parvo::mip::build(t, &MipOptions::default()).unwrap();
        for c in ExrCompression::ALL {
            let lossless = match c {
                ExrCompression::None
                | ExrCompression::Rle
                | ExrCompression::Zips
                | ExrCompression::Zip
                | ExrCompression::Piz => true,
                ExrCompression::Pxr24 => ty == ChannelType::F16,
                _ => false,
            };
            if !lossless {
                continue;
            }
            let p = dir.path().join(format!("{c}-{ty}.exr"));
            let opts = SaveOptions {
                exr: parvo::io::exr::ExrOptions {
                    compression: c,
                    tile: (32, 16),
                },
                ..SaveOptions::default()
            };
            io::save(chain.levels(), Rounding::Down, &p, OutputKind::EXR, &opts).unwrap();
            let back = io::load(p.to_str().unwrap(), &Limits::default()).unwrap();
            assert_eq!(back.levels, chain.levels(), "{c} {ty}");
        }
    }
}
