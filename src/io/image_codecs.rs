//! The formats the `image` crate decodes (PNG, JPEG, Radiance HDR, and
//! whatever else it is built with): the reader of every file no other
//! container claims. PNG's colour chunks, EXIF orientation and text
//! metadata are read here; OpenImageIO's readings are the reference.

use std::path::Path;

use super::container::Container;
use super::{FileFormat, Limits, LoadOptions, Loaded, Overlap, SourceInfo, image_errors, orient};
use crate::error::{Error, Result};
use crate::setting::Setting;
use crate::texel::{ChannelType, ColorSpace, Format};
use crate::texture::Texture;

/// The `image` crate's decoders (see the module docs).
pub struct ImageCodecs;

impl Container for ImageCodecs {
    fn id(&self) -> &'static str {
        "image"
    }
    fn name(&self) -> &'static str {
        "image"
    }
    fn read_extensions(&self) -> &'static [&'static str] {
        &["png", "jpg", "jpeg", "hdr"]
    }
    fn detect(&self, _magic: &[u8]) -> bool {
        true
    }
    fn load(
        &self,
        path: &Path,
        limits: &Limits,
        options: &LoadOptions,
        overlap: Option<Overlap<'_>>,
    ) -> Result<Loaded> {
        load_image(path, limits, options, overlap)
    }
}

/// The colour transfer a PNG's chunks declare, as OpenImageIO reads them:
/// `sRGB` → sRGB; else `cICP` (transfer 13 sRGB, 8 linear); else `gAMA`
/// (1.0 linear, 1/2.2 sRGB, other exponents sRGB with a note); an `iCCP`
/// profile is not interpreted (sRGB, with a note unless it names sRGB); no
/// chunk at all means sRGB, at any bit depth.
fn png_transfer(path: &Path, limits: &Limits) -> Result<(ColorSpace, Option<String>, bool)> {
    let file = std::fs::File::open(path).map_err(|e| Error::Io {
        path: path.to_path_buf(),
        action: "cannot open".into(),
        error: e,
    })?;
    let reader = png::Decoder::new_with_limits(
        std::io::BufReader::new(file),
        png::Limits {
            bytes: usize::try_from(limits.max_alloc).unwrap_or(usize::MAX),
        },
    )
    .read_info()
    .map_err(|e| image_errors::png_error(limits, &e))?;
    let info = reader.info();
    if info.srgb.is_some() {
        return Ok((ColorSpace::Srgb, None, true));
    }
    if let Some(c) = &info.coding_independent_code_points {
        return Ok(match c.transfer_function {
            13 => (ColorSpace::Srgb, None, true),
            8 => (ColorSpace::Linear, None, true),
            t => (
                ColorSpace::Srgb,
                Some(format!(
                    "cICP transfer characteristics {t} is neither sRGB (13) nor linear (8): read as sRGB"
                )),
                true,
            ),
        });
    }
    if let Some(g) = info.gama_chunk {
        let gamma = g.into_value() as f64;
        if (gamma - 1.0).abs() < 0.01 {
            return Ok((ColorSpace::Linear, None, true));
        }
        let note = ((1.0 / gamma - 2.2).abs() > 0.05).then(|| {
            format!(
                "gAMA {gamma:.5} (a {:.2} power law) read as sRGB, parvo's nearest transfer",
                1.0 / gamma
            )
        });
        return Ok((ColorSpace::Srgb, note, true));
    }
    if let Some(icc) = &info.icc_profile {
        let names_srgb = icc.windows(4).any(|w| w == b"sRGB");
        return Ok((
            ColorSpace::Srgb,
            (!names_srgb).then(|| "the ICC profile is not interpreted: read as sRGB".to_string()),
            true,
        ));
    }
    // Nothing said: OpenImageIO's reading, marked as an assumption.
    Ok((ColorSpace::Srgb, None, false))
}

/// What a PNG's chunks before the image data say that the `image` decoder
/// does not apply (see [`png_extras`]).
#[derive(Debug, Default)]
struct PngExtras {
    /// For 1-, 2- and 4-bit grey whose `tRNS` grey lies beyond the bit
    /// depth: the expanded 8-bit grey that is transparent. libpng (so
    /// OpenImageIO) keeps the sample's low bits, as the PNG specification
    /// says a sample is stored; the `png` decoder compares the whole low
    /// byte and so makes nothing transparent.
    grey_trns: Option<u8>,
    /// The orientation tag of the `eXIf` chunk, if it has one.
    exif_orientation: Option<u16>,
    /// The orientation tag of the EXIF block ImageMagick stores as hex in
    /// a `Raw profile type exif` text chunk, if it has one.
    text_orientation: Option<u16>,
    /// What was not understood, one sentence each.
    notes: Vec<String>,
}

