//! KTX 2.0: uncompressed and BC1–BC7 textures with the full mip chain.
//!
//! The writer is written by hand from the KTX 2.0 specification (Khronos,
//! "KTX File Format Specification", version 2.0): the `ktx2` crate only
//! reads, and an uncompressed container is a few dozen lines. Layout:
//!
//! 1. identifier (12 bytes) and header: `vkFormat`, `typeSize`, width,
//!    height, depth 0, layer count 0, face count 1, level count,
//!    supercompression 0;
//! 2. index: DFD, key/value data and (empty) supercompression global data;
//! 3. level index, level 0 first: byte offset, length, uncompressed length;
//! 4. the Data Format Descriptor: one basic block, colour model RGBSDA,
//!    BT.709 primaries, linear or sRGB transfer, premultiplied-alpha flag,
//!    one sample per channel (bit offset, bit length, channel id and the
//!    FLOAT/SIGNED/LINEAR qualifiers, sample lower/upper);
//! 5. key/value data, sorted by key, each entry padded to 4 bytes:
//!    `KTXorientation` = `rd`, `KTXwriter`, parvo's fingerprint and wrap
//!    modes;
//! 6. the levels, smallest first (the specification's order, so a reader
//!    streaming the file gets a usable texture early), each aligned to
//!    lcm(texel size, 4) bytes.
//!
//! Formats: `R8`, `R8G8`, `R8G8B8`, `R8G8B8A8` (UNORM and SRGB), the
//! `R16…_UNORM`, `R16…_SFLOAT` and `R32…_SFLOAT` families, and BC1–BC7.
//! Vulkan has no sRGB 16-bit or float formats and no grey + alpha format
//! (its two-channel formats are R, G data), so callers convert such data
//! first ([`storable`]: linear values, grey + alpha widened to RGBA).
//! Every DFD follows the KTX 2.0 restrictions on top of the Khronos Data
//! Format Specification's description of the format: under the sRGB
//! transfer the alpha sample (channel 15) carries
//! `KHR_DF_SAMPLE_DATATYPE_LINEAR` and no other sample does; the
//! premultiplied flag is set only where there is an alpha channel
//! (`tests/files/regression/ktx2_bc3_srgb_dfd_fails_ktx_validate.rs` checks every
//! format against an independent reading of both).
//!
//! Reading uses the `ktx2` crate, which validates the structure. Two
//! channels are R, G data unless the `KTXswizzle` key is `rrrg` (the
//! specification's luminance + alpha); other swizzles are reported, not
//! applied. A `KTXorientation` other than `rd` (rows stored bottom to
//! top for `u`, columns right to left for `l`) is applied to every level
//! on load, with a note, so the levels come out in the order parvo writes
//! (`rd`). Formats parvo does not read are named by their Vulkan names,
//! and Basis Universal files (BasisLZ/ETC1S, UASTC) as such.

use std::path::Path;

use super::{FINGERPRINT_KEY, FileFormat, Limits, Loaded, SaveOptions, SourceInfo, atomic};
use crate::compress::{BlockChain, BlockFormat};
use crate::env::Kind;
use crate::error::{Error, Result};
use crate::texel::{AlphaMode, ChannelType, ColorSpace, Format};
use crate::texture::Texture;
use std::io::Write;

/// The 12-byte file identifier `«KTX 20»\r\n\x1A\n`.
pub const IDENTIFIER: [u8; 12] = [
    0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A,
];

fn encode_err(reason: impl Into<String>) -> Error {
    Error::Encode {
        format: "KTX2",
        reason: reason.into(),
    }
}

fn decode_err(reason: impl std::fmt::Display) -> Error {
    Error::Decode {
        format: "KTX2",
        reason: reason.to_string(),
    }
}

/// The `VkFormat` for a texel format, if Vulkan has one (grey + alpha has
/// none: see [`storable`]).
pub fn vk_format(f: &Format) -> Option<u32> {
    if f.channels == 2 && f.has_alpha() {
        return None;
    }
    let i = (f.channels as usize).checked_sub(1).filter(|&i| i < 4)?;
    let srgb = f.color_space == ColorSpace::Srgb;
    let table: [u32; 4] = match (f.channel_type, srgb) {
        (ChannelType::U8, false) => [9, 16, 23, 37],
        (ChannelType::U8, true) => [15, 22, 29, 43],
        (ChannelType::U16, false) => [70, 77, 84, 91],
        (ChannelType::F16, false) => [76, 83, 90, 97],
        (ChannelType::F32, false) => [100, 103, 106, 109],
        _ => return None,
    };
    Some(table[i])
}

/// The texel format of a `VkFormat` parvo reads (inverse of [`vk_format`]):
/// two channels are R, G data ([`AlphaMode::None`]), four are RGBA with
/// straight alpha (the DFD's premultiplied flag and a `KTXswizzle` of
/// `rrrg` are applied by [`load`]).
pub fn format_of_vk(vk: u32) -> Option<Format> {
    use ChannelType::*;
    use ColorSpace::*;
    let (ch, ty, cs) = match vk {
        9 | 16 | 23 | 37 => ([9, 16, 23, 37].iter().position(|&v| v == vk)?, U8, Linear),
        15 | 22 | 29 | 43 => ([15, 22, 29, 43].iter().position(|&v| v == vk)?, U8, Srgb),
        70 | 77 | 84 | 91 => ([70, 77, 84, 91].iter().position(|&v| v == vk)?, U16, Linear),
        76 | 83 | 90 | 97 => ([76, 83, 90, 97].iter().position(|&v| v == vk)?, F16, Linear),
        100 | 103 | 106 | 109 => (
            [100, 103, 106, 109].iter().position(|&v| v == vk)?,
            F32,
            Linear,
        ),
        _ => return None,
    };
    let f = Format::new(ch as u8 + 1, ty, cs);
    Some(if f.channels == 2 {
        f.with_alpha(AlphaMode::None)
    } else {
        f
    })
}

/// The Vulkan name of a `VkFormat` value (`VK_FORMAT_R8G8_UNORM`), for
/// every format the KTX 2.0 specification allows (the `ktx2` crate's
/// table); `None` for values it does not list.
pub fn vk_format_name(vk: u32) -> Option<String> {
    if vk == 0 {
        return Some("VK_FORMAT_UNDEFINED".into());
    }
    let f = ::ktx2::Format::new(vk)?;
    // The crate's `Debug` prints the enumerant's name, or `Format(n)` for
    // a value it does not list: only listed values are named.
    ::ktx2::Format::ALL
        .contains(&f)
        .then(|| format!("VK_FORMAT_{f:?}"))
}

