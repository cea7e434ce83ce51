//! The pipeline's streamed chain (level 0 converted band by band, level 1
//! filtered from level-0 rows decoded as they are read, never a whole f32
//! copy of level 0) equals, bit for bit, the whole-image chain: level 0
//! decoded whole to linear f32, `mip::build` in f32, each level's alpha
//! associated and converted to the output type. Sizes where bands meet
//! (more than one 64-row band, a last partial band), straight alpha that
//! varies (alpha-weighted boxes), sRGB and linear, u8 and u16 sources, and
//! the outputs that convert (half EXR, premultiplied; f32 KTX2; u16 PNG).
//!
//! The second test holds the general band-by-band build (level 0 encoded
//! band by band, level 1 filtered from the level-0 rows each band's taps
//! name) to the same reference for every filter, odd sizes (the
//! polyphase box), every wrap mode (wrapped taps reach rows of the far
//! edge) and float sources (half and float EXR, premultiplied).

use parvo::io::{self, Limits, OutputKind, SaveOptions};
use parvo::mip::{self, MipFilter, MipOptions};
use parvo::pipeline::{self, Job, Settings};
use parvo::texel::{AlphaMode, ChannelType, ColorSpace, Format, Texels};
use parvo::texture::Texture;
use parvo::wrap::Wrap;

struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        self.0 >> 33
    }
}

/// RGBA with alpha varying in blocks (so some 2×2 boxes weight by alpha,
/// others are opaque), of `ty` (u8 or u16), sRGB.
fn source(w: u32, h: u32, ty: ChannelType, seed: u64) -> Texture {
    let mut r = Rng(seed);
    let n = (w * h * 4) as usize;
    let f = Format::new(4, ty, ColorSpace::Srgb);
    let alpha_of = |i: usize, r: &mut Rng| -> u64 {
        let (x, y) = ((i / 4) as u32 % w, (i / 4) as u32 / w);
        if (x / 6 + y / 5) % 3 == 0 {
            r.next()
        } else {
            u64::MAX
        }
    };
    match ty {
        ChannelType::U8 => {
            let v: Vec<u8> = (0..n)
                .map(|i| {
                    if i % 4 == 3 {
                        alpha_of(i, &mut r) as u8
                    } else {
                        r.next() as u8
                    }
                })
                .collect();
            Texture::from_u8(w, h, f, v).unwrap()
        }
        _ => {
            let v: Vec<u16> = (0..n)
                .map(|i| {
                    if i % 4 == 3 {
                        alpha_of(i, &mut r) as u16
                    } else {
                        r.next() as u16
                    }
                })
                .collect();
            Texture::from_u16(w, h, f, v).unwrap()
        }
    }
}

/// The whole-image chain, as the pipeline built it before streaming.
fn whole(base: &Texture, out: Format, premultiply: bool) -> Vec<Texture> {
    whole_with(base, out, premultiply, &MipOptions::default())
}

/// [`whole`] with other mip options (filter, wrap).
fn whole_with(
    base: &Texture,
    out: Format,
    premultiply: bool,
    options: &MipOptions,
) -> Vec<Texture> {
    let f32fmt =
        Format::new(4, ChannelType::F32, ColorSpace::Linear).with_alpha(base.format().alpha);
    let lin = base.convert(f32fmt).unwrap();
    let chain = mip::build(lin, options).unwrap();
    chain
        .into_levels()
        .into_iter()
        .map(|mut l| {
            if premultiply {
                let Texels::F32(v) = l.texels_mut() else {
                    unreachable!()
                };
                for px in v.chunks_exact_mut(4) {
                    let a = px[3];
                    px[..3].iter_mut().for_each(|c| *c *= a);
                }
                let f = l.format().with_alpha(AlphaMode::Premultiplied);
                l = l.reinterpret(f).unwrap();
            }
            let target = Format {
                alpha: l.format().alpha,
                ..out
            };
            l.convert(target).unwrap()
        })
        .collect()
}

