//! KTX 2.0: uncompressed textures with the full mip chain.
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
//! `R16…_UNORM`, `R16…_SFLOAT` and `R32…_SFLOAT` families. Vulkan has no
//! sRGB 16-bit or float formats, and its `R8G8_SRGB` would sRGB-decode the
//! alpha of grey + alpha, so callers convert such data first
//! ([`storable`]). Reading uses the `ktx2` crate, which validates the
//! structure.

use std::path::Path;

use super::{FINGERPRINT_KEY, FileFormat, Limits, Loaded, SaveOptions, SourceInfo, atomic};
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

/// The `VkFormat` for a texel format, if Vulkan has one.
pub fn vk_format(f: &Format) -> Option<u32> {
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

/// The texel format of a `VkFormat` parvo reads (inverse of [`vk_format`]).
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
    Some(Format::new(ch as u8 + 1, ty, cs))
}

/// The closest format KTX2 can store `f` in: same values where Vulkan has
/// the format; sRGB u16 and float become linear; sRGB grey + alpha (u8)
/// becomes RGBA so the alpha is not sRGB-decoded.
pub fn storable(f: Format) -> Format {
    let mut out = f;
    if f.color_space == ColorSpace::Srgb && f.channel_type != ChannelType::U8 {
        out.color_space = ColorSpace::Linear;
    }
    if f.color_space == ColorSpace::Srgb && f.channel_type == ChannelType::U8 && f.channels == 2 {
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

/// Serialise `levels` (level 0 first, sizes rounding down) as KTX2 bytes
/// written to `out`.
pub fn write_to(levels: &[Texture], opts: &SaveOptions, out: &mut impl Write) -> Result<()> {
    let first = &levels[0];
    let f = first.format();
    let vk = vk_format(&f).ok_or_else(|| {
        encode_err(format!(
            "no Vulkan format for {f} (convert it with ktx2::storable)"
        ))
    })?;
    let n = levels.len() as u64;
    let texel = f.texel_bytes() as u64;
    let dfd = dfd(&f);
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
    let level_index_at = 80u64;
    let dfd_at = level_index_at + 24 * n;
    let kvd_at = dfd_at + dfd.len() as u64;
    let align = lcm(texel, 4);
    let mut at = (kvd_at + kv.len() as u64).next_multiple_of(align);
    let data_start = at;
    // Offsets, smallest level first in the file.
    let mut offsets = vec![0u64; levels.len()];
    for k in (0..levels.len()).rev() {
        at = at.next_multiple_of(align);
        offsets[k] = at;
        at += levels[k].byte_len() as u64;
    }
    let mut head = Vec::with_capacity(data_start as usize);
    head.extend_from_slice(&IDENTIFIER);
    for v in [
        vk,
        f.channel_type.bytes() as u32,
        first.width(),
        first.height(),
        0,
        0,
        1,
        n as u32,
        0,
    ] {
        head.extend_from_slice(&v.to_le_bytes());
    }
    head.extend_from_slice(&(dfd_at as u32).to_le_bytes());
    head.extend_from_slice(&(dfd.len() as u32).to_le_bytes());
    head.extend_from_slice(&(kvd_at as u32).to_le_bytes());
    head.extend_from_slice(&(kv.len() as u32).to_le_bytes());
    head.extend_from_slice(&0u64.to_le_bytes());
    head.extend_from_slice(&0u64.to_le_bytes());
    for (k, l) in levels.iter().enumerate() {
        let len = l.byte_len() as u64;
        for v in [offsets[k], len, len] {
            head.extend_from_slice(&v.to_le_bytes());
        }
    }
    head.extend_from_slice(&dfd);
    head.extend_from_slice(&kv);
    head.resize(data_start as usize, 0);
    let io = |e: std::io::Error| encode_err(e.to_string());
    out.write_all(&head).map_err(io)?;
    let mut pos = data_start;
    for k in (0..levels.len()).rev() {
        let pad = (offsets[k] - pos) as usize;
        out.write_all(&vec![0u8; pad]).map_err(io)?;
        let bytes = super::le_bytes(levels[k].texels());
        out.write_all(&bytes).map_err(io)?;
        pos = offsets[k] + bytes.len() as u64;
    }
    Ok(())
}

/// Write `levels` to a `.ktx2` file atomically.
pub fn save(levels: &[Texture], path: &Path, opts: &SaveOptions) -> Result<()> {
    atomic::write(path, |w| write_to(levels, opts, w))
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
            "file is {} MiB, more than the {} MiB allowed (raise with --max-alloc)",
            len >> 20,
            limits.max_alloc >> 20
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
    let r = ::ktx2::Reader::new(bytes.as_slice()).ok()?;
    r.key_value_data()
        .find(|(k, _)| *k == FINGERPRINT_KEY)
        .map(|(_, v)| {
            String::from_utf8_lossy(v)
                .trim_end_matches('\0')
                .to_string()
        })
}

/// Load a KTX2 file: every mip level of an uncompressed 2-D texture.
pub fn load(path: &Path, limits: &Limits) -> Result<Loaded> {
    let bytes = read_bytes(path, limits)?;
    let r = ::ktx2::Reader::new(bytes.as_slice()).map_err(decode_err)?;
    let h = r.header();
    if h.supercompression_scheme.is_some() {
        return Err(decode_err("supercompressed files are not supported"));
    }
    if h.pixel_depth > 1 || h.layer_count > 1 || h.face_count != 1 {
        return Err(decode_err(
            "only 2-D textures are supported (no arrays, cube maps or volumes)",
        ));
    }
    let vk = h.format.map(|f| f.value()).unwrap_or(0);
    let mut format = format_of_vk(vk).ok_or_else(|| {
        decode_err(format!(
            "vkFormat {vk} is not an uncompressed format parvo reads"
        ))
    })?;
    if r.is_alpha_premultiplied() == Some(true) {
        format = format.with_alpha(AlphaMode::Premultiplied);
    }
    let (w, hgt) = (h.pixel_width, h.pixel_height.max(1));
    limits.check(w as u64, hgt as u64, bytes.len() as u64 * 2)?;
    let mut levels = Vec::new();
    for (k, level) in r.levels().enumerate() {
        let (lw, lh) = crate::mip::level_size(w, hgt, k as u32, crate::mip::Rounding::Down);
        let need = lw as usize * lh as usize * format.texel_bytes();
        if level.data.len() != need {
            return Err(decode_err(format!(
                "level {k} has {} bytes, {lw}x{lh} needs {need}",
                level.data.len()
            )));
        }
        let texels = super::texels_from_le(format.channel_type, level.data);
        levels.push(Texture::from_texels(lw, lh, format, texels)?);
    }
    if levels.is_empty() {
        return Err(decode_err("no levels"));
    }
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
    attributes.push(("vkFormat".into(), format!("{:?}", h.format)));
    attributes.sort();
    let mut notes = Vec::new();
    let wrap = super::recorded_wrap(
        attributes
            .iter()
            .find(|(k, _)| k == "parvo:wrapmodes")
            .map(|(_, v)| v.as_str()),
        &mut notes,
    );
    let mut info = SourceInfo::new(FileFormat::Ktx2, &format);
    info.notes = notes;
    info.channel_names = match format.channels {
        1 => vec!["R".into()],
        2 => vec!["R".into(), "G".into()],
        _ => super::layout_names(&format),
    };
    info.own_mips = levels.len() > 1;
    info.wrap = wrap;
    info.attributes = attributes;
    Ok(Loaded { levels, info })
}
