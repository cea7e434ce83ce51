//! The errors of the PNG, JPEG and Radiance HDR decoders (the `png` and
//! `image` crates, and `zune-jpeg` under `image`) in plain words.
//!
//! Those crates describe a broken file in their own terms: Rust debug
//! structures (`ChunkType { type: IDAT, critical: true, … }`), doubled
//! prefixes (`Format error decoding Png: …`), debug-quoted strings, the
//! I/O layer's `failed to fill whole buffer`. parvo reports one line a
//! user understands: what is wrong with the file ("the IDAT chunk comes
//! before the IHDR header chunk: the file is corrupt", "the file ends
//! early: it is truncated"). Most of their error types are opaque (only
//! their text is public), so the mapping works on that text, by the
//! messages each decoder version in `Cargo.lock` produces, and falls back
//! to the decoder's own sentence with the debug structures stripped.

use std::error::Error as _;

use crate::error::Error;

use super::{FileFormat, Limits};

fn decode(format: FileFormat, reason: impl Into<String>) -> Error {
    Error::Decode {
        format: format.name(),
        reason: reason.into(),
    }
}

/// Where a decoder needs more memory than the allocation limit allows.
fn over_limit(format: FileFormat, limits: &Limits) -> Error {
    Error::Limits(format!(
        "decoding this {format} needs more memory than the allocation limit of {} allows \
         (raise with {})",
        super::limits::byte_size(limits.max_alloc),
        crate::setting::Setting::MaxAlloc
    ))
}

/// An `image` crate error of a `format` file in words.
pub(super) fn image_error(format: FileFormat, limits: &Limits, e: image::ImageError) -> Error {
    use image::ImageError as E;
    match e {
        E::Limits(_) => over_limit(format, limits),
        E::IoError(io) => io_error(format, &io),
        E::Decoding(d) => match d.source() {
            Some(inner) => match inner.downcast_ref::<png::DecodingError>() {
                Some(p) => png_error(limits, p),
                None => decoder_text(format, &inner.to_string()),
            },
            None => decode(format, "the file is corrupt"),
        },
        E::Unsupported(u) => decode(format, unsupported(format, &u)),
        E::Parameter(p) => decode(
            format,
            format!("the decoded image does not match its header ({p})"),
        ),
        other => decode(format, strip_debug(&other.to_string())),
    }
}

fn io_error(format: FileFormat, io: &std::io::Error) -> Error {
    match io.kind() {
        std::io::ErrorKind::UnexpectedEof => decode(format, "the file ends early: it is truncated"),
        _ => decode(
            format,
            format!("cannot read the file: {}", crate::error::io_words(io)),
        ),
    }
}

fn unsupported(format: FileFormat, u: &image::error::UnsupportedError) -> String {
    use image::error::UnsupportedErrorKind as K;
    match u.kind() {
        K::Color(c) => format!("its colour layout ({c:?}) is not supported"),
        K::Format(_) => {
            let text = u.to_string();
            match (format, text.contains("xyze")) {
                (FileFormat::Hdr, true) => {
                    "its pixels are XYZE (FORMAT=32-bit_rle_xyze), not RGBE; parvo reads RGBE"
                        .into()
                }
                (FileFormat::Hdr, false) => "its FORMAT header line names another pixel format \
                                             than 32-bit_rle_rgbe, the one parvo reads"
                    .into(),
                _ => printable(&strip_debug(&text)),
            }
        }
        K::GenericFeature(f) => {
            let f = f.trim_matches('"');
            let lower = f.to_ascii_lowercase();
            let scheme = [
                (
                    "extended sequential huffman",
                    "12-bit (extended sequential) JPEG",
                ),
                ("lossless huffman", "lossless JPEG"),
                ("lossless arithmetic", "lossless arithmetic-coded JPEG"),
                (
                    "extended sequential dct arithmetic",
                    "arithmetic-coded JPEG",
                ),
                (
                    "progressive dct arithmetic",
                    "progressive arithmetic-coded JPEG",
                ),
            ]
            .iter()
            .find(|(k, _)| lower.contains(k))
            .map(|(_, v)| *v);
            match scheme {
                Some(s) => format!("{s} is not supported"),
                None => format!("{} is not supported", strip_debug(f)),
            }
        }
        _ => strip_debug(&u.to_string()),
    }
}

