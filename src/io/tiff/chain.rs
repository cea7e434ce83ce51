//! The directory chain of a TIFF file, walked by parvo before the `tiff`
//! crate reads it, and the few repairs that let the crate read files
//! OpenImageIO (libtiff) reads.
//!
//! The crate stops at things libtiff takes in its stride: a directory
//! without a `PhotometricInterpretation` tag, a chain of directories
//! that loops back on itself (Pillow's `multipage_multiple_frame_loop.tiff`),
//! palette (indexed-colour) images, which it refuses outright. Instead of
//! forking the crate, parvo walks the chain itself (a few hundred bytes
//! of directory entries per page, never the pixels) and hands the crate a
//! *view* of the file ([`Patched`]) in which
//! - a directory that needs a tag added or changed is rewritten after the
//!   end of the file and the pointer to it redirected (the original bytes
//!   stay where they are, so every offset in them stays valid);
//! - the pointer that closes a loop is cut, so pages before the loop read.
//!
//! Walking the chain first also lets parvo say what is wrong with a
//! broken file in words (a directory or a strip past the end of the file)
//! before the crate reports it in its own terms.

use std::collections::HashSet;
use std::fs::File;
use std::io::{self, Read, Seek, SeekFrom};

use super::raw::View;

/// Tags parvo reads or rewrites before the crate does.
pub(super) mod tag {
    pub const IMAGE_WIDTH: u16 = 256;
    pub const IMAGE_LENGTH: u16 = 257;
    pub const BITS_PER_SAMPLE: u16 = 258;
    pub const COMPRESSION: u16 = 259;
    pub const PHOTOMETRIC: u16 = 262;
    pub const STRIP_OFFSETS: u16 = 273;
    pub const SAMPLES_PER_PIXEL: u16 = 277;
    pub const ROWS_PER_STRIP: u16 = 278;
    pub const STRIP_BYTE_COUNTS: u16 = 279;
    pub const PLANAR_CONFIGURATION: u16 = 284;
    pub const PREDICTOR: u16 = 317;
    pub const TILE_WIDTH: u16 = 322;
    pub const TILE_LENGTH: u16 = 323;
    pub const TILE_OFFSETS: u16 = 324;
    pub const TILE_BYTE_COUNTS: u16 = 325;
    pub const COLOR_MAP: u16 = 320;
    pub const EXTRA_SAMPLES: u16 = 338;
    pub const SAMPLE_FORMAT: u16 = 339;
    pub const JPEG_TABLES: u16 = 347;
    pub const YCBCR_SUBSAMPLING: u16 = 530;
    pub const REFERENCE_BLACK_WHITE: u16 = 532;
    /// Pixar's `textureformat` (maketx writes it).
    pub const TEXTURE_FORMAT: u16 = 33302;
    /// Pixar's `wrapmodes`.
    pub const WRAP_MODES: u16 = 33303;
}

/// Most directories (pages or mip levels) parvo follows.
pub(super) const MAX_DIRECTORIES: usize = 4096;

/// Byte order and offset width of a file.
#[derive(Clone, Copy, Debug)]
pub(super) struct Layout {
    little: bool,
    /// BigTIFF: 8-byte offsets and counts, 20-byte entries.
    pub big: bool,
    /// The file's length in bytes.
    pub len: u64,
}

impl Layout {
    fn u16(&self, b: &[u8]) -> u16 {
        let b = [b[0], b[1]];
        if self.little {
            u16::from_le_bytes(b)
        } else {
            u16::from_be_bytes(b)
        }
    }
    fn u32(&self, b: &[u8]) -> u32 {
        let b = [b[0], b[1], b[2], b[3]];
        if self.little {
            u32::from_le_bytes(b)
        } else {
            u32::from_be_bytes(b)
        }
    }
    fn u64(&self, b: &[u8]) -> u64 {
        let mut a = [0u8; 8];
        a.copy_from_slice(&b[..8]);
        let b = a;
        if self.little {
            u64::from_le_bytes(b)
        } else {
            u64::from_be_bytes(b)
        }
    }
    /// An offset field (4 bytes, 8 in BigTIFF).
    fn offset(&self, b: &[u8]) -> u64 {
        if self.big {
            self.u64(b)
        } else {
            self.u32(b) as u64
        }
    }
    fn put_u16(&self, v: u16) -> [u8; 2] {
        if self.little {
            v.to_le_bytes()
        } else {
            v.to_be_bytes()
        }
    }
    /// An offset as stored (4 bytes, 8 in BigTIFF).
    fn put_offset(&self, v: u64) -> Vec<u8> {
        match (self.big, self.little) {
            (true, true) => v.to_le_bytes().to_vec(),
            (true, false) => v.to_be_bytes().to_vec(),
            (false, true) => (v as u32).to_le_bytes().to_vec(),
            (false, false) => (v as u32).to_be_bytes().to_vec(),
        }
    }
    fn offset_size(&self) -> u64 {
        if self.big { 8 } else { 4 }
    }
    fn count_size(&self) -> u64 {
        if self.big { 8 } else { 2 }
    }
    fn entry_size(&self) -> u64 {
        if self.big { 20 } else { 12 }
    }
}