/// `VK_FORMAT_… (n)`, or `vkFormat n` when the value has no name.
fn vk_describe(vk: u32) -> String {
    match vk_format_name(vk) {
        Some(name) => format!("{name} ({vk})"),
        None => format!("vkFormat {vk}"),
    }
}

/// The Khronos Data Format colour models (`KHR_DF_MODEL_*`) a KTX2 file
/// can name, for messages.
fn model_name(model: u32) -> Option<&'static str> {
    Some(match model {
        0 => "UNSPECIFIED",
        1 => "RGBSDA",
        2 => "YUVSDA",
        128 => "BC1A",
        129 => "BC2",
        130 => "BC3",
        131 => "BC4",
        132 => "BC5",
        133 => "BC6H",
        134 => "BC7",
        160 => "ETC1",
        161 => "ETC2",
        162 => "ASTC",
        163 => "ETC1S",
        164 => "PVRTC",
        165 => "PVRTC2",
        166 => "UASTC",
        167 => "UASTC_HDR_4x4",
        168 => "UASTC_HDR_6x6",
        _ => return None,
    })
}

/// Why a file's texel format is not read, in words: Basis Universal
/// (vkFormat 0 with BasisLZ supercompression or a UASTC/ETC1S colour
/// model) is named as such, other formats by their Vulkan names.
fn unsupported_format(vk: u32, scheme: u32, model: Option<u32>) -> Error {
    const TRANSCODE: &str = "transcode it to a BC or uncompressed format first \
                             (for example with KTX-Software's `ktx transcode`)";
    let reason = match (vk, scheme, model) {
        (0, 1, _) | (0, _, Some(163)) => format!(
            "this is a Basis Universal texture (ETC1S, BasisLZ supercompression), which parvo \
             does not read; {TRANSCODE}"
        ),
        (0, _, Some(166..=168)) => format!(
            "this is a Basis Universal texture ({}), which parvo does not read; {TRANSCODE}",
            model
                .and_then(model_name)
                .unwrap_or("UASTC")
                .replace('_', " ")
        ),
        (0, _, m) => format!(
            "the vkFormat is VK_FORMAT_UNDEFINED (0): the texels are described only by the data \
             format descriptor{}, which parvo does not read",
            m.map_or(String::new(), |m| match model_name(m) {
                Some(n) => format!(" (colour model {n})"),
                None => format!(" (colour model {m})"),
            })
        ),
        _ => format!(
            "{} is not a format parvo reads (it reads the uncompressed R, RG, RGB and RGBA \
             UNORM/SRGB 8-bit, UNORM 16-bit and SFLOAT 16/32-bit formats, and BC1-BC7)",
            vk_describe(vk)
        ),
    };
    decode_err(reason)
}

/// The closest format KTX2 can store `f` in: same values where Vulkan has
/// the format; sRGB u16 and float become linear; grey + alpha becomes RGBA
/// (grey in R, G and B).
///
/// Vulkan has no grey + alpha format: its two-channel formats are R, G
/// data, and that is how every reader takes them (`R8G8_SRGB` would even
/// sRGB-decode the alpha). The KTX 2.0 specification's other way, `R8G8`
/// with the `KTXswizzle` key `rrrg`, is read (see [`load`]) but not
/// written, since readers that ignore the key would show red and green.
/// Two channels without alpha stay two channels (`R8G8`, `R16G16`, ...).
pub fn storable(f: Format) -> Format {
    let mut out = f;
    if f.color_space == ColorSpace::Srgb && f.channel_type != ChannelType::U8 {
        out.color_space = ColorSpace::Linear;
    }
    if f.channels == 2 && f.has_alpha() {
        out.channels = 4;
    }
    out
}

/// The Data Format Descriptor (total size word and one basic block) for a
/// format [`vk_format`] accepts.
pub fn dfd(f: &Format) -> Vec<u8> {
    let ch = f.channels as u32;
    let bits = f.channel_type.bytes() as u32 * 8;
    let block_size = 24 + 16 * ch;
    let srgb = f.color_space == ColorSpace::Srgb;
    let mut w: Vec<u32> = vec![
        4 + block_size,
        0,                      // vendor 0 (Khronos), descriptor type 0 (basic)
        2 | (block_size << 16), // version 2
        1 | (1 << 8)
            | ((if srgb { 2 } else { 1 }) << 16)
            | ((u32::from(f.has_alpha() && f.alpha == AlphaMode::Premultiplied)) << 24),
        0,             // texel block 1x1x1x1
        ch * bits / 8, // bytesPlane0
        0,             // bytesPlane4..7
    ];
    for c in 0..ch {
        let is_alpha = ch == 4 && c == 3;
        let id = if is_alpha { 15 } else { c };
        let quals: u32 = if f.channel_type.is_float() {
            0x80 | 0x40
        } else if srgb && is_alpha {
            0x10
        } else {
            0
        };
        w.push((c * bits) | ((bits - 1) << 16) | ((id | quals) << 24));
        w.push(0);
        let (lower, upper) = match f.channel_type {
            ChannelType::U8 => (0, 255),
            ChannelType::U16 => (0, 65535),
            _ => ((-1.0f32).to_bits(), 1.0f32.to_bits()),
        };
        w.push(lower);
        w.push(upper);
    }
    w.iter().flat_map(|x| x.to_le_bytes()).collect()
}

fn kv_entry(key: &str, value: &str) -> Vec<u8> {
    let mut kv = Vec::new();
    kv.extend_from_slice(key.as_bytes());
    kv.push(0);
    kv.extend_from_slice(value.as_bytes());
    kv.push(0);
    let mut out = (kv.len() as u32).to_le_bytes().to_vec();
    out.extend_from_slice(&kv);
    while !out.len().is_multiple_of(4) {
        out.push(0);
    }
    out
}

fn lcm(a: u64, b: u64) -> u64 {
    fn gcd(a: u64, b: u64) -> u64 {
        if b == 0 { a } else { gcd(b, a % b) }
    }
    a / gcd(a, b) * b
}

/// Supercompression of each level's bytes (KTX 2.0 section 3.7).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Supercompression {
    /// Zstandard at this level (1–22): scheme 2.
    Zstd(i32),
    /// zlib (RFC 1950) at this level (1–12, libdeflate's scale): scheme 3.
    Zlib(i32),
}

impl Supercompression {
    /// The header's `supercompressionScheme`.
    pub fn scheme(self) -> u32 {
        match self {
            Supercompression::Zstd(_) => 2,
            Supercompression::Zlib(_) => 3,
        }
    }

