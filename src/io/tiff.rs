//! TIFF, read with the `tiff` crate: every directory of a mip-mapped
//! texture (maketx's `.tx`), or one page of a multi-page file, with what
//! the tags say about the texels.
//!
//! What the tags decide, as OpenImageIO's TIFF reader decides it:
//! - **Mip levels or pages.** A file whose first directory has Pixar's
//!   `textureformat` tag (33302, which maketx writes) is a texture: its
//!   directories are the mip levels, level 0 first. Otherwise the
//!   directories are pages; the first is read (`--subimage N` picks
//!   another) and a note says so.
//! - **Alpha.** `ExtraSamples` (338) says what the channels after the
//!   colour are: 1 associated alpha (what OpenImageIO and maketx write), 2
//!   unassociated alpha, 0 not alpha (data). Without the tag, a second or
//!   fourth channel is taken as associated alpha, OpenImageIO's assumption.
//! - **Wrap modes and tiling.** Pixar's `wrapmodes` (33303, e.g.
//!   `black,black`) and the tile size (322, 323).
//! - **Orientation** (274): applied on load unless turned off (see
//!   [`super::orient`]).
//!
//! Samples of 8 and 16 bits (unsigned) and 16/32/64-bit floats load as u8,
//! u16, f16 and f32 (f64 narrowed to f32), with one to four channels,
//! contiguous or planar. Palette, CMYK, YCbCr, Lab, bilevel, signed and
//! 32-bit integer samples are refused in plain words. TIFF carries no
//! transfer function parvo reads, so `--color auto` takes its texels as
//! linear.

use std::io::{BufReader, Read, Seek};
use std::path::Path;

use ::tiff::decoder::{Decoder, DecodingResult};
use ::tiff::tags::Tag;

use super::{FileFormat, Limits, LoadOptions, Loaded, SourceInfo};
use crate::error::{Error, Result};
use crate::mip::Rounding;
use crate::texel::{AlphaMode, ChannelType, ColorSpace, Format, Texels};
use crate::texture::Texture;

const PIXAR_TEXTUREFORMAT: u16 = 33302;
const PIXAR_WRAPMODES: u16 = 33303;

fn decode_err(reason: impl std::fmt::Display) -> Error {
    Error::Decode {
        format: "TIFF",
        reason: reason.to_string(),
    }
}

/// What one directory holds.
struct Directory {
    width: u32,
    height: u32,
    format: Format,
    /// Samples per pixel as stored (the texture keeps them all).
    samples: usize,
    planar: bool,
    tile: Option<(u32, u32)>,
    orientation: u16,
    alpha_note: Option<&'static str>,
}

fn ascii_tag<R: Read + Seek>(d: &mut Decoder<R>, tag: Tag) -> Option<String> {
    match d.find_tag(tag).ok().flatten()? {
        ::tiff::decoder::ifd::Value::Ascii(s) => Some(s.trim_end_matches('\0').to_string()),
        _ => None,
    }
}

fn unsigned<R: Read + Seek>(d: &mut Decoder<R>, tag: Tag) -> Result<Option<u32>> {
    d.find_tag_unsigned::<u32>(tag).map_err(decode_err)
}

