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
