//! The `tiff` crate's errors in plain words: what is wrong with the file
//! (a truncated strip, tags that disagree, a compression parvo does not
//! read), never the crate's own terms (`inconsistent sizes encountered`,
//! `failed to fill whole buffer`); limits are `Error::Limits` naming the
//! limit.

use ::tiff::tags::Tag;
use ::tiff::{TiffError, TiffFormatError, TiffUnsupportedError};

use super::chain::{self, tag, tag_name};
use super::{CRATE_TAG_LIMIT, Directory, decode_err, join};
use crate::error::Error;
use crate::io::Limits;

/// The allocation limit exceeded by `bytes` of decoded samples.
pub(super) fn alloc_limit(limits: &Limits, dir: &Directory, bytes: u64) -> Error {
    match limits.check(dir.width as u64, dir.height as u64, bytes) {
        Err(e) => e,
        Ok(()) => Error::Limits(format!(
            "decoding the {}x{} image needs more memory than the allocation limit allows",
            dir.width, dir.height
        )),
    }
}

/// A `tiff` crate error in plain words. `raw` is the directory being
/// read (parvo's own parse), used to say which tags disagree.
pub(super) fn words(
    e: TiffError,
    raw: Option<&chain::Dir>,
    l: &chain::Layout,
    limits: &Limits,
    dir: Option<&Directory>,
) -> Error {
    match e {
        TiffError::LimitsExceeded => limits_exceeded(raw, l, limits, dir),
        TiffError::IoError(io) => match io.kind() {
            std::io::ErrorKind::UnexpectedEof => {
                decode_err("the file ends before the pixel data it declares (it is truncated)")
            }
            std::io::ErrorKind::InvalidData | std::io::ErrorKind::InvalidInput => {
                compressed_corrupt(raw, l, &io.to_string())
            }
            // A decompressor's failure passed on as an I/O error with
            // no reason of its own ("Decode Error").
            std::io::ErrorKind::Other if io.to_string() == "Decode Error" => {
                compressed_corrupt(raw, l, "its decoder stops inside it")
            }
            _ => decode_err(format!(
                "cannot read the file: {}",
                crate::error::io_words(&io)
            )),
        },
        TiffError::IntSizeError => {
            corrupt("a size or offset in the file is larger than this machine can address".into())
        }
        TiffError::FormatError(f) => format_error(f, raw, l),
        TiffError::UnsupportedError(u) => decode_err(unsupported(u, raw, l)),
        TiffError::UsageError(_) => {
            corrupt("its strip or tile tables do not match the image".into())
        }
    }
}

/// `what`, said to make the file corrupt.
fn corrupt(what: String) -> Error {
    decode_err(format!("{what}: the file is corrupt"))
}

/// The crate's "limits exceeded": a tag larger than its fixed limit, or a
/// decoding buffer over the allocation limit.
fn limits_exceeded(
    raw: Option<&chain::Dir>,
    l: &chain::Layout,
    limits: &Limits,
    dir: Option<&Directory>,
) -> Error {
    // A tag larger than the crate's fixed limit (only while the
    // first directory is read, before parvo's limits apply)...
    let big = raw.and_then(|r| {
        r.entries
            .iter()
            .map(|e| (e, e.byte_len().unwrap_or(u64::MAX)))
            .find(|&(_, n)| n > CRATE_TAG_LIMIT)
    });
    if let Some((e, _)) = big
        && !e.fits(l)
    {
        return corrupt(format!(
            "its {} tag claims {} values, more than the file holds",
            tag_name(e.tag),
            e.count
        ));
    }
    if let Some(big) = big {
        return Error::Limits(format!(
            "the {} tag holds {} values, more than the TIFF decoder's fixed limit of 1 MiB \
             for one tag (too many strips or tiles for it)",
            tag_name(big.0.tag),
            big.0.count
        ));
    }
    // ... else a decoding buffer over the allocation limit.
    match dir {
        Some(d) => alloc_limit(
            limits,
            d,
            (d.width as u64 * d.height as u64)
                .saturating_mul(d.stored_samples as u64)
                .saturating_mul(d.bits.div_ceil(8) as u64),
        ),
        None => Error::Limits(
            "a strip, tile or tag of the file is larger than the allocation limit allows".into(),
        ),
    }
}

