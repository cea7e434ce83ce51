//! DDS (DirectDraw Surface): the full mip chain of a 2-D texture, written
//! with the header every common reader understands, and read from the
//! files other tools write.
//!
//! The header is written and parsed here field by field, after Microsoft's
//! DDS reference and DirectXTex's `EncodeDDSHeader`. (The `ddsfile` crate
//! was dropped: it sets `DDPF_RGB` with zero masks on every DXGI format,
//! which Pillow decodes as an all-black image, and `DDPF_RGB` instead of
//! `DDPF_LUMINANCE` on L8; its reader drops a mip count whose flag is
//! missing.)
//!
//! # Which header a format gets
//!
//! A **legacy header** (no DX10 extension) wherever the DX9 pixel-format
//! masks describe the texel exactly, with the masks and flags DirectXTex
//! writes; Pillow, OpenImageIO, DirectXTex and every DDS loader read these:
//!
//! | texels | header | flags, bits, masks (R, G, B, A) |
//! |---|---|---|
//! | R u8 | L8 | `LUMINANCE`, 8, `ff` |
//! | grey + straight alpha u8 | A8L8 | `LUMINANCE\|ALPHAPIXELS`, 16, `00ff`, –, –, `ff00` |
//! | RGB u8 | X8B8G8R8 (alpha byte 255) | `RGB`, 32, `ff`, `ff00`, `ff0000`, 0 |
//! | RGBA u8, straight | A8B8G8R8 | `RGB\|ALPHAPIXELS`, 32, `ff`, `ff00`, `ff0000`, `ff000000` |
//! | R u16 | L16 | `LUMINANCE`, 16, `ffff` |
//! | RG u16 (no alpha) | G16R16 | `RGB`, 32, `ffff`, `ffff0000`, 0, 0 |
//! | RGBA u16, straight | D3DFMT_A16B16G16R16 | `FOURCC` 36 (64 bits: no masks) |
//!
//! The **DX10 extension** (pixel format `FOURCC` alone, fourCC `DX10`, no
//! masks) where the legacy header cannot say what the data is:
//! - sRGB: `R8G8B8A8_UNORM_SRGB` (DXGI has no other uncompressed sRGB
//!   format, so sRGB grey, grey + alpha and RGB are widened to RGBA);
//! - half and single floats: `R16[G16[B16A16]]_FLOAT`, `R32[G32[B32[A32]]]_FLOAT`
//!   (DirectXTex writes D3DX's fourCCs 111–116 here; readers that know the
//!   DX10 header outnumber those that know D3DX's codes);
//! - premultiplied alpha (DX10's alpha mode is the only place to say so);
//! - data channels that a legacy header would call alpha or luminance: RG
//!   u8 (`R8G8_UNORM`, which DirectXTex would write as A8L8), RGBA u8/u16
//!   whose fourth channel is not alpha (alpha mode `CUSTOM`), grey + alpha
//!   u16 (`R16G16_UNORM` with alpha mode `STRAIGHT`);
//! - RGB u16 and f16, widened to RGBA with alpha 1 and alpha mode `OPAQUE`.
//!
//! The DX10 alpha mode is `STRAIGHT`, `PREMULTIPLIED`, `OPAQUE` (no alpha
//! in the source: R, RG, RGB, and widened data) or `CUSTOM` (a fourth
//! channel that is data). Reading inverts all of this: `OPAQUE` RGBA comes
//! back as RGB, two channels are grey + alpha only when the header says so
//! (A8L8, or a DX10 alpha mode `STRAIGHT`/`PREMULTIPLIED`), else R, G data.
//!
//! Levels are stored level 0 first, each `width × height` texels with rows
//! packed (pitch = width × bytes per texel), sizes rounding down: DDS has no
//! other rule, so rounding up is refused.
//!
//! # Reading
//! Besides parvo's own files: any legacy `RGB`/`LUMINANCE`/`ALPHA` layout of
//! 8 to 32 bits per texel with masks of up to 16 bits per channel (channels
//! of fewer bits are scaled to 8 bits, e.g. R5G6B5), the D3DX float and
//! 16-bit fourCCs (36, 111–116), the block-compressed formats (`DXT1`–`DXT5`,
//! `ATI1`/`BC4U`/`BC4S`, `ATI2`/`BC5U`/`BC5S`, and BC1–BC7 in DX10 files,
//! decoded with [`crate::compress`]; `DXT2`/`DXT4` are premultiplied), and
//! the uncompressed DXGI formats above plus `B8G8R8A8`/`B8G8R8X8` (UNORM
//! and sRGB) and the `TYPELESS` variants of those with a UNORM meaning
//! (read as UNORM, as Pillow reads them, with a note). A DX10 resource
//! dimension of 0 (unknown, as in Pillow's `bc1.dds`) is read as a 2-D
//! texture from the header's width and height, as Pillow and OpenImageIO
//! do. Cube maps, volumes, texture arrays and palettised files are refused
//! by name, as is every other format (DXGI formats by their names).

use std::io::Write;
use std::path::Path;

use super::{FileFormat, Limits, Loaded, SourceInfo, atomic};
use crate::compress::{BlockChain, BlockFormat};
use crate::env::Kind;
use crate::error::{Error, Result};
use crate::texel::{AlphaMode, ChannelType, ColorSpace, Format, Texels};
use crate::texture::Texture;

fn encode_err(reason: impl std::fmt::Display) -> Error {
    Error::Encode {
        format: "DDS",
        reason: reason.to_string(),
    }
}

fn decode_err(reason: impl std::fmt::Display) -> Error {
    Error::Decode {
        format: "DDS",
        reason: reason.to_string(),
    }
}

/// `DDS_HEADER.flags` (`DDSD_*`).
pub mod ddsd {
    /// `dwCaps` is valid.
    pub const CAPS: u32 = 0x1;
    /// `dwHeight` is valid.
    pub const HEIGHT: u32 = 0x2;
    /// `dwWidth` is valid.
    pub const WIDTH: u32 = 0x4;
    /// `dwPitchOrLinearSize` is the row pitch of an uncompressed texture.
    pub const PITCH: u32 = 0x8;
    /// `ddspf` is valid.
    pub const PIXELFORMAT: u32 = 0x1000;
    /// `dwMipMapCount` is valid.
    pub const MIPMAPCOUNT: u32 = 0x20000;
    /// `dwPitchOrLinearSize` is the byte size of a compressed level 0.
    pub const LINEARSIZE: u32 = 0x80000;
    /// `dwDepth` is valid (volume textures).
    pub const DEPTH: u32 = 0x800000;
}

/// `DDS_PIXELFORMAT.flags` (`DDPF_*`).
pub mod ddpf {
    /// The alpha mask is valid.
    pub const ALPHAPIXELS: u32 = 0x1;
    /// Alpha-only data (legacy).
    pub const ALPHA: u32 = 0x2;
    /// `dwFourCC` names the format.
    pub const FOURCC: u32 = 0x4;
    /// Uncompressed RGB data described by the masks.
    pub const RGB: u32 = 0x40;
    /// YUV data.
    pub const YUV: u32 = 0x200;
    /// Single-channel (luminance) data in the red mask.
    pub const LUMINANCE: u32 = 0x20000;
    /// Signed bump-map (du/dv) data.
    pub const BUMPDUDV: u32 = 0x80000;
}

/// `dwCaps` and `dwCaps2` bits.
pub mod caps {
    /// More than one surface (mip levels, faces).
    pub const COMPLEX: u32 = 0x8;
    /// Always set.
    pub const TEXTURE: u32 = 0x1000;
    /// Mip-mapped.
    pub const MIPMAP: u32 = 0x400000;
    /// `dwCaps2`: a cube map.
    pub const CUBEMAP: u32 = 0x200;
    /// `dwCaps2`: the six faces of a cube map (+X, −X, +Y, −Y, +Z, −Z:
    /// 0x400 … 0x8000).
    pub const ALL_FACES: u32 = 0xfc00;
    /// `dwCaps2`: a volume texture.
    pub const VOLUME: u32 = 0x200000;
}

/// The DX10 header's alpha mode (`DDS_ALPHA_MODE_*`, in `miscFlags2`).
pub mod alpha_mode {
    /// Unknown (readers assume straight).
    pub const UNKNOWN: u32 = 0;
    /// Straight (unassociated) alpha.
    pub const STRAIGHT: u32 = 1;
    /// Premultiplied (associated) alpha.
    pub const PREMULTIPLIED: u32 = 2;
    /// Opaque: the alpha channel, if any, is 1 everywhere.
    pub const OPAQUE: u32 = 3;
    /// The fourth channel is not transparency.
    pub const CUSTOM: u32 = 4;
}

