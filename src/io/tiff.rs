//! TIFF, read with the `tiff` crate: every directory of a mip-mapped
//! texture (maketx's `.tx`), or one page of a multi-page file, with what
//! the tags say about the texels.
//!
//! What the tags decide, as OpenImageIO's TIFF reader decides it:
//! - **Mip levels or pages.** A file whose first directory has Pixar's
//!   `textureformat` tag (33302, which maketx writes) is a texture: its
//!   directories are the mip levels, level 0 first. Otherwise the
//!   directories are pages; the first is read (`--subimage N` picks
//!   another) and a note says so. A chain of pages that loops back on
//!   itself is read up to the loop, with a note.
//! - **Environment maps.** `textureformat` `CubeFace Environment` or
//!   `LatLong Environment` (maketx `--envlatl`) marks an environment map:
//!   it is refused unless the caller asks to describe it
//!   ([`super::EnvironmentMaps`]).
//! - **Alpha.** `ExtraSamples` (338) says what the channels after the
//!   colour are: 1 associated alpha (what OpenImageIO and maketx write), 2
//!   unassociated alpha, 0 not alpha (data). Without the tag, a second or
//!   fourth channel is taken as associated alpha, OpenImageIO's assumption.
//! - **Colour.** `PhotometricInterpretation` (262): BlackIsZero grey,
//!   WhiteIsZero grey (one channel, inverted on load), RGB, or a palette
//!   (indexed colour), expanded to 8-bit RGB through its colour map as
//!   OpenImageIO does (entry / 257, rounded down). A file without the tag
//!   is read as OpenImageIO reads it: grey for one channel, two data
//!   channels for two, RGB for three or more.
//! - **Wrap modes and tiling.** Pixar's `wrapmodes` (33303, e.g.
//!   `black,black`) and the tile size (322, 323).
//! - **Orientation** (274): applied on load unless turned off (see
//!   [`super::orient`]).
//!
//! Samples of 8 and 16 bits (unsigned) and 16/32/64-bit floats load as u8,
//! u16, f16 and f32 (f64 narrowed to f32), with one to four channels,
//! contiguous or planar (`PlanarConfiguration` 2, every plane read and
//! interleaved), in strips or tiles. 1- to 7-bit grey widens to u8 as
//! OpenImageIO widens it (`v · 255 / (2^bits − 1)` rounded down: 0 → 0,
//! the largest code → 255). `FillOrder` 2 is read for uncompressed data.
//! Samples of other sizes (1–7 bits of several channels, 9–15, 17–31) and
//! YCbCr outside JPEG are unpacked by parvo (`tiff/raw.rs`); 24- and
//! 32-bit unsigned and signed integers load as f32 (v / the type's
//! maximum, OpenImageIO's float reading); CMYK of four 8- or 16-bit inks
//! and JPEG's YCbCr convert to RGB as OpenImageIO converts them. Lab,
//! LogL/LogLuv, old-style JPEG, other inks and compressions the crate
//! lacks (LZMA, WebP, Zstandard, CCITT Group 3) are refused in plain
//! words that say what to convert the file to.
//! TIFF carries no transfer function parvo reads, so `--color auto` takes
//! its texels as linear.
//!
//! The `tiff` crate reads the pixels; parvo walks the chain of
//! directories itself first (`tiff/chain.rs`), which lets it read files the
//! crate alone refuses (no photometric tag, a looping chain, palettes,
//! tiles stored under the strip tags) and say what is wrong with a broken
//! file in words rather than the crate's.

mod chain;
mod errors;
mod raw;

use std::fs::File;
use std::io::{BufReader, Read, Seek};
use std::path::Path;

use ::tiff::decoder::{Decoder, DecodingResult};
use ::tiff::tags::Tag;
use ::tiff::{TiffError, TiffFormatError};

use self::chain::{Fix, tag};
use self::errors::{alloc_limit, words};
use self::raw::{View, Ycc};
use super::{Environment, FileFormat, Limits, LoadOptions, Loaded, SourceInfo};
use crate::error::{Error, Result};
use crate::mip::Rounding;
use crate::setting::Setting;
use crate::texel::{AlphaMode, ChannelType, ColorSpace, Format, Texels};
use crate::texture::Texture;

fn decode_err(reason: impl std::fmt::Display) -> Error {
    Error::Decode {
        format: "TIFF",
        reason: reason.to_string(),
    }
}

/// The tag values the `tiff` crate accepts for one tag; larger ones are
/// refused as "limits exceeded" (its default, which also applies while
/// the first directory is read).
const CRATE_TAG_LIMIT: u64 = 1 << 20;

/// What one directory holds.
struct Directory {
    width: u32,
    height: u32,
    format: Format,
    /// Channels kept (the texture's channel count).
    samples: usize,
    /// Samples per pixel as stored.
    stored_samples: usize,
    bits: u16,
    planar: bool,
    tile: Option<(u32, u32)>,
    orientation: u16,
    alpha_note: Option<&'static str>,
    /// A palette's colour map: red, green and blue tables of 2^bits
    /// entries each.
    palette: Option<Vec<u16>>,
    /// FillOrder 2: the bits of every byte are stored in reverse order.
    bit_reversed: bool,
    /// Samples parvo unpacks itself (see `tiff/raw.rs`).
    view: Option<View>,
    /// The colour conversion to RGB the stored samples need.
    convert: Convert,
}

/// A conversion to RGB of samples the decoder returns as stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Convert {
    None,
    /// CMYK, converted as OpenImageIO converts it (`cmyk_to_rgb`:
    /// R = (1 − C)(1 − K) in float, rounded to the nearest code).
    Cmyk,
    /// CMYK in JPEG, which OpenImageIO reads through libtiff's RGBA
    /// interface: R = (255 − K)(255 − C) / 255 rounded down.
    CmykJpeg,
    /// YCbCr in JPEG, converted as libjpeg converts it for libtiff.
    YccJpeg,
}

impl Directory {
    /// What level 0's tags leave to an assumption, as notes: alpha taken
    /// without an ExtraSamples tag, a colour map rounded to 8 bits.
    fn notes(&self, notes: &mut Vec<String>) {
        if let Some(n) = self.alpha_note {
            notes.push(format!(
                "{n} ({} straight or none overrides)",
                Setting::Alpha
            ));
        }
        if let Some(map) = &self.palette
            && map.iter().any(|&v| v % 257 != 0)
        {
            notes.push(
                "palette TIFF: the colour map's 16-bit entries are rounded down to 8 bits, as \
                 OpenImageIO reads them"
                    .into(),
            );
        }
    }
}

