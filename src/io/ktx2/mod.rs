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
//! (`rd`). The uncompressed formats parvo has no texel type for are
//! unpacked into the nearest one as libktx's `ktx extract` presents them
//! (the `packed` module): `B8G8R8A8`-style orders put in R, G, B, A order;
//! packed UNORM fields (`R5G6B5`, `A1R5G5B5`, `R4G4B4A4`, ..., the 10- and
//! 12-bit `A2R10G10B10`, `R10X6…`, `R12X4…`) widened to u8 or u16 by bit
//! replication; `A8_UNORM` as grey 0 + alpha; 8/16-bit `_UINT` as codes,
//! `_SINT` as codes offset by half the range, `_SNORM` as f32. Formats
//! parvo does not read are named by their Vulkan names with the format to
//! convert them to, and Basis Universal files (BasisLZ/ETC1S, UASTC) as
//! such.

use std::path::Path;

use super::{FINGERPRINT_KEY, FileFormat, Limits, Loaded, SaveOptions, SourceInfo, atomic};
use crate::compress::{BlockChain, BlockFormat};
use crate::error::{Error, Result};
use crate::texel::{AlphaMode, ChannelType, ColorSpace, Format};
use crate::texture::ImageKind;
use crate::texture::Texture;
use std::io::Write;

mod packed;
mod read;
mod write;

use packed::{Packed, packed_of_vk};

pub use read::*;
pub use write::*;

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

/// The Vulkan name of a `_USCALED` or `_SSCALED` format (the UNORM
/// format's value plus 2 or 3), which KTX 2.0 prohibits and the `ktx2`
/// crate does not list, for messages about files that use one anyway.
fn scaled_name(vk: u32) -> Option<String> {
    const UNORM: [u32; 13] = [9, 16, 23, 30, 37, 44, 51, 58, 64, 70, 77, 84, 91];
    let (base, scaled) = UNORM.iter().find_map(|&b| match vk.checked_sub(b) {
        Some(2) => Some((b, "_USCALED")),
        Some(3) => Some((b, "_SSCALED")),
        _ => None,
    })?;
    Some(vk_format_name(base)?.replace("_UNORM", scaled))
}

/// `VK_FORMAT_… (n)`, or `vkFormat n` when the value has no name.
fn vk_describe(vk: u32) -> String {
    match vk_format_name(vk).or_else(|| scaled_name(vk)) {
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
        _ => format!("{} {}", vk_describe(vk), convert_to(vk)),
    };
    decode_err(reason)
}

/// What a vkFormat parvo does not read is, and what to convert it to,
/// after its name.
fn convert_to(vk: u32) -> &'static str {
    match vk {
        127 => "is a stencil format, which parvo does not read; store it as R8_UINT first",
        124..=130 => {
            "is a depth/stencil format, which parvo does not read; store the depth as \
             R16_UNORM or R32_SFLOAT first"
        }
        147..=184 | 1000054000..=1000054007 | 1000066000..=1000066013 | 1000288000..=1000288029 => {
            "is a block-compressed format parvo does not decode (it decodes BC1-BC7); convert it \
             to R8G8B8A8 or a BC format first (for example with KTX-Software's `ktx extract` to \
             PNG or EXR)"
        }
        1000156000..=1000156033 | 1000330000..=1000330003 => {
            "is a YCbCr (4:2:2 or multi-planar) format, which parvo does not read; convert it to \
             R8G8B8A8_UNORM or R16G16B16A16_UNORM first"
        }
        122 | 123 => {
            "is a packed float format parvo does not read; convert it to R16G16B16A16_SFLOAT \
             first"
        }
        _ => {
            "is not a format parvo reads; convert it to R8G8B8A8_UNORM (or _SRGB), \
             R16G16B16A16_UNORM or R32G32B32A32_SFLOAT first"
        }
    }
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

/// How KTX2 files are written: the options of this container alone
/// (`--zstd`, `--zlib`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Ktx2Options {
    /// Supercompression of every level, or none.
    pub supercompression: Option<Supercompression>,
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
            "a level declares {} uncompressed, more than the {} allowed (raise with {})",
            super::limits::byte_size(len),
            super::limits::byte_size(limits.max_alloc),
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

/// KTX 2.0 in the container table: reads and writes every vkFormat parvo
/// has a texel format for and the BC block formats, plain or
/// supercompressed; sizes rounded down; the fingerprint as key/value data.
pub struct Ktx2;

impl super::Container for Ktx2 {
    fn peek_kind(&self, head: &[u8], _path: &Path) -> Option<crate::texture::ImageKind> {
        Some(peek_kind(head))
    }
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
        images: &[&[Texture]],
        kind: ImageKind,
        _rounding: crate::mip::Rounding,
        path: &Path,
        options: &SaveOptions,
    ) -> Result<()> {
        save_images(images, kind, path, options)
    }
    fn save_blocks(
        &self,
        chains: &[BlockChain],
        kind: ImageKind,
        path: &Path,
        options: &SaveOptions,
    ) -> Result<()> {
        save_block_images(chains, kind, path, options)
    }
    fn stored_fingerprint(&self, path: &Path) -> Option<String> {
        stored_fingerprint(path)
    }
    fn holds(&self, kind: ImageKind) -> bool {
        kind != ImageKind::LatLong
    }
}