const DX10: u32 = u32::from_le_bytes(*b"DX10");
const D3D10_RESOURCE_DIMENSION_TEXTURE2D: u32 = 3;
const D3D11_RESOURCE_MISC_TEXTURECUBE: u32 = 0x4;

/// DDS_PIXELFORMAT.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PixelFormat {
    /// `DDPF_*` flags.
    pub flags: u32,
    /// Four-character code (with [`ddpf::FOURCC`]).
    pub fourcc: u32,
    /// Bits per texel (with `RGB`, `LUMINANCE`, `ALPHA`).
    pub rgb_bit_count: u32,
    /// Red (or luminance), green, blue and alpha masks.
    pub masks: [u32; 4],
}

/// DDS_HEADER_DXT10.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Dx10 {
    /// `DXGI_FORMAT` value.
    pub dxgi_format: u32,
    /// `D3D10_RESOURCE_DIMENSION` (3 = 2-D texture).
    pub resource_dimension: u32,
    /// `miscFlag` (0x4: cube map).
    pub misc_flag: u32,
    /// Array size (1 for a single texture).
    pub array_size: u32,
    /// `miscFlags2`: the alpha mode in its low 3 bits.
    pub misc_flags2: u32,
}

/// The 124-byte DDS_HEADER (after the `DDS ` magic) and the optional DX10
/// extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Header {
    /// `DDSD_*` flags.
    pub flags: u32,
    /// Height of level 0.
    pub height: u32,
    /// Width of level 0.
    pub width: u32,
    /// Row pitch (uncompressed) or level-0 byte size (compressed).
    pub pitch_or_linear_size: u32,
    /// Depth of a volume texture.
    pub depth: u32,
    /// Number of mip levels.
    pub mip_map_count: u32,
    /// The pixel format.
    pub pixel_format: PixelFormat,
    /// `dwCaps`.
    pub caps: u32,
    /// `dwCaps2`.
    pub caps2: u32,
    /// The DX10 extension, present when the fourCC is `DX10`.
    pub dx10: Option<Dx10>,
}

/// Size of the magic and DDS_HEADER.
pub const HEADER_BYTES: usize = 128;
/// Size of DDS_HEADER_DXT10.
pub const DX10_BYTES: usize = 20;

impl Header {
    /// The header as stored in a file, magic first.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w: Vec<u32> = vec![
            u32::from_le_bytes(*b"DDS "),
            124,
            self.flags,
            self.height,
            self.width,
            self.pitch_or_linear_size,
            self.depth,
            self.mip_map_count,
        ];
        w.extend([0u32; 11]);
        let pf = &self.pixel_format;
        w.extend([32, pf.flags, pf.fourcc, pf.rgb_bit_count]);
        w.extend(pf.masks);
        w.extend([self.caps, self.caps2, 0, 0, 0]);
        if let Some(d) = &self.dx10 {
            w.extend([
                d.dxgi_format,
                d.resource_dimension,
                d.misc_flag,
                d.array_size,
                d.misc_flags2,
            ]);
        }
        w.iter().flat_map(|x| x.to_le_bytes()).collect()
    }

    /// Parse the magic, the header and (with fourCC `DX10`) the extension
    /// from the start of a file.
    pub fn parse(bytes: &[u8]) -> Result<Header> {
        if bytes.len() < HEADER_BYTES {
            return Err(decode_err(format!(
                "the file has {} bytes, shorter than a DDS header (128)",
                bytes.len()
            )));
        }
        // Words 0..32 are the header (length checked above), 32..37 the
        // DX10 extension (checked before they are read).
        let (words, _) = bytes.as_chunks::<4>();
        let word = |i: usize| u32::from_le_bytes(words[i]);
        if &bytes[..4] != b"DDS " {
            return Err(decode_err("not a DDS file (no `DDS ` magic)"));
        }
        if word(1) != 124 {
            return Err(decode_err(format!(
                "header size field is {}, DDS headers are 124 bytes",
                word(1)
            )));
        }
        let pixel_format = PixelFormat {
            flags: word(20),
            fourcc: word(21),
            rgb_bit_count: word(22),
            masks: [word(23), word(24), word(25), word(26)],
        };
        let dx10 = if pixel_format.flags & ddpf::FOURCC != 0 && pixel_format.fourcc == DX10 {
            if bytes.len() < HEADER_BYTES + DX10_BYTES {
                return Err(decode_err("the file ends inside the DX10 header"));
            }
            Some(Dx10 {
                dxgi_format: word(32),
                resource_dimension: word(33),
                misc_flag: word(34),
                array_size: word(35),
                misc_flags2: word(36),
            })
        } else {
            None
        };
        Ok(Header {
            flags: word(2),
            height: word(3),
            width: word(4),
            pitch_or_linear_size: word(5),
            depth: word(6),
            mip_map_count: word(7),
            pixel_format,
            caps: word(27),
            caps2: word(28),
            dx10,
        })
    }

    /// Bytes before the level data.
    pub fn data_offset(&self) -> usize {
        HEADER_BYTES + if self.dx10.is_some() { DX10_BYTES } else { 0 }
    }
}

/// How a texel format is stored: the pixel format, the DX10 format and
/// alpha mode when the extension is needed, and the stored channel count
/// (more than the source's when the format widens).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    /// The header's pixel format.
    pub pixel_format: PixelFormat,
    /// `(DXGI_FORMAT, alpha mode)` of the DX10 extension, if used.
    pub dx10: Option<(u32, u32)>,
    /// Channels per stored texel.
    pub stored_channels: u8,
    /// Name of the stored format, e.g. `A8B8G8R8` or `R16G16B16A16_FLOAT`.
    pub name: &'static str,
}

fn legacy(flags: u32, bits: u32, masks: [u32; 4]) -> PixelFormat {
    PixelFormat {
        flags,
        fourcc: 0,
        rgb_bit_count: bits,
        masks,
    }
}

fn fourcc_only(fourcc: u32) -> PixelFormat {
    PixelFormat {
        flags: ddpf::FOURCC,
        fourcc,
        rgb_bit_count: 0,
        masks: [0; 4],
    }
}

/// The closest format DDS can store `f` in without widening: sRGB is kept
/// only for 8-bit data (DXGI has no other uncompressed sRGB format), so
/// sRGB u16 and float data are converted to linear values first.
pub fn storable(f: Format) -> Format {
    let mut out = f;
    if f.color_space == ColorSpace::Srgb && f.channel_type != ChannelType::U8 {
        out.color_space = ColorSpace::Linear;
    }
    out
}

/// The stored layout of `f` (see the module docs), or `None` for formats
/// [`storable`] would change (sRGB u16 and floats).
pub fn layout(f: &Format) -> Option<Layout> {
    use ChannelType::*;
    use alpha_mode::*;
    let srgb = f.color_space == ColorSpace::Srgb;
    if srgb && f.channel_type != U8 {
        return None;
    }
    let alpha = match (f.has_alpha(), f.alpha) {
        (true, AlphaMode::Premultiplied) => PREMULTIPLIED,
        (true, _) => STRAIGHT,
        (false, _) if f.channels == 4 => CUSTOM,
        (false, _) => OPAQUE,
    };
    let dx = |dxgi: u32, stored: u8, name: &'static str, mode: u32| Layout {
        pixel_format: fourcc_only(DX10),
        dx10: Some((dxgi, mode)),
        stored_channels: stored,
        name,
    };
    let leg = |pf: PixelFormat, stored: u8, name: &'static str| Layout {
        pixel_format: pf,
        dx10: None,
        stored_channels: stored,
        name,
    };
    let straight = alpha == STRAIGHT;
    Some(match (f.channel_type, f.channels, srgb) {
        (U8, _, true) => dx(29, 4, "R8G8B8A8_UNORM_SRGB", alpha),
        (U8, 1, _) => leg(legacy(ddpf::LUMINANCE, 8, [0xff, 0, 0, 0]), 1, "L8"),
        (U8, 2, _) if straight => leg(
            legacy(
                ddpf::LUMINANCE | ddpf::ALPHAPIXELS,
                16,
                [0xff, 0, 0, 0xff00],
            ),
            2,
            "A8L8",
        ),
        (U8, 2, _) => dx(49, 2, "R8G8_UNORM", alpha),
        (U8, 3, _) => leg(
            legacy(ddpf::RGB, 32, [0xff, 0xff00, 0xff_0000, 0]),
            4,
            "X8B8G8R8",
        ),
        (U8, _, _) if straight => leg(
            legacy(
                ddpf::RGB | ddpf::ALPHAPIXELS,
                32,
                [0xff, 0xff00, 0xff_0000, 0xff00_0000],
            ),
            4,
            "A8B8G8R8",
        ),
        (U8, _, _) => dx(28, 4, "R8G8B8A8_UNORM", alpha),
        (U16, 1, _) => leg(legacy(ddpf::LUMINANCE, 16, [0xffff, 0, 0, 0]), 1, "L16"),
        (U16, 2, _) if alpha == OPAQUE => leg(
            legacy(ddpf::RGB, 32, [0xffff, 0xffff_0000, 0, 0]),
            2,
            "G16R16",
        ),
        (U16, 2, _) => dx(35, 2, "R16G16_UNORM", alpha),
        (U16, 3, _) => dx(11, 4, "R16G16B16A16_UNORM", alpha),
        (U16, _, _) if straight => leg(fourcc_only(36), 4, "A16B16G16R16"),
        (U16, _, _) => dx(11, 4, "R16G16B16A16_UNORM", alpha),
        (F16, 1, _) => dx(54, 1, "R16_FLOAT", alpha),
        (F16, 2, _) => dx(34, 2, "R16G16_FLOAT", alpha),
        (F16, _, _) => dx(10, 4, "R16G16B16A16_FLOAT", alpha),
        (F32, 1, _) => dx(41, 1, "R32_FLOAT", alpha),
        (F32, 2, _) => dx(16, 2, "R32G32_FLOAT", alpha),
        (F32, 3, _) => dx(6, 3, "R32G32B32_FLOAT", alpha),
        (F32, _, _) => dx(2, 4, "R32G32B32A32_FLOAT", alpha),
    })
}