fn ascii_tag<R: Read + Seek>(d: &mut Decoder<R>, tag: Tag) -> Option<String> {
    match d.find_tag(tag).ok().flatten()? {
        ::tiff::decoder::ifd::Value::Ascii(s) => Some(s.trim_end_matches('\0').to_string()),
        _ => None,
    }
}

/// Reads the directory the decoder is at; `fix` says what parvo changed
/// in it before (see [`chain::Chain::repair`]).
struct Reader<'a> {
    raw: &'a chain::Dir,
    layout: chain::Layout,
    limits: &'a Limits,
}

impl Reader<'_> {
    /// A TIFF crate error while reading this directory, in words.
    fn err(&self, e: TiffError) -> Error {
        words(e, Some(self.raw), &self.layout, self.limits, None)
    }

    fn unsigned<R: Read + Seek>(&self, d: &mut Decoder<R>, tag: Tag) -> Result<Option<u32>> {
        d.find_tag_unsigned::<u32>(tag).map_err(|e| self.err(e))
    }

    fn directory<R: Read + Seek>(&self, d: &mut Decoder<R>, fix: Fix) -> Result<Directory> {
        if let Some(v) = fix.view {
            return self.view_directory(d, v);
        }
        let (width, height) = d.dimensions().map_err(|e| self.err(e))?;
        let stored_samples = self.unsigned(d, Tag::SamplesPerPixel)?.unwrap_or(1) as usize;
        let bits: Vec<u16> = d
            .find_tag_unsigned_vec::<u16>(Tag::BitsPerSample)
            .map_err(|e| self.err(e))?
            .unwrap_or_else(|| vec![1]);
        let sample_format: Vec<u16> = d
            .find_tag_unsigned_vec::<u16>(Tag::SampleFormat)
            .map_err(|e| self.err(e))?
            .unwrap_or_else(|| vec![1]);
        let planar = self.unsigned(d, Tag::PlanarConfiguration)?.unwrap_or(1) == 2;
        let orientation = self.unsigned(d, Tag::Orientation)?.unwrap_or(1) as u16;
        if bits.is_empty() || bits.iter().any(|&b| b != bits[0]) {
            return Err(decode_err(format!(
                "channels of different bit depths ({}) are not supported",
                join(&bits)
            )));
        }
        if sample_format.is_empty() || sample_format.iter().any(|&f| f != sample_format[0]) {
            return Err(decode_err(
                "channels of different sample formats (integer and float) are not supported",
            ));
        }
        let (bits, sample_format) = (bits[0], sample_format[0]);
        let mut extra: Vec<u16> = d
            .find_tag_unsigned_vec::<u16>(Tag::ExtraSamples)
            .map_err(|e| self.err(e))?
            .unwrap_or_default();
        // The decoder was told the data sample is alpha (see Fix).
        if fix.extra_data {
            extra = vec![0];
        }
        let missing = fix.stored_photometric.is_none();
        let photometric = match fix.stored_photometric {
            Some(p) => p,
            None => fix.told.unwrap_or(1) as u64,
        };
        let compression = self.unsigned(d, Tag::Compression)?.unwrap_or(1);
        let convert = self.conversion(d, photometric, compression, stored_samples, bits)?;
        let colour = colour_channels(photometric, stored_samples, bits, compression)?;
        let bit_reversed = self.bit_reversed(d)?;
        if !(1..=4).contains(&stored_samples) || stored_samples < colour {
            return Err(decode_err(format!(
                "{stored_samples} samples per pixel: parvo reads 1 to 4 channels"
            )));
        }
        let palette = if photometric == 3 {
            Some(self.palette(d, stored_samples, bits, sample_format)?)
        } else {
            None
        };
        let ty = channel_type(sample_format, bits, stored_samples, palette.is_some())?;
        let has_alpha_slot =
            (stored_samples == 2 || stored_samples == 4) && convert == Convert::None;
        let (alpha, alpha_note) = if missing && stored_samples == 2 && extra.is_empty() {
            // OpenImageIO reads two untagged channels as R, G data.
            (AlphaMode::None, None)
        } else if stored_samples > colour {
            extra_alpha(extra.first().copied(), has_alpha_slot)
        } else {
            (AlphaMode::Straight, None)
        };
        let alpha = if has_alpha_slot {
            alpha
        } else {
            AlphaMode::Straight
        };
        // The `tiff` crate returns RGB without a fourth sample that is not
        // alpha; one such sample stated inline is read (the crate is told
        // it is alpha, see Fix), any other cannot be.
        let (samples, alpha_note) =
            if colour == 3 && stored_samples == 4 && alpha == AlphaMode::None && !fix.extra_data {
                (
                    3,
                    Some(
                        "the fourth channel is not alpha (ExtraSamples 0) and is not read; RGB is",
                    ),
                )
            } else if palette.is_some() || convert != Convert::None {
                (3, alpha_note)
            } else {
                (stored_samples, alpha_note)
            };
        let tile = match (
            self.unsigned(d, Tag::TileWidth)?,
            self.unsigned(d, Tag::TileLength)?,
        ) {
            (Some(w), Some(h)) => Some((w, h)),
            _ => None,
        };
        Ok(Directory {
            width,
            height,
            format: Format::new(samples as u8, ty, ColorSpace::Linear).with_alpha(alpha),
            samples,
            stored_samples,
            bits,
            planar,
            tile,
            orientation,
            alpha_note,
            palette,
            bit_reversed,
            view: None,
            convert,
        })
    }

    /// A directory whose samples parvo unpacks (see `tiff/raw.rs`): what
    /// the file stores, not the rows of bytes the decoder is told of.
    fn view_directory<R: Read + Seek>(&self, d: &mut Decoder<R>, v: View) -> Result<Directory> {
        let stored_samples = v.samples as usize;
        let colour = if v.photometric == 2 || v.is_ycbcr() {
            3
        } else {
            1
        };
        if stored_samples < colour {
            return Err(decode_err(format!(
                "{stored_samples} samples per pixel for a colour image"
            )));
        }
        let ty = match v.bits {
            _ if v.is_ycbcr() => ChannelType::U8,
            0..=8 => ChannelType::U8,
            9..=16 => ChannelType::U16,
            _ => ChannelType::F32,
        };
        let has_alpha_slot = stored_samples == 2 || stored_samples == 4;
        let (alpha, alpha_note) = if stored_samples > colour && has_alpha_slot {
            extra_alpha(v.extra, true)
        } else {
            (AlphaMode::Straight, None)
        };
        let samples = if v.is_ycbcr() { 3 } else { stored_samples };
        let tile = self
            .raw
            .unsigned(&self.layout, tag::TILE_WIDTH)
            .zip(self.raw.unsigned(&self.layout, tag::TILE_LENGTH))
            .map(|(w, h)| (w as u32, h as u32));
        Ok(Directory {
            width: v.width,
            height: v.height,
            format: Format::new(samples as u8, ty, ColorSpace::Linear).with_alpha(alpha),
            samples,
            stored_samples,
            bits: v.bits,
            planar: v.planar,
            tile,
            orientation: self.unsigned(d, Tag::Orientation)?.unwrap_or(1) as u16,
            alpha_note,
            palette: None,
            bit_reversed: self.bit_reversed(d)?,
            view: Some(v),
            convert: Convert::None,
        })
    }

    /// The conversion to RGB that photometric interpretation
    /// `photometric` needs: CMYK (four 8- or 16-bit inks, `InkSet` CMYK)
    /// and JPEG-compressed YCbCr; other CMYK is refused in words.
    fn conversion<R: Read + Seek>(
        &self,
        d: &mut Decoder<R>,
        photometric: u64,
        compression: u32,
        stored_samples: usize,
        bits: u16,
    ) -> Result<Convert> {
        let jpeg = compression == 7;
        match photometric {
            5 => {
                let inks = self.unsigned(d, Tag::Unknown(332))?.unwrap_or(1);
                let format = d
                    .find_tag_unsigned_vec::<u16>(Tag::SampleFormat)
                    .map_err(|e| self.err(e))?
                    .and_then(|v| v.first().copied())
                    .unwrap_or(1);
                if inks != 1 {
                    return Err(decode_err(format!(
                        "a colour-separated TIFF of {stored_samples} inks that are not CMYK \
                         (InkSet {inks}) is not supported: convert it to RGB"
                    )));
                }
                if stored_samples != 4 {
                    return Err(decode_err(format!(
                        "CMYK TIFF with {stored_samples} samples per pixel is not supported (4 \
                         inks, C, M, Y and K, are): convert it to RGB or RGBA"
                    )));
                }
                if format != 1 || !matches!(bits, 8 | 16) || (jpeg && bits != 8) {
                    return Err(decode_err(format!(
                        "CMYK TIFF of {bits}-bit {} samples is not supported (8- and 16-bit \
                         unsigned inks are): convert it to RGB",
                        if format == 2 {
                            "signed"
                        } else if format == 3 {
                            "float"
                        } else {
                            "integer"
                        }
                    )));
                }
                Ok(if jpeg {
                    Convert::CmykJpeg
                } else {
                    Convert::Cmyk
                })
            }
            6 if jpeg && stored_samples == 3 && bits == 8 => Ok(Convert::YccJpeg),
            _ => Ok(Convert::None),
        }
    }

    /// `FillOrder` 2 stores the bits of each byte in reverse; libtiff
    /// reverses them before decoding, which for uncompressed data without
    /// a predictor is reversing the decoded bytes (`true`); other data in
    /// that order is refused.
    fn bit_reversed<R: Read + Seek>(&self, d: &mut Decoder<R>) -> Result<bool> {
        match self.unsigned(d, Tag::FillOrder)?.unwrap_or(1) {
            1 => Ok(false),
            2 if self.unsigned(d, Tag::Compression)?.unwrap_or(1) == 1
                && self.unsigned(d, Tag::Predictor)?.unwrap_or(1) == 1 =>
            {
                Ok(true)
            }
            2 => Err(decode_err(
                "FillOrder 2 (bits stored least significant first) is supported for \
                 uncompressed data without a predictor only",
            )),
            f => Err(decode_err(format!("FillOrder {f} is neither 1 nor 2"))),
        }
    }

    /// A palette image's colour map (red, green and blue tables of 2^bits
    /// entries each), after checking that its texels are one index of 1,
    /// 2, 4, 8 or 16 bits.
    fn palette<R: Read + Seek>(
        &self,
        d: &mut Decoder<R>,
        stored_samples: usize,
        bits: u16,
        sample_format: u16,
    ) -> Result<Vec<u16>> {
        if stored_samples != 1 || !matches!(bits, 1 | 2 | 4 | 8 | 16) || sample_format != 1 {
            return Err(decode_err(format!(
                "a palette image of {stored_samples} samples of {bits} bits is not supported \
                 (one index of 1, 2, 4, 8 or 16 bits is)"
            )));
        }
        let map = d
            .find_tag_unsigned_vec::<u16>(Tag::ColorMap)
            .map_err(|e| self.err(e))?
            .ok_or_else(|| decode_err("a palette image without a ColorMap tag"))?;
        let want = 3usize << bits;
        if map.len() != want {
            return Err(decode_err(format!(
                "the ColorMap has {} entries, a palette of {bits}-bit indices has {want}",
                map.len()
            )));
        }
        Ok(map)
    }

    /// The attributes `parvo info` shows, sorted: the text tags, Pixar's
    /// `textureformat` and `wrapmodes`, the compression and a non-default
    /// orientation.
    fn attributes<R: Read + Seek>(
        &self,
        d: &mut Decoder<R>,
        dir: &Directory,
        texture_format: &Option<String>,
        wrap_text: &Option<String>,
    ) -> Result<Vec<(String, String)>> {
        let mut attributes: Vec<(String, String)> = Vec::new();
        for (name, tag) in [
            ("ImageDescription", Tag::ImageDescription),
            ("Software", Tag::Software),
            ("DateTime", Tag::DateTime),
            ("Artist", Tag::Artist),
        ] {
            if let Some(v) = ascii_tag(d, tag) {
                attributes.push((name.into(), v));
            }
        }
        if let Some(t) = texture_format {
            attributes.push(("textureformat".into(), t.clone()));
        }
        if let Some(w) = wrap_text {
            attributes.push(("wrapmodes".into(), w.clone()));
        }
        if let Some(c) = self.unsigned(d, Tag::Compression)? {
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
        if dir.orientation != 1 {
            attributes.push(("Orientation".into(), dir.orientation.to_string()));
        }
        attributes.sort();
        Ok(attributes)
    }

    /// Decode the directory the decoder is at: every plane of a planar
    /// file, interleaved; sub-byte grey widened; palette indices mapped.
    fn texture<R: Read + Seek>(&self, d: &mut Decoder<R>, dir: &Directory) -> Result<Texture> {
        let (w, h) = (dir.width as usize, dir.height as usize);
        let n = w * h;
        let err = |e| words(e, Some(self.raw), &self.layout, self.limits, Some(dir));
        if let Some(v) = &dir.view {
            if v.texel_bytes() > self.limits.max_alloc {
                return Err(alloc_limit(self.limits, dir, v.texel_bytes()));
            }
            let mut result = DecodingResult::U8(Vec::new());
            d.read_image_to_buffer(&mut result).map_err(err)?;
            let mut buffer = result.as_buffer(0);
            let bytes = buffer.as_bytes_mut();
            if dir.bit_reversed {
                bytes.iter_mut().for_each(|b| *b = b.reverse_bits());
            }
            let texels = v.decode(bytes).map_err(decode_err)?;
            return Texture::from_texels(dir.width, dir.height, dir.format, texels);
        }
        let sample_bytes = (dir.bits as usize).div_ceil(8);
        let (mut result, per_pixel) = if dir.planar && dir.tile.is_some() && dir.stored_samples > 1
        {
            let need = (n as u64)
                .saturating_mul(dir.stored_samples as u64)
                .saturating_mul(sample_bytes as u64);
            if need > self.limits.max_alloc {
                return Err(alloc_limit(self.limits, dir, need));
            }
            (planar_tiles(d, dir).map_err(err)?, dir.stored_samples)
        } else {
            let mut result = DecodingResult::U8(Vec::new());
            let layout = d.read_image_to_buffer(&mut result).map_err(err)?;
            if result.as_buffer(0).byte_len() < layout.complete_len {
                // The crate reads only the first plane when all of them do
                // not fit its decoding buffer (the allocation limit).
                return Err(alloc_limit(self.limits, dir, layout.complete_len as u64));
            }
            let per_pixel = if dir.planar {
                layout.planes
            } else {
                layout.complete_len / (n * sample_bytes).max(1)
            };
            (result, per_pixel)
        };
        if dir.bit_reversed {
            for b in result.as_buffer(0).as_bytes_mut() {
                *b = b.reverse_bits();
            }
        }
        // Channels decoded per pixel and kept (a palette has one index).
        let keep = match dir.convert {
            _ if dir.palette.is_some() => 1,
            Convert::Cmyk | Convert::CmykJpeg => 4,
            _ => dir.samples,
        };
        if dir.bits >= 8 && per_pixel < keep {
            return Err(decode_err(format!(
                "the decoder returned {per_pixel} samples per pixel, the tags declare {keep}"
            )));
        }
        let pick = (n, per_pixel, keep, dir.planar);
        let texels = match result {
            DecodingResult::U8(v) if dir.bits < 8 => {
                let idx = unpack(&v, w, h, dir.bits as u32)?;
                match &dir.palette {
                    Some(map) => Texels::U8(expand_palette(&idx, map, 1 << dir.bits)),
                    None => {
                        Texels::U8(idx.into_iter().map(|i| widen(i, dir.bits as u32)).collect())
                    }
                }
            }
            DecodingResult::U8(v) => match &dir.palette {
                Some(map) => Texels::U8(expand_palette(&select(v, pick)?, map, 256)),
                None => Texels::U8(select(v, pick)?),
            },
            DecodingResult::U16(v) => match &dir.palette {
                Some(map) => Texels::U8(expand_palette(&select(v, pick)?, map, 65536)),
                None => Texels::U16(select(v, pick)?),
            },
            DecodingResult::F16(v) => Texels::F16(select(v, pick)?),
            DecodingResult::F32(v) => Texels::F32(select(v, pick)?),
            DecodingResult::F64(v) => {
                Texels::F32(select(v, pick)?.into_iter().map(|x| x as f32).collect())
            }
            DecodingResult::U32(v) => Texels::F32(scaled(select(v, pick)?, u32::MAX as f64)),
            DecodingResult::I8(v) => Texels::F32(scaled(select(v, pick)?, i8::MAX as f64)),
            DecodingResult::I16(v) => Texels::F32(scaled(select(v, pick)?, i16::MAX as f64)),
            DecodingResult::I32(v) => Texels::F32(scaled(select(v, pick)?, i32::MAX as f64)),
            _ => {
                return Err(decode_err(
                    "the decoder returned a sample type parvo does not read",
                ));
            }
        };
        let texels = match dir.convert {
            Convert::None => texels,
            c => to_rgb(c, texels)?,
        };
        Texture::from_texels(dir.width, dir.height, dir.format, texels)
    }
}

