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
    save_as(levels, rounding, path, opts, None)
}

/// [`save`] of an environment map: a lat-long image, or a cube map's six
/// faces stacked top to bottom (+X, −X, +Y, −Y, +Z, −Z) in every level,
/// marked with OpenEXR's `envmap` attribute and maketx's `textureformat`
/// (`LatLong Environment`, `CubeFace Environment`), as `maketx --envlatl`
/// and `--envcube` write them.
pub fn save_environment(
    levels: &[Texture],
    rounding: Rounding,
    path: &Path,
    opts: &SaveOptions,
    env: super::Environment,
) -> Result<()> {
    save_as(levels, rounding, path, opts, Some(env))
}

fn save_as(
    levels: &[Texture],
    rounding: Rounding,
    path: &Path,
    opts: &SaveOptions,
    env: Option<super::Environment>,
) -> Result<()> {
    let first = &levels[0];
    let (w, h) = (first.width(), first.height());
    let want = exr_level_sizes(w, h, rounding);
    let have: Vec<_> = levels.iter().map(|l| (l.width(), l.height())).collect();
    if levels.len() > 1 && have != want {
        return Err(encode_err(format!(
            "a mip-mapped OpenEXR file holds the full chain of {} levels, got {} (do not limit {} for .exr)",
            want.len(),
            levels.len(),
            crate::setting::Setting::Levels,
        )));
    }
    let (mut header, tiles) = plan(w, h, first.format(), levels.len() > 1, rounding, opts)?;
    if let Some(env) = env {
        mark_environment(&mut header, env);
    }
    write_file(path, header, |meta, writer| {
        let blocks: Vec<(usize, BlockIndex)> =
            meta.enumerate_ordered_header_block_indices().collect();
        write_blocks(writer, &blocks, |index| {
            tiles.chunk(&levels[index.level.x()], 0, index, &meta.headers)
        })
    })
}

/// `envmap` and `textureformat` of an environment map of kind `env`.
fn mark_environment(header: &mut Header, env: super::Environment) {
    use ::exr::meta::attribute::EnvironmentMap;
    let (map, name) = match env {
        super::Environment::LatLong => (EnvironmentMap::LatitudeLongitude, "LatLong Environment"),
        super::Environment::Cube => (EnvironmentMap::Cube, "CubeFace Environment"),
    };
    let attrs = &mut header.own_attributes;
    attrs.environment_map = Some(map);
    attrs.other.insert(
        Text::from("textureformat"),
        AttributeValue::Text(Text::from(name)),
    );
}

/// Where level 0 of a streamed EXR write ([`save_streamed`]) comes from:
/// its rows, a group at a time and in order, then the other levels.
pub trait Level0Source {
    /// Level-0 rows per call of [`Level0Source::rows`] (the last group
    /// may be shorter); a multiple of the tile height.
    fn group_rows(&self) -> usize;
    /// Level-0 rows `y0 .. y0 + n` as little-endian texels of the
    /// output format, `n` = `dst.len()` / (width · texel bytes).
    fn rows(&mut self, y0: usize, dst: &mut [u8]) -> Result<()>;
    /// Levels 1 .. of the chain, once every row of level 0 was asked for.
    fn rest(&mut self) -> Result<Vec<Texture>>;
}

/// [`save`] of a full mip chain whose level 0 is never held whole: its
/// tiles are compressed and written a group of rows at a time as `source`
/// makes them, then the other levels are asked for and written. The
/// bytes are those [`save`] writes for the same chain.
pub fn save_streamed(
    width: u32,
    height: u32,
    format: Format,
    rounding: Rounding,
    path: &Path,
    opts: &SaveOptions,
    source: &mut dyn Level0Source,
) -> Result<()> {
    let (header, tiles) = plan(width, height, format, true, rounding, opts)?;
    let group = source.group_rows();
    if group == 0 || !group.is_multiple_of(tiles.tile.1) {
        return Err(encode_err(format!(
            "level 0 comes in groups of {group} rows, not a multiple of the tile height {}",
            tiles.tile.1
        )));
    }
    let mut buffer = Texels::zeroed(format.channel_type, 0);
    let mut failure = None;
    let written = write_file(path, header, |meta, writer| {
        let blocks: Vec<(usize, BlockIndex)> =
            meta.enumerate_ordered_header_block_indices().collect();
        let level0 = blocks
            .iter()
            .take_while(|(_, i)| i.level.x() == 0 && i.level.y() == 0)
            .count();
        let mut at = 0;
        for y0 in (0..height as usize).step_by(group) {
            let n = group.min(height as usize - y0);
            let mut texels = std::mem::replace(&mut buffer, Texels::zeroed(format.channel_type, 0));
            texels.resize(n * width as usize * format.channels as usize);
            if let Err(e) = source.rows(y0, texels.bytes_mut()) {
                failure = Some(e);
                return Err(::exr::error::Error::Aborted);
            }
            let lvl = Texture::from_texels(width, n as u32, format, texels)
                .map_err(|e| ::exr::error::Error::Invalid(e.to_string().into()))?;
            let end = at
                + blocks[at..level0]
                    .iter()
                    .take_while(|(_, i)| i.pixel_position.y() < y0 + n)
                    .count();
            write_blocks(writer, &blocks[at..end], |index| {
                tiles.chunk(&lvl, y0, index, &meta.headers)
            })?;
            at = end;
            buffer = lvl.into_texels();
        }
        drop(buffer);
        debug_assert_eq!(at, level0);
        let rest = match source.rest() {
            Ok(r) => r,
            Err(e) => {
                failure = Some(e);
                return Err(::exr::error::Error::Aborted);
            }
        };
        let sizes = exr_level_sizes(width, height, rounding);
        if rest.len() + 1 != sizes.len()
            || rest
                .iter()
                .zip(&sizes[1..])
                .any(|(l, &s)| (l.width(), l.height()) != s || l.format() != format)
        {
            return Err(::exr::error::Error::Invalid(
                "the levels after level 0 do not make the chain".into(),
            ));
        }
        write_blocks(writer, &blocks[level0..], |index| {
            tiles.chunk(&rest[index.level.x() - 1], 0, index, &meta.headers)
        })
    });
    match failure {
        Some(e) => Err(e),
        None => written,
    }
}