/// The text of ImageMagick's raw profile form (`\nexif\n<length>\n<hex>`):
/// the EXIF block as bytes from its TIFF header on, when the text is one.
/// As OpenImageIO and Pillow read it: hex digits after the length, other
/// characters skipped; the block's `Exif\0\0` prefix dropped (Pillow also
/// takes a block that starts with the TIFF header).
fn raw_profile_exif(text: &str) -> Option<Vec<u8>> {
    let rest = text.trim_start().strip_prefix("exif")?.trim_start();
    let end = rest
        .find(|c: char| !c.is_ascii_digit())
        .unwrap_or(rest.len());
    let declared: usize = rest[..end].parse().ok().filter(|&n| n > 0)?;
    let nibbles: Vec<u8> = rest[end..]
        .chars()
        .filter_map(|c| c.to_digit(16).map(|d| d as u8))
        .collect();
    let mut bytes: Vec<u8> = nibbles.chunks_exact(2).map(|p| p[0] << 4 | p[1]).collect();
    bytes.truncate(declared);
    if bytes.len() >= 6 && bytes[..4].eq_ignore_ascii_case(b"Exif") {
        Some(bytes.split_off(6))
    } else if bytes.starts_with(b"II*\0") || bytes.starts_with(b"MM\0*") {
        Some(bytes)
    } else {
        None
    }
}

/// Read the chunks before a PNG's image data for what [`PngExtras`]
/// holds. A file whose header does not read gives nothing (the decoder
/// reports it).
fn png_extras(path: &Path) -> PngExtras {
    use image::metadata::Orientation;
    let mut out = PngExtras::default();
    let Ok(file) = std::fs::File::open(path) else {
        return out;
    };
    let mut decoder = png::Decoder::new(std::io::BufReader::new(file));
    decoder.set_ignore_text_chunk(false);
    let Ok(reader) = decoder.read_info() else {
        return out;
    };
    let info = reader.info();
    if info.color_type == png::ColorType::Grayscale
        && let Some(&[low]) = info.trns.as_deref()
    {
        let max = match info.bit_depth {
            png::BitDepth::One => 1u8,
            png::BitDepth::Two => 3,
            png::BitDepth::Four => 15,
            _ => 255,
        };
        if low > max {
            out.grey_trns = Some((low & max) * (255 / max));
        }
    }
    let tag = |exif: &[u8]| Orientation::from_exif_chunk(exif).map(|o| o.to_exif() as u16);
    out.exif_orientation = info.exif_metadata.as_deref().and_then(tag);
    const KEY: &str = "Raw profile type exif";
    // The text can be large (an EXIF thumbnail); a profile beyond this is
    // not read.
    const LIMIT: usize = 16 << 20;
    let texts = info
        .uncompressed_latin1_text
        .iter()
        .filter(|t| t.keyword.eq_ignore_ascii_case(KEY))
        .map(|t| Some(t.text.clone()))
        .chain(
            info.compressed_latin1_text
                .iter()
                .filter(|t| t.keyword.eq_ignore_ascii_case(KEY))
                .map(|t| {
                    let mut t = t.clone();
                    t.decompress_text_with_limit(LIMIT).ok()?;
                    t.get_text().ok()
                }),
        )
        .chain(
            info.utf8_text
                .iter()
                .filter(|t| t.keyword.eq_ignore_ascii_case(KEY))
                .map(|t| {
                    let mut t = t.clone();
                    t.decompress_text_with_limit(LIMIT).ok()?;
                    t.get_text().ok()
                }),
        );
    for text in texts {
        match text.as_deref().map(raw_profile_exif) {
            Some(Some(exif)) => {
                out.text_orientation = out.text_orientation.or_else(|| tag(&exif));
            }
            Some(None) => out.notes.push(format!(
                "the `{KEY}` text chunk is not an EXIF block in ImageMagick's hex form: ignored"
            )),
            None => out.notes.push(format!(
                "the compressed `{KEY}` text chunk does not inflate (damaged, or beyond 16 MiB): \
                 ignored"
            )),
        }
    }
    out
}