/// Integer codes as floats, `v / max` (OpenImageIO's conversion of
/// signed and 32-bit integers to float: −128 of 8 bits is −1.008).
fn scaled<T: Into<f64> + Copy>(v: Vec<T>, max: f64) -> Vec<f32> {
    v.into_iter().map(|x| (x.into() / max) as f32).collect()
}

/// RGB from CMYK or JPEG's YCbCr samples, as OpenImageIO (with libtiff
/// and libjpeg) converts them.
fn to_rgb(convert: Convert, texels: Texels) -> Result<Texels> {
    // OpenImageIO's arithmetic in f32: a code times 1/max, and back as
    // x · max + 0.5 truncated.
    fn cmyk<T: Copy + Into<f64>>(v: &[T], max: f32, from: impl Fn(f32) -> T) -> Vec<T> {
        let scale = 1.0 / max;
        v.chunks_exact(4)
            .flat_map(|p| {
                let f = |c: T| c.into() as f32 * scale;
                let k = 1.0 - f(p[3]);
                let ink = |c: T| (((1.0 - f(c)) * k) * max + 0.5).clamp(0.0, max);
                [from(ink(p[0])), from(ink(p[1])), from(ink(p[2]))]
            })
            .collect()
    }
    Ok(match (convert, texels) {
        (Convert::Cmyk, Texels::U8(v)) => Texels::U8(cmyk(&v, 255.0, |x| x as u8)),
        (Convert::Cmyk, Texels::U16(v)) => Texels::U16(cmyk(&v, 65535.0, |x| x as u16)),
        (Convert::CmykJpeg, Texels::U8(v)) => Texels::U8(
            v.chunks_exact(4)
                .flat_map(|p| {
                    let k = 255 - p[3] as u32;
                    [0, 1, 2].map(|c| (k * (255 - p[c] as u32) / 255) as u8)
                })
                .collect(),
        ),
        (Convert::YccJpeg, Texels::U8(v)) => {
            let t = Ycc::jpeg();
            Texels::U8(
                v.chunks_exact(3)
                    .flat_map(|p| t.rgb(p[0], p[1], p[2]))
                    .collect(),
            )
        }
        _ => {
            return Err(decode_err(
                "the decoder returned CMYK or YCbCr samples of another type than the tags declare",
            ));
        }
    })
}

