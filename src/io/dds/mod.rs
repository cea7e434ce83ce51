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
use crate::error::{Error, Result};
use crate::texel::{AlphaMode, ChannelType, ColorSpace, Format, Texels};
use crate::texture::ImageKind;
use crate::texture::Texture;

mod read;
mod write;

pub use read::*;
pub use write::*;

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

/// DDS in the container table: reads legacy and DX10 headers
/// (uncompressed and BC); writes the legacy header where a format has
/// one, else DX10; sizes rounded down; no fingerprint.
pub struct Dds;

impl super::Container for Dds {
    fn peek_kind(&self, head: &[u8], _path: &Path) -> Option<crate::texture::ImageKind> {
        Some(peek_kind(head))
    }
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
        images: &[&[Texture]],
        kind: ImageKind,
        _rounding: crate::mip::Rounding,
        path: &Path,
        _options: &super::SaveOptions,
    ) -> Result<()> {
        match kind {
            ImageKind::Plain => save(images[0], path),
            _ => save_images(images, kind, path),
        }
    }
    fn save_blocks(
        &self,
        chains: &[BlockChain],
        kind: ImageKind,
        path: &Path,
        _options: &super::SaveOptions,
    ) -> Result<()> {
        save_block_images(chains, kind, path)
    }
    fn holds(&self, kind: ImageKind) -> bool {
        kind != ImageKind::LatLong
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
