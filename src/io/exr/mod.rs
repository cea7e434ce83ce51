//! OpenEXR: read scanline, tiled and mip-mapped files (all levels, also
//! files maketx writes) and write tiled, mip-mapped textures.
//!
//! Reading goes through the `exr` crate after the header has been checked
//! against [`Limits`] (the declared size of every level the file holds).
//! Channels follow OpenImageIO's conventions: ordered by layer, then
//! `R, G, B, Y, A, …` (`X, Y, Z` in a layer that has them), all of them
//! when there are at most four, else the first layer's `R,G,B[,A]` or
//! `Y[,A]`; alpha only when named `A` and last of two or four, other
//! names are data channels; [`super::LoadOptions::channels`] picks by name.
//! A multi-part file reads part 0 (or [`super::LoadOptions::subimage`]),
//! a data window inside a larger display window is placed in it. Half files load as f16, everything
//! else (float, uint) as f32. EXR data is linear light with premultiplied
//! (associated) alpha, as the OpenEXR documentation defines it; [`save`]
//! expects premultiplied levels too (the CLI premultiplies straight
//! sources before writing).
//!
//! Writing: the `exr` crate panics when the number of levels does not match
//! the chain its header implies and when mip maps are asked for without
//! tiles, so [`save`] checks both first, and writes through
//! [`atomic`] so that even a panic never reaches the
//! destination. Channel names follow the convention texture systems read:
//! `R,G,B,A`, grey `Y`, grey + alpha `Y,A`. Besides the pixels the header
//! gets what OpenImageIO's texture system reads (`wrapmodes` as maketx
//! writes it, e.g. `periodic,periodic`; `textureformat` = `Plain Texture`),
//! the rounding mode in the tile description, and parvo's own attributes
//! (`parvo:...`, including the fingerprint that `--update` compares).

use std::fmt;
use std::path::Path;

use crate::setting::Setting;
use std::str::FromStr;

use ::exr::block::chunk::{Chunk, CompressedBlock, CompressedTileBlock, TileCoordinates};
use ::exr::block::writer::ChunksWriter;
use ::exr::block::{BlockIndex, UncompressedBlock};
use ::exr::math::RoundingMode;
use ::exr::meta::attribute::{
    AttributeValue, ChannelDescription, LevelMode, SampleType, Text, TileDescription,
};
use ::exr::meta::header::Header;
use ::exr::meta::{BlockDescription, MetaData};
use ::exr::prelude::traits::{ReadChannels, ReadLayers};
use ::exr::prelude::{FlatSamples, LayerAttributes, LineOrder, SmallVec, Vec2};
use half::f16;
use rayon::prelude::*;

use super::{FINGERPRINT_KEY, FileFormat, Limits, Loaded, SaveOptions, SourceInfo, atomic};
use crate::error::{Error, Result};
use crate::mip::Rounding;
use crate::texel::{AlphaMode, ChannelType, ColorSpace, Format, Texels};
use crate::texture::Texture;

mod placement;
mod read;
mod write;

pub use placement::{centred_from_edges, edges_from_centred};
pub use read::*;
pub use write::*;

/// How OpenEXR files are written: the options of this container alone
/// (`--tile`, `--compression`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ExrOptions {
    /// Tile size (width, height) of the tiled, mip-mapped file.
    pub tile: (u32, u32),
    /// Compression of every tile.
    pub compression: ExrCompression,
}

impl Default for ExrOptions {
    fn default() -> Self {
        ExrOptions {
            tile: (64, 64),
            compression: ExrCompression::default(),
        }
    }
}