/// A `png` crate error in words.
pub(super) fn png_error(limits: &Limits, e: &png::DecodingError) -> Error {
    use png::DecodingError as D;
    match e {
        D::IoError(io) => io_error(FileFormat::Png, io),
        D::LimitsExceeded => over_limit(FileFormat::Png, limits),
        D::Format(f) => decode(FileFormat::Png, png_format(&f.to_string())),
        D::Parameter(p) => decode(
            FileFormat::Png,
            format!("the decoded image does not match its header ({p})"),
        ),
    }
}

/// The `png` crate's format-error text (its error kinds are private) in
/// words.
fn png_format(text: &str) -> String {
    let t = text.trim_end_matches('.');
    chunk_fault(t)
        .or_else(|| data_fault(t))
        .or_else(|| header_fault(t))
        .or_else(|| palette_fault(t))
        .unwrap_or_else(|| {
            if t.contains("tEXt") || t.contains("iTXt") || t.contains("compressed text") {
                corrupt(format!("a text chunk is invalid ({})", lower_first(t)))
            } else {
                corrupt(lower_first(&printable(&strip_debug(t))))
            }
        })
}

/// `what`, said to make the file corrupt.
fn corrupt(what: String) -> String {
    format!("{what}: the file is corrupt")
}

/// A chunk that is damaged, misplaced, repeated or unknown (the `png`
/// error names it in a `ChunkType { type: … }` debug structure).
fn chunk_fault(t: &str) -> Option<String> {
    let chunks = chunk_names(t);
    let first = chunks.first().cloned().unwrap_or_else(|| "a".into());
    let chunk = |c: &str| {
        if c.chars().all(|c| c.is_ascii_alphabetic()) && c.len() == 4 {
            format!("the {c} chunk")
        } else {
            "bytes that are not a PNG chunk".to_string()
        }
    };
    let what = if t.starts_with("CRC error") {
        format!(
            "the checksum (CRC) of {} does not match its data",
            chunk(&first)
        )
    } else if t.ends_with("appeared before IHDR chunk") {
        let c = chunk(&first);
        let verb = if c.starts_with("the ") {
            "comes"
        } else {
            "come"
        };
        format!("{c} {verb} before the IHDR header chunk")
    } else if t.ends_with("is invalid after IDAT chunk") {
        format!(
            "{} comes after the image data (IDAT), where PNG does not allow it",
            chunk(&first)
        )
    } else if t.ends_with("is invalid before PLTE chunk") {
        format!("{} comes before the palette (PLTE)", chunk(&first))
    } else if t.ends_with("is invalid after PLTE chunk") {
        format!("{} comes after the palette (PLTE)", chunk(&first))
    } else if t.ends_with("must appear between PLTE and IDAT chunks") {
        format!(
            "{} is not between the palette (PLTE) and the image data (IDAT)",
            chunk(&first)
        )
    } else if t.ends_with("must appear at most once") {
        format!("{} appears more than once", chunk(&first))
    } else if t.starts_with("Chunk length wrong") {
        format!("the length of {} is wrong", chunk(&first))
    } else if let Some(name) = t.strip_prefix("Unrecognized critical chunk: ") {
        let name = name.trim_matches('"');
        if name.len() == 4 && name.chars().all(|c| c.is_ascii_alphabetic()) {
            format!("it has an unknown critical chunk, {name}, which a reader must not skip")
        } else {
            "it has bytes where a chunk should be".into()
        }
    } else if t.starts_with("Unexpected restart of") {
        format!("the run of {first} chunks is interrupted")
    } else {
        return None;
    };
    Some(corrupt(what))
}