/// Bytes per value of a TIFF field type (`None` for types TIFF does not
/// define).
fn type_size(ty: u16) -> Option<u64> {
    match ty {
        1 | 2 | 6 | 7 => Some(1),
        3 | 8 => Some(2),
        4 | 9 | 11 | 13 => Some(4),
        5 | 10 | 12 | 16..=18 => Some(8),
        _ => None,
    }
}

/// One directory entry as stored.
#[derive(Clone, Debug)]
pub(super) struct Entry {
    pub tag: u16,
    ty: u16,
    pub count: u64,
    /// The value field: the values when they fit (4 bytes, 8 in BigTIFF),
    /// else their offset.
    field: [u8; 8],
}

impl Entry {
    /// Bytes of the values (`None` for a type TIFF does not define).
    pub fn byte_len(&self) -> Option<u64> {
        type_size(self.ty)?.checked_mul(self.count)
    }

    /// The first value of an unsigned BYTE/SHORT/LONG/LONG8 entry whose
    /// values are stored in the entry itself.
    fn inline_unsigned(&self, l: &Layout) -> Option<u64> {
        if self.count == 0 || self.byte_len()? > l.offset_size() {
            return None;
        }
        match self.ty {
            1 => Some(self.field[0] as u64),
            3 => Some(l.u16(&self.field) as u64),
            4 | 13 => Some(l.u32(&self.field) as u64),
            16 => Some(l.u64(&self.field)),
            _ => None,
        }
    }

    /// Whether the values lie within a file of `l.len` bytes.
    pub fn fits(&self, l: &Layout) -> bool {
        match self.out_of_line(l) {
            Some((at, n)) => at.checked_add(n).is_some_and(|end| end <= l.len),
            None => self.byte_len().is_some(),
        }
    }

    /// Where the values lie in the file when they are not in the entry.
    fn out_of_line(&self, l: &Layout) -> Option<(u64, u64)> {
        let n = self.byte_len()?;
        (n > l.offset_size()).then(|| (l.offset(&self.field), n))
    }

    fn bytes(&self, l: &Layout) -> Vec<u8> {
        let mut b = Vec::with_capacity(l.entry_size() as usize);
        b.extend_from_slice(&l.put_u16(self.tag));
        b.extend_from_slice(&l.put_u16(self.ty));
        if l.big {
            b.extend_from_slice(&l.put_offset(self.count));
        } else {
            b.extend_from_slice(&l.put_offset(self.count.min(u32::MAX as u64)));
        }
        b.extend_from_slice(&self.field[..l.offset_size() as usize]);
        b
    }

    /// A LONG entry holding one value.
    pub fn long(l: &Layout, tag: u16, v: u32) -> Entry {
        let mut field = [0u8; 8];
        let b = if l.little {
            v.to_le_bytes()
        } else {
            v.to_be_bytes()
        };
        field[..4].copy_from_slice(&b);
        Entry {
            tag,
            ty: 4,
            count: 1,
            field,
        }
    }

    /// A SHORT entry holding one value.
    pub fn short(l: &Layout, tag: u16, v: u16) -> Entry {
        let mut field = [0u8; 8];
        field[..2].copy_from_slice(&l.put_u16(v));
        Entry {
            tag,
            ty: 3,
            count: 1,
            field,
        }
    }
}

/// One directory (image file directory, IFD) as stored.
#[derive(Clone, Debug)]
pub(super) struct Dir {
    offset: u64,
    pub entries: Vec<Entry>,
    next: u64,
}