#[test]
fn streamed_chains_equal_whole_image_chains_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let mut case = 0;
    for (w, h) in [(130, 258), (64, 64), (2, 200), (1024, 6)] {
        for ty in [ChannelType::U8, ChannelType::U16] {
            case += 1;
            let src = source(w, h, ty, case);
            let png = dir.path().join(format!("src{case}_{{level}}.png"));
            io::png_levels::save(std::slice::from_ref(&src), &png).unwrap();
            let input = png.to_str().unwrap().replace("{level}", "0");
            // (output, output type, premultiplied)
            let outs = [
                ("exr", ChannelType::F16, true),
                ("ktx2", ChannelType::F32, false),
                ("png", ChannelType::U16, false),
            ];
            for (ext, ty_out, premul) in outs {
                if ty_out == ty {
                    continue; // same type: no conversion, not streamed
                }
                let out = if ext == "png" {
                    dir.path().join(format!("o{case}_{{level}}.png"))
                } else {
                    dir.path().join(format!("o{case}.{ext}"))
                };
                let settings = Settings {
                    out_type: Some(ty_out),
                    ..Settings::default()
                };
                let job = Job::new(&input, &out).unwrap();
                pipeline::process(&job, &settings, &mut |_| {}).unwrap();
                let got: Vec<Texture> = if ext == "png" {
                    (0..)
                        .map(|k| out.to_str().unwrap().replace("{level}", &k.to_string()))
                        .take_while(|p| std::path::Path::new(p).exists())
                        .map(|p| io::load(&p, &Limits::default()).unwrap().into_base())
                        .collect()
                } else {
                    io::load(out.to_str().unwrap(), &Limits::default())
                        .unwrap()
                        .levels
                };
                let cs = if ty_out.is_float() {
                    ColorSpace::Linear
                } else {
                    ColorSpace::Srgb
                };
                let want = whole(&src, Format::new(4, ty_out, cs), premul);
                assert_eq!(got.len(), want.len(), "{w}x{h} {ty} -> {ext}");
                for (k, (g, e)) in got.iter().zip(&want).enumerate() {
                    assert!(
                        g.texels() == e.texels(),
                        "{w}x{h} {ty} -> {ext}: level {k} differs"
                    );
                }
            }
        }
    }
}

/// Band-by-band chains to EXR are written as they are built: level 0 a
/// group of rows at a time, the group a multiple of the tile height and of
/// the band (`io::exr::save_streamed`), or the whole chain first when no
/// group of at most 256 rows is both (tile height 63 with the box's bands
/// of 2^m rows). Every tile shape must
/// give the whole-image chain, and the same bytes as the whole-chain
/// writer (`io::save`) with the same header.
#[test]
fn fused_exr_writes_equal_whole_chain_writes_for_every_tile_shape() {
    let dir = tempfile::tempdir().unwrap();
    // The box shortcut (bands of 2^m rows) and the general band-by-band
    // build (Kaiser, odd size: level 0 in any rows, level 1 at the end).
    for (filter, w, h) in [(MipFilter::Box, 256, 200), (MipFilter::Kaiser, 131, 67)] {
        let src = source(w, h, ChannelType::U8, 77);
        let png = dir.path().join(format!("src{w}_{{level}}.png"));
        io::png_levels::save(std::slice::from_ref(&src), &png).unwrap();
        let input = png.to_str().unwrap().replace("{level}", "0");
        let options = MipOptions {
            filter,
            ..MipOptions::default()
        };
        let want = whole_with(
            &src,
            Format::new(4, ChannelType::F16, ColorSpace::Linear),
            true,
            &options,
        );
        for tile in [
            (64, 64),
            (8, 8),
            (24, 48),
            (64, 16),
            (63, 63),
            (256, 256),
            (5, 200),
        ] {
            let case = format!("{filter} {w}x{h}, tile {tile:?}");
            let out = dir.path().join(format!("o{w}_{}x{}.exr", tile.0, tile.1));
            let exr = io::exr::ExrOptions {
                tile,
                ..Default::default()
            };
            let settings = Settings {
                exr,
                filter,
                ..Settings::default()
            };
            let job = Job::new(&input, &out).unwrap();
            pipeline::process(&job, &settings, &mut |_| {}).unwrap();
            let got = io::load(out.to_str().unwrap(), &Limits::default())
                .unwrap()
                .levels;
            assert_eq!(got.len(), want.len(), "{case}");
            for (k, (g, e)) in got.iter().zip(&want).enumerate() {
                assert!(g.texels() == e.texels(), "{case}: level {k} differs");
            }
            // The whole-chain writer, with the header the pipeline wrote.
            let stored = io::stored_fingerprint(&out, OutputKind::EXR);
            let again = dir.path().join(format!("w{w}_{}x{}.exr", tile.0, tile.1));
            let save = SaveOptions {
                exr,
                fingerprint: stored,
                attributes: vec![
                    ("parvo:filter".into(), filter.to_string()),
                    ("parvo:source".into(), src.format().to_string()),
                    (
                        "parvo:rounding".into(),
                        mip::Rounding::default().to_string(),
                    ),
                ],
                ..SaveOptions::default()
            };
            io::save(
                &got,
                mip::Rounding::default(),
                &again,
                OutputKind::EXR,
                &save,
            )
            .unwrap();
            assert!(
                std::fs::read(&out).unwrap() == std::fs::read(&again).unwrap(),
                "{case}: bytes differ from the whole-chain writer"
            );
        }
        // A zero tile height from a library caller is an error, not a
        // group size search that never ends.
        let out = dir.path().join(format!("zero{w}.exr"));
        let settings = Settings {
            exr: parvo::io::exr::ExrOptions {
                tile: (64, 0),
                ..Default::default()
            },
            filter,
            ..Settings::default()
        };
        let job = Job::new(&input, &out).unwrap();
        assert!(pipeline::process(&job, &settings, &mut |_| {}).is_err());
        assert!(!out.exists());
    }
}