/// EXR compression, by the names OpenEXR tools use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum ExrCompression {
    /// `none`.
    None,
    /// `rle`.
    Rle,
    /// `zips`: zlib, one scanline per block.
    Zips,
    /// `zip`: zlib, 16 scanlines per block (the default, as maketx).
    #[default]
    Zip,
    /// `piz`: wavelet + Huffman.
    Piz,
    /// `pxr24`: lossy for f32 (24-bit), lossless for f16.
    Pxr24,
    /// `b44`: lossy, f16 only.
    B44,
    /// `b44a`: `b44` with flat-area optimisation.
    B44a,
    /// `dwaa`: lossy DCT, 32 scanlines.
    Dwaa,
    /// `dwab`: lossy DCT, 256 scanlines.
    Dwab,
}

impl ExrCompression {
    /// Every compression, in a stable order.
    pub const ALL: [ExrCompression; 10] = [
        ExrCompression::None,
        ExrCompression::Rle,
        ExrCompression::Zips,
        ExrCompression::Zip,
        ExrCompression::Piz,
        ExrCompression::Pxr24,
        ExrCompression::B44,
        ExrCompression::B44a,
        ExrCompression::Dwaa,
        ExrCompression::Dwab,
    ];

    /// The OpenEXR name.
    pub fn name(self) -> &'static str {
        match self {
            ExrCompression::None => "none",
            ExrCompression::Rle => "rle",
            ExrCompression::Zips => "zips",
            ExrCompression::Zip => "zip",
            ExrCompression::Piz => "piz",
            ExrCompression::Pxr24 => "pxr24",
            ExrCompression::B44 => "b44",
            ExrCompression::B44a => "b44a",
            ExrCompression::Dwaa => "dwaa",
            ExrCompression::Dwab => "dwab",
        }
    }

    fn to_exr(self) -> ::exr::compression::Compression {
        use ::exr::compression::Compression as C;
        match self {
            ExrCompression::None => C::Uncompressed,
            ExrCompression::Rle => C::RLE,
            ExrCompression::Zips => C::ZIP1,
            ExrCompression::Zip => C::ZIP16,
            ExrCompression::Piz => C::PIZ,
            ExrCompression::Pxr24 => C::PXR24,
            ExrCompression::B44 => C::B44,
            ExrCompression::B44a => C::B44A,
            ExrCompression::Dwaa => C::DWAA(None),
            ExrCompression::Dwab => C::DWAB(None),
        }
    }
}

impl fmt::Display for ExrCompression {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for ExrCompression {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        ExrCompression::ALL
            .into_iter()
            .find(|c| c.name().eq_ignore_ascii_case(s))
            .ok_or_else(|| {
                Error::parse(
                    "EXR compression",
                    s,
                    "expected none, rle, zips, zip, piz, pxr24, b44, b44a, dwaa or dwab",
                )
            })
    }
}

fn decode_err(e: impl fmt::Display) -> Error {
    Error::Decode {
        format: "OpenEXR",
        reason: e.to_string(),
    }
}