impl Dir {
    pub fn entry(&self, tag: u16) -> Option<&Entry> {
        self.entries.iter().find(|e| e.tag == tag)
    }

    /// The value of a one-value unsigned tag stored in its entry.
    pub fn unsigned(&self, l: &Layout, tag: u16) -> Option<u64> {
        self.entry(tag).and_then(|e| e.inline_unsigned(l))
    }

    fn size(&self, l: &Layout) -> u64 {
        l.count_size() + self.entries.len() as u64 * l.entry_size() + l.offset_size()
    }
}

/// What parvo changed in one directory before the crate reads it, and
/// why: the decoder sees `told` as the photometric interpretation.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct Fix {
    /// The `PhotometricInterpretation` the file stores (`None`: no tag).
    pub stored_photometric: Option<u64>,
    /// The value the decoder is given instead, if any: 1 (BlackIsZero)
    /// for palette indices, which parvo maps through the colour map
    /// itself; the value OpenImageIO assumes for a missing tag.
    pub told: Option<u16>,
    /// The fourth sample of an RGB directory is data (`ExtraSamples` 0):
    /// the decoder is told it is unassociated alpha (2), since the crate
    /// drops a sample it does not take for alpha, and parvo reads it back
    /// as data.
    pub extra_data: bool,
    /// The samples are handed to the decoder as rows of bytes, which
    /// parvo unpacks (see [`View`]).
    pub view: Option<View>,
}

/// The directories of a file up to the first repeated one (or the end of
/// the chain), and what happened on the way.
pub(super) struct Chain {
    pub layout: Layout,
    pub dirs: Vec<Dir>,
    /// Where the pointer to the first directory is stored.
    first_at: u64,
    /// The chain was cut after the last directory: a loop, or a
    /// directory that cannot be read.
    cut: bool,
    /// Sentences for the user (a loop, a page that cannot be read).
    pub notes: Vec<String>,
}

fn read_at(f: &mut File, at: u64, buf: &mut [u8]) -> io::Result<()> {
    f.seek(SeekFrom::Start(at))?;
    f.read_exact(buf)
}

/// Walk the chain of directories of the TIFF file `f`, `len` bytes long.
/// Errors are one line of plain words.
pub(super) fn walk(f: &mut File, len: u64) -> Result<Chain, String> {
    let mut head = [0u8; 16];
    let n = head.len().min(len as usize);
    read_at(f, 0, &mut head[..n]).map_err(|e| format!("cannot read its header: {e}"))?;
    let little = match &head[..2] {
        b"II" => true,
        b"MM" => false,
        _ => return Err("not a TIFF file (no II or MM byte-order mark)".into()),
    };
    let mut layout = Layout {
        little,
        big: false,
        len,
    };
    let first_at = match layout.u16(&head[2..]) {
        42 if len >= 8 => 4,
        43 if len >= 16 && layout.u16(&head[4..]) == 8 => {
            layout.big = true;
            8
        }
        42 | 43 => return Err("the file ends inside its header: it is truncated".into()),
        v => {
            return Err(format!(
                "version {v} in the header is neither 42 (TIFF) nor 43 (BigTIFF)"
            ));
        }
    };
    let mut at = layout.offset(&head[first_at as usize..]);
    let mut chain = Chain {
        layout,
        dirs: Vec::new(),
        first_at,
        cut: false,
        notes: Vec::new(),
    };
    let mut seen = HashSet::new();
    while at != 0 {
        let k = chain.dirs.len();
        if !seen.insert(at) {
            let back = chain.dirs.iter().position(|d| d.offset == at).unwrap_or(0);
            chain.notes.push(format!(
                "the chain of pages loops (page {} points back to page {back}): the {k} page{} \
                 before the loop {} read, as OpenImageIO reads them",
                k - 1,
                if k == 1 { "" } else { "s" },
                if k == 1 { "is" } else { "are" },
            ));
            chain.cut = true;
            break;
        }
        if k == MAX_DIRECTORIES {
            return Err(format!(
                "more than {MAX_DIRECTORIES} directories (pages or mip levels)"
            ));
        }
        match read_dir(f, &layout, at) {
            Ok(d) => {
                at = d.next;
                chain.dirs.push(d);
            }
            Err(e) if k == 0 => return Err(e),
            Err(e) => {
                chain.notes.push(format!(
                    "page {k} cannot be read ({e}): the file is read as its first {k} page{}",
                    if k == 1 { "" } else { "s" }
                ));
                chain.cut = true;
                break;
            }
        }
    }
    if chain.dirs.is_empty() {
        return Err("the header points to no directory (offset 0): the file holds no image".into());
    }
    Ok(chain)
}

