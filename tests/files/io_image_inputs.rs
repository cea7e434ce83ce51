//! The `image` codecs: JPEG (sRGB by default), 16-bit TIFF and Radiance
//! HDR (linear), grey kept as one channel.

use parvo::io::{self, FileFormat, Limits};
use parvo::texel::{ChannelType, ColorSpace};

fn load(p: &std::path::Path) -> io::Loaded {
    io::load(p.to_str().unwrap(), &Limits::default()).unwrap()
}

#[test]
fn jpeg_tiff_and_hdr_inputs_load_with_their_type_and_colour_space() {
    let dir = tempfile::tempdir().unwrap();

    let jpg = dir.path().join("g.jpg");
    image::GrayImage::from_fn(16, 8, |x, _| image::Luma([(x * 16) as u8]))
        .save(&jpg)
        .unwrap();
    let l = load(&jpg);
    assert_eq!(l.info.format, FileFormat::Jpeg);
    assert_eq!(l.base().channels(), 1);
    assert_eq!(l.base().format().color_space, ColorSpace::Srgb);

    let tif = dir.path().join("c.tiff");
    let px: Vec<u16> = (0..3u16)
        .flat_map(|y| (0..5u16).flat_map(move |x| [x * 1000, y * 1000, 65535]))
        .collect();
    tiff::encoder::TiffEncoder::new(std::fs::File::create(&tif).unwrap())
        .unwrap()
        .write_image::<tiff::encoder::colortype::RGB16>(5, 3, &px)
        .unwrap();
    let l = load(&tif);
    assert_eq!(l.info.format, FileFormat::Tiff);
    assert_eq!(l.base().channel_type(), ChannelType::U16);
    assert_eq!(l.base().format().color_space, ColorSpace::Linear);
    assert_eq!(
        l.base().texel_linear(4, 2)[..3],
        [4000.0 / 65535.0, 2000.0 / 65535.0, 1.0]
    );

    let hdr = dir.path().join("h.hdr");
    image::Rgb32FImage::from_fn(4, 4, |x, _| image::Rgb([x as f32 * 2.0, 0.5, 0.0]))
        .save(&hdr)
        .unwrap();
    let l = load(&hdr);
    assert_eq!(l.info.format, FileFormat::Hdr);
    assert_eq!(l.base().channel_type(), ChannelType::F32);
    assert_eq!(l.base().channels(), 3);
    assert_eq!(
        l.base().texel_linear(3, 0)[0],
        6.0,
        "HDR keeps values above 1"
    );
}

/// `load_overlapped` hands the overlap the header's size, channels and
/// type while a one-thread decoder runs (8-bit and 16-bit PNG, HDR),
/// loads the same texels as `load`, and never calls it for formats it
/// does not decode on one thread (OpenEXR, `builtin:`).
#[test]
fn overlapped_loads_tell_the_header_and_load_the_same_texels() {
    let dir = tempfile::tempdir().unwrap();
    let png8 = dir.path().join("a.png");
    image::RgbaImage::from_fn(37, 11, |x, y| image::Rgba([x as u8, y as u8, 7, 200]))
        .save(&png8)
        .unwrap();
    let png16 = dir.path().join("b.png");
    image::ImageBuffer::<image::LumaA<u16>, _>::from_fn(5, 9, |x, y| {
        image::LumaA([x as u16 * 999, y as u16])
    })
    .save(&png16)
    .unwrap();
    let hdr = dir.path().join("h.hdr");
    image::Rgb32FImage::from_fn(6, 2, |x, _| image::Rgb([x as f32, 0.5, 0.0]))
        .save(&hdr)
        .unwrap();
    let exr = dir.path().join("e.exr");
    io::save(
        &[parvo::texture::Texture::from_f32(
            4,
            4,
            parvo::texel::Format::new(4, ChannelType::F32, ColorSpace::Linear),
            (0..64).map(|i| i as f32 / 64.0).collect(),
        )
        .unwrap()],
        parvo::mip::Rounding::Down,
        &exr,
        io::OutputKind::EXR,
        &io::SaveOptions {
            exr: io::exr::ExrOptions {
                tile: (16, 16),
                ..Default::default()
            },
            ..io::SaveOptions::default()
        },
    )
    .unwrap();
    let cases = [
        (png8.clone(), Some((37, 11, 4, ChannelType::U8))),
        (png16, Some((5, 9, 2, ChannelType::U16))),
        (hdr, Some((6, 2, 3, ChannelType::F32))),
        (exr, None),
        ("builtin:checker:16".into(), None),
    ];
    for (path, want) in cases {
        let spec = path.to_str().unwrap();
        let mut told = Vec::new();
        let got = io::load_overlapped(
            spec,
            &Limits::default(),
            &io::LoadOptions::default(),
            Some(&mut |w, h, c, t| told.push((w, h, c, t))),
        )
        .unwrap();
        assert_eq!(told, want.into_iter().collect::<Vec<_>>(), "{spec}");
        let plain = io::load(spec, &Limits::default()).unwrap();
        assert!(got.base().texels() == plain.base().texels(), "{spec}");
    }
}