/// A malformed file (the crate's `TiffFormatError`) in words.
fn format_error(f: TiffFormatError, raw: Option<&chain::Dir>, l: &chain::Layout) -> Error {
    use TiffFormatError as F;
    match f {
        F::TiffSignatureNotFound | F::TiffSignatureInvalid => {
            decode_err("not a TIFF file (its signature is wrong)")
        }
        F::ImageFileDirectoryNotFound => {
            corrupt("a directory (page) the file points to is missing".into())
        }
        F::InconsistentSizesEncountered => corrupt(match raw {
            Some(r) => sizes_disagree(r, l),
            None => "its tags disagree about the layout of the image".into(),
        }),
        F::InvalidDimensions(w, h) => decode_err(format!(
            "the image is {w}x{h}: a width or height of zero holds no image"
        )),
        F::InvalidTag => corrupt("a text tag is not valid text".into()),
        F::InvalidTagValueType(t) => corrupt(format!(
            "the {} tag has the wrong value type",
            crate_tag_name(t)
        )),
        F::RequiredTagNotFound(t) => {
            decode_err(format!("the required {} tag is missing", crate_tag_name(t)))
        }
        F::UnknownPredictor(p) => {
            decode_err(format!("predictor {p} is not a TIFF predictor (1, 2 or 3)"))
        }
        F::UnknownPlanarConfiguration(c) => decode_err(format!(
            "planar configuration {c} is neither 1 (contiguous) nor 2 (planar)"
        )),
        F::InvalidTypeForTag => corrupt(
            match raw.and_then(|r| r.entries.iter().find(|e| e.byte_len().is_none())) {
                Some(e) => format!(
                    "its {} tag has a value type TIFF does not define",
                    tag_name(e.tag)
                ),
                None => "a tag has a value type TIFF does not define".into(),
            },
        ),
        F::InvalidCountForTag(t, n) => corrupt(format!(
            "the {} tag has {n} values, which does not fit the image",
            crate_tag_name(t)
        )),
        F::StripTileTagConflict => corrupt(
            "it has neither a complete pair of strip tags (StripOffsets, StripByteCounts) \
         nor of tile tags (TileOffsets, TileByteCounts)"
                .into(),
        ),
        F::CycleInOffsets => corrupt("its chain of directories loops".into()),
        F::SamplesPerPixelIsZero => corrupt("SamplesPerPixel is 0".into()),
        F::CompressedDataCorrupt(m) => compressed_corrupt(raw, l, &m),
        other => corrupt(format!("its structure is invalid ({other})")),
    }
}

/// What the crate does not read (its `TiffUnsupportedError`), in words.
fn unsupported(u: TiffUnsupportedError, raw: Option<&chain::Dir>, l: &chain::Layout) -> String {
    use TiffUnsupportedError as U;
    match u {
        U::FloatingPointPredictor(_) | U::HorizontalPredictor(_) => format!(
            "the {} predictor is not supported for samples of this depth",
            if matches!(u, U::FloatingPointPredictor(_)) {
                "floating-point"
            } else {
                "horizontal"
            }
        ),
        U::InconsistentBitsPerSample(b) => {
            let b: Vec<u16> = b.iter().map(|&x| x as u16).collect();
            format!(
                "channels of different bit depths ({}) are not supported",
                join(&b)
            )
        }
        U::InterpretationWithBits(_, b) => format!(
            "this photometric interpretation with {} bits per sample is not supported",
            b.first().copied().unwrap_or(0)
        ),
        U::UnknownInterpretation => match raw.and_then(|r| r.unsigned(l, tag::PHOTOMETRIC)) {
            Some(p @ (32844 | 32845)) => super::logluv(p),
            Some(p) => format!("photometric interpretation {p} is not supported"),
            None => "its PhotometricInterpretation tag does not hold one number".into(),
        },
        U::UnknownCompressionMethod => "its compression method is unknown".into(),
        U::UnsupportedCompressionMethod(m) => format!(
            "{} is not supported (parvo reads uncompressed, LZW, Deflate/ZIP, PackBits, JPEG \
         and CCITT Group 4 TIFF)",
            compression_name(m.to_u16())
        ),
        U::UnsupportedSampleDepth(b) | U::UnsupportedBitsPerChannel(b) => {
            format!("{b}-bit samples are not supported")
        }
        U::UnsupportedSampleFormat(_) => {
            match raw.and_then(|r| r.unsigned(l, tag::SAMPLE_FORMAT)) {
                Some(f) => format!(
                    "SampleFormat {f} is not supported (1 unsigned and 2 signed integers, 3 floats are)"
                ),
                None => "its SampleFormat is not supported (1 unsigned and 2 signed integers, 3 \
                     floats are)"
                    .into(),
            }
        }
        U::UnsupportedColorType(_) => {
            "this combination of channels and bit depth is not supported".into()
        }
        U::UnsupportedPlanarConfig(_) => "this planar configuration is not supported".into(),
        U::UnsupportedDataType => "a tag's data type is not supported".into(),
        U::UnsupportedInterpretation(_) => {
            "this photometric interpretation is not supported".into()
        }
        U::ChromaSubsampling => "subsampled YCbCr is not supported".into(),
        U::MisalignedTileBoundaries => {
            "tiles whose rows do not end on a byte are not supported".into()
        }
        other => format!("{other}"),
    }
}