/// A fault of the signature, the gamma, the animation chunks or the
/// image data (missing, short, not inflating).
fn data_fault(t: &str) -> Option<String> {
    Some(if t.starts_with("Bad gamma value") {
        corrupt("its gAMA chunk holds an invalid gamma".into())
    } else if t.contains("fcTL") || t.contains("fdAT") || t.contains("Sequence is not in order") {
        corrupt(format!(
            "its animation chunks are invalid ({})",
            lower_first(t)
        ))
    } else if t.starts_with("Invalid PNG signature") {
        "not a PNG file (its 8-byte signature is wrong)".into()
    } else if t.starts_with("IDAT or fdAT chunk is missing") {
        "it has no image data (no IDAT chunk): the file is corrupt or truncated".into()
    } else if t.starts_with("IDAT or fDAT chunk does not have enough data") {
        "its image data ends before the image does: the file is truncated".into()
    } else if t.starts_with("Corrupt deflate stream") {
        "its compressed image data (IDAT) is corrupt or cut short".into()
    } else {
        return None;
    })
}

/// A header (IHDR) value PNG does not allow: size, colour type, bit depth
/// or their combination, compression, filter or interlace method.
fn header_fault(t: &str) -> Option<String> {
    if t.starts_with("Invalid image dimensions") {
        return Some(corrupt(
            "its header declares a width or height of 0 or above 2^31".into(),
        ));
    }
    if let Some(rest) = t.strip_prefix("Invalid color/depth combination in header: ") {
        let (c, d) = rest.split_once('/').unwrap_or((rest, ""));
        let colour = match c {
            "Grayscale" => "grey",
            "Rgb" => "RGB",
            "Indexed" => "indexed-colour",
            "GrayscaleAlpha" => "grey + alpha",
            "Rgba" => "RGBA",
            other => other,
        };
        let depth = match d {
            "One" => "1",
            "Two" => "2",
            "Four" => "4",
            "Eight" => "8",
            "Sixteen" => "16",
            other => other,
        };
        return Some(corrupt(format!(
            "its header declares {colour} at {depth} bits per sample, which PNG does not allow"
        )));
    }
    for (prefix, what) in [
        ("Invalid bit depth ", "bit depth"),
        ("Invalid color type ", "colour type"),
        // These three follow the palette faults in the `png` texts' order;
        // no text starts with two of the prefixes, so the order is free.
        ("Unknown compression method ", "compression method"),
        ("Unknown filter method ", "filter method"),
        ("Unknown interlace method ", "interlace method"),
    ] {
        if let Some(n) = t.strip_prefix(prefix) {
            return Some(corrupt(format!(
                "its header declares {what} {n}, which PNG does not define"
            )));
        }
    }
    None
}

/// A palette too short or missing for an indexed image, or a
/// transparency chunk where PNG allows none.
fn palette_fault(t: &str) -> Option<String> {
    if let Some(rest) = t.strip_prefix("Not enough palette entries, expect ") {
        let (want, got) = rest.split_once(" got ").unwrap_or((rest, "fewer"));
        return Some(corrupt(format!(
            "its palette has {got} entries, the image needs {want}"
        )));
    }
    if t.starts_with("Missing palette of indexed image") {
        return Some(corrupt(
            "an indexed-colour image without a palette (PLTE chunk)".into(),
        ));
    }
    let c = t.strip_prefix("Transparency chunk found for color type ")?;
    Some(corrupt(format!(
        "a transparency (tRNS) chunk in a {} image, where PNG does not allow one",
        c.to_ascii_lowercase()
    )))
}

/// The four-letter names in a `png` error's `ChunkType { type: IDAT, … }`
/// debug structures.
fn chunk_names(t: &str) -> Vec<String> {
    t.match_indices("ChunkType { type: ")
        .filter_map(|(i, m)| {
            let rest = &t[i + m.len()..];
            rest.find(',').map(|e| rest[..e].to_string())
        })
        .collect()
}