/// The colour channels a `PhotometricInterpretation` means (1 grey or
/// palette index, 3 RGB); the interpretations parvo does not read are
/// refused in words.
fn colour_channels(
    photometric: u64,
    stored_samples: usize,
    bits: u16,
    compression: u32,
) -> Result<usize> {
    match photometric {
        1 | 3 => Ok(1),
        2 => Ok(3),
        // The crate inverts one WhiteIsZero channel (as libtiff
        // and OpenImageIO read it: 0 is white); parvo inverts the others
        // (see `tiff/raw.rs`).
        0 if stored_samples == 1 && matches!(bits, 1 | 2 | 4 | 8..=16 | 32 | 64) => Ok(1),
        0 if stored_samples == 1 => Err(decode_err(format!(
            "WhiteIsZero (inverted grey) TIFF of {bits}-bit samples is not supported in this \
             layout: store it as BlackIsZero grey"
        ))),
        0 => Err(decode_err(
            "WhiteIsZero (inverted grey) TIFF with an alpha or extra channel is not \
             supported: store it as BlackIsZero grey",
        )),
        4 => Err(decode_err(
            "transparency-mask TIFF (PhotometricInterpretation 4) is not supported",
        )),
        // CMYK's conversion was decided before.
        5 => Ok(3),
        6 if compression == 7 => Ok(3),
        6 => Err(decode_err(format!(
            "YCbCr TIFF of {stored_samples} samples of {bits} bits{} is not supported (8-bit \
             YCbCr in strips, interleaved, or in JPEG, is): store it as RGB",
            if compression == 1 {
                ""
            } else {
                " in this layout"
            }
        ))),
        8..=10 => Err(decode_err(
            "CIE L*a*b* TIFF is not supported: convert it to RGB",
        )),
        32844 | 32845 => Err(decode_err(logluv(photometric))),
        u64::MAX => Err(decode_err(
            "the PhotometricInterpretation tag does not hold one number",
        )),
        p => Err(decode_err(format!(
            "photometric interpretation {p} is not supported"
        ))),
    }
}