/// The header parvo writes for `levels` (level 0 first, rounding down).
pub fn header_for(levels: &[Texture]) -> Result<(Header, Layout)> {
    let first = levels
        .first()
        .ok_or_else(|| encode_err("nothing to write: no levels"))?;
    let f = first.format();
    let lay = layout(&f).ok_or_else(|| {
        encode_err(format!(
            "DDS has no format for {f} (convert it with dds::storable)"
        ))
    })?;
    let (w, h) = (first.width(), first.height());
    let n = levels.len() as u32;
    let full = crate::mip::level_count(w, h, crate::mip::Rounding::Down, None);
    if n > full {
        return Err(encode_err(format!(
            "{n} levels, a {w}x{h} chain has {full}"
        )));
    }
    for (k, l) in levels.iter().enumerate() {
        let want = crate::mip::level_size(w, h, k as u32, crate::mip::Rounding::Down);
        if (l.width(), l.height()) != want {
            return Err(encode_err(format!(
                "level {k} is {}x{}; DDS level sizes round down, so it must be {}x{}",
                l.width(),
                l.height(),
                want.0,
                want.1
            )));
        }
    }
    let texel = lay.stored_channels as u64 * f.channel_type.bytes() as u64;
    let pitch = u32::try_from(w as u64 * texel)
        .map_err(|_| encode_err(format!("a row of {w} texels is too long for DDS")))?;
    let header = Header {
        flags: ddsd::CAPS
            | ddsd::HEIGHT
            | ddsd::WIDTH
            | ddsd::PITCH
            | ddsd::PIXELFORMAT
            | ddsd::MIPMAPCOUNT,
        height: h,
        width: w,
        pitch_or_linear_size: pitch,
        depth: 0,
        mip_map_count: n,
        pixel_format: lay.pixel_format,
        caps: caps::TEXTURE
            | if n > 1 {
                caps::COMPLEX | caps::MIPMAP
            } else {
                0
            },
        caps2: 0,
        dx10: lay.dx10.map(|(dxgi, mode)| Dx10 {
            dxgi_format: dxgi,
            resource_dimension: D3D10_RESOURCE_DIMENSION_TEXTURE2D,
            misc_flag: 0,
            array_size: 1,
            misc_flags2: mode,
        }),
    };
    Ok((header, lay))
}

/// Serialise `levels` (level 0 first, sizes rounding down) as DDS bytes.
pub fn write_to(levels: &[Texture], out: &mut impl Write) -> Result<()> {
    let (header, lay) = header_for(levels)?;
    out.write_all(&header.to_bytes()).map_err(encode_err)?;
    write_levels(levels, &lay, out)
}

/// The DXGI format of a layout written with a legacy header, for the
/// DX10 header an array needs (`None` for luminance + alpha, which DXGI
/// has no format for).
fn dx10_of_legacy(lay: &Layout) -> Option<(u32, u32)> {
    use alpha_mode::*;
    Some(match lay.name {
        "L8" => (61, OPAQUE),
        "X8B8G8R8" => (28, OPAQUE),
        "A8B8G8R8" => (28, STRAIGHT),
        "L16" => (56, OPAQUE),
        "G16R16" => (35, OPAQUE),
        "A16B16G16R16" => (11, STRAIGHT),
        _ => return None,
    })
}

/// The header of a cube map, an array or a cube-map array of `kind`
/// whose images each hold `levels`' sizes and format: the legacy cube
/// flags for one cube map, a DX10 header with `arraySize` for arrays.
pub fn header_for_images(levels: &[Texture], kind: Kind) -> Result<(Header, Layout)> {
    let (mut header, mut lay) = header_for(levels)?;
    let count = match kind {
        Kind::Plain | Kind::LatLong => return Ok((header, lay)),
        Kind::Cube => 1,
        Kind::CubeArray { cubes } => cubes,
        Kind::Array { layers } => layers,
    };
    header.caps |= caps::COMPLEX;
    if kind.is_cube() {
        header.caps2 = caps::CUBEMAP | caps::ALL_FACES;
    }
    if count > 1 && header.dx10.is_none() {
        let (dxgi, mode) = dx10_of_legacy(&lay).ok_or_else(|| {
            encode_err(format!(
                "a DDS array needs a DX10 format and DXGI has none for {} (write it to KTX2)",
                lay.name
            ))
        })?;
        header.pixel_format = fourcc_only(DX10);
        header.dx10 = Some(Dx10 {
            dxgi_format: dxgi,
            resource_dimension: D3D10_RESOURCE_DIMENSION_TEXTURE2D,
            misc_flag: 0,
            array_size: 1,
            misc_flags2: mode,
        });
        lay.dx10 = Some((dxgi, mode));
    }
    if let Some(d) = &mut header.dx10 {
        d.array_size = count;
        if kind.is_cube() {
            d.misc_flag |= D3D11_RESOURCE_MISC_TEXTURECUBE;
        }
    }
    Ok((header, lay))
}

/// Serialise a cube map or an array (`images` in
/// [`super::Loaded::images`]'s order, each its levels) as DDS bytes:
/// image after image, each with all its levels.
pub fn write_images_to(images: &[&[Texture]], kind: Kind, out: &mut impl Write) -> Result<()> {
    let first = images
        .first()
        .ok_or_else(|| encode_err("nothing to write: no images"))?;
    let (header, lay) = header_for_images(first, kind)?;
    out.write_all(&header.to_bytes()).map_err(encode_err)?;
    for levels in images {
        write_levels(levels, &lay, out)?;
    }
    Ok(())
}

/// Write a cube map or an array atomically (see [`write_images_to`]).
pub fn save_images(images: &[&[Texture]], kind: Kind, path: &Path) -> Result<()> {
    if let Some(first) = images.first() {
        header_for_images(first, kind)?;
    }
    atomic::write(path, |w| write_images_to(images, kind, w))
}

/// One image's levels in `lay`'s stored channels.
fn write_levels(levels: &[Texture], lay: &Layout, out: &mut impl Write) -> Result<()> {
    let io = |e: std::io::Error| encode_err(e);
    for l in levels {
        if lay.stored_channels as usize == l.channels() {
            out.write_all(&super::le_bytes(l.texels())).map_err(io)?;
        } else {
            let wide = l.expand_channels(lay.stored_channels)?;
            out.write_all(&super::le_bytes(wide.texels())).map_err(io)?;
        }
    }
    Ok(())
}

/// Write `levels` (level 0 first, rounding down) as a DDS file atomically.
pub fn save(levels: &[Texture], path: &Path) -> Result<()> {
    header_for(levels)?;
    atomic::write(path, |w| write_to(levels, w))
}

