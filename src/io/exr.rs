//! OpenEXR: read scanline, tiled and mip-mapped files (all levels, also
//! files maketx writes) and write tiled, mip-mapped textures.
//!
//! Reading goes through the `exr` crate after the header has been checked
//! against [`Limits`] (the declared size of every level the file holds).
//! Channels: `R,G,B[,A]` (also with a layer prefix such as `diffuse.R`),
//! `Y[,A]` (grey), or any one channel. Half files load as f16, everything
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

/// Write `levels` as a tiled, mip-mapped EXR (see the module docs).
///
/// Tiles are assembled directly from the interleaved levels (no per-channel
/// copies of the chain) and compressed in parallel. `zip`/`zips` tiles are
/// compressed here with libdeflate at OpenEXR's default level 4, after
/// OpenEXR's own preprocessing (byte split + delta predictor), because the
/// `exr` crate's deflate (miniz level 4) was the slowest phase of `parvo
/// mip` (6.7 s of 8.1 s for a 4096² RGBA half texture on two cores); every
/// other compression goes through the `exr` crate.
pub fn save(levels: &[Texture], rounding: Rounding, path: &Path, opts: &SaveOptions) -> Result<()> {
    let first = &levels[0];
    let (w, h) = (first.width(), first.height());
    let want = exr_level_sizes(w, h, rounding);
    let have: Vec<_> = levels.iter().map(|l| (l.width(), l.height())).collect();
    if levels.len() > 1 && have != want {
        return Err(encode_err(format!(
            "a mip-mapped OpenEXR file holds the full chain of {} levels, got {} (do not limit --levels for .exr)",
            want.len(),
            levels.len()
        )));
    }
    let (tw, th) = opts.tile;
    if tw == 0 || th == 0 {
        return Err(encode_err("tile size must be at least 1x1"));
    }
    let fmt = first.format();
    let sample_type = match fmt.channel_type {
        ChannelType::F16 => SampleType::F16,
        ChannelType::F32 => SampleType::F32,
        other => return Err(encode_err(format!("EXR stores f16 or f32, not {other}"))),
    };
    if fmt.color_space == ColorSpace::Srgb {
        return Err(encode_err(
            "EXR holds linear data; convert sRGB texels first",
        ));
    }
    let names = super::layout_names(fmt.channels);
    // Channels are stored sorted by name (A, B, G, R).
    let mut order: Vec<usize> = (0..names.len()).collect();
    order.sort_by(|&a, &b| names[a].cmp(&names[b]));
    let channels: SmallVec<[ChannelDescription; 5]> = order
        .iter()
        .map(|&c| ChannelDescription::new(names[c].as_str(), sample_type, false))
        .collect();

    let mut attrs = LayerAttributes {
        software_name: Some(Text::from(concat!("parvo ", env!("CARGO_PKG_VERSION")))),
        // `wrapmodes`, as maketx writes it (the exr crate reserves the name
        // for this field).
        wrap_mode_name: Text::new_or_none(format!(
            "{},{}",
            opts.wrap.u.oiio_name(),
            opts.wrap.v.oiio_name()
        )),
        ..LayerAttributes::default()
    };
    let mut put = |k: &str, v: &str| -> Result<()> {
        let key =
            Text::new_or_none(k).ok_or_else(|| encode_err(format!("bad attribute name `{k}`")))?;
        let val = Text::new_or_none(v)
            .ok_or_else(|| encode_err(format!("attribute `{k}` is not representable: `{v}`")))?;
        attrs.other.insert(key, AttributeValue::Text(val));
        Ok(())
    };
    put("textureformat", "Plain Texture")?;
    if let Some(fp) = &opts.fingerprint {
        put(FINGERPRINT_KEY, fp)?;
    }
    for (k, v) in &opts.attributes {
        put(k, v)?;
    }
    let level_mode = if levels.len() > 1 {
        LevelMode::MipMap
    } else {
        LevelMode::Singular
    };
    let mut header = Header::new(
        Text::from("texture"),
        Vec2(w as usize, h as usize),
        channels,
    )
    .with_encoding(
        opts.compression.to_exr(),
        BlockDescription::Tiles(TileDescription {
            tile_size: Vec2(tw as usize, th as usize),
            level_mode,
            rounding_mode: to_exr_rounding(rounding),
        }),
        LineOrder::Increasing,
    );
    header.own_attributes = attrs;
    let zip = matches!(opts.compression, ExrCompression::Zip | ExrCompression::Zips);
    let tile = (tw as usize, th as usize);
    atomic::write(path, |out| {
        ::exr::block::write(
            out,
            std::iter::once(header).collect(),
            true,
            |meta, writer| {
                let blocks: Vec<(usize, BlockIndex)> =
                    meta.enumerate_ordered_header_block_indices().collect();
                // Bounded batches: parallel compression, ordered writes, and
                // never more than a batch of compressed tiles in memory.
                for batch in blocks.chunks(512) {
                    let chunks: Vec<::exr::error::Result<Chunk>> = batch
                        .par_iter()
                        .map(|(_, index)| {
                            let raw = tile_bytes(levels, index, &order);
                            if zip {
                                Ok(Chunk {
                                    layer_index: 0,
                                    compressed_block: CompressedBlock::Tile(CompressedTileBlock {
                                        coordinates: TileCoordinates {
                                            tile_index: Vec2(
                                                index.pixel_position.x() / tile.0,
                                                index.pixel_position.y() / tile.1,
                                            ),
                                            level_index: index.level,
                                        },
                                        compressed_pixels_le: zip_compress(raw)?,
                                    }),
                                })
                            } else {
                                UncompressedBlock {
                                    index: *index,
                                    data: raw,
                                }
                                .compress_to_chunk(&meta.headers)
                            }
                        })
                        .collect();
                    for ((index_in_header, _), chunk) in batch.iter().zip(chunks) {
                        writer.write_chunk(*index_in_header, chunk?)?;
                    }
                }
                Ok(())
            },
        )
        .map_err(encode_err)
    })
}

