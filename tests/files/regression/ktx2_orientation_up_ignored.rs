//! Peer corpus: KTX-Software-CTS's `orient-up-metadata-u.ktx2` has
//! `KTXorientation` `ru`: its rows are stored bottom to top. parvo read
//! the rows as stored without a word and labelled its own output `rd`, so
//! the output came out upside down. The orientation is now applied to
//! every level on load (rows flipped for `u`, columns for `l`) and said in
//! a note.
//!
//! The references are independent of parvo's reader: the CTS keeps `ktx
//! extract`'s PNG of the file's `rd` twin, and for files made here the
//! levels' bytes are read from the file at the offsets its level index
//! gives.

use std::path::{Path, PathBuf};

use parvo::io::{self, Limits, OutputKind, SaveOptions};
use parvo::{ChannelType, ColorSpace, Format, Rounding, Texels, Texture};

use super::util::{ok, parvo, s};

fn peer(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/peer")
        .join(name)
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap())
}

fn u64_at(b: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(b[at..at + 8].try_into().unwrap())
}

/// Every level of an uncompressed KTX2 file as stored: (width, height,
/// bytes), level 0 first, from the header and the level index.
fn stored_levels(path: &Path) -> Vec<(usize, usize, Vec<u8>)> {
    let b = std::fs::read(path).unwrap();
    assert_eq!(u32_at(&b, 44), 0, "not supercompressed");
    let (w, h, n) = (u32_at(&b, 20), u32_at(&b, 24), u32_at(&b, 40).max(1));
    (0..n as usize)
        .map(|k| {
            let (off, len) = (u64_at(&b, 80 + 24 * k), u64_at(&b, 88 + 24 * k));
            (
                (w >> k).max(1) as usize,
                (h >> k).max(1) as usize,
                b[off as usize..(off + len) as usize].to_vec(),
            )
        })
        .collect()
}

/// `bytes` (rows of `w` texels of `texel` bytes) with the rows and/or the
/// columns in reverse order.
fn flip(bytes: &[u8], w: usize, h: usize, texel: usize, rows: bool, cols: bool) -> Vec<u8> {
    let mut out = Vec::with_capacity(bytes.len());
    for y in 0..h {
        let sy = if rows { h - 1 - y } else { y };
        for x in 0..w {
            let sx = if cols { w - 1 - x } else { x };
            let i = (sy * w + sx) * texel;
            out.extend_from_slice(&bytes[i..i + texel]);
        }
    }
    out
}

fn u8s(t: &Texture) -> Vec<u8> {
    match t.texels() {
        Texels::U8(v) => v.clone(),
        other => panic!("8-bit texels expected, not {other:?}"),
    }
}

/// The CTS file against `ktx extract`'s output of its `rd` twin, through
/// the library, through `parvo info`'s note and through the KTX2 parvo
/// writes (labelled `rd`, so its stored rows must be the picture's).
#[test]
fn cts_orient_up_file_reads_as_its_down_twin() {
    let golden = image::open(peer("ktx-cts/golden/orient-down-metadata-u.png"))
        .unwrap()
        .into_rgb8();
    let (gw, gh) = golden.dimensions();
    let golden = golden.into_raw();
    for name in ["orient-up-metadata-u.ktx2", "orient-down-metadata-u.ktx2"] {
        let l = io::load(s(&peer(&format!("ktx-cts/{name}"))), &Limits::default()).unwrap();
        assert_eq!((l.base().width(), l.base().height()), (gw, gh), "{name}");
        assert_eq!(u8s(l.base()), golden, "{name}");
    }
    // The stored rows of the `ru` file are the picture upside down (the
    // file is not symmetric, so the check above can tell).
    let up = stored_levels(&peer("ktx-cts/orient-up-metadata-u.ktx2"));
    assert_ne!(up[0].2, golden);
    assert_eq!(
        flip(&up[0].2, gw as usize, gh as usize, 3, true, false),
        golden
    );

    let src = peer("ktx-cts/orient-up-metadata-u.ktx2");
    let info = parvo(&["info", s(&src)]);
    let text = ok(&info) + &String::from_utf8_lossy(&info.stderr);
    assert!(text.contains("KTXorientation `ru`"), "{text}");

    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.ktx2");
    let r = parvo(&["mip", s(&src), "-o", s(&out)]);
    ok(&r);
    assert!(String::from_utf8_lossy(&r.stderr).contains("KTXorientation `ru`"));
    let written = std::fs::read(&out).unwrap();
    assert!(
        written.windows(18).any(|w| w == b"KTXorientation\0rd\0"),
        "parvo's KTX2 says rd"
    );
    assert_eq!(stored_levels(&out)[0].2, golden, "parvo's output level 0");
}