/// The DXGI format of a block format (`_UNORM_SRGB` when `srgb`).
pub fn dxgi_block_format(f: BlockFormat, srgb: bool) -> u32 {
    let s = u32::from(srgb);
    match f {
        BlockFormat::Bc1 => 71 + s,
        BlockFormat::Bc2 => 74 + s,
        BlockFormat::Bc3 => 77 + s,
        BlockFormat::Bc4 { signed } => 80 + u32::from(signed),
        BlockFormat::Bc5 { signed } => 83 + u32::from(signed),
        BlockFormat::Bc6h { signed } => 95 + u32::from(signed),
        BlockFormat::Bc7 => 98 + s,
    }
}

/// The header parvo writes for a block-compressed chain: the DX10
/// extension with the block format's DXGI number and alpha mode,
/// `DDSD_LINEARSIZE` with level 0's byte size (DirectXTex's layout for
/// compressed textures).
pub fn header_for_blocks(chain: &BlockChain) -> Result<Header> {
    chain.validate()?;
    let n = chain.levels.len() as u32;
    let full = crate::mip::level_count(chain.width, chain.height, crate::mip::Rounding::Down, None);
    if n > full {
        return Err(encode_err(format!(
            "{n} levels, a {}x{} chain has {full}",
            chain.width, chain.height
        )));
    }
    let linear = u32::try_from(chain.levels[0].len())
        .map_err(|_| encode_err("level 0 is too large for a DDS header (4 GiB)"))?;
    let mode = match chain.alpha {
        AlphaMode::Premultiplied => alpha_mode::PREMULTIPLIED,
        AlphaMode::Straight => alpha_mode::STRAIGHT,
        AlphaMode::None => alpha_mode::OPAQUE,
    };
    Ok(Header {
        flags: ddsd::CAPS
            | ddsd::HEIGHT
            | ddsd::WIDTH
            | ddsd::LINEARSIZE
            | ddsd::PIXELFORMAT
            | ddsd::MIPMAPCOUNT,
        height: chain.height,
        width: chain.width,
        pitch_or_linear_size: linear,
        depth: 0,
        mip_map_count: n,
        pixel_format: fourcc_only(DX10),
        caps: caps::TEXTURE
            | if n > 1 {
                caps::COMPLEX | caps::MIPMAP
            } else {
                0
            },
        caps2: 0,
        dx10: Some(Dx10 {
            dxgi_format: dxgi_block_format(chain.format, chain.srgb),
            resource_dimension: D3D10_RESOURCE_DIMENSION_TEXTURE2D,
            misc_flag: 0,
            array_size: 1,
            misc_flags2: mode,
        }),
    })
}

/// Serialise a block-compressed chain as DDS bytes.
pub fn write_blocks_to(chain: &BlockChain, out: &mut impl Write) -> Result<()> {
    let header = header_for_blocks(chain)?;
    let io = |e: std::io::Error| encode_err(e);
    out.write_all(&header.to_bytes()).map_err(io)?;
    for l in &chain.levels {
        out.write_all(l).map_err(io)?;
    }
    Ok(())
}

/// Write a block-compressed chain as a DDS file atomically.
pub fn save_blocks(chain: &BlockChain, path: &Path) -> Result<()> {
    header_for_blocks(chain)?;
    atomic::write(path, |w| write_blocks_to(chain, w))
}

/// How the texels of a DDS file are stored, as parsed from its header.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Stored {
    /// Uncompressed values of `format`, `texel` bytes each, read with the
    /// masks of a legacy header when `masks` is set.
    Plain {
        format: Format,
        bytes: usize,
        masks: Option<Masked>,
        swap_rb: bool,
        drop_alpha: bool,
    },
    /// Block-compressed.
    Blocks {
        format: BlockFormat,
        srgb: bool,
        alpha: AlphaMode,
    },
}

/// A legacy masked layout: per output channel the mask (0 = constant).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Masked {
    masks: [u32; 4],
    channels: usize,
}

/// The DXGI formats parvo reads (uncompressed): format number, channels,
/// type, sRGB, R/B swapped (BGRA), 4th channel padding (BGRX), name.
/// `TYPELESS` formats are read as UNORM.
const DXGI_PLAIN: [(u32, u8, ChannelType, bool, bool, bool, &str); 27] = {
    use ChannelType::*;
    [
        (2, 4, F32, false, false, false, "R32G32B32A32_FLOAT"),
        (6, 3, F32, false, false, false, "R32G32B32_FLOAT"),
        (10, 4, F16, false, false, false, "R16G16B16A16_FLOAT"),
        (11, 4, U16, false, false, false, "R16G16B16A16_UNORM"),
        (9, 4, U16, false, false, false, "R16G16B16A16_TYPELESS"),
        (16, 2, F32, false, false, false, "R32G32_FLOAT"),
        (27, 4, U8, false, false, false, "R8G8B8A8_TYPELESS"),
        (28, 4, U8, false, false, false, "R8G8B8A8_UNORM"),
        (29, 4, U8, true, false, false, "R8G8B8A8_UNORM_SRGB"),
        (34, 2, F16, false, false, false, "R16G16_FLOAT"),
        (35, 2, U16, false, false, false, "R16G16_UNORM"),
        (33, 2, U16, false, false, false, "R16G16_TYPELESS"),
        (41, 1, F32, false, false, false, "R32_FLOAT"),
        (49, 2, U8, false, false, false, "R8G8_UNORM"),
        (48, 2, U8, false, false, false, "R8G8_TYPELESS"),
        (54, 1, F16, false, false, false, "R16_FLOAT"),
        (56, 1, U16, false, false, false, "R16_UNORM"),
        (53, 1, U16, false, false, false, "R16_TYPELESS"),
        (61, 1, U8, false, false, false, "R8_UNORM"),
        (60, 1, U8, false, false, false, "R8_TYPELESS"),
        (65, 1, U8, false, false, false, "A8_UNORM"),
        (87, 4, U8, false, true, false, "B8G8R8A8_UNORM"),
        (88, 4, U8, false, true, true, "B8G8R8X8_UNORM"),
        (90, 4, U8, false, true, false, "B8G8R8A8_TYPELESS"),
        (92, 4, U8, false, true, true, "B8G8R8X8_TYPELESS"),
        (91, 4, U8, true, true, false, "B8G8R8A8_UNORM_SRGB"),
        (93, 4, U8, true, true, true, "B8G8R8X8_UNORM_SRGB"),
    ]
};

/// Block formats in DX10 files: DXGI number, format, sRGB.
const DXGI_BLOCKS: [(u32, BlockFormat, bool); 21] = {
    use BlockFormat::*;
    [
        (70, Bc1, false),
        (71, Bc1, false),
        (72, Bc1, true),
        (73, Bc2, false),
        (74, Bc2, false),
        (75, Bc2, true),
        (76, Bc3, false),
        (77, Bc3, false),
        (78, Bc3, true),
        (79, Bc4 { signed: false }, false),
        (80, Bc4 { signed: false }, false),
        (81, Bc4 { signed: true }, false),
        (82, Bc5 { signed: false }, false),
        (83, Bc5 { signed: false }, false),
        (84, Bc5 { signed: true }, false),
        (94, Bc6h { signed: false }, false),
        (95, Bc6h { signed: false }, false),
        (96, Bc6h { signed: true }, false),
        (97, Bc7, false),
        (98, Bc7, false),
        (99, Bc7, true),
    ]
};