/// An error of the `exr` crate while reading, in parvo's words: what is
/// wrong in OpenEXR's terms, never the crate's phrase alone.
fn read_err(e: ::exr::error::Error) -> Error {
    use ::exr::error::Error as E;
    decode_err(match e {
        E::Invalid(m) => match &*m {
            "reference to missing bytes" | "not enough data" => {
                "the file ends before the data its header and offset table point to: it is \
                 truncated"
                    .to_string()
            }
            "file identifier missing" => "not an OpenEXR file (its magic number is wrong)".into(),
            m if m.contains("file feature flags") => {
                "its version field sets feature flags OpenEXR does not define: the file is \
                 corrupt or from a newer OpenEXR"
                    .into()
            }
            // The crate's phrases name what is wrong ("text too long",
            // "block position 9 exceeds total size 4") or the part that
            // is ("block type attribute value").
            m if ["invalid", "exceed", "too ", "missing", "must"]
                .iter()
                .any(|w| m.contains(w)) =>
            {
                format!("the file is corrupt ({m})")
            }
            m => format!("the file is corrupt: its {m} is invalid"),
        },
        E::NotSupported(m) if m.contains("subsampl") => SUBSAMPLED.into(),
        E::NotSupported(m) if m.contains("deep") => DEEP.into(),
        E::NotSupported(m) => format!("the file uses an OpenEXR feature parvo does not read ({m})"),
        E::Io(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => {
            "the file ends early: it is truncated".into()
        }
        E::Io(e) => format!("cannot read the file: {}", crate::error::io_words(&e)),
        E::Aborted => "reading was stopped".into(),
    })
}

/// The refusal of chroma-subsampled channels (OpenEXR's luminance/chroma
/// images: Y, RY, BY).
const SUBSAMPLED: &str = "its channels are subsampled (a luminance/chroma image: Y, RY and BY, as \
     OpenEXR's RGBA interface writes them), which parvo does not read: convert it to full-\
     resolution RGB or RGBA first";

/// The refusal of deep data.
const DEEP: &str = "deep (several samples per pixel) OpenEXR data is not a texture parvo reads: \
     flatten it to RGBA first";

fn encode_err(e: impl fmt::Display) -> Error {
    Error::Encode {
        format: "OpenEXR",
        reason: e.to_string(),
    }
}

fn to_exr_rounding(r: Rounding) -> RoundingMode {
    match r {
        Rounding::Down => RoundingMode::Down,
        Rounding::Up => RoundingMode::Up,
    }
}

/// Level sizes the header of a tiled mip-mapped file of this size implies.
fn exr_level_sizes(w: u32, h: u32, r: Rounding) -> Vec<(u32, u32)> {
    ::exr::meta::mip_map_levels(to_exr_rounding(r), Vec2(w as usize, h as usize))
        .map(|(_, s)| (s.width() as u32, s.height() as u32))
        .collect()
}

/// OpenEXR in the container table: reads scanline, tiled and mip-mapped
/// files (a chosen part, chosen channels); writes tiled, mip-mapped
/// files of f16 or f32, colour premultiplied by alpha as the format
/// defines it, the whole chain, sizes rounded down or up, the
/// fingerprint as an attribute, level 0 streamed band by band.
pub struct OpenExr;

impl super::Container for OpenExr {
    fn selects_subimage(&self) -> bool {
        true
    }
    fn peek_kind(&self, _head: &[u8], path: &Path) -> Option<crate::texture::ImageKind> {
        Some(peek_kind(path))
    }
    fn id(&self) -> &'static str {
        "exr"
    }
    fn name(&self) -> &'static str {
        "OpenEXR"
    }
    fn tag(&self) -> &'static str {
        "Exr"
    }
    fn summary(&self) -> &'static str {
        "Tiled, mip-mapped OpenEXR"
    }
    fn detect(&self, magic: &[u8]) -> bool {
        magic.starts_with(&[0x76, 0x2f, 0x31, 0x01])
    }
    fn load(
        &self,
        path: &Path,
        limits: &Limits,
        options: &super::LoadOptions,
        _overlap: Option<super::Overlap<'_>>,
    ) -> Result<Loaded> {
        load(path, limits, options)
    }
    fn read_extensions(&self) -> &'static [&'static str] {
        &["exr"]
    }
    fn selects_channels(&self) -> bool {
        true
    }
    fn stores(&self) -> Option<super::Stores> {
        Some(super::Stores {
            float: true,
            whole_chain: true,
            round_up: true,
            fingerprint: true,
            channel_names: true,
            streamed_level0: true,
            alpha: Some(crate::texel::AlphaMode::Premultiplied),
            ..super::Stores::NOTHING
        })
    }
    fn default_type(&self, src: ChannelType) -> ChannelType {
        if src == ChannelType::F32 {
            ChannelType::F32
        } else {
            ChannelType::F16
        }
    }
    fn data_type(&self, _main: ChannelType) -> ChannelType {
        ChannelType::F16
    }
    fn stored_fingerprint(&self, path: &Path) -> Option<String> {
        stored_fingerprint(path)
    }
    fn holds(&self, kind: crate::texture::ImageKind) -> bool {
        use crate::texture::ImageKind;
        matches!(
            kind,
            ImageKind::Plain | ImageKind::LatLong | ImageKind::Cube
        )
    }
    fn placement(&self) -> crate::env::Placement {
        crate::env::Placement::Edges
    }
    fn save(
        &self,
        images: &[&[Texture]],
        kind: crate::texture::ImageKind,
        rounding: Rounding,
        path: &Path,
        options: &SaveOptions,
    ) -> Result<()> {
        use crate::texture::ImageKind;
        match kind {
            ImageKind::Plain => save(images[0], rounding, path, options),
            _ if options.placement == crate::env::Placement::Centred => {
                let placed = edges_from_centred(images, kind, 0)?;
                let refs: Vec<&[Texture]> = placed.iter().map(Vec::as_slice).collect();
                let options = SaveOptions {
                    placement: crate::env::Placement::Edges,
                    ..options.clone()
                };
                self.save(&refs, kind, rounding, path, &options)
            }
            ImageKind::LatLong => save_environment(
                images[0],
                rounding,
                path,
                options,
                super::Environment::LatLong,
            ),
            _ => {
                let strip = cube_strip_levels(images, rounding)?;
                save_environment(&strip, rounding, path, options, super::Environment::Cube)
            }
        }
    }
}