/// The uncompressed bytes of one tile: for each line, for each channel in
/// file order, the samples of that line (little-endian, which is native on
/// every platform Rust's `half`/`f32` byte conversions are used on here).
fn tile_bytes(levels: &[Texture], index: &BlockIndex, order: &[usize]) -> Vec<u8> {
    let lvl = &levels[index.level.x()];
    let lw = lvl.width() as usize;
    let ch = lvl.channels();
    let (x0, y0) = (index.pixel_position.x(), index.pixel_position.y());
    let (bw, bh) = (index.pixel_size.x(), index.pixel_size.y());
    let mut raw = Vec::with_capacity(bw * bh * ch * lvl.channel_type().bytes());
    for y in y0..y0 + bh {
        let start = (y * lw + x0) * ch;
        let end = start + bw * ch;
        for &c in order {
            match lvl.texels() {
                Texels::F16(v) => gather(&v[start..end], ch, c, &mut raw, f16::to_le_bytes),
                Texels::F32(v) => gather(&v[start..end], ch, c, &mut raw, f32::to_le_bytes),
                _ => unreachable!("save checks for float texels"),
            }
        }
    }
    raw
}

/// Append channel `c` of the interleaved texels `row` as bytes.
fn gather<T: Copy, const N: usize>(
    row: &[T],
    ch: usize,
    c: usize,
    out: &mut Vec<u8>,
    bytes: fn(T) -> [u8; N],
) {
    let at = out.len();
    out.resize(at + row.len() / ch * N, 0);
    for (o, px) in out[at..].chunks_exact_mut(N).zip(row.chunks_exact(ch)) {
        o.copy_from_slice(&bytes(px[c]));
    }
}

thread_local! {
    static DEFLATE: std::cell::RefCell<libdeflater::Compressor> = std::cell::RefCell::new(
        libdeflater::Compressor::new(libdeflater::CompressionLvl::new(4).expect("level 4 is valid")),
    );
}