/// How the tiles of a file [`plan`] made are laid out and compressed.
struct Tiles {
    /// Channel indices in file order (sorted by name).
    order: Vec<usize>,
    zip: bool,
    tile: (usize, usize),
}

/// The header of a tiled EXR of `w`×`h` texels in `fmt` (mip-mapped or
/// one level), after checking what the `exr` crate would panic on.
fn plan(
    w: u32,
    h: u32,
    fmt: Format,
    mip: bool,
    rounding: Rounding,
    opts: &SaveOptions,
) -> Result<(Header, Tiles)> {
    let (tw, th) = opts.tile;
    if tw == 0 || th == 0 {
        return Err(encode_err("tile size must be at least 1x1"));
    }
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
    let names = match &opts.channel_names {
        Some(n) => {
            let mut sorted = n.clone();
            sorted.sort();
            sorted.dedup();
            if n.len() != fmt.channels as usize
                || sorted.len() != n.len()
                || n.iter()
                    .any(|c| c.is_empty() || Text::new_or_none(c.as_str()).is_none())
            {
                return Err(encode_err(format!(
                    "channel names {n:?} do not name {} distinct channels",
                    fmt.channels
                )));
            }
            n.clone()
        }
        None => super::layout_names(&fmt),
    };
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
    let level_mode = if mip {
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
    Ok((header, Tiles { order, zip, tile }))
}

impl Tiles {
    /// The compressed chunk of the tile `index`, from `lvl`, which holds
    /// the level's rows from `y_off` on.
    fn chunk(
        &self,
        lvl: &Texture,
        y_off: usize,
        index: &BlockIndex,
        headers: &[Header],
    ) -> ::exr::error::Result<Chunk> {
        let tile = self.tile;
        if self.zip {
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
                    compressed_pixels_le: zip_tile(lvl, y_off, index, &self.order)?,
                }),
            })
        } else {
            let mut data = Vec::new();
            tile_bytes(lvl, y_off, index, &self.order, &mut data);
            UncompressedBlock {
                index: *index,
                data,
            }
            .compress_to_chunk(headers)
        }
    }
}

/// Write a single-part EXR with `header` to `path` atomically, the chunks
/// by `body`, and the header's attributes sorted.
fn write_file(
    path: &Path,
    header: Header,
    body: impl FnOnce(
        &MetaData,
        &mut ::exr::block::writer::ChunkWriter<&mut std::io::BufWriter<&std::fs::File>>,
    ) -> ::exr::error::UnitResult,
) -> Result<()> {
    atomic::write(path, |out| {
        ::exr::block::write(
            &mut *out,
            std::iter::once(header).collect(),
            true,
            |meta, writer| body(&meta, writer),
        )
        .map_err(encode_err)?;
        // The exr crate writes custom attributes in hash-map order, which
        // changes from run to run; sort them in place so that the same
        // input and options give the same bytes.
        std::io::Write::flush(out).map_err(encode_err)?;
        sort_header_attributes(out.get_ref()).map_err(encode_err)
    })
}

/// Compress `blocks` on all threads and write them in order, in bounded
/// batches: batch k is written while batch k + 1 is being compressed, and
/// never more than two batches of compressed tiles are in memory.
fn write_blocks(
    writer: &mut (impl ChunksWriter + Send),
    blocks: &[(usize, BlockIndex)],
    chunk: impl Fn(&BlockIndex) -> ::exr::error::Result<Chunk> + Sync,
) -> ::exr::error::UnitResult {
    let compress = |batch: &[(usize, BlockIndex)]| -> Vec<::exr::error::Result<Chunk>> {
        batch.par_iter().map(|(_, index)| chunk(index)).collect()
    };
    let mut batches = blocks.chunks(512);
    let mut pending = batches.next().map(|b| (b, compress(b)));
    while let Some((batch, chunks)) = pending {
        let next = batches.next();
        let (written, compressed) = rayon::join(
            || -> ::exr::error::UnitResult {
                for ((index_in_header, _), chunk) in batch.iter().zip(chunks) {
                    writer.write_chunk(*index_in_header, chunk?)?;
                }
                Ok(())
            },
            || next.map(|b| (b, compress(b))),
        );
        written?;
        pending = compressed;
    }
    Ok(())
}