/// OpenEXR's cube faces (`ImfEnvmap.cpp`, `CubeMap::pixelPosition`) as
/// GL's faces of the same directions, or GL's as OpenEXR's: the same face
/// order (+X, −X, +Y, −Y, +Z, −Z), each face mirrored: the X and Z faces
/// left to right, the Y faces top to bottom (OpenEXR's +X face has +z to
/// the right and −y down, GL's −z to the right and −y down; its +Y face
/// +x right and −z down, GL's +x right and +z down). The mirror is its own
/// inverse. Texel placement is a separate matter
/// ([`crate::env::Placement`]).
pub fn mirror_cube_faces(faces: &[Texture]) -> Result<Vec<Texture>> {
    faces
        .iter()
        .enumerate()
        .map(|(f, t)| super::orient(t, if f == 2 || f == 3 { 4 } else { 2 }))
        .collect()
}

/// The levels of OpenEXR's cube-map strip for six faces' levels: level k
/// stacks the faces' level k while they are at least 1×1; the strip's
/// last levels (1×3, 1×1), which OpenEXR's level rule asks for but no
/// face has, are box-filtered from the 1×6 strip. Faces of a size that
/// is not a power of two cannot keep apart in the strip's levels.
fn cube_strip_levels(faces: &[&[Texture]], rounding: Rounding) -> Result<Vec<Texture>> {
    let n = faces[0][0].width();
    // GL's faces (parvo's order and orientation) as OpenEXR's.
    let mut strip: Vec<Texture> = (0..faces[0].len())
        .map(|k| {
            let level: Vec<Texture> = faces.iter().map(|f| f[k].clone()).collect();
            let level = mirror_cube_faces(&level)?;
            crate::env::cube::strip_from_faces(&level.iter().collect::<Vec<_>>())
        })
        .collect::<Result<_>>()?;
    if strip.len() == 1 {
        return Ok(strip);
    }
    let face_levels = crate::mip::level_count(n, n, rounding, None) as usize;
    if !n.is_power_of_two() || strip.len() != face_levels {
        return Err(encode_err(format!(
            "an OpenEXR cube map stacks its six faces in each level, which keeps them apart only \
             for power-of-two faces with every level down to 1x1 (got {n}x{n} faces with {} \
             levels); KTX2 and DDS store any cube map",
            strip.len()
        )));
    }
    let Some(last) = strip.pop() else {
        return Err(encode_err("no levels"));
    };
    let options = crate::mip::MipOptions {
        rounding,
        ..Default::default()
    };
    let tail = crate::mip::build(last, &options)?;
    strip.extend(tail.into_levels());
    Ok(strip)
}