fn read_dir(f: &mut File, l: &Layout, at: u64) -> Result<Dir, String> {
    let cs = l.count_size();
    if at.checked_add(cs).is_none_or(|end| end > l.len) {
        return Err(format!(
            "its directory at byte {at} lies past the end of the file ({} bytes): the file is truncated",
            l.len
        ));
    }
    let mut b = [0u8; 8];
    read_at(f, at, &mut b[..cs as usize]).map_err(|e| format!("cannot read it: {e}"))?;
    let count = if l.big { l.u64(&b) } else { l.u16(&b) as u64 };
    if count == 0 {
        return Err(format!("its directory at byte {at} has no entries"));
    }
    let size = count
        .checked_mul(l.entry_size())
        .and_then(|s| s.checked_add(l.offset_size()));
    let end = size.and_then(|s| s.checked_add(at + cs));
    if end.is_none_or(|end| end > l.len) {
        return Err(format!(
            "its directory at byte {at} ({count} entries) runs past the end of the file ({} bytes): \
             the file is truncated",
            l.len
        ));
    }
    let size = size.unwrap_or(0) as usize;
    let mut raw = vec![0u8; size];
    read_at(f, at + cs, &mut raw).map_err(|e| format!("cannot read it: {e}"))?;
    let es = l.entry_size() as usize;
    let mut entries = Vec::with_capacity(count as usize);
    for e in raw[..count as usize * es].chunks_exact(es) {
        let mut field = [0u8; 8];
        let (count, value) = if l.big {
            (l.u64(&e[4..]), &e[12..20])
        } else {
            (l.u32(&e[4..]) as u64, &e[8..12])
        };
        field[..value.len()].copy_from_slice(value);
        entries.push(Entry {
            tag: l.u16(e),
            ty: l.u16(&e[2..]),
            count,
            field,
        });
    }
    let next = l.offset(&raw[count as usize * es..]);
    Ok(Dir {
        offset: at,
        entries,
        next,
    })
}

/// The problem with directory `dir`'s entries a reader would trip over
/// first, in words: values or pixel data past the end of the file.
pub(super) fn check_extents(f: &mut File, l: &Layout, dir: &Dir) -> Result<(), String> {
    // The tags the decoder reads (others it never looks at, as libtiff
    // ignores a broken private tag).
    const READ: [u16; 24] = [
        tag::IMAGE_WIDTH,
        tag::IMAGE_LENGTH,
        tag::COMPRESSION,
        tag::PHOTOMETRIC,
        274, // Orientation
        tag::SAMPLES_PER_PIXEL,
        tag::ROWS_PER_STRIP,
        tag::PLANAR_CONFIGURATION,
        266, // FillOrder
        tag::PREDICTOR,
        tag::TILE_WIDTH,
        tag::TILE_LENGTH,
        tag::BITS_PER_SAMPLE,
        tag::STRIP_OFFSETS,
        tag::STRIP_BYTE_COUNTS,
        tag::TILE_OFFSETS,
        tag::TILE_BYTE_COUNTS,
        tag::EXTRA_SAMPLES,
        tag::SAMPLE_FORMAT,
        tag::COLOR_MAP,
        tag::JPEG_TABLES,
        tag::TEXTURE_FORMAT,
        tag::WRAP_MODES,
        tag::YCBCR_SUBSAMPLING,
    ];
    for e in dir.entries.iter().filter(|e| READ.contains(&e.tag)) {
        if let Some((at, n)) = e.out_of_line(l)
            && at.checked_add(n).is_none_or(|end| end > l.len)
        {
            return Err(format!(
                "the values of its {} tag lie past the end of the file: it is truncated or corrupt",
                tag_name(e.tag)
            ));
        }
    }
    for (offsets, counts, what) in [
        (tag::STRIP_OFFSETS, tag::STRIP_BYTE_COUNTS, "strip"),
        (tag::TILE_OFFSETS, tag::TILE_BYTE_COUNTS, "tile"),
    ] {
        let (Some(o), Some(c)) = (dir.entry(offsets), dir.entry(counts)) else {
            continue;
        };
        let (Some(o), Some(c)) = (values(f, l, o), values(f, l, c)) else {
            continue;
        };
        let need = uncompressed_sizes(f, l, dir, what == "tile", o.len());
        for (k, (&at, &n)) in o.iter().zip(&c).enumerate() {
            // An uncompressed chunk is read for the bytes its rows need
            // (libtiff ignores a larger byte count, as in Pillow's
            // `tiff_wrong_bits_per_sample.tiff`).
            let n = need
                .as_ref()
                .and_then(|v| v.get(k))
                .map_or(n, |&m| m.min(n));
            if at.checked_add(n).is_none_or(|end| end > l.len) {
                return Err(format!(
                    "{what} {k} of {} lies past the end of the file (bytes {at} to {}, the file has {}): \
                     it is truncated",
                    o.len(),
                    at.saturating_add(n),
                    l.len
                ));
            }
        }
    }
    Ok(())
}