    /// `zstd` or `zlib`.
    pub fn name(self) -> &'static str {
        match self {
            Supercompression::Zstd(_) => "zstd",
            Supercompression::Zlib(_) => "zlib",
        }
    }

    /// Compress one level's bytes.
    pub fn compress(self, data: &[u8]) -> Result<Vec<u8>> {
        match self {
            Supercompression::Zstd(level) => {
                zstd::bulk::compress(data, level).map_err(|e| encode_err(format!("zstd: {e}")))
            }
            Supercompression::Zlib(level) => {
                let lvl = libdeflater::CompressionLvl::new(level)
                    .map_err(|_| encode_err(format!("zlib level {level}: use 1 to 12")))?;
                let mut c = libdeflater::Compressor::new(lvl);
                let mut out = vec![0u8; c.zlib_compress_bound(data.len())];
                // The output is sized by the compressor's own bound, so
                // running out of room is a fault of the bound, not of data.
                let n = c.zlib_compress(data, &mut out).map_err(|_| {
                    encode_err("zlib compression needed more room than its bound promised")
                })?;
                out.truncate(n);
                Ok(out)
            }
        }
    }
}

/// Decompress a level of `scheme` to exactly `len` bytes (the level
/// index's `uncompressedByteLength`, checked against the limits first).
fn decompress(scheme: u32, data: &[u8], len: u64, limits: &Limits) -> Result<Vec<u8>> {
    if len > limits.max_alloc {
        return Err(Error::Limits(format!(
            "a level declares {} MiB uncompressed, more than the {} MiB allowed (raise with {})",
            len >> 20,
            limits.max_alloc >> 20,
            crate::setting::Setting::MaxAlloc
        )));
    }
    let len = len as usize;
    let out = match scheme {
        2 => zstd::bulk::decompress(data, len)
            .map_err(|e| decode_err(format!("a zstd level does not decompress: {e}")))?,
        3 => {
            let mut out = vec![0u8; len];
            let n = libdeflater::Decompressor::new()
                .zlib_decompress(data, &mut out)
                .map_err(|e| {
                    decode_err(match e {
                        libdeflater::DecompressionError::InsufficientSpace => {
                            format!("a zlib level inflates to more than the {len} bytes its index declares")
                        }
                        _ => "a zlib level is corrupt (bad data or checksum)".to_string(),
                    })
                })?;
            out.truncate(n);
            out
        }
        1 => {
            return Err(decode_err(
                "BasisLZ supercompression (Basis Universal ETC1S) is not one parvo reads",
            ));
        }
        s => {
            return Err(decode_err(format!(
                "supercompression scheme {s} is not one the KTX 2.0 specification defines \
                 (0 none, 1 BasisLZ, 2 Zstandard, 3 zlib)"
            )));
        }
    };
    if out.len() != len {
        return Err(decode_err(format!(
            "a level decompresses to {} bytes, the level index says {len}",
            out.len()
        )));
    }
    Ok(out)
}

/// What the header and DFD say about the texels, besides their bytes.
struct Desc {
    vk: u32,
    type_size: u32,
    dfd: Vec<u8>,
    /// Bytes of one texel block (a texel, or a 4×4 block).
    block_bytes: u64,
}

/// The `VkFormat` of a block format (the `_SRGB_BLOCK` variant when
/// `srgb`; BC1 with alpha as `BC1_RGBA`).
pub fn vk_block_format(f: BlockFormat, srgb: bool, alpha: bool) -> u32 {
    let s = u32::from(srgb);
    match f {
        BlockFormat::Bc1 if alpha => 133 + s,
        BlockFormat::Bc1 => 131 + s,
        BlockFormat::Bc2 => 135 + s,
        BlockFormat::Bc3 => 137 + s,
        BlockFormat::Bc4 { signed } => 139 + u32::from(signed),
        BlockFormat::Bc5 { signed } => 141 + u32::from(signed),
        BlockFormat::Bc6h { signed } => 143 + u32::from(signed),
        BlockFormat::Bc7 => 145 + s,
    }
}

/// The block format of a `VkFormat` (131–146): format, sRGB, BC1 alpha.
pub fn block_format_of_vk(vk: u32) -> Option<(BlockFormat, bool, bool)> {
    // The second of each pair: SRGB, or SNORM/SFLOAT.
    let odd = vk.is_multiple_of(2);
    Some(match vk {
        131 | 132 => (BlockFormat::Bc1, odd, false),
        133 | 134 => (BlockFormat::Bc1, odd, true),
        135 | 136 => (BlockFormat::Bc2, odd, true),
        137 | 138 => (BlockFormat::Bc3, odd, true),
        139 | 140 => (BlockFormat::Bc4 { signed: odd }, false, false),
        141 | 142 => (BlockFormat::Bc5 { signed: odd }, false, false),
        143 | 144 => (BlockFormat::Bc6h { signed: odd }, false, false),
        145 | 146 => (BlockFormat::Bc7, odd, true),
        _ => return None,
    })
}