/// OpenEXR's ZIP compression of one block: split even and odd bytes, delta
/// predictor, zlib. Blocks that do not shrink are stored raw, as OpenEXR
/// does (readers recognise them by their size).
fn zip_compress(raw: Vec<u8>) -> ::exr::error::Result<Vec<u8>> {
    let n = raw.len();
    let half = n.div_ceil(2);
    let mut tmp = vec![0u8; n];
    {
        let (even, odd) = tmp.split_at_mut(half);
        let pairs = raw.chunks_exact(2);
        if let [last] = pairs.remainder() {
            even[half - 1] = *last;
        }
        for ((p, e), o) in pairs.zip(even.iter_mut()).zip(odd.iter_mut()) {
            *e = p[0];
            *o = p[1];
        }
    }
    // Delta predictor, back to front so each byte still sees its
    // unmodified predecessor: t[i] = t[i] - t[i-1] + 128 (mod 256).
    for i in (1..n).rev() {
        tmp[i] = tmp[i].wrapping_sub(tmp[i - 1]).wrapping_add(128);
    }
    let out = DEFLATE.with(|c| {
        let mut c = c.borrow_mut();
        let mut out = vec![0u8; c.zlib_compress_bound(n)];
        c.zlib_compress(&tmp, &mut out).map(|len| {
            out.truncate(len);
            out
        })
    });
    match out {
        Ok(out) if out.len() < n => Ok(out),
        Ok(_) => Ok(raw),
        Err(e) => Err(::exr::error::Error::Invalid(
            format!("deflate failed: {e:?}").into(),
        )),
    }
}

/// Read the fingerprint attribute of an EXR file written by parvo.
pub fn stored_fingerprint(path: &Path) -> Option<String> {
    let meta = MetaData::read_from_file(path, false).ok()?;
    let header = meta.headers.first()?;
    let key = Text::from(FINGERPRINT_KEY);
    let v = header
        .own_attributes
        .other
        .get(&key)
        .or_else(|| header.shared_attributes.other.get(&key))?;
    match v {
        AttributeValue::Text(t) => Some(t.to_string()),
        _ => None,
    }
}

fn attribute_text(v: &AttributeValue) -> String {
    match v {
        AttributeValue::Text(t) => t.to_string(),
        AttributeValue::F32(x) => x.to_string(),
        AttributeValue::F64(x) => x.to_string(),
        AttributeValue::I32(x) => x.to_string(),
        AttributeValue::TextVector(v) => v
            .iter()
            .map(|t| t.to_string())
            .collect::<Vec<_>>()
            .join(", "),
        other => format!("{other:?}"),
    }
}