fn directory<R: Read + Seek>(d: &mut Decoder<R>) -> Result<Directory> {
    let (width, height) = d.dimensions().map_err(decode_err)?;
    let samples = unsigned(d, Tag::SamplesPerPixel)?.unwrap_or(1) as usize;
    let bits: Vec<u16> = d
        .find_tag_unsigned_vec::<u16>(Tag::BitsPerSample)
        .map_err(decode_err)?
        .unwrap_or_else(|| vec![1]);
    let sample_format: Vec<u16> = d
        .find_tag_unsigned_vec::<u16>(Tag::SampleFormat)
        .map_err(decode_err)?
        .unwrap_or_else(|| vec![1]);
    let photometric = unsigned(d, Tag::PhotometricInterpretation)?.unwrap_or(1);
    let planar = unsigned(d, Tag::PlanarConfiguration)?.unwrap_or(1) == 2;
    let orientation = unsigned(d, Tag::Orientation)?.unwrap_or(1) as u16;
    if bits.iter().any(|&b| b != bits[0]) || sample_format.iter().any(|&f| f != sample_format[0]) {
        return Err(decode_err(
            "channels of different bit depths or sample formats are not supported",
        ));
    }
    let colour = match photometric {
        0 | 1 => 1,
        2 => 3,
        3 => return Err(decode_err("palette (indexed-colour) TIFF is not supported")),
        5 => return Err(decode_err("CMYK TIFF is not supported")),
        6 => return Err(decode_err("YCbCr TIFF is not supported (store it as RGB)")),
        8..=10 => return Err(decode_err("CIE L*a*b* TIFF is not supported")),
        p => {
            return Err(decode_err(format!(
                "photometric interpretation {p} is not supported"
            )));
        }
    };
    if photometric == 0 {
        return Err(decode_err(
            "WhiteIsZero (inverted grey) TIFF is not supported",
        ));
    }
    if !(1..=4).contains(&samples) || samples < colour {
        return Err(decode_err(format!(
            "{samples} samples per pixel: parvo reads 1 to 4 channels"
        )));
    }
    let ty = match (sample_format[0], bits[0]) {
        (1, 8) => ChannelType::U8,
        (1, 16) => ChannelType::U16,
        (3, 16) => ChannelType::F16,
        (3, 32) | (3, 64) => ChannelType::F32,
        (1, b) if b < 8 => {
            return Err(decode_err(format!("{b}-bit samples are not supported")));
        }
        (1, b) => {
            return Err(decode_err(format!(
                "{b}-bit unsigned integer samples are not supported (8 and 16 are)"
            )));
        }
        (2, b) => {
            return Err(decode_err(format!(
                "signed {b}-bit samples are not supported"
            )));
        }
        (f, b) => {
            return Err(decode_err(format!(
                "sample format {f} with {b} bits is not supported"
            )));
        }
    };
    let extra: Vec<u16> = d
        .find_tag_unsigned_vec::<u16>(Tag::ExtraSamples)
        .map_err(decode_err)?
        .unwrap_or_default();
    let has_alpha_slot = samples == 2 || samples == 4;
    let (alpha, alpha_note) = if samples > colour {
        match extra.first() {
            Some(1) => (AlphaMode::Premultiplied, None),
            Some(2) => (AlphaMode::Straight, None),
            Some(_) => (AlphaMode::None, None),
            None if has_alpha_slot => (
                AlphaMode::Premultiplied,
                Some(
                    "no ExtraSamples tag: the last channel is taken as associated alpha, as \
                     OpenImageIO does (--alpha straight or none overrides)",
                ),
            ),
            None => (AlphaMode::None, None),
        }
    } else {
        (AlphaMode::Straight, None)
    };
    let alpha = if has_alpha_slot {
        alpha
    } else {
        AlphaMode::Straight
    };
    // The `tiff` crate returns RGB without a fourth sample that is not
    // alpha; that channel cannot be read.
    let (samples, alpha_note) = if colour == 3 && samples == 4 && alpha == AlphaMode::None {
        (
            3,
            Some("the fourth channel is not alpha (ExtraSamples 0) and is not read; RGB is"),
        )
    } else {
        (samples, alpha_note)
    };
    let tile = match (unsigned(d, Tag::TileWidth)?, unsigned(d, Tag::TileLength)?) {
        (Some(w), Some(h)) => Some((w, h)),
        _ => None,
    };
    Ok(Directory {
        width,
        height,
        format: Format::new(samples as u8, ty, ColorSpace::Linear).with_alpha(alpha),
        samples,
        planar,
        tile,
        orientation,
        alpha_note,
    })
}

/// The first `want` samples of a decoded image, interleaved when the file
/// is planar.
fn take<T: Copy>(mut v: Vec<T>, want: usize, planar: bool, samples: usize, n: usize) -> Vec<T> {
    v.truncate(want);
    if planar { interleave(v, samples, n) } else { v }
}