/// Rewrite the attributes of a single-part EXR header in name order, in
/// place: the same attributes in another order take the same bytes, so
/// the offset table and the pixels after them stay where they are.
fn sort_header_attributes(mut file: &std::fs::File) -> std::io::Result<()> {
    use std::io::{Read, Seek, SeekFrom, Write};
    let bad = |m: &str| std::io::Error::new(std::io::ErrorKind::InvalidData, m.to_string());
    file.seek(SeekFrom::Start(0))?;
    // Magic and version (8 bytes), then the attributes; headers of files
    // parvo writes are small, a few KiB cover them.
    let mut head = Vec::new();
    file.take(1 << 20).read_to_end(&mut head)?;
    let mut at = 8usize;
    let mut attrs: Vec<(Vec<u8>, std::ops::Range<usize>)> = Vec::new();
    let cstr = |b: &[u8], from: usize| -> std::io::Result<usize> {
        b[from..]
            .iter()
            .position(|&c| c == 0)
            .map(|p| from + p)
            .ok_or_else(|| bad("EXR header: unterminated name"))
    };
    loop {
        if at >= head.len() {
            return Err(bad("EXR header: no end"));
        }
        if head[at] == 0 {
            break;
        }
        let name_end = cstr(&head, at)?;
        let type_end = cstr(&head, name_end + 1)?;
        let size_at = type_end + 1;
        let size = head
            .get(size_at..)
            .and_then(|b| b.first_chunk::<4>())
            .map(|b| i32::from_le_bytes(*b))
            .ok_or_else(|| bad("EXR header: truncated attribute"))?;
        let end =
            size_at + 4 + usize::try_from(size).map_err(|_| bad("EXR header: negative size"))?;
        if end > head.len() {
            return Err(bad("EXR header: attribute past the end"));
        }
        attrs.push((head[at..name_end].to_vec(), at..end));
        at = end;
    }
    let mut sorted = attrs.clone();
    sorted.sort_by(|a, b| a.0.cmp(&b.0));
    let bytes: Vec<u8> = sorted
        .iter()
        .flat_map(|(_, r)| head[r.clone()].iter().copied())
        .collect();
    debug_assert_eq!(bytes.len(), at - 8);
    file.seek(SeekFrom::Start(8))?;
    file.write_all(&bytes)?;
    file.seek(SeekFrom::End(0))?;
    Ok(())
}

/// The uncompressed bytes of one tile: for each line, for each channel in
/// file order, the samples of that line (little-endian, which is native on
/// every platform Rust's `half`/`f32` byte conversions are used on here),
/// into `raw` (cleared first); `lvl` holds the level's rows from `y_off`
/// on.
fn tile_bytes(lvl: &Texture, y_off: usize, index: &BlockIndex, order: &[usize], raw: &mut Vec<u8>) {
    let lw = lvl.width() as usize;
    let ch = lvl.channels();
    let (x0, y0) = (index.pixel_position.x(), index.pixel_position.y() - y_off);
    let (bw, bh) = (index.pixel_size.x(), index.pixel_size.y());
    raw.clear();
    raw.reserve(bw * bh * ch * lvl.channel_type().bytes());
    for y in y0..y0 + bh {
        let start = (y * lw + x0) * ch;
        let end = start + bw * ch;
        for &c in order {
            match lvl.texels() {
                Texels::F16(v) => gather(&v[start..end], ch, c, raw, |x: f16| x.to_le_bytes()),
                Texels::F32(v) => gather(&v[start..end], ch, c, raw, |x: f32| x.to_le_bytes()),
                _ => unreachable!("save checks for float texels"),
            }
        }
    }
}

/// Append channel `c` of the interleaved texels `row` as little-endian
/// bytes (`to_le_bytes`, inlined so the loop vectorises).
fn gather<T: Copy, const N: usize>(
    row: &[T],
    ch: usize,
    c: usize,
    out: &mut Vec<u8>,
    bytes: impl Fn(T) -> [u8; N],
) {
    let at = out.len();
    out.resize(at + row.len() / ch * N, 0);
    for (o, px) in out[at..].chunks_exact_mut(N).zip(row.chunks_exact(ch)) {
        o.copy_from_slice(&bytes(px[c]));
    }
}

/// The deflate level of ZIP blocks, checked while compiling (a constant).
const ZIP_LEVEL: libdeflater::CompressionLvl = match libdeflater::CompressionLvl::new(4) {
    Ok(level) => level,
    Err(_) => panic!("4 is a libdeflate level"),
};

thread_local! {
    static DEFLATE: std::cell::RefCell<libdeflater::Compressor> =
        std::cell::RefCell::new(libdeflater::Compressor::new(ZIP_LEVEL));
}

/// OpenEXR's ZIP compression of one tile (see [`tile_bytes`]): split even
/// and odd bytes, delta predictor, zlib. Blocks that do not shrink are
/// stored raw, as OpenEXR does (readers recognise them by their size).
/// Every buffer but the result is reused per thread: fresh ones per tile
/// cost page faults whenever the allocator returns memory to the OS.
fn zip_tile(
    lvl: &Texture,
    y_off: usize,
    index: &BlockIndex,
    order: &[usize],
) -> ::exr::error::Result<Vec<u8>> {
    SCRATCH.with(|scratch| {
        let [raw, split, delta, out] = &mut *scratch.borrow_mut();
        tile_bytes(lvl, y_off, index, order, raw);
        let n = raw.len();
        split.resize(n, 0);
        delta.resize(n, 0);
        zip_compress_with(raw, &mut split[..n], &mut delta[..n], out)
    })
}