/// Microsoft's `DXGI_FORMAT_*` enumerants without the prefix, by value
/// (every value DXGI defines; the gaps 116-129 and 133-188 are unused).
const DXGI_NAMES: [(u32, &str); 121] = [
    (0, "UNKNOWN"),
    (1, "R32G32B32A32_TYPELESS"),
    (2, "R32G32B32A32_FLOAT"),
    (3, "R32G32B32A32_UINT"),
    (4, "R32G32B32A32_SINT"),
    (5, "R32G32B32_TYPELESS"),
    (6, "R32G32B32_FLOAT"),
    (7, "R32G32B32_UINT"),
    (8, "R32G32B32_SINT"),
    (9, "R16G16B16A16_TYPELESS"),
    (10, "R16G16B16A16_FLOAT"),
    (11, "R16G16B16A16_UNORM"),
    (12, "R16G16B16A16_UINT"),
    (13, "R16G16B16A16_SNORM"),
    (14, "R16G16B16A16_SINT"),
    (15, "R32G32_TYPELESS"),
    (16, "R32G32_FLOAT"),
    (17, "R32G32_UINT"),
    (18, "R32G32_SINT"),
    (19, "R32G8X24_TYPELESS"),
    (20, "D32_FLOAT_S8X24_UINT"),
    (21, "R32_FLOAT_X8X24_TYPELESS"),
    (22, "X32_TYPELESS_G8X24_UINT"),
    (23, "R10G10B10A2_TYPELESS"),
    (24, "R10G10B10A2_UNORM"),
    (25, "R10G10B10A2_UINT"),
    (26, "R11G11B10_FLOAT"),
    (27, "R8G8B8A8_TYPELESS"),
    (28, "R8G8B8A8_UNORM"),
    (29, "R8G8B8A8_UNORM_SRGB"),
    (30, "R8G8B8A8_UINT"),
    (31, "R8G8B8A8_SNORM"),
    (32, "R8G8B8A8_SINT"),
    (33, "R16G16_TYPELESS"),
    (34, "R16G16_FLOAT"),
    (35, "R16G16_UNORM"),
    (36, "R16G16_UINT"),
    (37, "R16G16_SNORM"),
    (38, "R16G16_SINT"),
    (39, "R32_TYPELESS"),
    (40, "D32_FLOAT"),
    (41, "R32_FLOAT"),
    (42, "R32_UINT"),
    (43, "R32_SINT"),
    (44, "R24G8_TYPELESS"),
    (45, "D24_UNORM_S8_UINT"),
    (46, "R24_UNORM_X8_TYPELESS"),
    (47, "X24_TYPELESS_G8_UINT"),
    (48, "R8G8_TYPELESS"),
    (49, "R8G8_UNORM"),
    (50, "R8G8_UINT"),
    (51, "R8G8_SNORM"),
    (52, "R8G8_SINT"),
    (53, "R16_TYPELESS"),
    (54, "R16_FLOAT"),
    (55, "D16_UNORM"),
    (56, "R16_UNORM"),
    (57, "R16_UINT"),
    (58, "R16_SNORM"),
    (59, "R16_SINT"),
    (60, "R8_TYPELESS"),
    (61, "R8_UNORM"),
    (62, "R8_UINT"),
    (63, "R8_SNORM"),
    (64, "R8_SINT"),
    (65, "A8_UNORM"),
    (66, "R1_UNORM"),
    (67, "R9G9B9E5_SHAREDEXP"),
    (68, "R8G8_B8G8_UNORM"),
    (69, "G8R8_G8B8_UNORM"),
    (70, "BC1_TYPELESS"),
    (71, "BC1_UNORM"),
    (72, "BC1_UNORM_SRGB"),
    (73, "BC2_TYPELESS"),
    (74, "BC2_UNORM"),
    (75, "BC2_UNORM_SRGB"),
    (76, "BC3_TYPELESS"),
    (77, "BC3_UNORM"),
    (78, "BC3_UNORM_SRGB"),
    (79, "BC4_TYPELESS"),
    (80, "BC4_UNORM"),
    (81, "BC4_SNORM"),
    (82, "BC5_TYPELESS"),
    (83, "BC5_UNORM"),
    (84, "BC5_SNORM"),
    (85, "B5G6R5_UNORM"),
    (86, "B5G5R5A1_UNORM"),
    (87, "B8G8R8A8_UNORM"),
    (88, "B8G8R8X8_UNORM"),
    (89, "R10G10B10_XR_BIAS_A2_UNORM"),
    (90, "B8G8R8A8_TYPELESS"),
    (91, "B8G8R8A8_UNORM_SRGB"),
    (92, "B8G8R8X8_TYPELESS"),
    (93, "B8G8R8X8_UNORM_SRGB"),
    (94, "BC6H_TYPELESS"),
    (95, "BC6H_UF16"),
    (96, "BC6H_SF16"),
    (97, "BC7_TYPELESS"),
    (98, "BC7_UNORM"),
    (99, "BC7_UNORM_SRGB"),
    (100, "AYUV"),
    (101, "Y410"),
    (102, "Y416"),
    (103, "NV12"),
    (104, "P010"),
    (105, "P016"),
    (106, "OPAQUE_420"),
    (107, "YUY2"),
    (108, "Y210"),
    (109, "Y216"),
    (110, "NV11"),
    (111, "AI44"),
    (112, "IA44"),
    (113, "P8"),
    (114, "A8P8"),
    (115, "B4G4R4A4_UNORM"),
    (130, "P208"),
    (131, "V208"),
    (132, "V408"),
    (189, "SAMPLER_FEEDBACK_MIN_MIP_OPAQUE"),
    (190, "SAMPLER_FEEDBACK_MIP_REGION_USED_OPAQUE"),
];

/// The name of a `DXGI_FORMAT` value (Microsoft's `DXGI_FORMAT_*`
/// enumerants without the prefix), `None` for values it does not define.
pub fn dxgi_name(v: u32) -> Option<&'static str> {
    DXGI_NAMES.iter().find(|e| e.0 == v).map(|e| e.1)
}

/// `NAME (n)`, or the number alone when DXGI defines no such format.
fn dxgi_describe(v: u32) -> String {
    match dxgi_name(v) {
        Some(n) => format!("{n} ({v})"),
        None => format!("{v} (not a DXGI format)"),
    }
}

/// The meaning a `_TYPELESS` DXGI format is read with, as Pillow reads
/// them (OpenImageIO 3.2 refuses them): UNORM (`UF16` for BC6H), or `None`
/// when `v` is not typeless.
fn typeless_reading(v: u32) -> Option<String> {
    let name = dxgi_name(v)?.strip_suffix("_TYPELESS")?;
    Some(if name == "BC6H" {
        "BC6H_UF16".to_string()
    } else {
        format!("{name}_UNORM")
    })
}

fn fourcc_text(v: u32) -> String {
    let d3d = match v {
        36 => "D3DFMT_A16B16G16R16",
        110 => "D3DFMT_Q16W16V16U16",
        111 => "D3DFMT_R16F",
        112 => "D3DFMT_G16R16F",
        113 => "D3DFMT_A16B16G16R16F",
        114 => "D3DFMT_R32F",
        115 => "D3DFMT_G32R32F",
        116 => "D3DFMT_A32B32G32R32F",
        _ => "",
    };
    if !d3d.is_empty() {
        return format!("{v} ({d3d})");
    }
    let b = v.to_le_bytes();
    if v > 255
        && b.iter()
            .all(|c| c.is_ascii_graphic() || *c == b' ' || *c == 0)
    {
        format!("`{}`", String::from_utf8_lossy(&b).trim_end_matches('\0'))
    } else {
        format!("{v}")
    }
}

/// DirectDraw's palette flags (ddraw.h `DDPF_PALETTEINDEXED*`) and the
/// index width each names: texels are indices into a palette stored after
/// the header.
const PALETTE_FLAGS: [(u32, &str); 5] = [
    (0x800, "1-bit"),
    (0x1000, "2-bit"),
    (0x8, "4-bit"),
    (0x20, "8-bit"),
    (0x10, ""),
];

/// Block formats named by a fourCC: code, format, alpha (`DXT2` and `DXT4`
/// are the premultiplied `DXT3` and `DXT5`).
const FOURCC_BLOCKS: [(&[u8; 4], BlockFormat, AlphaMode); 11] = {
    use AlphaMode::{Premultiplied, Straight};
    use BlockFormat::*;
    [
        (b"DXT1", Bc1, Straight),
        (b"DXT2", Bc2, Premultiplied),
        (b"DXT3", Bc2, Straight),
        (b"DXT4", Bc3, Premultiplied),
        (b"DXT5", Bc3, Straight),
        (b"ATI1", Bc4 { signed: false }, Straight),
        (b"BC4U", Bc4 { signed: false }, Straight),
        (b"BC4S", Bc4 { signed: true }, Straight),
        (b"ATI2", Bc5 { signed: false }, Straight),
        (b"BC5U", Bc5 { signed: false }, Straight),
        (b"BC5S", Bc5 { signed: true }, Straight),
    ]
};

/// Uncompressed formats named by a D3DX fourCC number (`D3DFMT_*`, see
/// [`fourcc_text`]): code, channels, type; linear, two channels are R, G
/// data.
const FOURCC_PLAIN: [(u32, u8, ChannelType); 7] = {
    use ChannelType::*;
    [
        (36, 4, U16),
        (111, 1, F16),
        (112, 2, F16),
        (113, 4, F16),
        (114, 1, F32),
        (115, 2, F32),
        (116, 4, F32),
    ]
};