/// Random RGBA floats in [0, 1.5) with alpha in [0, 1), premultiplied, as
/// an EXR holds them.
fn float_source(w: u32, h: u32, ty: ChannelType, seed: u64) -> Texture {
    let mut r = Rng(seed);
    let mut v: Vec<f32> = Vec::with_capacity((w * h * 4) as usize);
    for _ in 0..w * h {
        let a = (r.next() % 1000) as f32 / 1000.0;
        for _ in 0..3 {
            v.push((r.next() % 1500) as f32 / 1000.0 * a);
        }
        v.push(a);
    }
    let f =
        Format::new(4, ChannelType::F32, ColorSpace::Linear).with_alpha(AlphaMode::Premultiplied);
    let t = Texture::from_f32(w, h, f, v).unwrap();
    t.convert(Format {
        channel_type: ty,
        ..f
    })
    .unwrap()
}

#[test]
fn banded_chains_equal_whole_image_chains_for_every_filter_and_wrap_mode() {
    let dir = tempfile::tempdir().unwrap();
    let mut case = 0;
    // Odd sizes (the polyphase box), one even size for the other filters;
    // level 1 has 33, 75 and 48 rows: bands of 16 meet inside the taps.
    for (w, h) in [(131u32, 67u32), (37, 150), (64, 96)] {
        for ty in [
            ChannelType::U8,
            ChannelType::U16,
            ChannelType::F16,
            ChannelType::F32,
        ] {
            case += 1;
            let (input, base) = if ty.is_float() {
                let src = float_source(w, h, ty, case);
                let p = dir.path().join(format!("src{case}.exr"));
                io::save(
                    std::slice::from_ref(&src),
                    parvo::mip::Rounding::Down,
                    &p,
                    OutputKind::EXR,
                    &SaveOptions::default(),
                )
                .unwrap();
                (p.to_str().unwrap().to_string(), src)
            } else {
                let src = source(w, h, ty, case);
                let png = dir.path().join(format!("src{case}_{{level}}.png"));
                io::png_levels::save(std::slice::from_ref(&src), &png).unwrap();
                (png.to_str().unwrap().replace("{level}", "0"), src)
            };
            // What the pipeline reads (alpha mode, colour space).
            let base_read = io::load(&input, &Limits::default()).unwrap().into_base();
            assert!(base_read.texels() == base.texels());
            let straight = base_read.format().alpha == AlphaMode::Straight;
            for filter in MipFilter::ALL {
                for wrap in ["repeat", "clamp", "mirror", "border"] {
                    let wrap: Wrap = wrap.parse().unwrap();
                    // (extension, output type, premultiplied on the way)
                    let outs = [
                        ("exr", ChannelType::F16, straight),
                        ("ktx2", ChannelType::F32, false),
                    ];
                    for (ext, ty_out, premul) in outs {
                        if ty_out == ty {
                            continue; // same type: no conversion, built whole
                        }
                        let out = dir.path().join(format!("o{case}.{ext}"));
                        let settings = Settings {
                            out_type: Some(ty_out),
                            filter,
                            wrap: Some(wrap),
                            ..Settings::default()
                        };
                        let job = Job::new(&input, &out).unwrap();
                        pipeline::process(&job, &settings, &mut |_| {}).unwrap();
                        let got = io::load(out.to_str().unwrap(), &Limits::default())
                            .unwrap()
                            .levels;
                        let options = MipOptions {
                            filter,
                            wrap,
                            ..MipOptions::default()
                        };
                        let want = whole_with(
                            &base_read,
                            Format::new(4, ty_out, ColorSpace::Linear),
                            premul,
                            &options,
                        );
                        assert_eq!(
                            got.len(),
                            want.len(),
                            "{w}x{h} {ty} {filter:?} {wrap:?} -> {ext}"
                        );
                        for (k, (g, e)) in got.iter().zip(&want).enumerate() {
                            assert!(
                                g.texels() == e.texels(),
                                "{w}x{h} {ty} {filter:?} {wrap:?} -> {ext}: level {k} differs"
                            );
                        }
                    }
                }
            }
        }
    }
}