thread_local! {
    /// A tile's bytes, their byte-split copy, its delta coding and the
    /// compressed bytes, reused per thread.
    static SCRATCH: std::cell::RefCell<[Vec<u8>; 4]> =
        const { std::cell::RefCell::new([Vec::new(), Vec::new(), Vec::new(), Vec::new()]) };
}

/// The ZIP block of `raw`, with `split` and `delta` (`raw.len()` bytes
/// each) and `out` as scratch buffers.
fn zip_compress_with(
    raw: &[u8],
    split: &mut [u8],
    delta: &mut [u8],
    out: &mut Vec<u8>,
) -> ::exr::error::Result<Vec<u8>> {
    let n = raw.len();
    let half = n.div_ceil(2);
    {
        let (even, odd) = split.split_at_mut(half);
        let (pairs, last) = raw.as_chunks::<2>();
        if let [last] = last {
            even[half - 1] = *last;
        }
        for ((&[a, b], e), o) in pairs.iter().zip(even.iter_mut()).zip(odd.iter_mut()) {
            *e = a;
            *o = b;
        }
    }
    // Delta predictor: d[i] = s[i] - s[i-1] + 128 (mod 256), d[0] = s[0]
    // (into a second buffer, so the loop vectorises).
    if let (Some(d0), Some(&s0)) = (delta.first_mut(), split.first()) {
        *d0 = s0;
    }
    for (d, w) in delta[1..].iter_mut().zip(split.windows(2)) {
        *d = w[1].wrapping_sub(w[0]).wrapping_add(128);
    }
    let tmp = &*delta;
    let len = DEFLATE.with(|c| {
        let mut c = c.borrow_mut();
        out.resize(c.zlib_compress_bound(n), 0);
        c.zlib_compress(tmp, out)
    });
    match len {
        Ok(len) if len < n => Ok(out[..len].to_vec()),
        Ok(_) => Ok(raw.to_vec()),
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

/// The kind of environment an OpenEXR file's first header declares
/// (`envmap`, or maketx's `textureformat`), from its headers alone:
/// [`crate::env::Kind::Cube`] for a cube-face strip, `LatLong`, else
/// `Plain` (also for a file whose headers do not read).
pub(crate) fn peek_kind(path: &Path) -> crate::env::Kind {
    use crate::env::Kind;
    use ::exr::meta::attribute::EnvironmentMap;
    let read = || {
        let meta = MetaData::read_from_file(path, false).ok()?;
        let h = meta.headers.first()?;
        let format = match h.own_attributes.other.get(&Text::from("textureformat")) {
            Some(AttributeValue::Text(t)) => t.to_string(),
            _ => String::new(),
        };
        Some(match (h.own_attributes.environment_map, format.as_str()) {
            (Some(EnvironmentMap::Cube), _) | (None, "CubeFace Environment") => Kind::Cube,
            (Some(EnvironmentMap::LatitudeLongitude), _) | (None, "LatLong Environment") => {
                Kind::LatLong
            }
            _ => Kind::Plain,
        })
    };
    std::panic::catch_unwind(read)
        .ok()
        .flatten()
        .unwrap_or(Kind::Plain)
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

/// OpenImageIO's order of channel suffixes within a layer (its
/// `ChanNameHolder::compute_special_index`); a layer holding `X` and `Y` or
/// `Z` uses the second list, so positions and normals keep X, Y, Z order.
const SPECIAL: [&str; 20] = [
    "R", "Red", "G", "Green", "B", "Blue", "Y", "real", "imag", "A", "Alpha", "AR", "RA", "AG",
    "GA", "AB", "BA", "Z", "Depth", "Zback",
];
const SPECIAL_XYZ: [&str; 21] = [
    "R", "Red", "G", "Green", "B", "Blue", "X", "Y", "Z", "real", "imag", "A", "Alpha", "AR", "RA",
    "AG", "GA", "AB", "BA", "Depth", "Zback",
];

/// `diffuse.R` → (`diffuse`, `R`); `R` → (``, `R`).
fn split_name(n: &str) -> (&str, &str) {
    match n.rfind('.') {
        Some(i) => (&n[..i], &n[i + 1..]),
        None => ("", n),
    }
}

fn is_alpha_name(n: &str) -> bool {
    let s = split_name(n).1;
    s.eq_ignore_ascii_case("A") || s.eq_ignore_ascii_case("Alpha")
}

/// Channel indices in the order OpenImageIO presents them: by layer, then
/// by the special-name order, then by name.
fn oiio_order(names: &[String]) -> Vec<usize> {
    let has = |layer: &str, suffix: &str| {
        names.iter().any(|n| {
            let (l, s) = split_name(n);
            l == layer && s.eq_ignore_ascii_case(suffix)
        })
    };
    let key = |i: usize| {
        let (layer, suffix) = split_name(&names[i]);
        let xyz = has(layer, "X") && (has(layer, "Y") || has(layer, "Z"));
        let list: &[&str] = if xyz { &SPECIAL_XYZ } else { &SPECIAL };
        let special = list
            .iter()
            .position(|s| s.eq_ignore_ascii_case(suffix))
            .unwrap_or(10_000);
        (layer.to_string(), special, suffix.to_string())
    };
    let mut order: Vec<usize> = (0..names.len()).collect();
    order.sort_by_key(|&i| key(i));
    order
}

/// Which channels to load, and whether the last is alpha: `requested`
/// names (full names, in the order given), or by OpenImageIO's
/// conventions: every channel when there are at most four, else the first
/// layer's `R,G,B[,A]` or `Y[,A]`. A channel is alpha only when it is
/// named `A` (or `Alpha`) and is the last of two or four. Returns the
/// indices, the alpha flag and a note when the mapping is not the obvious
/// one.
fn choose_channels(
    names: &[String],
    requested: Option<&[String]>,
) -> Result<(Vec<usize>, bool, Option<String>)> {
    let list = names.join(",");
    let order: Vec<usize> = match requested {
        Some(req) => {
            if req.is_empty() || req.len() > 4 {
                return Err(Error::InvalidOption(format!(
                    "{} takes 1 to 4 names, got {}",
                    Setting::Channels,
                    req.len()
                )));
            }
            let mut v = Vec::new();
            for r in req {
                let i = names.iter().position(|n| n == r).ok_or_else(|| {
                    Error::InvalidOption(format!(
                        "{}: no channel `{r}` (the file has {list})",
                        Setting::Channels
                    ))
                })?;
                if v.contains(&i) {
                    return Err(Error::InvalidOption(format!(
                        "{}: `{r}` given twice",
                        Setting::Channels
                    )));
                }
                v.push(i);
            }
            v
        }
        None => {
            let sorted = oiio_order(names);
            if sorted.len() <= 4 {
                sorted
            } else {
                let mut layers: Vec<&str> =
                    sorted.iter().map(|&i| split_name(&names[i]).0).collect();
                layers.dedup();
                let find = |layer: &str, suffix: &str| {
                    sorted.iter().copied().find(|&i| {
                        let (l, s) = split_name(&names[i]);
                        l == layer && s == suffix
                    })
                };
                let pick = layers.iter().find_map(|&l| {
                    let a = find(l, "A");
                    match (find(l, "R"), find(l, "G"), find(l, "B"), find(l, "Y")) {
                        (Some(r), Some(g), Some(b), _) => Some(
                            [Some(r), Some(g), Some(b), a]
                                .into_iter()
                                .flatten()
                                .collect(),
                        ),
                        (_, _, _, Some(y)) => Some([Some(y), a].into_iter().flatten().collect()),
                        _ => None,
                    }
                });
                pick.ok_or_else(|| {
                    decode_err(format!(
                        "{} channels ({list}) and no layer with R,G,B or Y: parvo reads 1 to 4 channels, pick them with {}",
                        names.len(),
                        Setting::Channels
                    ))
                })?
            }
        }
    };
    let n = order.len();
    let alpha = matches!(n, 2 | 4) && is_alpha_name(&names[order[n - 1]]);
    let chosen: Vec<&str> = order.iter().map(|&i| names[i].as_str()).collect();
    let suffixes: Vec<&str> = chosen.iter().map(|n| split_name(n).1).collect();
    let obvious = matches!(
        suffixes.as_slice(),
        ["R", "G", "B"] | ["R", "G", "B", "A"] | ["Y"] | ["Y", "A"]
    );
    let mut note = None;
    if !obvious || chosen.len() < names.len() {
        let layout = match (n, alpha) {
            (1, _) => "one channel".to_string(),
            (2, true) => "grey + alpha".to_string(),
            (3, _) => "R,G,B".to_string(),
            (4, true) => "R,G,B + alpha".to_string(),
            (k, false) => format!("{k} data channels, no alpha"),
            _ => unreachable!("1 to 4 channels"),
        };
        let mut s = format!("channels {} read as {layout}", chosen.join(","));
        if chosen.len() < names.len() {
            s.push_str(&format!(
                " (the file has {list}; {} picks others)",
                Setting::Channels
            ));
        }
        if !alpha && chosen.iter().any(|c| is_alpha_name(c)) {
            s.push_str("; the A channel is not last of 2 or 4, so it is data");
        }
        note = Some(s);
    }
    Ok((order, alpha, note))
}

/// The pixels of one part as the `exr` crate reads them: every resolution
/// level of every channel.
type Part = ::exr::image::Layer<::exr::image::AnyChannels<::exr::image::Levels<FlatSamples>>>;

/// Load an EXR file: the first part (or `options.subimage`), all its mip
/// levels, the channels chosen as the module docs say; a data window that is
/// not the display window is placed in the display window, black outside
/// (as maketx pads it), what lies outside is cropped, and a note says so.
pub fn load(path: &Path, limits: &Limits, options: &super::LoadOptions) -> Result<Loaded> {
    let meta = MetaData::read_from_file(path, false).map_err(decode_err)?;
    let parts = meta.headers.len();
    let part = options.subimage;
    let header = meta.headers.get(part).ok_or_else(|| {
        Error::InvalidOption(format!(
            "{} {part}: the file has {parts} part{}",
            Setting::Subimage,
            if parts == 1 { "" } else { "s" }
        ))
    })?;
    if header.deep {
        return Err(decode_err("deep data is not a texture"));
    }
    let mut notes = Vec::new();
    if parts > 1 {
        notes.push(format!(
            "multi-part file: using part {part} ({}) of {parts}; {} N picks another",
            header
                .own_attributes
                .layer_name
                .as_ref()
                .map_or_else(|| "unnamed".to_string(), |t| format!("`{t}`")),
            Setting::Subimage
        ));
    }
    let Declared {
        sizes,
        tile,
        rounding,
        mipmapped,
    } = declared_levels(header);
    let all_names: Vec<String> = header
        .channels
        .list
        .iter()
        .map(|c| c.name.to_string())
        .collect();
    let (order, alpha, note) = choose_channels(&all_names, options.channels.as_deref())?;
    notes.extend(note);
    check_decoded_size(&meta, part, &sizes, order.len(), limits)?;
    let mut attributes = header_attributes(header);
    let environment = environment_of(header, &attributes, options, &mut notes)?;
    let data_window = header.data_window();
    let display = header.shared_attributes.display_window;
    if data_window != display {
        check_display_window(data_window, display, order.len(), limits, &mut attributes)?;
    }
    attributes.sort();
    let wrap = super::recorded_wrap(
        attributes
            .iter()
            .find(|(k, _)| k == "wrapmodes")
            .map(|(_, v)| v.as_str()),
        &mut notes,
    );

    let layer = read_part(path, part)?;
    let list = &layer.channel_data.list;
    // The crate's channel list is sorted by name, as the header's is.
    let by_name = |n: &str| list.iter().position(|c| c.name.to_string() == n);
    let order: Vec<usize> = order
        .iter()
        .map(|&i| by_name(&all_names[i]).ok_or_else(|| decode_err("channel list changed")))
        .collect::<Result<_>>()?;
    let mut levels = read_levels(list, &order, &sizes, mipmapped, alpha)?;
    if data_window != display {
        let (placed, note) = place_in_display_window(&levels[0], data_window, display)?;
        if levels.len() > 1 {
            notes.push(format!(
                "{note}; the file's own {} mip levels are dropped (they cover the data window) and rebuilt",
                levels.len()
            ));
        } else {
            notes.push(note);
        }
        levels = vec![placed];
    }
    let info = SourceInfo {
        format: FileFormat::Exr,
        own_mips: levels.len() > 1,
        rounding,
        wrap,
        tile,
        channel_names: order.iter().map(|&i| list[i].name.to_string()).collect(),
        attributes,
        notes,
        blocks: None,
        // OpenEXR stores linear values by definition.
        color_stated: true,
        environment,
        // A cube-face environment stays one strip image here
        // (`environment` says what it is).
        kind: crate::env::Kind::Plain,
    };
    Ok(Loaded::plain(levels, info))
}

/// The levels a header declares.
struct Declared {
    /// Level sizes: all of a mip map; level 0 of scan lines and of a rip
    /// map, whose anisotropic levels are not a mip chain.
    sizes: Vec<(usize, usize)>,
    /// The tile size of a tiled file.
    tile: Option<(u32, u32)>,
    rounding: Rounding,
    /// A mip map: every level in `sizes` must be in the file.
    mipmapped: bool,
}

/// The levels `header` declares.
fn declared_levels(header: &Header) -> Declared {
    let (w, h) = (header.layer_size.width(), header.layer_size.height());
    let BlockDescription::Tiles(t) = header.blocks else {
        return Declared {
            sizes: vec![(w, h)],
            tile: None,
            rounding: Rounding::Down,
            mipmapped: false,
        };
    };
    let rounding = match t.rounding_mode {
        RoundingMode::Down => Rounding::Down,
        RoundingMode::Up => Rounding::Up,
    };
    let tile = Some((t.tile_size.width() as u32, t.tile_size.height() as u32));
    let mipmapped = t.level_mode == LevelMode::MipMap;
    let sizes = if mipmapped {
        ::exr::meta::mip_map_levels(t.rounding_mode, header.layer_size)
            .map(|(_, s)| (s.width(), s.height()))
            .collect()
    } else {
        // Rip maps: only level 0 (anisotropic levels are not a mip chain).
        vec![(w, h)]
    };
    Declared {
        sizes,
        tile,
        rounding,
        mipmapped,
    }
}

/// Hold what decoding part `part` allocates to `limits`, from the headers
/// alone: the `exr` crate's planes of the declared levels (of every part
/// when another than the first is read) plus our interleaved copy of
/// `kept` channels.
fn check_decoded_size(
    meta: &MetaData,
    part: usize,
    sizes: &[(usize, usize)],
    kept: usize,
    limits: &Limits,
) -> Result<()> {
    let header = &meta.headers[part];
    let (w, h) = (header.layer_size.width(), header.layer_size.height());
    let channels = header.channels.list.len() as u64;
    let texels: u64 = sizes.iter().map(|&(a, b)| a as u64 * b as u64).sum();
    let planes: u64 = if part == 0 {
        texels.saturating_mul(channels).saturating_mul(4)
    } else {
        meta.headers
            .iter()
            .map(|h| {
                (h.layer_size.area() as u64)
                    .saturating_mul(h.channels.list.len() as u64)
                    .saturating_mul(8)
            })
            .sum()
    };
    limits.check(
        w as u64,
        h as u64,
        planes.saturating_add(texels.saturating_mul(kept as u64 * 4)),
    )
}

/// The header's attributes as text for `parvo info`: the other (custom)
/// ones, the standard ones that are set, and the compression; unsorted.
fn header_attributes(header: &Header) -> Vec<(String, String)> {
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
    attributes
}

/// An environment map, by OpenEXR's `envmap` attribute or the
/// `textureformat` maketx writes: refused, or described in `notes`, as
/// [`super::environment_map`] decides.
fn environment_of(
    header: &Header,
    attributes: &[(String, String)],
    options: &super::LoadOptions,
    notes: &mut Vec<String>,
) -> Result<Option<super::Environment>> {
    use ::exr::meta::attribute::EnvironmentMap;
    let own = &header.own_attributes;
    let (w, h) = (header.layer_size.width(), header.layer_size.height());
    let texture_format = attributes
        .iter()
        .find(|(k, _)| k == "textureformat")
        .map(|(_, v)| v.clone());
    let environment = match (own.environment_map, texture_format.as_deref()) {
        (Some(EnvironmentMap::Cube), _) | (None, Some("CubeFace Environment")) => {
            Some(super::Environment::Cube)
        }
        (Some(EnvironmentMap::LatitudeLongitude), _) | (None, Some("LatLong Environment")) => {
            Some(super::Environment::LatLong)
        }
        _ => None,
    };
    if let Some(kind) = environment {
        let mut detail = Vec::new();
        if let Some(t) = &texture_format {
            detail.push(format!("textureformat \"{t}\""));
        }
        if let Some(e) = own.environment_map {
            detail.push(format!(
                "envmap {}",
                match e {
                    EnvironmentMap::LatitudeLongitude => "latlong",
                    EnvironmentMap::Cube => "cube",
                }
            ));
        }
        detail.push(if kind == super::Environment::Cube && h == 6 * w {
            format!("six {w}x{w} faces stacked top to bottom")
        } else {
            format!("{w}x{h}")
        });
        super::environment_map("OpenEXR", kind, &detail.join(", "), options, notes)?;
    }
    Ok(environment)
}

/// A data window that is not the display window: level 0 is placed in the
/// display window, so its size is what is allocated and is held to the
/// limits too (an 8x8 data window in an 83886074x8 display window asked
/// for 18 GB: tests/files/regression/exr_display_window_unbounded.rs); both
/// windows go into `attributes`.
fn check_display_window(
    data_window: ::exr::meta::attribute::IntegerBounds,
    display: ::exr::meta::attribute::IntegerBounds,
    kept: usize,
    limits: &Limits,
    attributes: &mut Vec<(String, String)>,
) -> Result<()> {
    let (dw, dh) = (display.size.width() as u64, display.size.height() as u64);
    limits.check(
        dw,
        dh,
        dw.saturating_mul(dh).saturating_mul(kept as u64 * 4),
    )?;
    for (name, window) in [("dataWindow", data_window), ("displayWindow", display)] {
        attributes.push((
            name.into(),
            format!(
                "({}, {}) {}x{}",
                window.position.x(),
                window.position.y(),
                window.size.width(),
                window.size.height()
            ),
        ));
    }
    Ok(())
}

/// Read the pixels of part `part`, every level of every channel.
fn read_part(path: &Path, part: usize) -> Result<Part> {
    let reader = ::exr::prelude::read()
        .no_deep_data()
        .all_resolution_levels()
        .all_channels();
    if part == 0 {
        return Ok(reader
            .first_valid_layer()
            .all_attributes()
            .from_file(path)
            .map_err(decode_err)?
            .layer_data);
    }
    let mut layers = reader
        .all_layers()
        .all_attributes()
        .from_file(path)
        .map_err(decode_err)?
        .layer_data;
    if part >= layers.len() {
        return Err(decode_err(format!("part {part} has no readable pixels")));
    }
    Ok(layers.swap_remove(part))
}

/// The levels of channels `order` of `list` (indices into it),
/// interleaved: f16 when every chosen channel is half, else f32; linear,
/// with premultiplied alpha when `alpha`. `sizes` are the declared level
/// sizes, all of which a mip map (`mipmapped`) must hold.
fn read_levels(
    list: &[::exr::image::AnyChannel<::exr::image::Levels<FlatSamples>>],
    order: &[usize],
    sizes: &[(usize, usize)],
    mipmapped: bool,
    alpha: bool,
) -> Result<Vec<Texture>> {
    let half = order.iter().all(|&i| {
        matches!(
            list[i].sample_data.levels_as_slice()[0],
            FlatSamples::F16(_)
        )
    });
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
    let ty = if half {
        ChannelType::F16
    } else {
        ChannelType::F32
    };
    // OpenEXR stores colour associated with (premultiplied by) alpha.
    let mut format = Format::new(order.len() as u8, ty, ColorSpace::Linear);
    format = format.with_alpha(if alpha {
        AlphaMode::Premultiplied
    } else {
        AlphaMode::None
    });
    let mut levels = Vec::with_capacity(nlev);
    for (k, &(lw, lh)) in sizes.iter().enumerate().take(nlev) {
        let planes: Vec<&FlatSamples> = per_channel.iter().map(|c| c[k]).collect();
        let texels = interleave(&planes, lw * lh, half)?;
        levels.push(Texture::from_texels(lw as u32, lh as u32, format, texels)?);
    }
    Ok(levels)
}

/// One level's channel planes of `n` samples each, interleaved (f16 when
/// `half`, else every plane converted to f32).
fn interleave(planes: &[&FlatSamples], n: usize, half: bool) -> Result<Texels> {
    let ch = planes.len();
    if half {
        let mut out = vec![f16::ZERO; n * ch];
        for (c, plane) in planes.iter().enumerate() {
            let FlatSamples::F16(p) = plane else {
                return Err(decode_err("channel type changed between levels"));
            };
            if p.len() != n {
                return Err(decode_err("level has the wrong number of samples"));
            }
            for (o, v) in out.iter_mut().skip(c).step_by(ch).zip(p.iter()) {
                *o = *v;
            }
        }
        Ok(Texels::F16(out))
    } else {
        let mut out = vec![0f32; n * ch];
        for (c, p) in planes.iter().enumerate() {
            if p.len() != n {
                return Err(decode_err("level has the wrong number of samples"));
            }
            for (o, v) in out.iter_mut().skip(c).step_by(ch).zip(p.values_as_f32()) {
                *o = v;
            }
        }
        Ok(Texels::F32(out))
    }
}

/// Level 0 placed in the display window: texels of the data window inside
/// it copied at their offset, zero (transparent black) elsewhere.
fn place_in_display_window(
    t: &Texture,
    data: ::exr::meta::attribute::IntegerBounds,
    display: ::exr::meta::attribute::IntegerBounds,
) -> Result<(Texture, String)> {
    let (dw, dh) = (display.size.width() as u32, display.size.height() as u32);
    let mut out = Texture::new(dw, dh, t.format())?;
    let ch = t.channels();
    let (ox, oy) = (
        data.position.x() as i64 - display.position.x() as i64,
        data.position.y() as i64 - display.position.y() as i64,
    );
    let (sw, sh) = (t.width() as i64, t.height() as i64);
    let x0 = ox.max(0);
    let x1 = (ox + sw).min(dw as i64);
    let y0 = oy.max(0);
    let y1 = (oy + sh).min(dh as i64);
    let inside = (x1 - x0).max(0) * (y1 - y0).max(0);
    fn copy<T: Copy>(src: &[T], dst: &mut [T], ch: usize, sw: i64, dw: i64, r: [i64; 6]) {
        let [ox, oy, x0, x1, y0, y1] = r;
        if x1 <= x0 {
            return;
        }
        for y in y0..y1 {
            let s = (((y - oy) * sw + (x0 - ox)) as usize) * ch;
            let d = ((y * dw + x0) as usize) * ch;
            let n = ((x1 - x0) as usize) * ch;
            dst[d..d + n].copy_from_slice(&src[s..s + n]);
        }
    }
    let r = [ox, oy, x0, x1, y0, y1];
    match (t.texels(), out.texels_mut()) {
        (Texels::F16(s), Texels::F16(d)) => copy(s, d, ch, sw, dw as i64, r),
        (Texels::F32(s), Texels::F32(d)) => copy(s, d, ch, sw, dw as i64, r),
        _ => return Err(decode_err("EXR levels are f16 or f32")),
    }
    let cropped = sw * sh - inside;
    let mut note = format!(
        "data window ({}, {}) {}x{} placed in the display window ({}, {}) {dw}x{dh}, black outside (as maketx pads it)",
        data.position.x(),
        data.position.y(),
        sw,
        sh,
        display.position.x(),
        display.position.y()
    );
    if cropped > 0 {
        note.push_str(&format!(
            "; {cropped} texels outside the display window are cropped"
        ));
    }
    Ok((out, note))
}

/// OpenEXR in the container table: reads scanline, tiled and mip-mapped
/// files (a chosen part, chosen channels); writes tiled, mip-mapped
/// files of f16 or f32, colour premultiplied by alpha as the format
/// defines it, the whole chain, sizes rounded down or up, the
/// fingerprint as an attribute, level 0 streamed band by band.
pub struct OpenExr;

impl super::Container for OpenExr {
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
    fn save(
        &self,
        levels: &[Texture],
        rounding: Rounding,
        path: &Path,
        options: &SaveOptions,
    ) -> Result<()> {
        save(levels, rounding, path, options)
    }
    fn stored_fingerprint(&self, path: &Path) -> Option<String> {
        stored_fingerprint(path)
    }
    fn holds(&self, kind: crate::env::Kind) -> bool {
        use crate::env::Kind;
        matches!(kind, Kind::Plain | Kind::LatLong | Kind::Cube)
    }
    fn save_images(
        &self,
        images: &[&[Texture]],
        kind: crate::env::Kind,
        rounding: Rounding,
        path: &Path,
        options: &SaveOptions,
    ) -> Result<()> {
        use crate::env::Kind;
        match kind {
            Kind::Plain => save(images[0], rounding, path, options),
            Kind::LatLong => save_environment(
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

/// The levels of OpenEXR's cube-map strip for six faces' levels: level k
/// stacks the faces' level k while they are at least 1×1; the strip's
/// last levels (1×3, 1×1), which OpenEXR's level rule asks for but no
/// face has, are box-filtered from the 1×6 strip. Faces of a size that
/// is not a power of two cannot keep apart in the strip's levels.
fn cube_strip_levels(faces: &[&[Texture]], rounding: Rounding) -> Result<Vec<Texture>> {
    let n = faces[0][0].width();
    let mut strip: Vec<Texture> = (0..faces[0].len())
        .map(|k| {
            let level: Vec<&Texture> = faces.iter().map(|f| &f[k]).collect();
            crate::env::cube::strip_from_faces(&level)
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
