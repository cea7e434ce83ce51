//! Writing tiled, mip-mapped OpenEXR: whole chains, environment maps, level
//! 0 streamed band by band, ZIP tiles by libdeflate, and the fingerprint
//! read back.

use super::*;

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
/// and `--envcube` write them. The texels are written as given: placed
/// as OpenEXR places them ([`super::edges_from_centred`] makes them so
/// from centred texels; the container's `save` does it for you).
pub fn save_environment(
    levels: &[Texture],
    rounding: Rounding,
    path: &Path,
    opts: &SaveOptions,
    env: crate::io::Environment,
) -> Result<()> {
    save_as(levels, rounding, path, opts, Some(env))
}

pub(super) fn save_as(
    levels: &[Texture],
    rounding: Rounding,
    path: &Path,
    opts: &SaveOptions,
    env: Option<crate::io::Environment>,
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
pub(super) fn mark_environment(header: &mut Header, env: crate::io::Environment) {
    use ::exr::meta::attribute::EnvironmentMap;
    let (map, name) = match env {
        crate::io::Environment::LatLong => {
            (EnvironmentMap::LatitudeLongitude, "LatLong Environment")
        }
        crate::io::Environment::Cube => (EnvironmentMap::Cube, "CubeFace Environment"),
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
pub(super) struct Tiles {
    /// Channel indices in file order (sorted by name).
    order: Vec<usize>,
    zip: bool,
    tile: (usize, usize),
}

/// The header of a tiled EXR of `w`×`h` texels in `fmt` (mip-mapped or
/// one level), after checking what the `exr` crate would panic on.
pub(super) fn plan(
    w: u32,
    h: u32,
    fmt: Format,
    mip: bool,
    rounding: Rounding,
    opts: &SaveOptions,
) -> Result<(Header, Tiles)> {
    let (tw, th) = opts.exr.tile;
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
        None => crate::io::layout_names(&fmt),
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
        opts.exr.compression.to_exr(),
        BlockDescription::Tiles(TileDescription {
            tile_size: Vec2(tw as usize, th as usize),
            level_mode,
            rounding_mode: to_exr_rounding(rounding),
        }),
        LineOrder::Increasing,
    );
    header.own_attributes = attrs;
    let zip = matches!(
        opts.exr.compression,
        ExrCompression::Zip | ExrCompression::Zips
    );
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
pub(super) fn write_file(
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
pub(super) fn write_blocks(
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
pub(super) fn sort_header_attributes(mut file: &std::fs::File) -> std::io::Result<()> {
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
pub(super) fn tile_bytes(
    lvl: &Texture,
    y_off: usize,
    index: &BlockIndex,
    order: &[usize],
    raw: &mut Vec<u8>,
) {
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
pub(super) fn gather<T: Copy, const N: usize>(
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
pub(super) const ZIP_LEVEL: libdeflater::CompressionLvl = match libdeflater::CompressionLvl::new(4)
{
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
pub(super) fn zip_tile(
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
pub(super) fn zip_compress_with(
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
