//! Helpers shared by the regression tests: running the `parvo` binary and
//! writing input files with other libraries than parvo's own writers.
#![allow(dead_code)]

use std::path::Path;
use std::process::{Command, Output};

use exr::prelude::*;

/// The binary under test: this build's, or the one `PARVO_BIN` names (to
/// check that a regression test fails on an older build).
pub fn bin() -> std::path::PathBuf {
    std::env::var_os("PARVO_BIN")
        .map(Into::into)
        .unwrap_or_else(|| env!("CARGO_BIN_EXE_parvo").into())
}

pub fn parvo(args: &[&str]) -> Output {
    Command::new(bin()).args(args).output().expect("run parvo")
}

pub fn parvo_stdin(args: &[&str], stdin: &str) -> Output {
    use std::io::Write;
    let mut child = Command::new(bin())
        .args(args)
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("run parvo");
    child
        .stdin
        .take()
        .unwrap()
        .write_all(stdin.as_bytes())
        .unwrap();
    child.wait_with_output().unwrap()
}

pub fn ok(o: &Output) -> String {
    assert!(
        o.status.success(),
        "parvo failed ({:?}): {}",
        o.status.code(),
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A scanline f32 EXR written with the `exr` crate (not parvo's writer),
/// channels given by name, each `w·h` values row-major.
pub fn write_exr(path: &Path, channels: &[(&str, Vec<f32>)], w: usize, h: usize) {
    write_exr_with(path, channels, w, h, LayerAttributes::default(), None);
}

/// As [`write_exr`], with layer attributes and an optional data window
/// origin inside a larger display window `(x, y, width, height)`.
pub fn write_exr_with(
    path: &Path,
    channels: &[(&str, Vec<f32>)],
    w: usize,
    h: usize,
    attrs: LayerAttributes,
    display: Option<(i32, i32, usize, usize)>,
) {
    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = channels
        .iter()
        .map(|(n, v)| AnyChannel::new(*n, FlatSamples::F32(v.clone())))
        .collect();
    let layer = Layer::new(
        (w, h),
        attrs,
        Encoding {
            compression: Compression::ZIP16,
            blocks: Blocks::ScanLines,
            line_order: LineOrder::Increasing,
        },
        AnyChannels::sort(list),
    );
    let mut image = Image::from_layer(layer);
    if let Some((x, y, dw, dh)) = display {
        image.attributes.display_window = IntegerBounds::new((0, 0), (dw, dh));
        image.layer_data.attributes.layer_position = Vec2(x, y);
    }
    image.write().to_file(path).unwrap();
}

/// Level `k` of a PNG level template as 16-bit codes (8-bit files are
/// widened by 257), read with the `image` crate.
pub fn png_u16(path: &Path) -> (u32, u32, usize, Vec<u16>) {
    let img = image::open(path).unwrap();
    let ch = img.color().channel_count() as usize;
    let (w, h) = (img.width(), img.height());
    let v = match img {
        image::DynamicImage::ImageLuma8(b) => {
            b.into_raw().iter().map(|&x| x as u16 * 257).collect()
        }
        image::DynamicImage::ImageLumaA8(b) => {
            b.into_raw().iter().map(|&x| x as u16 * 257).collect()
        }
        image::DynamicImage::ImageRgb8(b) => b.into_raw().iter().map(|&x| x as u16 * 257).collect(),
        image::DynamicImage::ImageRgba8(b) => {
            b.into_raw().iter().map(|&x| x as u16 * 257).collect()
        }
        image::DynamicImage::ImageLuma16(b) => b.into_raw(),
        image::DynamicImage::ImageLumaA16(b) => b.into_raw(),
        image::DynamicImage::ImageRgb16(b) => b.into_raw(),
        image::DynamicImage::ImageRgba16(b) => b.into_raw(),
        other => panic!("unexpected PNG layout {:?}", other.color()),
    };
    (w, h, ch, v)
}

/// A TIFF written with the `tiff` crate's encoder: one directory per
/// `(width, height, samples)` entry, 8-bit samples of colour type `C`, each
/// with the extra tags given (`ExtraSamples`, Pixar's `textureformat`, ...).
pub fn write_tiff_u8<C>(path: &Path, dirs: &[(u32, u32, Vec<u8>)], tags: &[(u16, TagValue)])
where
    C: tiff::encoder::colortype::ColorType<Inner = u8>,
{
    let mut enc = tiff::encoder::TiffEncoder::new(std::fs::File::create(path).unwrap()).unwrap();
    for (w, h, px) in dirs {
        let mut img = enc.new_image::<C>(*w, *h).unwrap();
        for (tag, v) in tags {
            let t = tiff::tags::Tag::from_u16_exhaustive(*tag);
            match v {
                TagValue::Short(s) => img.encoder().write_tag(t, s.as_slice()).unwrap(),
                TagValue::Ascii(s) => img.encoder().write_tag(t, s.as_str()).unwrap(),
            }
        }
        img.write_data(px).unwrap();
    }
}

/// A tag value for [`write_tiff_u8`].
pub enum TagValue {
    Short(Vec<u16>),
    Ascii(String),
}
