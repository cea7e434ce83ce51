//! Issue 27 #9 (PNG, JPEG, TIFF, HDR part): decode errors printed the
//! decoders' own terms: Rust debug structures (`ChunkType { type: IDAT,
//! critical: true, … } chunk appeared before IHDR chunk` for image-png's
//! `x_ihdr_missing.png`), doubled prefixes ("cannot decode PNG: Format
//! error decoding Png: …"), the TIFF crate's "inconsistent sizes
//! encountered", "failed to fill whole buffer" and "decoder limits
//! exceeded" (not tied to the limits parvo documents). Each is now one
//! line saying what is wrong with the file; a limit is a limit error.

use std::path::Path;

use super::util::{RawIfd, parvo, peer, s, write_raw_tiff};

/// Words of the decoders that must not reach a user.
const JARGON: [&str; 9] = [
    "ChunkType",
    "{",
    "Format error decoding",
    "failed to fill whole buffer",
    "inconsistent sizes",
    "decoder limits exceeded",
    "Png",
    "Jpeg",
    "Hdr",
];

/// The error of loading `path` (through the library and through `parvo
/// info`), checked to be one plain line; returned for the caller's
/// specific check.
fn error_of(path: &Path) -> String {
    let e = match parvo::io::load(s(path), &parvo::io::Limits::default()) {
        Ok(_) => panic!("{}: loaded, expected an error", path.display()),
        Err(e) => e.to_string(),
    };
    let r = parvo(&["info", s(path)]);
    assert_eq!(r.status.code(), Some(1));
    let cli = String::from_utf8_lossy(&r.stderr).into_owned();
    assert!(
        cli.contains(&e),
        "the CLI prints the library's error: {cli}"
    );
    assert_eq!(cli.trim_end().lines().count(), 1, "one line: {cli}");
    for j in JARGON {
        assert!(!e.contains(j), "`{j}` in: {e}");
    }
    e
}

fn png_bytes() -> Vec<u8> {
    let img = image::RgbImage::from_fn(9, 7, |x, y| image::Rgb([x as u8 * 20, y as u8 * 30, 7]));
    let mut out = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut out), image::ImageFormat::Png)
        .unwrap();
    out
}

#[test]
fn png_errors_say_what_is_wrong_in_words() {
    let e = error_of(&peer("x_ihdr_missing.png"));
    assert!(
        e.contains("the IDAT chunk comes before the IHDR header chunk"),
        "{e}"
    );
    let dir = tempfile::tempdir().unwrap();
    let good = png_bytes();
    // The IDAT chunk's stored CRC changed: it no longer matches.
    let idat = good.windows(4).position(|w| w == b"IDAT").unwrap();
    let len = u32::from_be_bytes(good[idat - 4..idat].try_into().unwrap()) as usize;
    let mut bad = good.clone();
    bad[idat + 4 + len] ^= 0x55;
    let p = dir.path().join("crc.png");
    std::fs::write(&p, &bad).unwrap();
    let e = error_of(&p);
    assert!(e.contains("checksum (CRC) of the IDAT chunk"), "{e}");
    // Cut inside the IDAT chunk.
    let p = dir.path().join("cut.png");
    std::fs::write(&p, &good[..idat + 10]).unwrap();
    let e = error_of(&p);
    assert!(e.contains("truncated") || e.contains("cut short"), "{e}");
    // A header with RGB at 2 bits per sample.
    let mut bad = good.clone();
    bad[24] = 2;
    let crc = crc32(&bad[12..29]);
    bad[29..33].copy_from_slice(&crc.to_be_bytes());
    let p = dir.path().join("depth.png");
    std::fs::write(&p, &bad).unwrap();
    let e = error_of(&p);
    assert!(e.contains("RGB at 2 bits per sample"), "{e}");
}