/// The bytes each of the `count` chunks (strips or tiles) of an
/// uncompressed directory holds, from its sizes; `None` when the data is
/// compressed or the sizes cannot be read.
fn uncompressed_sizes(
    f: &mut File,
    l: &Layout,
    dir: &Dir,
    tiles: bool,
    count: usize,
) -> Option<Vec<u64>> {
    if dir.unsigned(l, tag::COMPRESSION).unwrap_or(1) != 1 {
        return None;
    }
    let w = dir.unsigned(l, tag::IMAGE_WIDTH)?;
    let h = dir.unsigned(l, tag::IMAGE_LENGTH)?;
    let samples = dir.unsigned(l, tag::SAMPLES_PER_PIXEL).unwrap_or(1);
    let bits = match dir.entry(tag::BITS_PER_SAMPLE) {
        Some(e) => *values(f, l, e)?.first()?,
        None => 1,
    };
    let per_chunk = if dir.unsigned(l, tag::PLANAR_CONFIGURATION) == Some(2) {
        1
    } else {
        samples
    };
    let row = |width: u64| {
        width
            .checked_mul(bits)?
            .checked_mul(per_chunk)
            .map(|b| b.div_ceil(8))
    };
    if tiles {
        let tw = dir.unsigned(l, tag::TILE_WIDTH)?;
        let th = dir.unsigned(l, tag::TILE_LENGTH)?;
        let n = row(tw)?.checked_mul(th)?;
        Some(vec![n; count])
    } else {
        let rps = dir
            .unsigned(l, tag::ROWS_PER_STRIP)
            .unwrap_or(h)
            .clamp(1, h.max(1));
        let per_plane = h.div_ceil(rps).max(1);
        let r = row(w)?;
        Some(
            (0..count as u64)
                .map(|k| {
                    let first = (k % per_plane) * rps;
                    rps.min(h.saturating_sub(first)) * r
                })
                .collect(),
        )
    }
}

/// The values of a RATIONAL entry (`None` for another type or values
/// that cannot be read).
pub(super) fn rationals(f: &mut File, l: &Layout, e: &Entry) -> Option<Vec<f64>> {
    if e.ty != 5 || e.count > 64 {
        return None;
    }
    let (at, n) = e.out_of_line(l)?;
    let mut raw = vec![0u8; n as usize];
    read_at(f, at, &mut raw).ok()?;
    Some(
        raw.chunks_exact(8)
            .map(|b| l.u32(b) as f64 / (l.u32(&b[4..]) as f64).max(f64::MIN_POSITIVE))
            .collect(),
    )
}

/// The unsigned values of a SHORT/LONG/LONG8 entry (`None` for another
/// type or values that cannot be read).
pub(super) fn values(f: &mut File, l: &Layout, e: &Entry) -> Option<Vec<u64>> {
    let size = match e.ty {
        3 => 2,
        4 | 13 => 4,
        16 => 8,
        _ => return None,
    };
    let n = e.byte_len()?;
    let raw = match e.out_of_line(l) {
        Some((at, n)) => {
            if n > (64 << 20) {
                return None;
            }
            let mut raw = vec![0u8; n as usize];
            read_at(f, at, &mut raw).ok()?;
            raw
        }
        None => e.field[..n as usize].to_vec(),
    };
    Some(
        raw.chunks_exact(size)
            .map(|b| match size {
                2 => l.u16(b) as u64,
                4 => l.u32(b) as u64,
                _ => l.u64(b),
            })
            .collect(),
    )
}

