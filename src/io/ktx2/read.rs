//! Reading KTX2: every vkFormat parvo has a texel format for, the formats
//! unpacked into one (the `packed` module) and the BC formats,
//! supercompressed or not, the DFD's alpha and colour, orientation and
//! swizzle applied.

use super::*;

pub(super) fn read_bytes(path: &Path, limits: &Limits) -> Result<Vec<u8>> {
    let len = std::fs::metadata(path)
        .map_err(|e| Error::Io {
            path: path.to_path_buf(),
            action: "cannot open".into(),
            error: e,
        })?
        .len();
    if len > limits.max_alloc {
        return Err(Error::Limits(format!(
            "file is {}, more than the {} allowed (raise with {})",
            crate::io::limits::byte_size(len),
            crate::io::limits::byte_size(limits.max_alloc),
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
pub(super) fn dfd_model_word(bytes: &[u8]) -> Option<u32> {
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
pub(super) fn dfd_premultiplied(bytes: &[u8]) -> bool {
    dfd_model_word(bytes).is_some_and(|w| (w >> 24) & 1 == 1)
}

/// The `ktx2` crate's reader of `bytes`, after the checks it lacks: its
/// DFD parser panics (`NonZeroU8::new(dim + 1).unwrap()`) on a texel
/// block dimension byte of 255, so every basic DFD block is checked
/// first, and any other panic inside the crate becomes an error.
pub(super) fn reader(bytes: &[u8]) -> Result<::ktx2::Reader<&[u8]>> {
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
pub(super) fn parse_error(e: ::ktx2::ParseError) -> Error {
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
pub(super) fn orientation(value: &str, two_d: bool) -> (u16, Option<String>) {
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
    load_with(path, limits, &crate::io::LoadOptions::default())
}

/// [`load`] with [`crate::io::LoadOptions`]: cube maps and arrays are read
/// whole (every face and layer) when `options` accept them.
pub fn load_with(path: &Path, limits: &Limits, options: &crate::io::LoadOptions) -> Result<Loaded> {
    let bytes = read_bytes(path, limits)?;
    load_bytes(&bytes, limits, options)
}

pub(super) fn load_bytes(
    bytes: &[u8],
    limits: &Limits,
    options: &crate::io::LoadOptions,
) -> Result<Loaded> {
    let r = reader(bytes)?;
    let h = r.header();
    let kind = image_kind(&h)?;
    let mut notes = Vec::new();
    crate::io::layered_image(
        "KTX2",
        kind,
        (h.pixel_width, h.pixel_height.max(1)),
        options,
    )?;
    let scheme = u32::from_le_bytes(bytes[44..48].try_into().map_err(decode_err)?);
    let vk = h.format.map(|f| f.value()).unwrap_or(0);
    let block = block_format_of_vk(vk);
    let packed = match (block, format_of_vk(vk)) {
        (None, None) => packed_of_vk(vk),
        _ => None,
    };
    let mut format = match (block, packed) {
        (Some((bf, srgb, _)), _) => bf.decoded_format(srgb),
        (None, Some(p)) => {
            notes.extend(p.note(&vk_format_name(vk).unwrap_or_default()));
            p.format
        }
        (None, None) => format_of_vk(vk).ok_or_else(|| {
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
        packed,
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
                    .map(|l| crate::io::orient(l, code))
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
    let wrap = crate::io::recorded_wrap(
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
        _ => crate::io::layout_names(&format),
    };
    info.own_mips = levels.len() > 1;
    info.blocks = block.map(|b| b.0);
    info.wrap = wrap;
    info.attributes = attributes;
    info.kind = kind;
    info.one_d = h.pixel_height == 0;
    Ok(Loaded {
        levels,
        info,
        images: images.collect(),
    })
}

/// How a file's levels are stored, from its header: what sizing,
/// inflating and decoding them needs.
pub(super) struct StoredLevels {
    /// Level 0's size (a 1-D texture has height 1).
    width: u32,
    height: u32,
    /// The supercompression scheme (0: none).
    scheme: u32,
    /// The block format, sRGB, and whether it has alpha; `None` for plain
    /// texels of `format`.
    block: Option<(BlockFormat, bool, bool)>,
    /// The stored layout of a format unpacked on load (`B8G8R8A8`,
    /// `R5G6B5`, `R8G8B8A8_UINT`, ...); `None` for blocks and for texels
    /// stored as `format`.
    packed: Option<Packed>,
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
        let texel = match (self.block, self.packed) {
            (Some((bf, ..)), _) => return bf.level_bytes(w, h),
            (None, Some(p)) => p.bytes as u64,
            (None, None) => self.format.texel_bytes() as u64,
        };
        w as u64 * h as u64 * texel
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
    /// length): BC blocks decoded, packed texels unpacked, plain texels
    /// read little-endian.
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
                let texels = match self.packed {
                    Some(p) => p.unpack(data),
                    None => crate::io::texels_from_le(self.format.channel_type, data),
                };
                Texture::from_texels(w, h, self.format, texels)
            }
        }
    }
}

/// The kind of image a file starting with `head` holds, from its
/// header's layer and face counts alone (a plain 2-D image when the
/// header is too short or not a cube map or an array).
pub(crate) fn peek_kind(head: &[u8]) -> ImageKind {
    let word = |at: usize| {
        head.get(at..at + 4)
            .map_or(0, |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    match (word(36), word(32)) {
        (6, 0) => ImageKind::Cube,
        (6, cubes) => ImageKind::CubeArray { cubes },
        (1, 0) => ImageKind::Plain,
        (1, layers) => ImageKind::Array { layers },
        _ => ImageKind::Plain,
    }
}

/// The kind of image the header describes (KTX 2.0 section 3.4: a
/// layer count of 0 is not an array, 1 or more is); volumes and face
/// counts other than 1 and 6 are refused.
pub(super) fn image_kind(h: &::ktx2::Header) -> Result<ImageKind> {
    if h.face_count != 1 && h.face_count != 6 {
        return Err(decode_err(format!(
            "the header gives {} faces (1, or 6 for a cube map)",
            h.face_count
        )));
    }
    if h.pixel_depth > 1 {
        return Err(decode_err(format!(
            "volume textures are not supported (this one is {} texels deep; parvo reads 2-D \
             textures, arrays and cube maps): store its depth slices as the layers of a 2-D \
             array texture first",
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
        (false, 0) => ImageKind::Plain,
        (false, layers) => ImageKind::Array { layers },
        (true, 0) => ImageKind::Cube,
        (true, cubes) => ImageKind::CubeArray { cubes },
    })
}

/// `format` as the file's `KTXswizzle` (KTX 2.0 section "KTXswizzle")
/// reads it: `rrrg` on a two-channel plain format is the specification's
/// luminance + alpha; the other mappings that keep the stored channels'
/// meaning need nothing, and any other is reported in `notes`, not
/// applied.
pub(super) fn apply_swizzle(
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
pub(super) fn attributes_of(
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