/// The refusal of SGI's log-encoded TIFF (PhotometricInterpretation
/// 32844 LogL, 32845 LogLuv).
pub(super) fn logluv(photometric: u64) -> String {
    format!(
        "{} (SGI log-encoded high dynamic range) TIFF is not supported: convert it to OpenEXR \
         or to a float RGB TIFF",
        if photometric == 32844 {
            "LogL"
        } else {
            "LogLuv"
        }
    )
}

/// The channel type samples of `sample_format` (1 unsigned, 2 signed, 3
/// float) and `bits` load as: u8 for palette indices and sub-byte grey,
/// u16, f16, or f32 (also for f64); the others are refused in words.
fn channel_type(
    sample_format: u16,
    bits: u16,
    stored_samples: usize,
    palette: bool,
) -> Result<ChannelType> {
    Ok(match (sample_format, bits) {
        _ if palette => ChannelType::U8,
        (1, 1..=7) if stored_samples == 1 => ChannelType::U8,
        (1, 8) => ChannelType::U8,
        (1, 16) => ChannelType::U16,
        (3, 16) => ChannelType::F16,
        (3, 32) | (3, 64) => ChannelType::F32,
        // Signed and 32-bit unsigned integers load as f32 scaled as
        // OpenImageIO converts them to float (v / the type's maximum).
        (1, 32) | (2, 8 | 16 | 32) => ChannelType::F32,
        (1, b) if b < 8 => {
            return Err(decode_err(format!(
                "{b}-bit samples are supported for one grey channel, not for {stored_samples} \
                 channels"
            )));
        }
        (1, b @ (9..=15 | 17..=31)) => {
            return Err(decode_err(format!(
                "{b}-bit samples with a predictor, in tiles of planar data or in JPEG are not \
                 supported (libtiff reads no predictor for them either): store them as 16-bit"
            )));
        }
        (1, b) => {
            return Err(decode_err(format!(
                "{b}-bit unsigned integer samples are not supported (1 to 32 bits are)"
            )));
        }
        (2, b) => {
            return Err(decode_err(format!(
                "signed {b}-bit samples are not supported (8, 16 and 32 bits are)"
            )));
        }
        (f, b) => {
            return Err(decode_err(format!(
                "sample format {f} with {b} bits is not supported"
            )));
        }
    })
}

/// What the first `ExtraSamples` value says the channel after the colour
/// is: 1 associated alpha, 2 unassociated alpha, other values data;
/// without the tag, a second or fourth channel (`has_alpha_slot`) is
/// associated alpha, OpenImageIO's assumption, with a note saying so.
fn extra_alpha(extra: Option<u16>, has_alpha_slot: bool) -> (AlphaMode, Option<&'static str>) {
    match extra {
        Some(1) => (AlphaMode::Premultiplied, None),
        Some(2) => (AlphaMode::Straight, None),
        Some(_) => (AlphaMode::None, None),
        None if has_alpha_slot => (
            AlphaMode::Premultiplied,
            Some(
                "no ExtraSamples tag: the last channel is taken as associated alpha, as \
                 OpenImageIO does",
            ),
        ),
        None => (AlphaMode::None, None),
    }
}