/// A tag's name as the TIFF specification spells it, or its number.
pub(super) fn tag_name(t: u16) -> String {
    let name = match t {
        254 => "NewSubfileType",
        256 => "ImageWidth",
        257 => "ImageLength",
        258 => "BitsPerSample",
        259 => "Compression",
        262 => "PhotometricInterpretation",
        266 => "FillOrder",
        273 => "StripOffsets",
        274 => "Orientation",
        277 => "SamplesPerPixel",
        278 => "RowsPerStrip",
        279 => "StripByteCounts",
        284 => "PlanarConfiguration",
        317 => "Predictor",
        320 => "ColorMap",
        322 => "TileWidth",
        323 => "TileLength",
        324 => "TileOffsets",
        325 => "TileByteCounts",
        330 => "SubIFDs",
        338 => "ExtraSamples",
        339 => "SampleFormat",
        347 => "JPEGTables",
        530 => "YCbCrSubSampling",
        33302 => "textureformat",
        33303 => "wrapmodes",
        _ => return format!("tag {t}"),
    };
    name.to_string()
}

impl Chain {
    /// Decide what each directory needs (see [`Fix`]) and build the view
    /// of the file the decoder reads: directories rewritten after the
    /// end, pointers redirected, a loop cut. Notes say what was assumed.
    pub fn repair(&self, mut file: File) -> Result<(Patched, Vec<Fix>, Vec<String>), String> {
        let l = &self.layout;
        let mut notes = Vec::new();
        let fixes: Vec<Fix> = (self.dirs.iter().enumerate())
            .map(|(k, d)| self.fix(&mut file, k, d, &mut notes))
            .collect();
        // The rewritten directories start a little after the end of the
        // file: a strip that runs past the end reads nothing there (the
        // gap reads as the end of the file), never a rewritten directory.
        let tail_base = l.len.div_ceil(16) * 16 + 16;
        let mut view = Patched::new(file, l.len, tail_base);
        let mut pointer_at = self.first_at;
        for (k, (d, &fix)) in self.dirs.iter().zip(&fixes).enumerate() {
            let rewrite = Rewrite::of(l, d);
            let last = k + 1 == self.dirs.len();
            let changed = fix.told.is_some() || fix.extra_data || fix.view.is_some();
            let next_at = if changed || rewrite.needed() {
                let next = if last && self.cut { 0 } else { d.next };
                let new = rewritten(l, d, fix, rewrite, next);
                let at = view.append_dir(l, &new)?;
                view.write_at(pointer_at, &l.put_offset(at));
                at + new.size(l) - l.offset_size()
            } else {
                d.offset + d.size(l) - l.offset_size()
            };
            if last && self.cut {
                view.write_at(next_at, &l.put_offset(0));
            }
            pointer_at = next_at;
        }
        Ok((view, fixes, notes))
    }

