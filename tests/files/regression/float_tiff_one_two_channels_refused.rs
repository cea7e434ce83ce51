//! Issue 18, smaller point: 1- and 2-channel float TIFFs were refused with
//! decoder jargon (`Unknown(32)`, `Multiband {…}`). They are read now
//! (maketx reads them), and what is still unsupported is said in words.

use super::util::s;
use tiff::encoder::colortype::{ColorType, Gray32Float};
use tiff::tags::{PhotometricInterpretation, SampleFormat};

/// Grey + alpha as two 32-bit floats (the crate has no such colour type).
struct GrayA32Float;
impl ColorType for GrayA32Float {
    type Inner = f32;
    const TIFF_VALUE: PhotometricInterpretation = PhotometricInterpretation::BlackIsZero;
    const BITS_PER_SAMPLE: &'static [u16] = &[32, 32];
    const SAMPLE_FORMAT: &'static [SampleFormat] = &[SampleFormat::IEEEFP, SampleFormat::IEEEFP];
    fn horizontal_predict(row: &[f32], result: &mut Vec<f32>) {
        result.extend_from_slice(row);
    }
}

#[test]
fn one_and_two_channel_float_tiffs_load() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("g.tif");
    let mut e = tiff::encoder::TiffEncoder::new(std::fs::File::create(&p).unwrap()).unwrap();
    e.write_image::<Gray32Float>(2, 1, &[0.5, 7.25]).unwrap();
    let l = parvo::io::load(s(&p), &parvo::io::Limits::default()).unwrap();
    assert_eq!(l.base().to_linear(), [0.5, 7.25]);
    let p = dir.path().join("ga.tif");
    let mut e = tiff::encoder::TiffEncoder::new(std::fs::File::create(&p).unwrap()).unwrap();
    let mut img = e.new_image::<GrayA32Float>(2, 1).unwrap();
    img.encoder()
        .write_tag(tiff::tags::Tag::ExtraSamples, &[2u16][..])
        .unwrap();
    img.write_data(&[0.5, 1.0, 2.0, 0.25]).unwrap();
    let l = parvo::io::load(s(&p), &parvo::io::Limits::default()).unwrap();
    let f = l.base().format();
    assert_eq!(
        (f.channels, f.has_alpha(), f.alpha),
        (2, true, parvo::AlphaMode::Straight)
    );
    assert_eq!(l.base().to_linear(), [0.5, 1.0, 2.0, 0.25]);
}

/// CMYK was refused here; it reads as RGB since issue 53 (see
/// tiff_valid_kinds_refused.rs), R = (1 − C)(1 − K).
#[test]
fn cmyk_tiffs_read_as_rgb() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("cmyk.tif");
    let mut e = tiff::encoder::TiffEncoder::new(std::fs::File::create(&p).unwrap()).unwrap();
    e.write_image::<tiff::encoder::colortype::CMYK8>(1, 1, &[1, 2, 3, 4])
        .unwrap();
    let l = parvo::io::load(s(&p), &parvo::io::Limits::default()).unwrap();
    let want: Vec<u8> = [1.0f64, 2.0, 3.0]
        .iter()
        .map(|c| ((1.0 - c / 255.0) * (1.0 - 4.0 / 255.0) * 255.0).round() as u8)
        .collect();
    assert_eq!(l.base().texels(), &parvo::Texels::U8(want));
}