#[test]
fn jpeg_and_hdr_errors_say_what_is_wrong_in_words() {
    let dir = tempfile::tempdir().unwrap();
    let img = image::RgbImage::from_fn(33, 17, |x, y| image::Rgb([x as u8 * 7, y as u8 * 13, 99]));
    let mut jpg = Vec::new();
    img.write_to(
        &mut std::io::Cursor::new(&mut jpg),
        image::ImageFormat::Jpeg,
    )
    .unwrap();
    let p = dir.path().join("cut.jpg");
    std::fs::write(&p, &jpg[..60]).unwrap();
    let e = error_of(&p);
    assert!(e.contains("truncated"), "{e}");
    let hdr_img = image::Rgb32FImage::from_fn(20, 9, |x, y| image::Rgb([x as f32, y as f32, 0.5]));
    let mut hdr = Vec::new();
    image::DynamicImage::ImageRgb32F(hdr_img)
        .write_to(&mut std::io::Cursor::new(&mut hdr), image::ImageFormat::Hdr)
        .unwrap();
    let p = dir.path().join("cut.hdr");
    std::fs::write(&p, &hdr[..hdr.len() - 40]).unwrap();
    let e = error_of(&p);
    assert!(e.contains("truncated"), "{e}");
}

fn grey_strips(w: u32, h: u32, offsets_for: usize, data: Vec<u8>) -> RawIfd {
    RawIfd {
        entries: vec![
            (256, 4, vec![w]),
            (257, 4, vec![h]),
            (258, 3, vec![8]),
            (262, 3, vec![1]),
            (277, 3, vec![1]),
            (278, 4, vec![h]),
        ],
        chunks: vec![data; offsets_for],
        tiled: false,
    }
}

#[test]
fn tiff_errors_say_what_is_wrong_in_words() {
    let dir = tempfile::tempdir().unwrap();
    // Two strips listed where 4 rows in strips of 4 rows make one.
    let p = dir.path().join("two.tif");
    write_raw_tiff(&p, &[grey_strips(3, 4, 2, vec![1; 12])], None);
    let e = error_of(&p);
    assert!(e.contains("it lists 2 strips"), "{e}");
    assert!(e.contains("make 1"), "{e}");
    // The one strip cut short by the end of the file.
    let p = dir.path().join("short.tif");
    write_raw_tiff(&p, &[grey_strips(30, 40, 1, vec![1; 1200])], None);
    let mut bytes = std::fs::read(&p).unwrap();
    // The strip is written first, after the 8-byte header; move the
    // directory up over its second half.
    let dir_at = u32::from_le_bytes(bytes[4..8].try_into().unwrap()) as usize;
    let ifd = bytes[dir_at..].to_vec();
    bytes.truncate(8 + 600);
    let new_at = bytes.len() as u32;
    bytes.extend_from_slice(&ifd);
    // Offsets stored beyond the entries (none here: all fit) stay valid
    // only if they point before the cut; the entries hold everything.
    bytes[4..8].copy_from_slice(&new_at.to_le_bytes());
    std::fs::write(&p, &bytes).unwrap();
    let e = error_of(&p);
    assert!(
        e.contains("strip 0 of 1 lies past the end of the file") && e.contains("truncated"),
        "{e}"
    );
}

/// The decoding buffer of 64-bit float samples is twice what their f32
/// texels take: the `tiff` crate's own limit refused it with "decoder
/// limits exceeded"; it is parvo's allocation limit, and says so.
#[test]
fn a_tiff_over_the_allocation_limit_is_a_limit_error() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (64u32, 64u32);
    let data: Vec<u8> = (0..w * h).flat_map(|i| (i as f64).to_le_bytes()).collect();
    let mut d = grey_strips(w, h, 1, data);
    d.entries.retain(|e| e.0 != 258);
    d.entries.push((258, 3, vec![64]));
    d.entries.push((339, 3, vec![3]));
    let p = dir.path().join("f64.tif");
    write_raw_tiff(&p, &[d], None);
    let limits = parvo::io::Limits {
        max_alloc: 20_000,
        ..parvo::io::Limits::default()
    };
    // The f32 texels (16 KiB) fit the limit; the f64 samples do not.
    match parvo::io::load(s(&p), &limits) {
        Err(parvo::Error::Limits(m)) => assert!(m.contains("allowed"), "{m}"),
        other => panic!("expected a limit error, got {:?}", other.map(|_| ())),
    }
    let l = parvo::io::load(s(&p), &parvo::io::Limits::default()).unwrap();
    assert_eq!(l.base().to_linear()[4095], 4095.0);
}

/// CRC-32 of PNG chunks (ISO 3309), bit by bit.
fn crc32(bytes: &[u8]) -> u32 {
    let mut c = 0xFFFF_FFFFu32;
    for &b in bytes {
        c ^= b as u32;
        for _ in 0..8 {
            c = if c & 1 != 0 {
                0xEDB8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
        }
    }
    !c
}