    /// What directory `k` needs told to the decoder (see [`Fix`]); a
    /// missing `PhotometricInterpretation` gets a note in `notes`.
    fn fix(&self, f: &mut File, k: usize, d: &Dir, notes: &mut Vec<String>) -> Fix {
        let l = &self.layout;
        let stored = d.entry(tag::PHOTOMETRIC).map(|e| e.inline_unsigned(l));
        let stored_photometric = match stored {
            None => None,
            Some(Some(v)) => Some(v),
            Some(None) => Some(u64::MAX),
        };
        let told = match stored_photometric {
            // Palette indices are decoded as grey and mapped here.
            Some(3) => Some(1),
            Some(_) => None,
            None => {
                // libtiff's and OpenImageIO's guess: grey for one
                // colour channel, RGB otherwise.
                let samples = d.unsigned(l, tag::SAMPLES_PER_PIXEL).unwrap_or(1);
                let extra = d.entry(tag::EXTRA_SAMPLES).map_or(0, |e| e.count);
                let rgb = samples.saturating_sub(extra) >= 3;
                notes.push(format!(
                    "{}no PhotometricInterpretation tag: read as {}, as OpenImageIO does",
                    if self.dirs.len() > 1 {
                        format!("page {k}: ")
                    } else {
                        String::new()
                    },
                    match (rgb, samples) {
                        (true, _) => "RGB",
                        (false, 2) if extra == 0 => "two data channels (R, G)",
                        _ => "grey (BlackIsZero)",
                    }
                ));
                // The crate reads 1 and 2 samples as grey only.
                Some(if rgb { 2 } else { 1 })
            }
        };
        // RGB with one extra sample that is data (ExtraSamples 0,
        // one value inline): the crate reads RGB only.
        let samples = d.unsigned(l, tag::SAMPLES_PER_PIXEL).unwrap_or(1);
        let rgb = matches!(stored_photometric.or(told.map(u64::from)), Some(2));
        let extra_data = rgb
            && samples == 4
            && d.entry(tag::EXTRA_SAMPLES)
                .is_some_and(|e| e.count == 1 && e.inline_unsigned(l) == Some(0));
        let view = View::of(f, l, d, stored_photometric.or(told.map(u64::from)));
        Fix {
            stored_photometric,
            told,
            extra_data,
            view,
        }
    }
}

/// What parvo changes in a directory's entries besides its [`Fix`], for
/// files libtiff reads and the `tiff` crate alone would not.
#[derive(Clone, Copy, Debug)]
struct Rewrite {
    /// The tiles of a tiled image are stored under the strip tags.
    tiles_as_strips: bool,
    /// `BitsPerSample` is cut to this many values (one per sample).
    bits_count: Option<u64>,
}

impl Rewrite {
    /// What directory `d` needs.
    fn of(l: &Layout, d: &Dir) -> Rewrite {
        // Old writers (libtiff's `quad-tile.tif`) store the tiles
        // of a tiled image under the strip tags; libtiff reads them
        // as tiles.
        let tiles_as_strips = d.entry(tag::TILE_WIDTH).is_some()
            && d.entry(tag::TILE_LENGTH).is_some()
            && d.entry(tag::TILE_OFFSETS).is_none()
            && d.entry(tag::TILE_BYTE_COUNTS).is_none()
            && d.entry(tag::STRIP_OFFSETS).is_some()
            && d.entry(tag::STRIP_BYTE_COUNTS).is_some();
        // More BitsPerSample values than samples (Pillow's
        // `tiff_wrong_bits_per_sample_2.tiff`): libtiff reads the
        // first ones. Only done where the values stay out of line.
        let samples = d.unsigned(l, tag::SAMPLES_PER_PIXEL).unwrap_or(1);
        let bits_count = d.entry(tag::BITS_PER_SAMPLE).and_then(|e| {
            let fits = Entry {
                count: samples,
                ..e.clone()
            }
            .byte_len()
            .is_some_and(|n| n > l.offset_size());
            (e.count > samples && fits).then_some(samples)
        });
        Rewrite {
            tiles_as_strips,
            bits_count,
        }
    }

    /// Whether the entries change at all.
    fn needed(self) -> bool {
        self.tiles_as_strips || self.bits_count.is_some()
    }
}

/// Directory `d` as the decoder is to read it: the photometric
/// interpretation it is told, the data sample called unassociated alpha,
/// `rewrite`'s changes, entries sorted by tag, `next` as the next pointer.
fn rewritten(l: &Layout, d: &Dir, fix: Fix, rewrite: Rewrite, next: u64) -> Dir {
    let told = fix.told;
    let mut entries: Vec<Entry> = d
        .entries
        .iter()
        .filter(|e| told.is_none() || e.tag != tag::PHOTOMETRIC)
        .cloned()
        .collect();
    if let Some(v) = told {
        entries.push(Entry::short(l, tag::PHOTOMETRIC, v));
    }
    if fix.extra_data {
        for e in entries.iter_mut().filter(|e| e.tag == tag::EXTRA_SAMPLES) {
            *e = Entry::short(l, tag::EXTRA_SAMPLES, 2);
        }
    }
    if let Some(n) = rewrite.bits_count {
        for e in entries.iter_mut().filter(|e| e.tag == tag::BITS_PER_SAMPLE) {
            e.count = n;
        }
    }
    if rewrite.tiles_as_strips {
        for e in &mut entries {
            e.tag = match e.tag {
                tag::STRIP_OFFSETS => tag::TILE_OFFSETS,
                tag::STRIP_BYTE_COUNTS => tag::TILE_BYTE_COUNTS,
                t => t,
            };
        }
    }
    if let Some(v) = fix.view {
        entries = v.entries(l, entries);
    }
    entries.sort_by_key(|e| e.tag);
    Dir {
        offset: 0,
        entries,
        next,
    }
}