/// Why the crate found the strip or tile tables inconsistent, from the
/// directory's own entries.
fn sizes_disagree(r: &chain::Dir, l: &chain::Layout) -> String {
    let samples = r.unsigned(l, tag::SAMPLES_PER_PIXEL).unwrap_or(1);
    let extra = r.entry(tag::EXTRA_SAMPLES).map_or(0, |e| e.count);
    if extra > samples {
        return format!(
            "ExtraSamples lists {extra} extra channels, but SamplesPerPixel is {samples}"
        );
    }
    if let Some(b) = r.entry(tag::BITS_PER_SAMPLE)
        && b.count != 1
        && b.count != samples
    {
        return format!(
            "BitsPerSample has {} values for {samples} sample{} per pixel",
            b.count,
            if samples == 1 { "" } else { "s" }
        );
    }
    let planes = if r.unsigned(l, tag::PLANAR_CONFIGURATION) == Some(2) {
        samples
    } else {
        1
    };
    let (w, h) = (
        r.unsigned(l, tag::IMAGE_WIDTH).unwrap_or(0),
        r.unsigned(l, tag::IMAGE_LENGTH).unwrap_or(0),
    );
    let per_plane = |n: u64| {
        if planes > 1 {
            format!(" in each of {planes} planes")
        } else {
            let _ = n;
            String::new()
        }
    };
    if let (Some(o), Some(c)) = (r.entry(tag::TILE_OFFSETS), r.entry(tag::TILE_BYTE_COUNTS)) {
        if o.count != c.count {
            return format!(
                "TileOffsets has {} values, TileByteCounts {}",
                o.count, c.count
            );
        }
        let (tw, th) = (
            r.unsigned(l, tag::TILE_WIDTH).unwrap_or(0),
            r.unsigned(l, tag::TILE_LENGTH).unwrap_or(0),
        );
        if tw > 0 && th > 0 {
            let want = w.div_ceil(tw) * h.div_ceil(th) * planes;
            return format!(
                "it lists {} tile{}, a {w}x{h} image in {tw}x{th} tiles has {}{}",
                o.count,
                if o.count == 1 { "" } else { "s" },
                want / planes.max(1),
                per_plane(want)
            );
        }
    } else if let (Some(o), Some(c)) =
        (r.entry(tag::STRIP_OFFSETS), r.entry(tag::STRIP_BYTE_COUNTS))
    {
        if o.count != c.count {
            return format!(
                "StripOffsets has {} values, StripByteCounts {}",
                o.count, c.count
            );
        }
        let rows = r
            .unsigned(l, tag::ROWS_PER_STRIP)
            .unwrap_or(h)
            .min(h.max(1));
        if rows == 0 {
            return "RowsPerStrip is 0".into();
        }
        let want = h.div_ceil(rows) * planes;
        return format!(
            "it lists {} strip{}, {h} rows in strips of {rows} rows make {}{}",
            o.count,
            if o.count == 1 { "" } else { "s" },
            want / planes.max(1),
            per_plane(want)
        );
    }
    "its tags disagree about the layout of the image".into()
}

/// A corrupt compressed stream, named by its compression.
fn compressed_corrupt(raw: Option<&chain::Dir>, l: &chain::Layout, message: &str) -> Error {
    let method = raw
        .and_then(|r| r.unsigned(l, tag::COMPRESSION))
        .unwrap_or(0);
    decode_err(match method {
        5 => format!(
            "the LZW-compressed pixel data cannot be decoded ({message}): the file is corrupt, or \
             written with the old LZW variant of TIFF 5.0, which parvo does not read"
        ),
        m => format!(
            "the pixel data ({}) is corrupt ({message})",
            compression_name(m as u16)
        ),
    })
}

fn crate_tag_name(t: Tag) -> String {
    tag_name(t.to_u16())
}

pub(super) fn compression_name(c: u16) -> String {
    let name = match c {
        1 => return "no compression".into(),
        2 => "CCITT RLE",
        3 => "CCITT Group 3",
        4 => "CCITT Group 4",
        5 => "LZW",
        6 => "old-style JPEG",
        7 => "JPEG",
        8 | 32946 => "Deflate",
        32773 => "PackBits",
        32809 => "ThunderScan",
        34887 => "LERC",
        34925 => "LZMA",
        50000 => "Zstandard",
        50001 => "WebP",
        50002 => "JPEG XL",
        other => return format!("compression method {other}"),
    };
    format!("{name} compression")
}