/// Debug structures (`Name { … }`) replaced by their first field's value
/// and debug quotes removed: the decoder's sentence as readable text.
fn strip_debug(t: &str) -> String {
    let mut out = String::with_capacity(t.len());
    let mut rest = t;
    while let Some(open) = rest.find(" { ") {
        let Some(close) = rest[open..].find(" }") else {
            break;
        };
        let head = &rest[..open];
        let name_start = head
            .rfind(|c: char| !c.is_alphanumeric())
            .map_or(0, |i| i + 1);
        out.push_str(&head[..name_start]);
        let inner = &rest[open + 3..open + close];
        let value = inner
            .split(',')
            .next()
            .and_then(|f| f.split_once(": ").map(|(_, v)| v))
            .unwrap_or(inner);
        out.push_str(value);
        rest = &rest[open + close + 2..];
    }
    out.push_str(rest);
    out.replace('"', "")
}

/// `t` with control characters and debug escapes of them (`\u{1c}`)
/// shown as `?`.
fn printable(t: &str) -> String {
    let mut out = String::with_capacity(t.len());
    let mut rest = t;
    while let Some(i) = rest.find("\\u{") {
        out.push_str(&rest[..i]);
        match rest[i..].find('}') {
            Some(e) => {
                out.push('?');
                rest = &rest[i + e + 1..];
            }
            None => break,
        }
    }
    out.push_str(rest);
    out.chars()
        .map(|c| if c.is_control() { '?' } else { c })
        .collect()
}

fn lower_first(t: &str) -> String {
    let mut c = t.chars();
    match c.next() {
        Some(f) => f.to_lowercase().collect::<String>() + c.as_str(),
        None => String::new(),
    }
}

/// Whether a JPEG file ends with its end-of-image marker (EOI, `FF D9`)
/// after its last scan, judged from its last 64 KiB: entropy-coded data
/// never holds `FF D9` (an `FF` there is followed by `00` or a restart
/// marker), so a file cut short lacks it. Bytes after the marker
/// (padding) are allowed.
pub(super) fn jpeg_has_end_marker(path: &std::path::Path) -> std::io::Result<bool> {
    use std::io::{Read, Seek, SeekFrom};
    let mut f = std::fs::File::open(path)?;
    let len = f.metadata()?.len();
    let from = len.saturating_sub(64 << 10);
    f.seek(SeekFrom::Start(from))?;
    let mut tail = Vec::new();
    f.read_to_end(&mut tail)?;
    Ok(tail_has_end_marker(&tail))
}

fn tail_has_end_marker(tail: &[u8]) -> bool {
    let after_scan = match tail.windows(2).rposition(|w| w == [0xFF, 0xDA]) {
        Some(at) => &tail[at..],
        None => tail,
    };
    after_scan.windows(2).any(|w| w == [0xFF, 0xD9])
}