fn load_image(
    path: &Path,
    limits: &Limits,
    options: &LoadOptions,
    overlap: Option<Overlap<'_>>,
) -> Result<Loaded> {
    use image::ImageDecoder;
    let io_err = |action: &str, e| Error::Io {
        path: path.to_path_buf(),
        action: action.into(),
        error: e,
    };
    let mut reader = image::ImageReader::open(path)
        .map_err(|e| io_err("cannot open", e))?
        .with_guessed_format()
        .map_err(|e| io_err("cannot read", e))?;
    let file_format = match reader.format() {
        Some(image::ImageFormat::Png) => FileFormat::Png,
        Some(image::ImageFormat::Jpeg) => FileFormat::Jpeg,
        Some(image::ImageFormat::Hdr) => FileFormat::Hdr,
        _ => {
            return Err(Error::Decode {
                format: "input",
                reason: "not a file format parvo reads (PNG, JPEG, TIFF, Radiance HDR, OpenEXR, \
                         KTX2, DDS)"
                    .into(),
            });
        }
    };
    let mut notes = Vec::new();
    let mut color_stated = true;
    let png_cs = if file_format == FileFormat::Png {
        let (cs, note, stated) = png_transfer(path, limits)?;
        notes.extend(note);
        color_stated = stated;
        Some(cs)
    } else {
        None
    };
    let extras = if file_format == FileFormat::Png {
        png_extras(path)
    } else {
        PngExtras::default()
    };
    notes.extend(extras.notes.iter().cloned());
    if file_format == FileFormat::Jpeg {
        // zune-jpeg decodes a file cut short without a word, as libjpeg
        // does with a warning (and OpenImageIO without one).
        if !image_errors::jpeg_has_end_marker(path).map_err(|e| io_err("cannot read", e))? {
            notes.push(
                "the JPEG ends without its end-of-image marker: it is probably truncated, and \
                 what lies past its end is decoded from incomplete data"
                    .into(),
            );
        }
    }
    let lim = |e: image::ImageError| image_errors::image_error(file_format, limits, e);
    // Width and height are checked below against `limits` (whose error
    // names the limit); the decoders keep the allocation limit.
    let mut il = limits.to_image();
    il.max_image_width = None;
    il.max_image_height = None;
    reader.limits(il);
    let mut decoder = reader.into_decoder().map_err(lim)?;
    let mut orientation = decoder.orientation().map_err(lim)?.to_exif() as u16;
    // A PNG's `eXIf` tag first, else ImageMagick's text form (OpenImageIO
    // reads both, the chunk last).
    if extras.exif_orientation.is_none()
        && let Some(o) = extras.text_orientation
    {
        orientation = o;
    }
    let (w, h) = decoder.dimensions();
    limits.check(w as u64, h as u64, decoder.total_bytes())?;
    let mut img = decode(decoder, file_format, overlap, lim)?;
    if let (Some(t), image::DynamicImage::ImageLumaA8(b)) = (extras.grey_trns, &mut img) {
        for px in b.chunks_exact_mut(2) {
            px[1] = if px[0] == t { 0 } else { u8::MAX };
        }
    }
    let mut tex = texture_of(img, file_format, png_cs)?;
    let mut attributes = Vec::new();
    if orientation != 1 {
        attributes.push(("Orientation".to_string(), orientation.to_string()));
        if options.auto_orient {
            tex = orient(&tex, orientation)?;
            notes.push(format!(
                "EXIF orientation {orientation} applied ({} keeps the stored order)",
                Setting::NoAutoOrient
            ));
        } else {
            notes.push(format!(
                "EXIF orientation {orientation} not applied ({})",
                Setting::NoAutoOrient
            ));
        }
    }
    let mut info = SourceInfo::new(file_format, &tex.format());
    info.attributes = attributes;
    info.notes = notes;
    info.color_stated = color_stated;
    Ok(Loaded {
        levels: vec![tex],
        info,
    })
}