/// The file as the `tiff` crate reads it: the bytes on disk with a few
/// pointer fields replaced, a gap that reads as the end of the file, and
/// then the rewritten directories.
pub(super) struct Patched {
    file: File,
    len: u64,
    tail_base: u64,
    tail: Vec<u8>,
    patches: Vec<(u64, Vec<u8>)>,
    pos: u64,
    /// Where `file`'s own cursor is (`None`: unknown).
    file_pos: Option<u64>,
}

impl Patched {
    fn new(file: File, len: u64, tail_base: u64) -> Self {
        Patched {
            file,
            len,
            tail_base,
            tail: Vec::new(),
            patches: Vec::new(),
            pos: 0,
            file_pos: None,
        }
    }

    fn append_dir(&mut self, l: &Layout, d: &Dir) -> Result<u64, String> {
        while !self.tail.len().is_multiple_of(8) {
            self.tail.push(0);
        }
        let at = self.tail_base + self.tail.len() as u64;
        if !l.big && at + d.size(l) > u32::MAX as u64 {
            return Err(
                "the file is too close to TIFF's 4 GiB limit for parvo to supply a missing tag"
                    .into(),
            );
        }
        if l.big {
            self.tail
                .extend_from_slice(&l.put_offset(d.entries.len() as u64));
        } else {
            self.tail
                .extend_from_slice(&l.put_u16(d.entries.len() as u16));
        }
        for e in &d.entries {
            self.tail.extend_from_slice(&e.bytes(l));
        }
        self.tail.extend_from_slice(&l.put_offset(d.next));
        Ok(at)
    }

    fn write_at(&mut self, at: u64, bytes: &[u8]) {
        if at >= self.tail_base {
            let i = (at - self.tail_base) as usize;
            self.tail[i..i + bytes.len()].copy_from_slice(bytes);
        } else {
            self.patches.retain(|(p, _)| *p != at);
            self.patches.push((at, bytes.to_vec()));
        }
    }
}

impl Read for Patched {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        if self.pos < self.len {
            let n = (buf.len() as u64).min(self.len - self.pos) as usize;
            if self.file_pos != Some(self.pos) {
                self.file.seek(SeekFrom::Start(self.pos))?;
            }
            let got = match self.file.read(&mut buf[..n]) {
                Ok(k) => k,
                Err(e) => {
                    self.file_pos = None;
                    return Err(e);
                }
            };
            let (from, to) = (self.pos, self.pos + got as u64);
            for (at, bytes) in &self.patches {
                let end = at + bytes.len() as u64;
                if *at < to && end > from {
                    let s = (*at).max(from);
                    let e = end.min(to);
                    buf[(s - from) as usize..(e - from) as usize]
                        .copy_from_slice(&bytes[(s - at) as usize..(e - at) as usize]);
                }
            }
            self.pos = to;
            self.file_pos = Some(to);
            Ok(got)
        } else if self.pos >= self.tail_base {
            let i = (self.pos - self.tail_base) as usize;
            if i >= self.tail.len() {
                return Ok(0);
            }
            let n = buf.len().min(self.tail.len() - i);
            buf[..n].copy_from_slice(&self.tail[i..i + n]);
            self.pos += n as u64;
            Ok(n)
        } else {
            // The gap between the file and the rewritten directories.
            Ok(0)
        }
    }
}

impl Seek for Patched {
    fn seek(&mut self, to: SeekFrom) -> io::Result<u64> {
        let end = self.tail_base + self.tail.len() as u64;
        let new = match to {
            SeekFrom::Start(p) => Some(p),
            SeekFrom::End(d) => end.checked_add_signed(d),
            SeekFrom::Current(d) => self.pos.checked_add_signed(d),
        };
        match new {
            Some(p) => {
                self.pos = p;
                Ok(p)
            }
            None => Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                "seek before the start of the file",
            )),
        }
    }
}