/// What the header says is stored, and a description for `parvo info`.
fn stored_of(h: &Header) -> Result<(Stored, String)> {
    let pf = &h.pixel_format;
    if let Some(d) = &h.dx10 {
        return stored_of_dx10(d);
    }
    refuse_palette(pf)?;
    if pf.flags & ddpf::FOURCC != 0 {
        return stored_of_fourcc(pf.fourcc);
    }
    if pf.flags & (ddpf::YUV | ddpf::BUMPDUDV) != 0 {
        return Err(decode_err(
            "YUV and signed bump-map (DUDV) pixel formats are not supported",
        ));
    }
    stored_of_masks(pf)
}

/// What a DX10 header's DXGI format and alpha mode say is stored.
fn stored_of_dx10(d: &Dx10) -> Result<(Stored, String)> {
    let mode = d.misc_flags2 & 7;
    if let Some(&(_, bf, srgb)) = DXGI_BLOCKS.iter().find(|e| e.0 == d.dxgi_format) {
        let alpha = match mode {
            alpha_mode::PREMULTIPLIED => AlphaMode::Premultiplied,
            alpha_mode::OPAQUE => AlphaMode::None,
            _ => AlphaMode::Straight,
        };
        return Ok((
            Stored::Blocks {
                format: bf,
                srgb,
                alpha,
            },
            format!(
                "DX10 {}",
                dxgi_name(d.dxgi_format).unwrap_or(if srgb { "sRGB" } else { "" })
            ),
        ));
    }
    let &(_, ch, ty, srgb, swap, padded, name) = DXGI_PLAIN
        .iter()
        .find(|e| e.0 == d.dxgi_format)
        .ok_or_else(|| {
        decode_err(format!(
            "DXGI format {} is not one parvo reads (it reads the uncompressed UNORM 8-bit \
                 and 16-bit, half and float R/RG/RGB/RGBA/BGRA formats and BC1-BC7)",
            dxgi_describe(d.dxgi_format)
        ))
    })?;
    let cs = if srgb {
        ColorSpace::Srgb
    } else {
        ColorSpace::Linear
    };
    let mut format = Format::new(ch, ty, cs);
    let mut drop_alpha = padded;
    match (ch, mode) {
        (2, alpha_mode::STRAIGHT) => {}
        (2, alpha_mode::PREMULTIPLIED) | (4, alpha_mode::PREMULTIPLIED) => {
            format = format.with_alpha(AlphaMode::Premultiplied)
        }
        (2, _) => format = format.with_alpha(AlphaMode::None),
        (4, alpha_mode::OPAQUE) => drop_alpha = true,
        (4, alpha_mode::CUSTOM) => format = format.with_alpha(AlphaMode::None),
        _ => {}
    }
    let bytes = ch as usize * ty.bytes();
    if drop_alpha {
        format.channels = 3;
    }
    Ok((
        Stored::Plain {
            format,
            bytes,
            masks: None,
            swap_rb: swap,
            drop_alpha,
        },
        format!("DX10 {name}"),
    ))
}

/// Refuse a palettised pixel format ([`PALETTE_FLAGS`]).
fn refuse_palette(pf: &PixelFormat) -> Result<()> {
    let Some((_, bits)) = PALETTE_FLAGS.iter().find(|(flag, _)| pf.flags & flag != 0) else {
        return Ok(());
    };
    Err(decode_err(format!(
        "this is a palettised DDS ({}palette indices, pixel format flags {:#x}), which parvo \
         does not read",
        if bits.is_empty() {
            String::new()
        } else {
            format!("{bits} ")
        },
        pf.flags
    )))
}

/// What a fourCC says is stored ([`FOURCC_BLOCKS`], [`FOURCC_PLAIN`]).
fn stored_of_fourcc(code: u32) -> Result<(Stored, String)> {
    if code == 0 {
        return Err(decode_err(
            "the pixel format says a fourCC names the format, but the fourCC is empty (0)",
        ));
    }
    let blocks = FOURCC_BLOCKS
        .iter()
        .find(|e| e.0 == &code.to_le_bytes())
        .map(|&(_, format, alpha)| Stored::Blocks {
            format,
            srgb: false,
            alpha,
        });
    let plain = || {
        FOURCC_PLAIN
            .iter()
            .find(|e| e.0 == code)
            .map(|&(_, ch, ty)| {
                let mut format = Format::new(ch, ty, ColorSpace::Linear);
                if ch == 2 {
                    format = format.with_alpha(AlphaMode::None);
                }
                Stored::Plain {
                    format,
                    bytes: ch as usize * ty.bytes(),
                    masks: None,
                    swap_rb: false,
                    drop_alpha: false,
                }
            })
    };
    let st = blocks.or_else(plain).ok_or_else(|| {
        decode_err(format!(
            "fourCC {} is not a format parvo reads (it reads DXT1-DXT5, ATI1/ATI2, \
             BC4U/BC4S/BC5U/BC5S, DX10 and the D3DX codes 36 and 111-116)",
            fourcc_text(code)
        ))
    })?;
    Ok((st, format!("fourCC {}", fourcc_text(code))))
}

/// What a legacy pixel format's bit count, masks and RGB / LUMINANCE /
/// ALPHA flags say is stored.
fn stored_of_masks(pf: &PixelFormat) -> Result<(Stored, String)> {
    let lin = ColorSpace::Linear;
    let bits = pf.rgb_bit_count;
    if !matches!(bits, 8 | 16 | 24 | 32) {
        return Err(decode_err(format!(
            "legacy pixel format with {bits} bits per texel (8, 16, 24 or 32 are read)"
        )));
    }
    let bytes = bits as usize / 8;
    let fits = |m: u32| bits == 32 || m >> bits == 0;
    let [mut r, g, b, mut a] = pf.masks;
    let has_a = pf.flags & ddpf::ALPHAPIXELS != 0;
    let (channels, masks) = if pf.flags & ddpf::LUMINANCE != 0 {
        // Pillow writes L8 with mask ff000000 and A8L8 with alpha mask
        // ff000000, outside the texel; it reads them as plain L / LA bytes.
        if !fits(r) || r == 0 {
            r = if bits == 16 && !has_a { 0xffff } else { 0xff };
        }
        if has_a {
            if !fits(a) || a == 0 {
                a = 0xff00;
            }
            (2, [r, a, 0, 0])
        } else {
            (1, [r, 0, 0, 0])
        }
    } else if pf.flags & ddpf::RGB != 0 {
        if bits == 32 && r == 0xffff_ffff && g == 0 && b == 0 {
            // D3DX's alternative R32F (DirectXTex reads it as R32_FLOAT).
            return Ok((
                Stored::Plain {
                    format: Format::new(1, ChannelType::F32, lin),
                    bytes: 4,
                    masks: None,
                    swap_rb: false,
                    drop_alpha: false,
                },
                "legacy R32F (RGB mask ffffffff)".into(),
            ));
        }
        if has_a && a != 0 {
            (4, [r, g, b, a])
        } else if b == 0 && g != 0 {
            (2, [r, g, 0, 0])
        } else {
            (3, [r, g, b, 0])
        }
    } else if pf.flags & ddpf::ALPHA != 0 {
        (1, [a, 0, 0, 0])
    } else {
        return Err(decode_err(format!(
            "the pixel format flags ({:#x}) set none of RGB, LUMINANCE, ALPHA or FOURCC, so they \
             name no texel layout",
            pf.flags
        )));
    };
    let widest = masks[..channels]
        .iter()
        .map(|m| m.count_ones())
        .max()
        .unwrap_or(0);
    if widest == 0 || widest > 16 || masks[..channels].iter().any(|&m| !fits(m)) {
        return Err(decode_err(format!(
            "legacy masks {:#x} {:#x} {:#x} {:#x} do not describe a {bits}-bit texel parvo reads",
            pf.masks[0], pf.masks[1], pf.masks[2], pf.masks[3]
        )));
    }
    let ty = if widest <= 8 {
        ChannelType::U8
    } else {
        ChannelType::U16
    };
    let mut format = Format::new(channels as u8, ty, lin);
    if channels == 2 && !has_a {
        format = format.with_alpha(AlphaMode::None);
    }
    let desc = format!(
        "legacy {}{} {bits}-bit, masks {:#x} {:#x} {:#x} {:#x}",
        if pf.flags & ddpf::LUMINANCE != 0 {
            "LUMINANCE"
        } else if pf.flags & ddpf::RGB != 0 {
            "RGB"
        } else {
            "ALPHA"
        },
        if has_a { "|ALPHAPIXELS" } else { "" },
        pf.masks[0],
        pf.masks[1],
        pf.masks[2],
        pf.masks[3]
    );
    Ok((
        Stored::Plain {
            format,
            bytes,
            masks: Some(Masked { masks, channels }),
            swap_rb: false,
            drop_alpha: false,
        },
        desc,
    ))
}