/// Decode the whole image, running `overlap` on another thread meanwhile.
/// 8-bit images (the common large case) are decoded into a buffer whose
/// pages that thread maps first (`mem::populate`): the decoder runs on
/// one core, and first touches of a 16384² RGBA8 image cost it seconds.
fn decode<D: image::ImageDecoder>(
    decoder: D,
    file_format: FileFormat,
    overlap: Option<Overlap<'_>>,
    lim: impl Fn(image::ImageError) -> Error,
) -> Result<image::DynamicImage> {
    use image::{ColorType, DynamicImage, ImageBuffer};
    let (w, h) = decoder.dimensions();
    let ct = decoder.color_type();
    let overlap = overlap.map(|f| {
        let ch = ct.channel_count();
        let ty = match ct.bytes_per_pixel() / ch {
            1 => ChannelType::U8,
            2 => ChannelType::U16,
            _ => ChannelType::F32,
        };
        move || f(w, h, ch, ty)
    });
    if !matches!(
        ct,
        ColorType::L8 | ColorType::La8 | ColorType::Rgb8 | ColorType::Rgba8
    ) {
        return std::thread::scope(|s| {
            if let Some(f) = overlap {
                s.spawn(f);
            }
            DynamicImage::from_decoder(decoder)
        })
        .map_err(lim);
    }
    let mut buf: Vec<u8> = crate::mem::zeroed(
        usize::try_from(decoder.total_bytes())
            .map_err(|_| Error::Limits("image larger than memory".into()))?,
    );
    let (ptr, len) = (buf.as_ptr() as usize, buf.len());
    let populate = len >= 64 << 20;
    std::thread::scope(|s| {
        if populate || overlap.is_some() {
            s.spawn(move || {
                if populate {
                    crate::mem::populate(ptr as *const u8, len);
                }
                if let Some(mut f) = overlap {
                    f();
                }
            });
        }
        decoder.read_image(&mut buf)
    })
    .map_err(lim)?;
    let bad = || Error::Decode {
        format: file_format.name(),
        reason: "the decoded image does not match its declared size".into(),
    };
    Ok(match ct {
        ColorType::L8 => {
            DynamicImage::ImageLuma8(ImageBuffer::from_raw(w, h, buf).ok_or_else(bad)?)
        }
        ColorType::La8 => {
            DynamicImage::ImageLumaA8(ImageBuffer::from_raw(w, h, buf).ok_or_else(bad)?)
        }
        ColorType::Rgb8 => {
            DynamicImage::ImageRgb8(ImageBuffer::from_raw(w, h, buf).ok_or_else(bad)?)
        }
        _ => DynamicImage::ImageRgba8(ImageBuffer::from_raw(w, h, buf).ok_or_else(bad)?),
    })
}

/// The decoded image as a texture: 8- and 16-bit integer images as they
/// are, in the colour space the PNG's chunks declare (`png_cs`), sRGB for
/// JPEG, linear otherwise; float images as f32 RGB or RGBA, linear.
fn texture_of(
    img: image::DynamicImage,
    file_format: FileFormat,
    png_cs: Option<ColorSpace>,
) -> Result<Texture> {
    use ChannelType::*;
    use image::DynamicImage;
    let (w, h) = (img.width(), img.height());
    let f = |ch: u8, ty: ChannelType| {
        let cs = match (file_format, png_cs) {
            (FileFormat::Png, Some(cs)) if !ty.is_float() => cs,
            (FileFormat::Jpeg, _) if ty == ChannelType::U8 => ColorSpace::Srgb,
            _ => ColorSpace::Linear,
        };
        Format::new(ch, ty, cs)
    };
    match img {
        DynamicImage::ImageLuma8(b) => Texture::from_u8(w, h, f(1, U8), b.into_raw()),
        DynamicImage::ImageLumaA8(b) => Texture::from_u8(w, h, f(2, U8), b.into_raw()),
        DynamicImage::ImageRgb8(b) => Texture::from_u8(w, h, f(3, U8), b.into_raw()),
        DynamicImage::ImageRgba8(b) => Texture::from_u8(w, h, f(4, U8), b.into_raw()),
        DynamicImage::ImageLuma16(b) => Texture::from_u16(w, h, f(1, U16), b.into_raw()),
        DynamicImage::ImageLumaA16(b) => Texture::from_u16(w, h, f(2, U16), b.into_raw()),
        DynamicImage::ImageRgb16(b) => Texture::from_u16(w, h, f(3, U16), b.into_raw()),
        DynamicImage::ImageRgba16(b) => Texture::from_u16(w, h, f(4, U16), b.into_raw()),
        DynamicImage::ImageRgb32F(b) => Texture::from_f32(w, h, f(3, F32), b.into_raw()),
        other => Texture::from_f32(w, h, f(4, F32), other.into_rgba32f().into_raw()),
    }
}