/// A JPEG (zune-jpeg) or Radiance HDR decoder's text in words.
fn decoder_text(format: FileFormat, text: &str) -> Error {
    let t = text.trim().trim_matches('"');
    let lower = t.to_ascii_lowercase();
    let reason = |s: &str| -> String {
        match s.split_once("Reason:") {
            Some((_, r)) => format!(
                " ({})",
                lower_first(strip_debug(r.trim()).trim_end_matches('.'))
            ),
            None => String::new(),
        }
    };
    let words: String = match format {
        FileFormat::Jpeg => {
            if lower.contains("not enough bytes")
                || lower.contains("exhausted data")
                || lower.contains("no more bytes")
                || lower.contains("eof")
            {
                "the file ends early: it is truncated".into()
            } else if lower.contains("illegal start bytes") || lower.contains("magic") {
                "not a JPEG file (it does not start with a JPEG start-of-image marker)".into()
            } else if lower.contains("sof segment") {
                format!(
                    "its frame header (SOF) is invalid{}: the file is corrupt",
                    reason(t)
                )
            } else if lower.contains("sos segment") {
                format!(
                    "its scan header (SOS) is invalid{}: the file is corrupt",
                    reason(t)
                )
            } else if lower.contains("dqt segment") {
                format!(
                    "its quantization tables (DQT) are invalid{}: the file is corrupt",
                    reason(t)
                )
            } else if lower.contains("huffman") {
                "its Huffman-coded data or tables are invalid: the file is corrupt".into()
            } else if lower.contains("mcu") {
                "its compressed image data is corrupt".into()
            } else if lower.contains("width or height is set to zero") {
                "its header declares a width or height of 0: the file is corrupt".into()
            } else {
                format!(
                    "the file is corrupt ({})",
                    lower_first(&printable(&strip_debug(t)))
                )
            }
        }
        FileFormat::Hdr => {
            if lower.contains("signature not found") {
                "not a Radiance HDR file (it does not start with #?RADIANCE)".into()
            } else if lower.contains("eof in header") {
                "the file ends inside its header: it is truncated".into()
            } else if lower.contains("eof in dimensions") {
                "the file ends before its dimensions line (-Y height +X width): it is truncated"
                    .into()
            } else if lower.starts_with("dimensions line") {
                "its dimensions line is not of the form -Y height +X width: the file is corrupt"
                    .into()
            } else if lower.starts_with("cannot parse") || lower.starts_with("not enough numbers") {
                format!(
                    "a header line holds a value that is not a number ({}): the file is corrupt",
                    lower_first(t)
                )
            } else if lower.contains("scanline") {
                "a run-length-encoded scanline is malformed: the file is corrupt".into()
            } else {
                format!(
                    "the file is corrupt ({})",
                    lower_first(&printable(&strip_debug(t)))
                )
            }
        }
        _ => format!(
            "the file is corrupt ({})",
            lower_first(&printable(&strip_debug(t)))
        ),
    };
    decode(format, words)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn png_chunk_structures_become_chunk_names() {
        let t = "ChunkType { type: IDAT, critical: true, private: false, reserved: false, \
                 safecopy: false } chunk appeared before IHDR chunk";
        assert_eq!(
            png_format(t),
            "the IDAT chunk comes before the IHDR header chunk: the file is corrupt"
        );
        let t = "CRC error: expected 0xbadbadba have 0xe81f9f28 while decoding ChunkType { type: \
                 IDAT, critical: true, private: false, reserved: false, safecopy: false } chunk.";
        assert_eq!(
            png_format(t),
            "the checksum (CRC) of the IDAT chunk does not match its data: the file is corrupt"
        );
        let t = "ChunkType { type: R\\0y\\0, critical: true, private: false, reserved: true, \
                 safecopy: false } chunk appeared before IHDR chunk";
        assert_eq!(
            png_format(t),
            "bytes that are not a PNG chunk come before the IHDR header chunk: the file is corrupt"
        );
    }

    #[test]
    fn a_jpeg_cut_short_has_no_end_marker_after_its_last_scan() {
        // SOI, an APP1 thumbnail with its own EOI, SOS, data, EOI.
        let whole = [
            0xFF, 0xD8, 0xFF, 0xE1, 0xFF, 0xD8, 0xFF, 0xD9, 0xFF, 0xDA, 1, 2, 0xFF, 0x00, 3, 0xFF,
            0xD9, 0, 0,
        ];
        assert!(tail_has_end_marker(&whole));
        assert!(!tail_has_end_marker(&whole[..15]));
        // A tail that starts inside the scan data.
        assert!(tail_has_end_marker(&whole[11..]));
        assert!(!tail_has_end_marker(&whole[11..15]));
    }

    #[test]
    fn control_characters_and_their_escapes_print_as_question_marks() {
        assert_eq!(printable("a\\u{1c}b\u{7}c"), "a?b?c");
    }

    #[test]
    fn debug_structures_are_stripped() {
        assert_eq!(
            strip_debug("bad Foo { a: 1, b: 2 } here \"x\""),
            "bad 1 here x"
        );
    }
}