/// Interleave planar data (all of channel 0, then channel 1, ...).
fn interleave<T: Copy>(v: Vec<T>, ch: usize, n: usize) -> Vec<T> {
    if ch == 1 {
        return v;
    }
    let mut out = Vec::with_capacity(n * ch);
    for i in 0..n {
        for c in 0..ch {
            out.push(v[c * n + i]);
        }
    }
    out
}

fn read_texture<R: Read + Seek>(d: &mut Decoder<R>, dir: &Directory) -> Result<Texture> {
    let n = dir.width as usize * dir.height as usize;
    let want = n * dir.samples;
    let result = d.read_image().map_err(decode_err)?;
    let check = |len: usize| {
        if len < want {
            Err(decode_err(format!(
                "decoded {len} samples, a {}x{} image of {} channels has {want}{}",
                dir.width,
                dir.height,
                dir.samples,
                if dir.planar {
                    " (planar files whose planes do not all decode are not supported)"
                } else {
                    ""
                }
            )))
        } else {
            Ok(())
        }
    };
    let len = match &result {
        DecodingResult::U8(v) => v.len(),
        DecodingResult::U16(v) => v.len(),
        DecodingResult::F16(v) => v.len(),
        DecodingResult::F32(v) => v.len(),
        DecodingResult::F64(v) => v.len(),
        _ => return Err(decode_err("unexpected sample type from the decoder")),
    };
    check(len)?;
    let (planar, samples) = (dir.planar, dir.samples);
    let texels = match result {
        DecodingResult::U8(v) => Texels::U8(take(v, want, planar, samples, n)),
        DecodingResult::U16(v) => Texels::U16(take(v, want, planar, samples, n)),
        DecodingResult::F16(v) => Texels::F16(take(v, want, planar, samples, n)),
        DecodingResult::F32(v) => Texels::F32(take(v, want, planar, samples, n)),
        DecodingResult::F64(v) => Texels::F32(take(
            v.into_iter().map(|x| x as f32).collect(),
            want,
            planar,
            samples,
            n,
        )),
        _ => return Err(decode_err("unexpected sample type from the decoder")),
    };
    Texture::from_texels(dir.width, dir.height, dir.format, texels)
}