/// A mip chain of awkward sizes written by parvo (`rd`), its
/// `KTXorientation` value then changed in the file: every level must read
/// as the stored bytes flipped as the value says.
#[test]
fn every_level_is_flipped_as_the_orientation_says() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (13u32, 7u32);
    let f = Format::new(4, ChannelType::U8, ColorSpace::Linear);
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let levels: Vec<Texture> = (0..4)
        .map(|k| {
            let (lw, lh) = parvo::mip::level_size(w, h, k, Rounding::Down);
            let v = (0..lw * lh * 4)
                .map(|_| {
                    seed ^= seed << 13;
                    seed ^= seed >> 7;
                    seed ^= seed << 17;
                    (seed >> 24) as u8
                })
                .collect();
            Texture::from_u8(lw, lh, f, v).unwrap()
        })
        .collect();
    let base = dir.path().join("rd.ktx2");
    io::save(
        &levels,
        Rounding::Down,
        &base,
        OutputKind::KTX2,
        &SaveOptions::default(),
    )
    .unwrap();
    let bytes = std::fs::read(&base).unwrap();
    let at = bytes
        .windows(18)
        .position(|w| w == b"KTXorientation\0rd\0")
        .expect("parvo writes KTXorientation rd");
    let stored = stored_levels(&base);
    assert_eq!(stored.len(), 4);
    for (value, rows, cols) in [
        ("rd", false, false),
        ("ru", true, false),
        ("ld", false, true),
        ("lu", true, true),
    ] {
        let p = dir.path().join(format!("{value}.ktx2"));
        let mut b = bytes.clone();
        // The same length in place: the key/value entry keeps its size.
        b[at + 15..at + 17].copy_from_slice(value.as_bytes());
        std::fs::write(&p, &b).unwrap();
        let l = io::load(s(&p), &Limits::default()).unwrap();
        assert_eq!(l.levels.len(), 4, "{value}");
        for (k, (lw, lh, raw)) in stored.iter().enumerate() {
            let t = &l.levels[k];
            assert_eq!((t.width() as usize, t.height() as usize), (*lw, *lh));
            assert_eq!(
                u8s(t),
                flip(raw, *lw, *lh, 4, rows, cols),
                "{value}: level {k} ({lw}x{lh})"
            );
        }
        let noted = l.info.notes.iter().any(|n| n.contains("KTXorientation"));
        assert_eq!(noted, rows || cols, "{value}: {:?}", l.info.notes);
    }
    // A value that is not an orientation: read as stored, and said.
    let p = dir.path().join("bad.ktx2");
    let mut b = bytes.clone();
    b[at + 15..at + 17].copy_from_slice(b"up");
    std::fs::write(&p, &b).unwrap();
    let l = io::load(s(&p), &Limits::default()).unwrap();
    assert_eq!(u8s(&l.levels[0]), stored[0].2);
    assert!(
        l.info
            .notes
            .iter()
            .any(|n| n.contains("KTXorientation `up` not understood")),
        "{:?}",
        l.info.notes
    );
}