/// Bytes of level `k` (`w × h`) as stored.
fn stored_len(st: &Stored, w: u32, h: u32) -> u64 {
    match st {
        Stored::Plain { bytes, .. } => w as u64 * h as u64 * *bytes as u64,
        Stored::Blocks { format, .. } => format.level_bytes(w, h),
    }
}

/// Texels of one level from its stored bytes.
fn decode_level(st: &Stored, w: u32, h: u32, data: &[u8]) -> Result<Texture> {
    match *st {
        Stored::Blocks {
            format,
            srgb,
            alpha,
        } => crate::compress::decode(format, srgb, alpha, w, h, data),
        Stored::Plain {
            format,
            bytes,
            masks: Some(m),
            ..
        } => {
            let n = w as usize * h as usize;
            let shifts: Vec<(u32, u32, u32)> = m.masks[..m.channels]
                .iter()
                .map(|&mask| (mask, mask.trailing_zeros() % 32, mask.count_ones()))
                .collect();
            let get = |px: &[u8]| {
                let mut b = [0u8; 4];
                b[..bytes].copy_from_slice(px);
                u32::from_le_bytes(b)
            };
            let scale = |v: u32, bits: u32, to: u32| -> u32 {
                if bits == 0 {
                    return 0;
                }
                let max_in = (1u64 << bits) - 1;
                let max_out = (1u64 << to) - 1;
                ((v as u64 * max_out * 2 + max_in) / (2 * max_in)) as u32
            };
            let texels = match format.channel_type {
                ChannelType::U8 => {
                    let mut out = Vec::with_capacity(n * m.channels);
                    for px in data.chunks_exact(bytes).take(n) {
                        let v = get(px);
                        for &(mask, sh, bits) in &shifts {
                            out.push(scale((v & mask) >> sh, bits, 8) as u8);
                        }
                    }
                    Texels::U8(out)
                }
                _ => {
                    let mut out = Vec::with_capacity(n * m.channels);
                    for px in data.chunks_exact(bytes).take(n) {
                        let v = get(px);
                        for &(mask, sh, bits) in &shifts {
                            out.push(scale((v & mask) >> sh, bits, 16) as u16);
                        }
                    }
                    Texels::U16(out)
                }
            };
            Texture::from_texels(w, h, format, texels)
        }
        Stored::Plain {
            format,
            bytes,
            masks: None,
            swap_rb,
            drop_alpha,
        } => {
            let ty = format.channel_type;
            let stored_ch = bytes / ty.bytes();
            let mut texels = super::texels_from_le(ty, data);
            fn fix<T: Copy>(v: Vec<T>, ch: usize, swap: bool, drop: bool) -> Vec<T> {
                if !swap && !drop {
                    return v;
                }
                let keep = if drop { 3 } else { ch };
                let mut out = Vec::with_capacity(v.len() / ch * keep);
                for px in v.chunks_exact(ch) {
                    let mut p = [px[0], px[1 % ch], px[2 % ch], px[3 % ch]];
                    if swap {
                        p.swap(0, 2);
                    }
                    out.extend_from_slice(&p[..keep]);
                }
                out
            }
            texels = match texels {
                Texels::U8(v) => Texels::U8(fix(v, stored_ch, swap_rb, drop_alpha)),
                Texels::U16(v) => Texels::U16(fix(v, stored_ch, swap_rb, drop_alpha)),
                Texels::F16(v) => Texels::F16(fix(v, stored_ch, swap_rb, drop_alpha)),
                Texels::F32(v) => Texels::F32(fix(v, stored_ch, swap_rb, drop_alpha)),
            };
            Texture::from_texels(w, h, format, texels)
        }
    }
}

/// Read and check the header of the DDS file at `path` (for `parvo info`
/// and tests).
pub fn read_header(path: &Path) -> Result<Header> {
    use std::io::Read;
    let mut head = Vec::with_capacity(HEADER_BYTES + DX10_BYTES);
    std::fs::File::open(path)
        .and_then(|f| {
            f.take((HEADER_BYTES + DX10_BYTES) as u64)
                .read_to_end(&mut head)
        })
        .map_err(|e| Error::Io {
            path: path.to_path_buf(),
            action: "cannot read".into(),
            error: e,
        })?;
    Header::parse(&head)
}

/// The kind of image a file starting with `head` (its header) holds;
/// a plain 2-D image when it cannot tell.
pub(crate) fn peek_kind(head: &[u8]) -> Kind {
    Header::parse(head)
        .ok()
        .and_then(|h| dds_kind(&h).ok())
        .unwrap_or(Kind::Plain)
}

/// The kind of image a header describes: a cube map (the legacy cube
/// flag with all six faces, or DX10's `TEXTURECUBE` with `arraySize`
/// cubes), an array (DX10 `arraySize` > 1) or one 2-D image.
fn dds_kind(header: &Header) -> Result<Kind> {
    let dx_cube = header
        .dx10
        .is_some_and(|d| d.misc_flag & D3D11_RESOURCE_MISC_TEXTURECUBE != 0);
    // An array size of 0 is read as 1, as Pillow and OpenImageIO read it
    // (they ignore the field; Pillow's own `bc1.dds` has 0).
    let count = header.dx10.map_or(1, |d| d.array_size.max(1));
    if dx_cube || header.caps2 & caps::CUBEMAP != 0 {
        if !dx_cube && header.caps2 & caps::ALL_FACES != caps::ALL_FACES {
            return Err(decode_err(format!(
                "a cube map with only {} of its six faces (parvo reads whole cube maps)",
                (header.caps2 & caps::ALL_FACES).count_ones()
            )));
        }
        if header.width != header.height {
            return Err(decode_err(format!(
                "a cube map's faces must be square, the header gives {}x{}",
                header.width, header.height
            )));
        }
        return Ok(if count == 1 {
            Kind::Cube
        } else {
            Kind::CubeArray { cubes: count }
        });
    }
    Ok(if count == 1 {
        Kind::Plain
    } else {
        Kind::Array { layers: count }
    })
}

/// The kinds of DDS file parvo does not read (volumes, buffers), refused
/// in words before any texel is read.
fn refuse_unsupported(header: &Header) -> Result<()> {
    let h = header.height;
    if header.caps2 & caps::VOLUME != 0 || (header.flags & ddsd::DEPTH != 0 && header.depth > 1) {
        return Err(decode_err(
            "volume textures are not supported (parvo reads 2-D textures)",
        ));
    }
    if let Some(d) = &header.dx10 {
        match d.resource_dimension {
            D3D10_RESOURCE_DIMENSION_TEXTURE2D => {}
            // Unknown: Pillow and OpenImageIO do not read the field and take
            // the header's width and height (Pillow's own `bc1.dds` has 0).
            0 => {}
            // A 1-D texture is a row of texels.
            2 if h == 1 => {}
            2 => {
                return Err(decode_err(format!(
                    "the DX10 header says a 1-D texture, but the height is {h}"
                )));
            }
            4 => {
                return Err(decode_err(
                    "volume textures are not supported (parvo reads 2-D textures)",
                ));
            }
            1 => {
                return Err(decode_err(
                    "the DX10 header describes a buffer, not a texture",
                ));
            }
            n => {
                return Err(decode_err(format!(
                    "the DX10 header's resource dimension is {n}; it defines 2 (1-D), 3 (2-D) \
                     and 4 (3-D texture)"
                )));
            }
        }
    }
    Ok(())
}

/// Load a DDS file: every mip level of a 2-D texture (see the module docs
/// for the formats read); a cube map or an array is refused (see
/// [`load_with`]).
pub fn load(path: &Path, limits: &Limits) -> Result<Loaded> {
    load_with(path, limits, &super::LoadOptions::default())
}