/// Every plane of a tiled planar image, plane after plane, read tile by
/// tile: the `tiff` crate's whole-image read of tiled planar files
/// overruns its buffer at the bottom tiles of the planes after the first
/// (it clips only the first plane's tiles to the image).
fn planar_tiles<R: Read + Seek>(
    d: &mut Decoder<R>,
    dir: &Directory,
) -> std::result::Result<DecodingResult, TiffError> {
    let (w, h) = (dir.width as usize, dir.height as usize);
    let (tw, th) = d.chunk_dimensions();
    let (tw, th) = (tw as usize, th as usize);
    let (across, down) = (w.div_ceil(tw), h.div_ceil(th));
    let bytes = (dir.bits as usize).div_ceil(8);
    let plane = w * h * bytes;
    let mut out = vec![0u8; plane * dir.stored_samples];
    let mut kind = None;
    for p in 0..dir.stored_samples {
        for ty in 0..down {
            for tx in 0..across {
                let index = (p * across * down + ty * across + tx) as u32;
                let chunk = d.read_chunk(index)?;
                kind.get_or_insert(match &chunk {
                    DecodingResult::U8(_) => 0,
                    DecodingResult::U16(_) => 1,
                    DecodingResult::F16(_) => 2,
                    DecodingResult::F32(_) => 3,
                    _ => 4,
                });
                let mut chunk = chunk;
                let src = chunk.as_buffer(0);
                let src = src.as_bytes();
                // Rows of the tile inside the image, each as wide as the
                // tile's part inside the image.
                let cw = tw.min(w - tx * tw);
                let rows = th.min(h - ty * th);
                let row = cw * bytes;
                if src.len() < rows * row {
                    return Err(TiffError::FormatError(
                        TiffFormatError::InconsistentSizesEncountered,
                    ));
                }
                for r in 0..rows {
                    let at = p * plane + ((ty * th + r) * w + tx * tw) * bytes;
                    out[at..at + row].copy_from_slice(&src[r * row..(r + 1) * row]);
                }
            }
        }
    }
    Ok(match kind {
        Some(0) | None => DecodingResult::U8(out),
        Some(1) => DecodingResult::U16(bytemuck::pod_collect_to_vec(&out)),
        Some(2) => DecodingResult::F16(bytemuck::pod_collect_to_vec(&out)),
        Some(3) => DecodingResult::F32(bytemuck::pod_collect_to_vec(&out)),
        _ => DecodingResult::F64(bytemuck::pod_collect_to_vec(&out)),
    })
}

/// The first `keep` of the `per_pixel` samples of each of `n` pixels,
/// interleaved (a planar image holds all of channel 0, then channel 1, ...).
/// `pick` is (n, per_pixel, keep, planar).
fn select<T: Copy>(v: Vec<T>, pick: (usize, usize, usize, bool)) -> Result<Vec<T>> {
    let (n, per_pixel, keep, planar) = pick;
    if v.len() < n * per_pixel {
        return Err(decode_err(format!(
            "the decoder returned {} samples, the tags declare {}",
            v.len(),
            n * per_pixel
        )));
    }
    Ok(match (planar, per_pixel == keep) {
        (false, true) => {
            let mut v = v;
            v.truncate(n * keep);
            v
        }
        (false, false) => v
            .chunks_exact(per_pixel)
            .take(n)
            .flat_map(|px| px[..keep].iter().copied())
            .collect(),
        (true, _) if keep == 1 => {
            let mut v = v;
            v.truncate(n);
            v
        }
        (true, _) => {
            let mut out = Vec::with_capacity(n * keep);
            for i in 0..n {
                for c in 0..keep {
                    out.push(v[c * n + i]);
                }
            }
            out
        }
    })
}

/// A `bits`-bit code widened to 8 bits: `v · 255 / (2^bits − 1)`
/// rounded down (0 → 0, the largest code → 255; exact for 1, 2 and 4
/// bits), as OpenImageIO widens them.
fn widen(v: u8, bits: u32) -> u8 {
    let max = (1u32 << bits) - 1;
    (v as u32 * 255 / max) as u8
}