/// Load a TIFF file (see the module docs).
pub fn load(path: &Path, limits: &Limits, options: &LoadOptions) -> Result<Loaded> {
    let file = std::fs::File::open(path).map_err(|e| Error::Io {
        path: path.to_path_buf(),
        action: "cannot open".into(),
        error: e,
    })?;
    let mut tl = ::tiff::decoder::Limits::default();
    tl.decoding_buffer_size = usize::try_from(limits.max_alloc).unwrap_or(usize::MAX);
    tl.intermediate_buffer_size = tl.decoding_buffer_size;
    let mut d = Decoder::new(BufReader::new(file))
        .map_err(decode_err)?
        .with_limits(tl);
    let texture_format = ascii_tag(&mut d, Tag::Unknown(PIXAR_TEXTUREFORMAT));
    let mipmapped = texture_format.is_some();
    let mut notes = Vec::new();
    // Count the directories (cheap: the IFD chain, not the pixels).
    let mut pages = 1usize;
    while d.more_images() {
        d.next_image().map_err(decode_err)?;
        pages += 1;
        if pages > 4096 {
            return Err(decode_err("more than 4096 directories"));
        }
    }
    let first = if mipmapped { 0 } else { options.subimage };
    if first >= pages {
        return Err(Error::InvalidOption(format!(
            "--subimage {first}: the file has {pages} page{}",
            if pages == 1 { "" } else { "s" }
        )));
    }
    if mipmapped && options.subimage != 0 {
        return Err(Error::InvalidOption(
            "--subimage: this TIFF is a mip-mapped texture, its directories are its levels".into(),
        ));
    }
    if !mipmapped && pages > 1 {
        notes.push(format!(
            "multi-page TIFF: using page {first} of {pages}; --subimage N picks another"
        ));
    }
    d.seek_to_image(first).map_err(decode_err)?;
    let dir0 = directory(&mut d)?;
    let wrap_text = ascii_tag(&mut d, Tag::Unknown(PIXAR_WRAPMODES));
    let mut attributes: Vec<(String, String)> = Vec::new();
    for (name, tag) in [
        ("ImageDescription", Tag::ImageDescription),
        ("Software", Tag::Software),
        ("DateTime", Tag::DateTime),
        ("Artist", Tag::Artist),
    ] {
        if let Some(v) = ascii_tag(&mut d, tag) {
            attributes.push((name.into(), v));
        }
    }
    if let Some(t) = &texture_format {
        attributes.push(("textureformat".into(), t.clone()));
    }
    if let Some(w) = &wrap_text {
        attributes.push(("wrapmodes".into(), w.clone()));
    }
    if let Some(c) = unsigned(&mut d, Tag::Compression)? {
        let name = match c {
            1 => "none".to_string(),
            5 => "lzw".into(),
            7 => "jpeg".into(),
            8 | 32946 => "zip".into(),
            32773 => "packbits".into(),
            other => other.to_string(),
        };
        attributes.push(("compression".into(), name));
    }
    if dir0.orientation != 1 {
        attributes.push(("Orientation".into(), dir0.orientation.to_string()));
    }
    attributes.sort();
    // Declared sizes of every level read, checked before decoding.
    let count = if mipmapped { pages } else { 1 };
    let full = crate::mip::level_count(dir0.width, dir0.height, Rounding::Down, None) as usize;
    let up = crate::mip::level_count(dir0.width, dir0.height, Rounding::Up, None) as usize;
    if count > full.max(up) {
        return Err(decode_err(format!(
            "{count} directories, more than a {}x{} mip chain has",
            dir0.width, dir0.height
        )));
    }
    let texel = dir0.format.texel_bytes() as u64;
    limits.check(
        dir0.width as u64,
        dir0.height as u64,
        (dir0.width as u64 * dir0.height as u64)
            .saturating_mul(texel)
            .saturating_mul(if count > 1 { 2 } else { 1 }),
    )?;
    if let Some(n) = dir0.alpha_note {
        notes.push(n.to_string());
    }
    let mut levels = vec![read_texture(&mut d, &dir0)?];
    let mut rounding = Rounding::Down;
    for k in 1..count {
        d.seek_to_image(k).map_err(decode_err)?;
        let dir = directory(&mut d)?;
        if k == 1 {
            let up_size = crate::mip::level_size(dir0.width, dir0.height, 1, Rounding::Up);
            let down_size = crate::mip::level_size(dir0.width, dir0.height, 1, Rounding::Down);
            if (dir.width, dir.height) == down_size {
                rounding = Rounding::Down;
            } else if (dir.width, dir.height) == up_size {
                rounding = Rounding::Up;
            }
        }
        let want = crate::mip::level_size(dir0.width, dir0.height, k as u32, rounding);
        if (dir.width, dir.height) != want || dir.format != dir0.format {
            return Err(decode_err(format!(
                "mip level {k} is {}x{} {}, level 0 implies {}x{} {}",
                dir.width, dir.height, dir.format, want.0, want.1, dir0.format
            )));
        }
        levels.push(read_texture(&mut d, &dir)?);
    }
    if dir0.orientation != 1 {
        if options.auto_orient {
            for l in &mut levels {
                *l = super::orient(l, dir0.orientation)?;
            }
            notes.push(format!(
                "TIFF orientation {} applied (--no-auto-orient keeps the stored order)",
                dir0.orientation
            ));
        } else {
            notes.push(format!(
                "TIFF orientation {} not applied (--no-auto-orient)",
                dir0.orientation
            ));
        }
    }
    let format = levels[0].format();
    let mut info = SourceInfo::new(FileFormat::Tiff, &format);
    info.own_mips = levels.len() > 1;
    info.rounding = rounding;
    info.wrap = super::recorded_wrap(wrap_text.as_deref(), &mut notes);
    info.tile = dir0.tile;
    info.attributes = attributes;
    info.notes = notes;
    Ok(Loaded { levels, info })
}