/// Load an EXR file: the first part, all its mip levels.
pub fn load(path: &Path, limits: &Limits) -> Result<Loaded> {
    let meta = MetaData::read_from_file(path, false).map_err(decode_err)?;
    let header = meta
        .headers
        .first()
        .ok_or_else(|| decode_err("no image part in the file"))?;
    if header.deep {
        return Err(decode_err("deep data is not a texture"));
    }
    let (w, h) = (header.layer_size.width(), header.layer_size.height());
    let (sizes, tile, rounding, mipmapped) = match header.blocks {
        BlockDescription::ScanLines => (vec![(w, h)], None, Rounding::Down, false),
        BlockDescription::Tiles(t) => {
            let rounding = match t.rounding_mode {
                RoundingMode::Down => Rounding::Down,
                RoundingMode::Up => Rounding::Up,
            };
            let tile = Some((t.tile_size.width() as u32, t.tile_size.height() as u32));
            match t.level_mode {
                LevelMode::MipMap => {
                    let s: Vec<_> = ::exr::meta::mip_map_levels(t.rounding_mode, header.layer_size)
                        .map(|(_, s)| (s.width(), s.height()))
                        .collect();
                    (s, tile, rounding, true)
                }
                // Rip maps: only level 0 (anisotropic levels are not a mip chain).
                _ => (vec![(w, h)], tile, rounding, false),
            }
        }
    };
    let channels = header.channels.list.len() as u64;
    let texels: u64 = sizes.iter().map(|&(a, b)| a as u64 * b as u64).sum();
    // Decoded bytes: the exr crate's planes plus our interleaved copy.
    limits.check(
        w as u64,
        h as u64,
        texels.saturating_mul(channels).saturating_mul(8),
    )?;
    let mut attributes: Vec<(String, String)> = Vec::new();
    for (k, v) in header
        .shared_attributes
        .other
        .iter()
        .chain(header.own_attributes.other.iter())
    {
        attributes.push((k.to_string(), attribute_text(v)));
    }
    let own = &header.own_attributes;
    for (k, v) in [
        ("software", &own.software_name),
        ("comments", &own.comments),
        ("owner", &own.owner),
        ("capDate", &own.capture_date),
        ("name", &own.layer_name),
        ("wrapmodes", &own.wrap_mode_name),
    ] {
        if let Some(t) = v {
            attributes.push((k.to_string(), t.to_string()));
        }
    }
    attributes.push(("compression".into(), header.compression.to_string()));
    attributes.sort();
    let wrap = attributes
        .iter()
        .find(|(k, _)| k == "wrapmodes")
        .and_then(|(_, v)| v.parse().ok());

    let image = ::exr::prelude::read()
        .no_deep_data()
        .all_resolution_levels()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .map_err(decode_err)?;
    let layer = image.layer_data;
    let list = &layer.channel_data.list;
    let all_names: Vec<String> = list.iter().map(|c| c.name.to_string()).collect();
    let short = |n: &str| n.rsplit('.').next().unwrap_or(n).to_string();
    let find = |want: &str| all_names.iter().position(|n| short(n) == want);
    let order: Vec<usize> = match (find("R"), find("G"), find("B"), find("A"), find("Y")) {
        (Some(r), Some(g), Some(b), a, _) => [Some(r), Some(g), Some(b), a]
            .into_iter()
            .flatten()
            .collect(),
        (_, _, _, a, Some(y)) => [Some(y), a].into_iter().flatten().collect(),
        _ if (1..=4).contains(&list.len()) => (0..list.len()).collect(),
        _ => {
            return Err(decode_err(format!(
                "channels {} do not form a texture (expected R,G,B[,A], Y[,A] or 1 to 4 channels)",
                all_names.join(",")
            )));
        }
    };
    let half = order
        .iter()
        .all(|&i| header.channels.list[i].sample_type == SampleType::F16);
    let per_channel: Vec<Vec<&FlatSamples>> = order
        .iter()
        .map(|&i| match &list[i].sample_data {
            ::exr::image::Levels::Singular(s) => vec![s],
            ::exr::image::Levels::Mip { level_data, .. } => level_data.iter().collect(),
            ::exr::image::Levels::Rip { level_data, .. } => {
                level_data.map_data.iter().take(1).collect()
            }
        })
        .collect();
    let nlev = per_channel[0].len();
    if nlev == 0
        || per_channel.iter().any(|c| c.len() != nlev)
        || (mipmapped && nlev != sizes.len())
    {
        return Err(decode_err("inconsistent mip levels between channels"));
    }
    let ch = order.len();
    let ty = if half {
        ChannelType::F16
    } else {
        ChannelType::F32
    };
    // OpenEXR stores colour associated with (premultiplied by) alpha.
    let mut format = Format::new(ch as u8, ty, ColorSpace::Linear);
    if format.has_alpha() {
        format = format.with_alpha(AlphaMode::Premultiplied);
    }
    let mut levels = Vec::with_capacity(nlev);
    for (k, &(lw, lh)) in sizes.iter().enumerate().take(nlev) {
        let n = lw * lh;
        let texels = if half {
            let mut out = vec![f16::ZERO; n * ch];
            for (c, planes) in per_channel.iter().enumerate() {
                let FlatSamples::F16(p) = planes[k] else {
                    return Err(decode_err("channel type changed between levels"));
                };
                if p.len() != n {
                    return Err(decode_err("level has the wrong number of samples"));
                }
                for (o, v) in out.iter_mut().skip(c).step_by(ch).zip(p.iter()) {
                    *o = *v;
                }
            }
            Texels::F16(out)
        } else {
            let mut out = vec![0f32; n * ch];
            for (c, planes) in per_channel.iter().enumerate() {
                let p = planes[k];
                if p.len() != n {
                    return Err(decode_err("level has the wrong number of samples"));
                }
                for (o, v) in out.iter_mut().skip(c).step_by(ch).zip(p.values_as_f32()) {
                    *o = v;
                }
            }
            Texels::F32(out)
        };
        levels.push(Texture::from_texels(lw as u32, lh as u32, format, texels)?);
    }
    let info = SourceInfo {
        format: FileFormat::Exr,
        own_mips: levels.len() > 1,
        rounding,
        wrap,
        tile,
        channel_names: order.iter().map(|&i| all_names[i].clone()).collect(),
        attributes,
    };
    Ok(Loaded { levels, info })
}