/// [`load`] with [`super::LoadOptions`]: cube maps and arrays are read
/// whole (every face and layer, each with its levels) when `options`
/// accept them.
pub fn load_with(path: &Path, limits: &Limits, options: &super::LoadOptions) -> Result<Loaded> {
    let header = read_header(path)?;
    let (w, h) = (header.width, header.height);
    if w == 0 || h == 0 {
        return Err(decode_err(format!("the header declares a {w}x{h} texture")));
    }
    refuse_unsupported(&header)?;
    let kind = dds_kind(&header)?;
    super::layered_image("DDS", kind, (w, h), options)?;
    let images = kind.images();
    let (stored, desc) = stored_of(&header)?;
    let full = crate::mip::level_count(w, h, crate::mip::Rounding::Down, None);
    let declared = header.mip_map_count.max(1);
    if declared > full {
        return Err(decode_err(format!(
            "the header declares {declared} mip levels, a {w}x{h} chain has {full}"
        )));
    }
    let sizes: Vec<(u32, u32)> = (0..declared)
        .map(|k| crate::mip::level_size(w, h, k, crate::mip::Rounding::Down))
        .collect();
    let decoded_bytes: u64 = {
        let f = match stored {
            Stored::Plain { format, .. } => format,
            Stored::Blocks { format, srgb, .. } => format.decoded_format(srgb),
        };
        sizes
            .iter()
            .map(|&(a, b)| a as u64 * b as u64 * f.texel_bytes() as u64)
            .sum::<u64>()
            .saturating_mul(images as u64)
    };
    let file_len = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
    limits.check(w as u64, h as u64, decoded_bytes.saturating_add(file_len))?;
    let bytes = std::fs::read(path).map_err(|e| Error::Io {
        path: path.to_path_buf(),
        action: "cannot read".into(),
        error: e,
    })?;
    // Image by image (face or layer), each with all its levels.
    let mut at = header.data_offset();
    let mut all: Vec<Vec<Texture>> = Vec::with_capacity(images);
    for image in 0..images {
        all.push(
            read_levels(&bytes, &mut at, &stored, &sizes, &header, images > 1).map_err(
                |e| match e {
                    Error::Decode { format, reason } if images > 1 => Error::Decode {
                        format,
                        reason: format!("image {image} of {images}: {reason}"),
                    },
                    e => e,
                },
            )?,
        );
    }
    let mut all = all.into_iter();
    let Some(levels) = all.next() else {
        return Err(decode_err("no image"));
    };
    let base = &levels[0];
    let format = base.format();
    let mut info = SourceInfo::new(FileFormat::Dds, &format);
    info.own_mips = levels.len() > 1;
    info.channel_names = match (format.channels, format.has_alpha()) {
        (1, _) => vec!["R".into()],
        (2, true) => vec!["Y".into(), "A".into()],
        (2, false) => vec!["R".into(), "G".into()],
        (3, _) => vec!["R".into(), "G".into(), "B".into()],
        _ => vec!["R".into(), "G".into(), "B".into(), "A".into()],
    };
    info.attributes = vec![("dds:format".into(), desc)];
    if let Some(d) = &header.dx10
        && let Some(meaning) = typeless_reading(d.dxgi_format)
    {
        info.notes.push(format!(
            "DXGI format {} says no type; read as {meaning}, as Pillow reads it",
            dxgi_name(d.dxgi_format).unwrap_or_default()
        ));
    }
    if let Stored::Blocks { format: bf, .. } = stored {
        info.attributes
            .push(("dds:compression".into(), bf.name().to_string()));
        info.blocks = Some(bf);
    }
    if let Some(d) = &header.dx10 {
        let mode = match d.misc_flags2 & 7 {
            alpha_mode::STRAIGHT => "straight",
            alpha_mode::PREMULTIPLIED => "premultiplied",
            alpha_mode::OPAQUE => "opaque",
            alpha_mode::CUSTOM => "custom",
            _ => "unknown",
        };
        info.attributes.push(("dds:alphaMode".into(), mode.into()));
    }
    info.attributes.sort();
    info.kind = kind;
    Ok(Loaded {
        levels,
        info,
        images: all.collect(),
    })
}

/// The levels of one image from `bytes` at `*at` (moved past them).
fn read_levels(
    bytes: &[u8],
    at: &mut usize,
    stored: &Stored,
    sizes: &[(u32, u32)],
    header: &Header,
    layered: bool,
) -> Result<Vec<Texture>> {
    let mut levels = Vec::with_capacity(sizes.len());
    for (k, &(lw, lh)) in sizes.iter().enumerate() {
        let need = stored_len(stored, lw, lh) as usize;
        let Some(data) = bytes.get(*at..*at + need) else {
            if k > 0 && !layered && header.flags & ddsd::MIPMAPCOUNT == 0 {
                // A mip count without its flag, and no data for it: the
                // file holds one level (DirectXTex would refuse it).
                break;
            }
            return Err(decode_err(format!(
                "the file ends inside level {k} ({lw}x{lh}, {need} bytes from offset {at}; the file has {})",
                bytes.len()
            )));
        };
        levels.push(decode_level(stored, lw, lh, data)?);
        *at += need;
    }
    Ok(levels)
}

/// DDS in the container table: reads legacy and DX10 headers
/// (uncompressed and BC); writes the legacy header where a format has
/// one, else DX10; sizes rounded down; no fingerprint.
pub struct Dds;

impl super::Container for Dds {
    fn id(&self) -> &'static str {
        "dds"
    }
    fn name(&self) -> &'static str {
        "DDS"
    }
    fn tag(&self) -> &'static str {
        "Dds"
    }
    fn summary(&self) -> &'static str {
        "DDS"
    }
    fn detect(&self, magic: &[u8]) -> bool {
        magic.starts_with(b"DDS ")
    }
    fn load(
        &self,
        path: &Path,
        limits: &Limits,
        options: &super::LoadOptions,
        _overlap: Option<super::Overlap<'_>>,
    ) -> Result<Loaded> {
        load_with(path, limits, options)
    }
    fn read_extensions(&self) -> &'static [&'static str] {
        &["dds"]
    }
    fn stores(&self) -> Option<super::Stores> {
        Some(super::Stores {
            float: true,
            integer: true,
            blocks: true,
            ..super::Stores::NOTHING
        })
    }
    fn storable(&self, f: Format) -> Format {
        storable(f)
    }
    fn save(
        &self,
        levels: &[Texture],
        _rounding: crate::mip::Rounding,
        path: &Path,
        _options: &super::SaveOptions,
    ) -> Result<()> {
        save(levels, path)
    }
    fn save_blocks(
        &self,
        chain: &BlockChain,
        path: &Path,
        _options: &super::SaveOptions,
    ) -> Result<()> {
        save_blocks(chain, path)
    }
    fn holds(&self, kind: Kind) -> bool {
        kind != Kind::LatLong
    }
    fn save_images(
        &self,
        images: &[&[Texture]],
        kind: Kind,
        _rounding: crate::mip::Rounding,
        path: &Path,
        _options: &super::SaveOptions,
    ) -> Result<()> {
        save_images(images, kind, path)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_round_trips_through_bytes() {
        let h = Header {
            flags: 0x2100f,
            height: 5,
            width: 7,
            pitch_or_linear_size: 28,
            depth: 0,
            mip_map_count: 3,
            pixel_format: fourcc_only(DX10),
            caps: 0x401008,
            caps2: 0,
            dx10: Some(Dx10 {
                dxgi_format: 10,
                resource_dimension: 3,
                misc_flag: 0,
                array_size: 1,
                misc_flags2: 1,
            }),
        };
        let b = h.to_bytes();
        assert_eq!(b.len(), HEADER_BYTES + DX10_BYTES);
        assert_eq!(Header::parse(&b).unwrap(), h);
    }

    #[test]
    fn format_tables_agree_with_the_dxgi_names() {
        // Each value once, ascending, so a lookup finds the only entry.
        assert!(DXGI_NAMES.windows(2).all(|p| p[0].0 < p[1].0));
        // The formats read carry the names Microsoft gives their values.
        for e in DXGI_PLAIN {
            assert_eq!(dxgi_name(e.0), Some(e.6), "{}", e.0);
        }
        for (v, bf, srgb) in DXGI_BLOCKS {
            let name = dxgi_name(v).unwrap();
            assert!(name.starts_with(&bf.to_string()[..3]), "{v} {name} {bf}");
            assert_eq!(name.ends_with("_SRGB"), srgb, "{v} {name}");
        }
        assert_eq!(dxgi_name(116), None);
        assert_eq!(dxgi_name(191), None);
    }

    #[test]
    fn every_storable_format_has_a_layout() {
        for ch in 1..=4u8 {
            for ty in [
                ChannelType::U8,
                ChannelType::U16,
                ChannelType::F16,
                ChannelType::F32,
            ] {
                for cs in [ColorSpace::Linear, ColorSpace::Srgb] {
                    for a in [
                        AlphaMode::Straight,
                        AlphaMode::Premultiplied,
                        AlphaMode::None,
                    ] {
                        let f = storable(Format::new(ch, ty, cs).with_alpha(a));
                        let l = layout(&f).unwrap_or_else(|| panic!("{f}"));
                        assert!(l.stored_channels >= ch, "{f}");
                    }
                }
            }
        }
    }
}