/// The Data Format Descriptor of a block format (Khronos Data Format
/// Specification 1.3, section 5.6 and the BC models of section 5.6.3):
/// colour model `KHR_DF_MODEL_BC1A` … `BC7` (128–134), texel block 4×4,
/// `bytesPlane0` the block size, one sample per stored part (BC1's
/// colour, or `ALPHAPRESENT` with alpha; BC2/BC3 alpha at bit 0 and colour
/// at bit 64; BC5 red and green), sample ranges 0..`u32::MAX` (the values
/// `libktx` writes), FLOAT (and SIGNED) for BC6H.
///
/// The KTX 2.0 rules on top of the format's own description (section
/// "Data Format Descriptor", Restrictions): with the sRGB transfer the
/// alpha sample (channel 15: BC2's and BC3's alpha block) carries
/// `KHR_DF_SAMPLE_DATATYPE_LINEAR`, and no other sample does; the transfer
/// is sRGB only for the formats that have an `_SRGB` variant (BC1, BC2,
/// BC3, BC7), and the premultiplied flag is set only for formats with an
/// alpha channel (the Data Format Specification asks irrelevant fields to
/// be zero).
pub fn dfd_block(f: BlockFormat, srgb: bool, premultiplied: bool, alpha: bool) -> Vec<u8> {
    let srgb = srgb && block_has_srgb(f);
    let premultiplied = premultiplied && block_has_alpha(f, alpha);
    let (model, samples): (u32, Vec<(u32, u32, u32)>) = match f {
        // (bit offset, bit length − 1, channel id | qualifiers)
        BlockFormat::Bc1 => (128, vec![(0, 63, u32::from(alpha))]),
        BlockFormat::Bc2 => (129, vec![(0, 63, 15), (64, 63, 0)]),
        BlockFormat::Bc3 => (130, vec![(0, 63, 15), (64, 63, 0)]),
        BlockFormat::Bc4 { signed } => (131, vec![(0, 63, if signed { 0x40 } else { 0 })]),
        BlockFormat::Bc5 { signed } => {
            let q = if signed { 0x40 } else { 0 };
            (132, vec![(0, 63, q), (64, 63, 1 | q)])
        }
        BlockFormat::Bc6h { signed } => (133, vec![(0, 127, if signed { 0xC0 } else { 0x80 })]),
        BlockFormat::Bc7 => (134, vec![(0, 127, 0)]),
    };
    let block_size = 24 + 16 * samples.len() as u32;
    let mut w: Vec<u32> = vec![
        4 + block_size,
        0,
        2 | (block_size << 16),
        model | (1 << 8) | ((if srgb { 2 } else { 1 }) << 16) | (u32::from(premultiplied) << 24),
        3 | (3 << 8), // texel block 4×4×1×1 (dimensions − 1)
        f.block_bytes() as u32,
        0,
    ];
    for (offset, len1, mut id) in samples {
        if srgb && id == 15 {
            id |= 0x10; // KHR_DF_SAMPLE_DATATYPE_LINEAR: alpha is not sRGB-encoded
        }
        w.push(offset | (len1 << 16) | (id << 24));
        w.push(0);
        let (lower, upper) = match f {
            BlockFormat::Bc6h { signed: true } => ((-1.0f32).to_bits(), 1.0f32.to_bits()),
            BlockFormat::Bc6h { signed: false } => (0, 1.0f32.to_bits()),
            BlockFormat::Bc4 { signed: true } | BlockFormat::Bc5 { signed: true } => {
                (0x8000_0000, 0x7FFF_FFFF)
            }
            _ => (0, u32::MAX),
        };
        w.push(lower);
        w.push(upper);
    }
    w.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// True for the block formats with an `_SRGB` variant.
fn block_has_srgb(f: BlockFormat) -> bool {
    matches!(
        f,
        BlockFormat::Bc1 | BlockFormat::Bc2 | BlockFormat::Bc3 | BlockFormat::Bc7
    )
}

/// True when a block format stores alpha (BC1 only in its `RGBA` form).
fn block_has_alpha(f: BlockFormat, bc1_alpha: bool) -> bool {
    match f {
        BlockFormat::Bc1 => bc1_alpha,
        BlockFormat::Bc2 | BlockFormat::Bc3 | BlockFormat::Bc7 => true,
        _ => false,
    }
}

/// Serialise `levels` (level 0 first, sizes rounding down) as KTX2 bytes
/// written to `out`.
pub fn write_to(levels: &[Texture], opts: &SaveOptions, out: &mut impl Write) -> Result<()> {
    write_images_to(&[levels], Kind::Plain, opts, out)
}

/// The header's layer and face counts for `kind` holding `images` 2-D
/// images (KTX 2.0 section 3.4), or why it cannot.
fn layer_face_counts(kind: Kind, images: usize) -> Result<(u32, u32)> {
    if kind.images() != images {
        return Err(encode_err(format!(
            "a {} holds {} images, got {images}",
            kind.describe(),
            kind.images()
        )));
    }
    Ok(match kind {
        Kind::Plain | Kind::LatLong => (0, 1),
        Kind::Array { layers } => (layers, 1),
        Kind::Cube => (0, 6),
        Kind::CubeArray { cubes } => (cubes, 6),
    })
}

/// Serialise a cube map, an array or a 2-D texture of `kind`: `images`
/// holds each face or layer's levels (level 0 first, sizes rounding
/// down, every image the same size, format and level count), in the
/// order of [`super::Loaded::images`]; each KTX2 level holds level k of
/// every image, one after the other.
pub fn write_images_to(
    images: &[&[Texture]],
    kind: Kind,
    opts: &SaveOptions,
    out: &mut impl Write,
) -> Result<()> {
    let (layers, faces) = layer_face_counts(kind, images.len())?;
    let levels = *images
        .first()
        .ok_or_else(|| encode_err("nothing to write: no images"))?;
    let first = levels
        .first()
        .ok_or_else(|| encode_err("nothing to write: no levels"))?;
    for (i, image) in images.iter().enumerate() {
        let same = image.len() == levels.len()
            && image.iter().zip(levels).all(|(a, b)| {
                (a.width(), a.height(), a.format()) == (b.width(), b.height(), b.format())
            });
        if !same {
            return Err(encode_err(format!(
                "image {i} of the {} differs from the first in size, format or level count",
                kind.describe()
            )));
        }
    }
    if faces == 6 && first.width() != first.height() {
        return Err(encode_err(format!(
            "a cube map's faces must be square, got {}x{}",
            first.width(),
            first.height()
        )));
    }
    let f = first.format();
    let vk = vk_format(&f).ok_or_else(|| {
        encode_err(format!(
            "Vulkan has no format for {f} (convert the levels to ktx2::storable's format first)"
        ))
    })?;
    let desc = Desc {
        vk,
        type_size: f.channel_type.bytes() as u32,
        dfd: dfd(&f),
        block_bytes: f.texel_bytes() as u64,
    };
    let payloads: Vec<std::borrow::Cow<[u8]>> = if images.len() == 1 {
        levels.iter().map(|l| super::le_bytes(l.texels())).collect()
    } else {
        (0..levels.len())
            .map(|k| {
                let mut level = Vec::new();
                for image in images {
                    level.extend_from_slice(&super::le_bytes(image[k].texels()));
                }
                std::borrow::Cow::Owned(level)
            })
            .collect()
    };
    let shape = Shape {
        width: first.width(),
        height: first.height(),
        layers,
        faces,
    };
    write_payloads(shape, &desc, &payloads, opts, out)
}

/// The header's image dimensions.
struct Shape {
    width: u32,
    height: u32,
    /// `layerCount` (0: not an array).
    layers: u32,
    /// `faceCount` (6 for a cube map).
    faces: u32,
}

/// Serialise a block-compressed chain as KTX2 bytes written to `out`.
pub fn write_blocks_to(chain: &BlockChain, opts: &SaveOptions, out: &mut impl Write) -> Result<()> {
    chain.validate()?;
    let alpha = chain.alpha != AlphaMode::None;
    let desc = Desc {
        vk: vk_block_format(chain.format, chain.srgb, alpha),
        // Block-compressed formats have typeSize 1 (KTX 2.0 section 3.2).
        type_size: 1,
        dfd: dfd_block(
            chain.format,
            chain.srgb,
            chain.alpha == AlphaMode::Premultiplied,
            alpha,
        ),
        block_bytes: chain.format.block_bytes() as u64,
    };
    let payloads: Vec<std::borrow::Cow<[u8]>> = chain
        .levels
        .iter()
        .map(|l| std::borrow::Cow::Borrowed(l.as_slice()))
        .collect();
    let shape = Shape {
        width: chain.width,
        height: chain.height,
        layers: 0,
        faces: 1,
    };
    write_payloads(shape, &desc, &payloads, opts, out)
}

/// The container around the levels' bytes: header, level index, DFD,
/// key/value data, then the levels smallest first, supercompressed (on
/// all threads) when `opts` asks.
fn write_payloads(
    shape: Shape,
    desc: &Desc,
    payloads: &[std::borrow::Cow<[u8]>],
    opts: &SaveOptions,
    out: &mut impl Write,
) -> Result<()> {
    use rayon::prelude::*;
    let n = payloads.len() as u64;
    let mut kv = Vec::new();
    let mut entries: Vec<(String, String)> = vec![
        ("KTXorientation".into(), "rd".into()),
        (
            "KTXwriter".into(),
            concat!("parvo ", env!("CARGO_PKG_VERSION")).into(),
        ),
        (
            "parvo:wrapmodes".into(),
            format!("{},{}", opts.wrap.u.oiio_name(), opts.wrap.v.oiio_name()),
        ),
    ];
    if let Some(fp) = &opts.fingerprint {
        entries.push((FINGERPRINT_KEY.into(), fp.clone()));
    }
    entries.extend(opts.attributes.iter().cloned());
    entries.sort();
    entries.dedup_by(|a, b| a.0 == b.0);
    for (k, v) in &entries {
        kv.extend(kv_entry(k, v));
    }
    // Supercompressed levels: compressed in parallel, written in order.
    let packed: Option<Vec<Vec<u8>>> = match opts.supercompression {
        Some(sc) => Some(
            payloads
                .par_iter()
                .map(|p| sc.compress(p))
                .collect::<Result<Vec<_>>>()?,
        ),
        None => None,
    };
    let stored: Vec<&[u8]> = match &packed {
        Some(v) => v.iter().map(|x| x.as_slice()).collect(),
        None => payloads.iter().map(|p| p.as_ref()).collect(),
    };
    let level_index_at = 80u64;
    let dfd_at = level_index_at + 24 * n;
    let kvd_at = dfd_at + desc.dfd.len() as u64;
    // Section 3.10: levels are aligned to lcm(texel block size, 4), or to
    // 1 byte when supercompressed.
    let align = if packed.is_some() {
        1
    } else {
        lcm(desc.block_bytes, 4)
    };
    let mut at = (kvd_at + kv.len() as u64).next_multiple_of(align);
    let data_start = at;
    // Offsets, smallest level first in the file.
    let mut offsets = vec![0u64; payloads.len()];
    for k in (0..payloads.len()).rev() {
        at = at.next_multiple_of(align);
        offsets[k] = at;
        at += stored[k].len() as u64;
    }
    let mut head = Vec::with_capacity(data_start as usize);
    head.extend_from_slice(&IDENTIFIER);
    for v in [
        desc.vk,
        desc.type_size,
        shape.width,
        shape.height,
        0,
        shape.layers,
        shape.faces,
        n as u32,
        opts.supercompression.map_or(0, |s| s.scheme()),
    ] {
        head.extend_from_slice(&v.to_le_bytes());
    }
    head.extend_from_slice(&(dfd_at as u32).to_le_bytes());
    head.extend_from_slice(&(desc.dfd.len() as u32).to_le_bytes());
    head.extend_from_slice(&(kvd_at as u32).to_le_bytes());
    head.extend_from_slice(&(kv.len() as u32).to_le_bytes());
    head.extend_from_slice(&0u64.to_le_bytes());
    head.extend_from_slice(&0u64.to_le_bytes());
    for k in 0..payloads.len() {
        for v in [offsets[k], stored[k].len() as u64, payloads[k].len() as u64] {
            head.extend_from_slice(&v.to_le_bytes());
        }
    }
    head.extend_from_slice(&desc.dfd);
    head.extend_from_slice(&kv);
    head.resize(data_start as usize, 0);
    let io = |e: std::io::Error| encode_err(e.to_string());
    out.write_all(&head).map_err(io)?;
    let mut pos = data_start;
    for k in (0..payloads.len()).rev() {
        let pad = (offsets[k] - pos) as usize;
        out.write_all(&vec![0u8; pad]).map_err(io)?;
        out.write_all(stored[k]).map_err(io)?;
        pos = offsets[k] + stored[k].len() as u64;
    }
    Ok(())
}

/// Write a block-compressed chain to a `.ktx2` file atomically.
pub fn save_blocks(chain: &BlockChain, path: &Path, opts: &SaveOptions) -> Result<()> {
    chain.validate()?;
    atomic::write(path, |w| write_blocks_to(chain, opts, w))
}

/// Write `levels` to a `.ktx2` file atomically.
pub fn save(levels: &[Texture], path: &Path, opts: &SaveOptions) -> Result<()> {
    atomic::write(path, |w| write_to(levels, opts, w))
}

/// Write a cube map, an array or a 2-D texture (see [`write_images_to`])
/// to a `.ktx2` file atomically.
pub fn save_images(
    images: &[&[Texture]],
    kind: Kind,
    path: &Path,
    opts: &SaveOptions,
) -> Result<()> {
    atomic::write(path, |w| write_images_to(images, kind, opts, w))
}

fn read_bytes(path: &Path, limits: &Limits) -> Result<Vec<u8>> {
    let len = std::fs::metadata(path)
        .map_err(|e| Error::Io {
            path: path.to_path_buf(),
            action: "cannot open".into(),
            error: e,
        })?
        .len();
    if len > limits.max_alloc {
        return Err(Error::Limits(format!(
            "file is {} MiB, more than the {} MiB allowed (raise with {})",
            len >> 20,
            limits.max_alloc >> 20,
            crate::setting::Setting::MaxAlloc
        )));
    }
    std::fs::read(path).map_err(|e| Error::Io {
        path: path.to_path_buf(),
        action: "cannot read".into(),
        error: e,
    })
}

/// Read the fingerprint key of a KTX2 file written by parvo.
pub fn stored_fingerprint(path: &Path) -> Option<String> {
    let bytes = std::fs::read(path).ok()?;
    let r = reader(&bytes).ok()?;
    r.key_value_data()
        .find(|(k, _)| *k == FINGERPRINT_KEY)
        .map(|(_, v)| {
            String::from_utf8_lossy(v)
                .trim_end_matches('\0')
                .to_string()
        })
}

/// The colour model / primaries / transfer / flags word of the first DFD
/// block, read from the bytes (not through the `ktx2` crate's DFD parser:
/// see [`reader`]), when it is a Khronos basic block.
fn dfd_model_word(bytes: &[u8]) -> Option<u32> {
    let word = |at: usize| {
        bytes
            .get(at..at.checked_add(4)?)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    // dfdByteOffset; then the total size word, the vendor/type word, the
    // version/size word, and the model/primaries/transfer/flags word.
    let at = word(48)? as usize;
    if word(52)? < 16 || word(at.checked_add(4)?)? != 0 {
        return None;
    }
    word(at.checked_add(12)?)
}

/// The premultiplied-alpha flag of the basic DFD block.
fn dfd_premultiplied(bytes: &[u8]) -> bool {
    dfd_model_word(bytes).is_some_and(|w| (w >> 24) & 1 == 1)
}

/// The `ktx2` crate's reader of `bytes`, after the checks it lacks: its
/// DFD parser panics (`NonZeroU8::new(dim + 1).unwrap()`) on a texel
/// block dimension byte of 255, so every basic DFD block is checked
/// first, and any other panic inside the crate becomes an error.
fn reader(bytes: &[u8]) -> Result<::ktx2::Reader<&[u8]>> {
    let word = |at: usize| {
        bytes
            .get(at..at.checked_add(4)?)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    if let (Some(at), Some(len)) = (word(48), word(52)) {
        let (start, len) = (at as usize, len as usize);
        let end = start.saturating_add(len).min(bytes.len());
        // After the total size word: blocks of vendor/type, version/size.
        let mut b = start.saturating_add(4);
        while b.saturating_add(16) <= end {
            let (Some(head), Some(size)) = (word(b), word(b + 4)) else {
                break;
            };
            let size = (size >> 16) as usize;
            if head == 0 && bytes[b + 12..b + 16].contains(&255) {
                return Err(decode_err(
                    "the data format descriptor gives a texel block dimension of 256",
                ));
            }
            if size == 0 {
                break;
            }
            b = b.saturating_add(size);
        }
    }
    std::panic::catch_unwind(|| ::ktx2::Reader::new(bytes))
        .map_err(|_| decode_err("malformed file (the KTX2 parser failed)"))?
        .map_err(parse_error)
}

/// The `ktx2` crate's parse errors in a user's words.
fn parse_error(e: ::ktx2::ParseError) -> Error {
    use ::ktx2::ParseError::*;
    decode_err(match e {
        BadMagic => "not a KTX 2.0 file (its 12-byte identifier is missing)".to_string(),
        ZeroWidth => "the header gives a width of 0".to_string(),
        ZeroFaceCount => "the header gives a face count of 0".to_string(),
        InvalidSampleBitLength => {
            "the data format descriptor has a sample with an invalid bit length".to_string()
        }
        UnexpectedEnd => {
            "the file is truncated: its header, an index or a level ends past the end of the file"
                .to_string()
        }
        other => format!("malformed file ({other})"),
    })
}

/// What a `KTXorientation` value asks of a texture (`two_d`: the file has
/// a height): the EXIF orientation code that puts its rows top to bottom
/// and its columns left to right (1 none, 2 mirror, 3 both, 4 flip), and
/// the sentence that says so or that the value is not understood. The
/// value is `r` or `l` (the direction of increasing x) followed, in 2-D,
/// by `d` or `u` (of increasing y); a third letter is a volume's and
/// irrelevant here.
fn orientation(value: &str, two_d: bool) -> (u16, Option<String>) {
    let mut c = value.chars();
    let x = c.next();
    let y = if two_d { c.next() } else { Some('d') };
    let (left, up) = match (x, y) {
        (Some('r'), Some('d')) => return (1, None),
        (Some(x @ ('r' | 'l')), Some(y @ ('d' | 'u'))) => (x == 'l', y == 'u'),
        _ => {
            return (
                1,
                Some(format!(
                    "KTXorientation `{value}` not understood (expected r or l, then d or u): the \
                     levels are read as stored, top row first"
                )),
            );
        }
    };
    let what = match (left, up) {
        (true, true) => "rows stored bottom to top and columns right to left",
        (true, false) => "columns stored right to left",
        _ => "rows stored bottom to top",
    };
    let code = match (left, up) {
        (true, true) => 3,
        (true, false) => 2,
        _ => 4,
    };
    (
        code,
        Some(format!(
            "KTXorientation `{value}` ({what}): every level turned to rows top to bottom, \
             columns left to right"
        )),
    )
}

/// Load a KTX2 file: every mip level of a 2-D texture (uncompressed, or
/// BC1–BC7, optionally zstd/zlib supercompressed), its rows and columns
/// put in parvo's order (top to bottom, left to right) as its
/// `KTXorientation` says.
pub fn load(path: &Path, limits: &Limits) -> Result<Loaded> {
    load_with(path, limits, &super::LoadOptions::default())
}

/// [`load`] with [`super::LoadOptions`]: cube maps and arrays are read
/// whole (every face and layer) when `options` accept them.
pub fn load_with(path: &Path, limits: &Limits, options: &super::LoadOptions) -> Result<Loaded> {
    let bytes = read_bytes(path, limits)?;
    load_bytes(&bytes, limits, options)
}

fn load_bytes(bytes: &[u8], limits: &Limits, options: &super::LoadOptions) -> Result<Loaded> {
    let r = reader(bytes)?;
    let h = r.header();
    let kind = image_kind(&h)?;
    let mut notes = Vec::new();
    super::layered_image(
        "KTX2",
        kind,
        (h.pixel_width, h.pixel_height.max(1)),
        options,
    )?;
    let scheme = u32::from_le_bytes(bytes[44..48].try_into().map_err(decode_err)?);
    let vk = h.format.map(|f| f.value()).unwrap_or(0);
    let block = block_format_of_vk(vk);
    let mut format = match block {
        Some((bf, srgb, _)) => bf.decoded_format(srgb),
        None => format_of_vk(vk).ok_or_else(|| {
            unsupported_format(vk, scheme, dfd_model_word(bytes).map(|w| w & 0xff))
        })?,
    };
    let premultiplied = dfd_premultiplied(bytes);
    format = apply_swizzle(&r, format, block.is_some(), &mut notes);
    if premultiplied && format.has_alpha() {
        format = format.with_alpha(AlphaMode::Premultiplied);
    }
    let stored = StoredLevels {
        width: h.pixel_width,
        height: h.pixel_height.max(1),
        scheme,
        block,
        format,
        premultiplied,
        images: kind.images(),
    };
    stored.check_decoded_size(r.levels().len(), bytes.len(), limits)?;
    // images[i][k]: level k of face or layer i.
    let mut images: Vec<Vec<Texture>> = vec![Vec::new(); stored.images];
    for (k, level) in r.levels().enumerate() {
        for (i, t) in stored.read(k, &level, limits)?.into_iter().enumerate() {
            images[i].push(t);
        }
    }
    if images[0].is_empty() {
        return Err(decode_err("no levels"));
    }
    if let Some((_, v)) = r.key_value_data().find(|(k, _)| *k == "KTXorientation") {
        let text = String::from_utf8_lossy(v)
            .trim_end_matches('\0')
            .to_string();
        let (code, note) = orientation(&text, h.pixel_height > 0);
        // A cube map's faces are defined in their own orientation
        // (KTX 2.0 section 4.2): KTXorientation does not apply to them.
        if code != 1 && !kind.is_cube() {
            for levels in &mut images {
                *levels = levels
                    .iter()
                    .map(|l| super::orient(l, code))
                    .collect::<Result<_>>()?;
            }
        }
        notes.extend(note);
    }
    let mut images = images.into_iter();
    let Some(levels) = images.next() else {
        return Err(decode_err("no images"));
    };
    let attributes = attributes_of(&r, vk, block, scheme);
    let wrap = super::recorded_wrap(
        attributes
            .iter()
            .find(|(k, _)| k == "parvo:wrapmodes")
            .map(|(_, v)| v.as_str()),
        &mut notes,
    );
    let format = levels.first().map_or(format, |l| l.format());
    let mut info = SourceInfo::new(FileFormat::Ktx2, &format);
    info.notes = notes;
    info.channel_names = match (format.channels, format.has_alpha()) {
        (1, _) => vec!["R".into()],
        (2, false) => vec!["R".into(), "G".into()],
        _ => super::layout_names(&format),
    };
    info.own_mips = levels.len() > 1;
    info.blocks = block.map(|b| b.0);
    info.wrap = wrap;
    info.attributes = attributes;
    info.kind = kind;
    Ok(Loaded {
        levels,
        info,
        images: images.collect(),
    })
}

/// How a file's levels are stored, from its header: what sizing,
/// inflating and decoding them needs.
struct StoredLevels {
    /// Level 0's size (a 1-D texture has height 1).
    width: u32,
    height: u32,
    /// The supercompression scheme (0: none).
    scheme: u32,
    /// The block format, sRGB, and whether it has alpha; `None` for plain
    /// texels of `format`.
    block: Option<(BlockFormat, bool, bool)>,
    /// The texel format the levels decode to.
    format: Format,
    /// The DFD says alpha is premultiplied.
    premultiplied: bool,
    /// Faces times layers: the 2-D images each level holds, one after
    /// the other (KTX 2.0 section 3.9.7).
    images: usize,
}

impl StoredLevels {
    /// The size of level `k` (rounded down, as KTX 2.0 defines).
    fn size(&self, k: usize) -> (u32, u32) {
        crate::mip::level_size(
            self.width,
            self.height,
            k as u32,
            crate::mip::Rounding::Down,
        )
    }

    /// Bytes of one `w × h` image as stored (before supercompression).
    fn image_len(&self, (w, h): (u32, u32)) -> u64 {
        match self.block {
            Some((bf, ..)) => bf.level_bytes(w, h),
            None => w as u64 * h as u64 * self.format.texel_bytes() as u64,
        }
    }

    /// Bytes of a `w × h` level as stored (every face and layer, before
    /// supercompression).
    fn stored_len(&self, size: (u32, u32)) -> u64 {
        self.image_len(size).saturating_mul(self.images as u64)
    }

    /// Hold what decoding `count` levels of a file of `file_len` bytes
    /// allocates to `limits`, from the header alone: the decoded texels
    /// of every level, the file, and one inflated level when
    /// supercompressed (block formats decode to 4-16 times their stored
    /// bytes, and supercompressed levels can be thousands of times the
    /// file's).
    fn check_decoded_size(&self, count: usize, file_len: usize, limits: &Limits) -> Result<()> {
        let decoded: u64 = (0..count)
            .map(|k| {
                let (lw, lh) = self.size(k);
                (lw as u64 * lh as u64)
                    .saturating_mul(self.format.texel_bytes() as u64)
                    .saturating_mul(self.images as u64)
            })
            .fold(0, u64::saturating_add);
        let inflated = if self.scheme != 0 {
            self.stored_len(self.size(0))
        } else {
            0
        };
        limits.check(
            self.width as u64,
            self.height as u64,
            decoded
                .saturating_add(file_len as u64)
                .saturating_add(inflated),
        )
    }

    /// Level `k` of every face and layer: inflated when supercompressed,
    /// its length checked, decoded.
    fn read(&self, k: usize, level: &::ktx2::Level<'_>, limits: &Limits) -> Result<Vec<Texture>> {
        let (lw, lh) = self.size(k);
        let need = self.stored_len((lw, lh));
        let unpacked;
        let data: &[u8] = if self.scheme != 0 {
            // The declared length is what gets allocated: it must be the
            // level's size before anything is inflated.
            if level.uncompressed_byte_length != need {
                return Err(decode_err(format!(
                    "level {k} declares {} bytes uncompressed, a {lw}x{lh} level has {need}",
                    level.uncompressed_byte_length
                )));
            }
            unpacked = decompress(self.scheme, level.data, need, limits)?;
            &unpacked
        } else {
            level.data
        };
        if data.len() as u64 != need {
            return Err(decode_err(match self.block {
                Some((bf, ..)) => format!(
                    "level {k} has {} bytes, a {lw}x{lh} {bf} level needs {need}",
                    data.len()
                ),
                None => format!("level {k} has {} bytes, {lw}x{lh} needs {need}", data.len()),
            }));
        }
        data.chunks_exact(self.image_len((lw, lh)) as usize)
            .map(|image| self.decode(image, (lw, lh)))
            .collect()
    }

    /// One `w × h` level from its stored bytes (inflated, of the right
    /// length): BC blocks decoded, plain texels read little-endian.
    fn decode(&self, data: &[u8], (w, h): (u32, u32)) -> Result<Texture> {
        match self.block {
            Some((bf, srgb, has_alpha)) => {
                let alpha = if !has_alpha {
                    // BC1_RGB: alpha is 1 whatever the blocks say.
                    AlphaMode::None
                } else if self.premultiplied {
                    AlphaMode::Premultiplied
                } else {
                    AlphaMode::Straight
                };
                crate::compress::decode(bf, srgb, alpha, w, h, data)
            }
            None => {
                let texels = super::texels_from_le(self.format.channel_type, data);
                Texture::from_texels(w, h, self.format, texels)
            }
        }
    }
}

/// The kind of image a file starting with `head` holds, from its
/// header's layer and face counts alone (a plain 2-D image when the
/// header is too short or not a cube map or an array).
pub(crate) fn peek_kind(head: &[u8]) -> Kind {
    let word = |at: usize| {
        head.get(at..at + 4)
            .map_or(0, |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    match (word(36), word(32)) {
        (6, 0) => Kind::Cube,
        (6, cubes) => Kind::CubeArray { cubes },
        (1, 0) => Kind::Plain,
        (1, layers) => Kind::Array { layers },
        _ => Kind::Plain,
    }
}

/// The kind of image the header describes (KTX 2.0 section 3.4: a
/// layer count of 0 is not an array, 1 or more is); volumes and face
/// counts other than 1 and 6 are refused.
fn image_kind(h: &::ktx2::Header) -> Result<Kind> {
    if h.face_count != 1 && h.face_count != 6 {
        return Err(decode_err(format!(
            "the header gives {} faces (1, or 6 for a cube map)",
            h.face_count
        )));
    }
    if h.pixel_depth > 1 {
        return Err(decode_err(format!(
            "volume textures are not supported (this one is {} texels deep; parvo reads 2-D \
             textures, arrays and cube maps)",
            h.pixel_depth
        )));
    }
    let cube = h.face_count == 6;
    if cube && (h.pixel_width != h.pixel_height) {
        return Err(decode_err(format!(
            "a cube map's faces must be square, the header gives {}x{}",
            h.pixel_width, h.pixel_height
        )));
    }
    Ok(match (cube, h.layer_count) {
        (false, 0) => Kind::Plain,
        (false, layers) => Kind::Array { layers },
        (true, 0) => Kind::Cube,
        (true, cubes) => Kind::CubeArray { cubes },
    })
}

/// `format` as the file's `KTXswizzle` (KTX 2.0 section "KTXswizzle")
/// reads it: `rrrg` on a two-channel plain format is the specification's
/// luminance + alpha; the other mappings that keep the stored channels'
/// meaning need nothing, and any other is reported in `notes`, not
/// applied.
fn apply_swizzle(
    r: &::ktx2::Reader<&[u8]>,
    format: Format,
    blocks: bool,
    notes: &mut Vec<String>,
) -> Format {
    let swizzle = r
        .key_value_data()
        .find(|(k, _)| *k == "KTXswizzle")
        .map(|(_, v)| {
            String::from_utf8_lossy(v)
                .trim_end_matches('\0')
                .to_string()
        });
    let Some(sw) = &swizzle else {
        return format;
    };
    let identity = ["r001", "rg01", "rgb1", "rgba"][(format.channels as usize).clamp(1, 4) - 1];
    if format.channels == 2 && sw == "rrrg" && !blocks {
        return format.with_alpha(AlphaMode::Straight);
    }
    if sw != identity && sw != "rgba" && !(format.channels == 1 && sw == "rrr1") {
        notes.push(format!(
            "KTXswizzle `{sw}` is not applied: the channels are read as stored"
        ));
    }
    format
}

/// The attributes `parvo info` shows, sorted: the key/value data (text,
/// or its length when binary), the vkFormat, the block format stored and
/// the supercompression.
fn attributes_of(
    r: &::ktx2::Reader<&[u8]>,
    vk: u32,
    block: Option<(BlockFormat, bool, bool)>,
    scheme: u32,
) -> Vec<(String, String)> {
    let mut attributes: Vec<(String, String)> = r
        .key_value_data()
        .map(|(k, v)| {
            let text = if v.iter().all(|&b| b == 0 || (32..127).contains(&b)) {
                String::from_utf8_lossy(v)
                    .trim_end_matches('\0')
                    .to_string()
            } else {
                format!("<{} bytes>", v.len())
            };
            (k.to_string(), text)
        })
        .collect();
    attributes.push(("vkFormat".into(), vk_describe(vk)));
    if let Some((bf, srgb, _)) = block {
        attributes.push((
            "stored".into(),
            format!("{bf}{}", if srgb { "_SRGB" } else { "" }),
        ));
    }
    if scheme != 0 {
        attributes.push((
            "supercompression".into(),
            match scheme {
                2 => "zstd".into(),
                3 => "zlib".into(),
                s => format!("scheme {s}"),
            },
        ));
    }
    attributes.sort();
    attributes
}

/// KTX 2.0 in the container table: reads and writes every vkFormat parvo
/// has a texel format for and the BC block formats, plain or
/// supercompressed; sizes rounded down; the fingerprint as key/value data.
pub struct Ktx2;

impl super::Container for Ktx2 {
    fn id(&self) -> &'static str {
        "ktx2"
    }
    fn name(&self) -> &'static str {
        "KTX2"
    }
    fn tag(&self) -> &'static str {
        "Ktx2"
    }
    fn summary(&self) -> &'static str {
        "KTX 2.0"
    }
    fn detect(&self, magic: &[u8]) -> bool {
        magic.starts_with(IDENTIFIER.as_slice())
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
        &["ktx2"]
    }
    fn stores(&self) -> Option<super::Stores> {
        Some(super::Stores {
            float: true,
            integer: true,
            blocks: true,
            fingerprint: true,
            supercompression: true,
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
        options: &SaveOptions,
    ) -> Result<()> {
        save(levels, path, options)
    }
    fn save_blocks(&self, chain: &BlockChain, path: &Path, options: &SaveOptions) -> Result<()> {
        save_blocks(chain, path, options)
    }
    fn stored_fingerprint(&self, path: &Path) -> Option<String> {
        stored_fingerprint(path)
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
        options: &SaveOptions,
    ) -> Result<()> {
        save_images(images, kind, path, options)
    }
}
