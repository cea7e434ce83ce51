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

/// One directory of a TIFF written byte by byte by [`write_raw_tiff`]
/// (independent of the `tiff` crate and of parvo, so a test can write
/// what neither writes: planar data, a missing tag, a looping chain).
pub struct RawIfd {
    /// Tags and their SHORT (3) or LONG (4) values, or ASCII (2) text as
    /// bytes; the strip or tile offsets and byte counts are added.
    pub entries: Vec<(u16, u16, Vec<u32>)>,
    /// The strips (or tiles), in file order.
    pub chunks: Vec<Vec<u8>>,
    /// Tiles (TileOffsets/TileByteCounts) rather than strips.
    pub tiled: bool,
}

/// A little-endian classic TIFF of `ifds`, each directory pointing to the
/// next; the last points back to directory `loop_to` when given.
pub fn write_raw_tiff(path: &Path, ifds: &[RawIfd], loop_to: Option<usize>) {
    let mut out: Vec<u8> = b"II*\0\0\0\0\0".to_vec();
    let mut dir_at = Vec::new();
    let mut next_field = Vec::new();
    for ifd in ifds {
        let mut offsets = Vec::new();
        for c in &ifd.chunks {
            offsets.push(out.len() as u32);
            out.extend_from_slice(c);
            if out.len() % 2 == 1 {
                out.push(0);
            }
        }
        let (o, c) = if ifd.tiled { (324, 325) } else { (273, 279) };
        let mut entries = ifd.entries.clone();
        entries.push((o, 4, offsets));
        entries.push((c, 4, ifd.chunks.iter().map(|c| c.len() as u32).collect()));
        entries.sort_by_key(|e| e.0);
        let at = out.len();
        dir_at.push(at as u32);
        let values_at = at + 2 + 12 * entries.len() + 4;
        let mut values = Vec::new();
        let mut dir = (entries.len() as u16).to_le_bytes().to_vec();
        for (tag, ty, v) in &entries {
            let bytes: Vec<u8> = match ty {
                2 => v.iter().map(|&b| b as u8).collect(),
                3 => v.iter().flat_map(|&x| (x as u16).to_le_bytes()).collect(),
                _ => v.iter().flat_map(|&x| x.to_le_bytes()).collect(),
            };
            dir.extend_from_slice(&tag.to_le_bytes());
            dir.extend_from_slice(&ty.to_le_bytes());
            dir.extend_from_slice(&(v.len() as u32).to_le_bytes());
            if bytes.len() <= 4 {
                let mut f = bytes.clone();
                f.resize(4, 0);
                dir.extend_from_slice(&f);
            } else {
                dir.extend_from_slice(&((values_at + values.len()) as u32).to_le_bytes());
                values.extend_from_slice(&bytes);
                if values.len() % 2 == 1 {
                    values.push(0);
                }
            }
        }
        next_field.push(out.len() + dir.len());
        dir.extend_from_slice(&[0; 4]);
        out.extend_from_slice(&dir);
        out.extend_from_slice(&values);
    }
    out[4..8].copy_from_slice(&dir_at[0].to_le_bytes());
    for k in 1..ifds.len() {
        let f = next_field[k - 1];
        out[f..f + 4].copy_from_slice(&dir_at[k].to_le_bytes());
    }
    if let Some(to) = loop_to {
        let f = next_field[ifds.len() - 1];
        out[f..f + 4].copy_from_slice(&dir_at[to].to_le_bytes());
    }
    std::fs::write(path, out).unwrap();
}

/// A fixed-seed generator of test data (SplitMix64).
pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
}

/// The path of a peer project's test file under tests/data/peer/.
pub fn peer(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/peer")
        .join(name)
}