pub(super) fn join(v: &[u16]) -> String {
    v.iter()
        .map(|b| b.to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

/// One value per pixel from rows of `bits`-bit values (1 to 8) packed
/// most significant bit first, each row starting on a byte.
fn unpack(packed: &[u8], w: usize, h: usize, bits: u32) -> Result<Vec<u8>> {
    let stride = (w * bits as usize).div_ceil(8);
    if packed.len() < stride * h {
        return Err(decode_err(format!(
            "the decoder returned {} bytes, {h} rows of {w} {bits}-bit values take {}",
            packed.len(),
            stride * h
        )));
    }
    let mask = (1u16 << bits) - 1;
    let mut out = Vec::with_capacity(w * h);
    for row in packed.chunks_exact(stride).take(h) {
        for x in 0..w {
            let bit = x * bits as usize;
            // The value's bits within the two bytes it may straddle.
            let pair = ((row[bit / 8] as u16) << 8) | *row.get(bit / 8 + 1).unwrap_or(&0) as u16;
            let shift = 16 - bits as usize - bit % 8;
            out.push(((pair >> shift) & mask) as u8);
        }
    }
    Ok(out)
}

/// RGB u8 texels of palette indices: each colour-map entry (16 bits)
/// divided by 257 and rounded down, as OpenImageIO converts them.
fn expand_palette<I: Copy + Into<usize>>(idx: &[I], map: &[u16], size: usize) -> Vec<u8> {
    let to8 = |v: u16| (v / 257) as u8;
    let mut out = Vec::with_capacity(idx.len() * 3);
    for &i in idx {
        let i: usize = i.into();
        out.extend_from_slice(&[to8(map[i]), to8(map[size + i]), to8(map[2 * size + i])]);
    }
    out
}

/// The environment-map kind a `textureformat` names.
fn environment(texture_format: Option<&str>) -> Option<Environment> {
    match texture_format? {
        "CubeFace Environment" => Some(Environment::Cube),
        "LatLong Environment" => Some(Environment::LatLong),
        _ => None,
    }
}

/// The environment kind a TIFF's first directory declares with maketx's
/// `textureformat` tag: [`crate::texture::ImageKind::LatLong`] for `LatLong
/// Environment`, else `Plain` (also for a file that does not read). A
/// `CubeFace Environment` stays `Plain`: maketx lays its faces out 3x2,
/// which parvo does not build from, and the load refuses it in words.
pub(crate) fn peek_kind(path: &Path) -> crate::texture::ImageKind {
    let read = || {
        let file = File::open(path).ok()?;
        let mut d = Decoder::new(BufReader::new(file)).ok()?;
        ascii_tag(&mut d, Tag::Unknown(tag::TEXTURE_FORMAT))
    };
    match std::panic::catch_unwind(read).ok().flatten().as_deref() {
        Some("LatLong Environment") => crate::texture::ImageKind::LatLong,
        _ => crate::texture::ImageKind::Plain,
    }
}

/// Load a TIFF file (see the module docs).
pub fn load(path: &Path, limits: &Limits, options: &LoadOptions) -> Result<Loaded> {
    let open = || {
        File::open(path).map_err(|e| Error::Io {
            path: path.to_path_buf(),
            action: "cannot open".into(),
            error: e,
        })
    };
    let mut file = open()?;
    let len = file
        .metadata()
        .map_err(|e| Error::Io {
            path: path.to_path_buf(),
            action: "cannot read".into(),
            error: e,
        })?
        .len();
    let chain = chain::walk(&mut file, len).map_err(decode_err)?;
    let l = chain.layout;
    let pages = chain.dirs.len();
    // A texture: its first directory has Pixar's `textureformat` tag.
    let mipmapped = chain.dirs[0].entry(tag::TEXTURE_FORMAT).is_some();
    let (first, count) = directories_read(pages, mipmapped, options)?;
    for d in &chain.dirs[first..first + count] {
        if d.unsigned(&l, tag::COMPRESSION) == Some(6) {
            return Err(decode_err(
                "old-style JPEG compression (Compression 6, from before TIFF 6.0) is not \
                 supported: re-save it with JPEG (7), Deflate or LZW compression",
            ));
        }
        chain::check_extents(&mut file, &l, d).map_err(decode_err)?;
    }
    let (view, fixes, fix_notes) = chain.repair(open()?).map_err(decode_err)?;
    let mut notes = chain_notes(&chain, fix_notes, first, mipmapped);
    let reader = |k: usize| Reader {
        raw: &chain.dirs[k],
        layout: l,
        limits,
    };
    let mut d = Decoder::new(BufReader::new(view))
        .map_err(|e| reader(0).err(e))?
        .with_limits(decoder_limits(limits, len));
    d.seek_to_image(first).map_err(|e| reader(first).err(e))?;
    let r0 = reader(first);
    let dir0 = r0.directory(&mut d, fixes[first])?;
    let texture_format = ascii_tag(&mut d, Tag::Unknown(tag::TEXTURE_FORMAT));
    let wrap_text = ascii_tag(&mut d, Tag::Unknown(tag::WRAP_MODES));
    let attributes = r0.attributes(&mut d, &dir0, &texture_format, &wrap_text)?;
    let env = environment(texture_format.as_deref());
    if let Some(kind) = env {
        super::environment_map(
            "TIFF",
            kind,
            &format!(
                "textureformat \"{}\", {}x{}",
                texture_format.as_deref().unwrap_or(""),
                dir0.width,
                dir0.height
            ),
            options,
            &mut notes,
        )?;
    }
    check_levels(&dir0, count, limits)?;
    dir0.notes(&mut notes);
    let mut levels = vec![r0.texture(&mut d, &dir0)?];
    let mut rounding = Rounding::Down;
    for (k, &fix) in fixes.iter().enumerate().take(count).skip(1) {
        d.seek_to_image(k).map_err(|e| reader(k).err(e))?;
        let rk = reader(k);
        let dir = rk.directory(&mut d, fix)?;
        if k == 1 {
            rounding = level_rounding(&dir0, &dir).unwrap_or(rounding);
        }
        let want = crate::mip::level_size(dir0.width, dir0.height, k as u32, rounding);
        if (dir.width, dir.height) != want || dir.format != dir0.format {
            return Err(decode_err(format!(
                "mip level {k} is {}x{} {}, level 0 implies {}x{} {}",
                dir.width, dir.height, dir.format, want.0, want.1, dir0.format
            )));
        }
        levels.push(rk.texture(&mut d, &dir)?);
    }
    if dir0.orientation != 1 {
        apply_orientation(&mut levels, dir0.orientation, options, &mut notes)?;
    }
    let format = levels[0].format();
    let mut info = SourceInfo::new(FileFormat::Tiff, &format);
    info.own_mips = levels.len() > 1;
    info.rounding = rounding;
    info.wrap = super::recorded_wrap(wrap_text.as_deref(), &mut notes);
    info.tile = dir0.tile;
    info.attributes = attributes;
    info.environment = env;
    info.notes = notes;
    // TIFF names no transfer parvo reads: its values are taken as they
    // are (linear), as OpenImageIO reads them, and that is an assumption.
    info.color_stated = false;
    Ok(Loaded::plain(levels, info))
}

/// The notes of walking and repairing the chain of directories: of the
/// page read only, unless all are read (a mip-mapped texture); a note
/// that the file has other pages.
fn chain_notes(
    chain: &chain::Chain,
    fix_notes: Vec<String>,
    first: usize,
    mipmapped: bool,
) -> Vec<String> {
    let pages = chain.dirs.len();
    let mut notes = Vec::new();
    if !mipmapped && pages > 1 {
        notes.push(format!(
            "multi-page TIFF: using page {first} of {pages}; {} N picks another",
            Setting::Subimage
        ));
    }
    notes.extend(chain.notes.iter().cloned());
    if mipmapped {
        notes.extend(fix_notes);
    } else {
        // Only the page read.
        let prefix = format!("page {first}: ");
        notes.extend(
            fix_notes
                .into_iter()
                .filter(|n| pages == 1 || n.starts_with(&prefix))
                .map(|n| n.trim_start_matches(&prefix).to_string()),
        );
    }
    notes
}

/// Which of `pages` directories are read, as (first, count): all of a
/// mip-mapped texture, else the one page `options.subimage` picks.
fn directories_read(
    pages: usize,
    mipmapped: bool,
    options: &LoadOptions,
) -> Result<(usize, usize)> {
    let first = if mipmapped { 0 } else { options.subimage };
    if first >= pages {
        return Err(Error::InvalidOption(format!(
            "{} {first}: the file has {pages} page{}",
            Setting::Subimage,
            if pages == 1 { "" } else { "s" }
        )));
    }
    if mipmapped && options.subimage != 0 {
        return Err(Error::InvalidOption(format!(
            "{}: this TIFF is a mip-mapped texture, its directories are its levels",
            Setting::Subimage
        )));
    }
    Ok((first, if mipmapped { pages } else { 1 }))
}

/// The `tiff` crate's limits: its decoding buffers held to the allocation
/// limit; a tag's values to the file's length (at least the crate's own
/// default, at most the allocation limit).
fn decoder_limits(limits: &Limits, len: u64) -> ::tiff::decoder::Limits {
    let mut tl = ::tiff::decoder::Limits::default();
    tl.decoding_buffer_size = usize::try_from(limits.max_alloc).unwrap_or(usize::MAX);
    tl.intermediate_buffer_size = tl.decoding_buffer_size;
    tl.ifd_value_size =
        usize::try_from(len.min(limits.max_alloc).max(CRATE_TAG_LIMIT)).unwrap_or(usize::MAX);
    tl
}

/// The declared sizes of every level read, checked before decoding: no
/// more directories than a mip chain of level 0 has, level 0 (twice, with
/// the levels after it) within `limits`.
fn check_levels(dir0: &Directory, count: usize, limits: &Limits) -> Result<()> {
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
    )
}

/// The rounding a mip chain's level 1 shows (`None` when its size is
/// neither level 0 halved down nor up; the size check then refuses it).
fn level_rounding(dir0: &Directory, dir1: &Directory) -> Option<Rounding> {
    let up_size = crate::mip::level_size(dir0.width, dir0.height, 1, Rounding::Up);
    let down_size = crate::mip::level_size(dir0.width, dir0.height, 1, Rounding::Down);
    if (dir1.width, dir1.height) == down_size {
        Some(Rounding::Down)
    } else if (dir1.width, dir1.height) == up_size {
        Some(Rounding::Up)
    } else {
        None
    }
}

/// The TIFF `Orientation` (274) applied to every level, unless turned off;
/// a note says which.
fn apply_orientation(
    levels: &mut [Texture],
    orientation: u16,
    options: &LoadOptions,
    notes: &mut Vec<String>,
) -> Result<()> {
    if options.auto_orient {
        for l in levels.iter_mut() {
            *l = super::orient(l, orientation)?;
        }
        notes.push(format!(
            "TIFF orientation {} applied ({} keeps the stored order)",
            orientation,
            Setting::NoAutoOrient
        ));
    } else {
        notes.push(format!(
            "TIFF orientation {} not applied ({})",
            orientation,
            Setting::NoAutoOrient
        ));
    }
    Ok(())
}

/// TIFF in the container table (read only): strips and tiles, chunky and
/// planar, 8/16/32-bit, pages and mip-mapped directories.
pub struct Tiff;

impl super::Container for Tiff {
    fn selects_subimage(&self) -> bool {
        true
    }
    fn peek_kind(&self, _head: &[u8], path: &Path) -> Option<crate::texture::ImageKind> {
        Some(peek_kind(path))
    }
    fn id(&self) -> &'static str {
        "tiff"
    }
    fn name(&self) -> &'static str {
        "TIFF"
    }
    fn detect(&self, magic: &[u8]) -> bool {
        [b"II*\0", b"MM\0*", b"II+\0", b"MM\0+"]
            .iter()
            .any(|m| magic.starts_with(*m))
    }
    fn load(
        &self,
        path: &Path,
        limits: &Limits,
        options: &LoadOptions,
        _overlap: Option<super::Overlap<'_>>,
    ) -> Result<Loaded> {
        load(path, limits, options)
    }
    fn read_extensions(&self) -> &'static [&'static str] {
        &["tif", "tiff", "tx"]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unpack_reads_rows_msb_first_each_on_a_byte() {
        // 5 pixels of 2 bits: 00 01 10 11 | 01 (row padded to 2 bytes).
        let rows = [0b0001_1011, 0b0100_0000, 0b1110_0100, 0b1000_0000];
        assert_eq!(
            unpack(&rows, 5, 2, 2).unwrap(),
            [0, 1, 2, 3, 1, 3, 2, 1, 0, 2]
        );
        assert!(unpack(&rows[..3], 5, 2, 2).is_err());
    }

    #[test]
    fn palette_entries_round_down_as_openimageio() {
        // Values checked against OpenImageIO 3.2 reading a palette TIFF.
        let mut map = vec![0u16; 3 * 4];
        map[..4].copy_from_slice(&[0xFF00, 0x8000, 0x0100, 0xFFFF]);
        let rgb = expand_palette(&[0u8, 1, 2, 3], &map, 4);
        assert_eq!(
            rgb.iter().step_by(3).copied().collect::<Vec<_>>(),
            [254, 127, 0, 255]
        );
    }

    #[test]
    fn planar_samples_interleave_and_extra_ones_drop() {
        let v = vec![1, 2, 3, 10, 20, 30, 100, 200, 300, 7, 7, 7];
        assert_eq!(
            select(v.clone(), (3, 4, 3, true)).unwrap(),
            [1, 10, 100, 2, 20, 200, 3, 30, 300]
        );
        assert_eq!(
            select(v.clone(), (3, 4, 3, false)).unwrap(),
            [1, 2, 3, 20, 30, 100, 300, 7, 7]
        );
        assert!(select(v, (4, 4, 3, true)).is_err());
    }

    #[test]
    fn sub_byte_codes_widen_as_openimageio() {
        for bits in 1..=7u32 {
            let max = (1u8 << bits) - 1;
            assert_eq!(widen(0, bits), 0);
            assert_eq!(widen(max, bits), 255, "{bits} bits");
        }
        // 1, 2 and 4 bits scale exactly.
        assert_eq!(widen(1, 2), 85);
        assert_eq!(widen(7, 4), 119);
        // 6 bits: codes OpenImageIO 3.2 read from libtiff's
        // flower-minisblack-06.tif (16 → 64, 32 → 129, 62 → 250).
        assert_eq!([widen(16, 6), widen(32, 6), widen(62, 6)], [64, 129, 250]);
    }
}
