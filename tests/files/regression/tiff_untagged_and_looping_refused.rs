//! Issue 27 #8: two TIFFs OpenImageIO reads were refused. A float grey
//! file without a PhotometricInterpretation tag (Pillow's
//! `10ct_32bit_128.tiff`: "unknown photometric interpretation"), which
//! OpenImageIO reads as BlackIsZero; and a multi-page file whose chain of
//! pages loops (Pillow's `multipage_multiple_frame_loop.tiff`: "file
//! contained a cycle"), although the pages before the loop read. Both
//! read now, with a note; that file's pages are palette images, which
//! read too (expanded through the colour map as OpenImageIO does).

use super::util::{RawIfd, Rng, ok, parvo, peer, s, write_raw_tiff};

fn strip(w: u32, h: u32, samples: u32, bits: u32, format: u32, data: Vec<u8>) -> RawIfd {
    RawIfd {
        entries: vec![
            (256, 4, vec![w]),
            (257, 4, vec![h]),
            (258, 3, vec![bits; samples as usize]),
            (277, 3, vec![samples]),
            (278, 4, vec![h]),
            (339, 3, vec![format; samples as usize]),
        ],
        chunks: vec![data],
        tiled: false,
    }
}

fn notes(path: &std::path::Path) -> Vec<String> {
    let j: serde_json::Value =
        serde_json::from_str(&ok(&parvo(&["info", "--json", s(path)]))).unwrap();
    j["notes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n.as_str().unwrap().to_string())
        .collect()
}

#[test]
fn a_tiff_without_photometric_tag_reads_as_openimageio_reads_it() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = Rng(10);
    // One float channel (10ct_32bit_128.tiff's layout): grey.
    let (w, h) = (7u32, 5u32);
    let vals: Vec<f32> = (0..w * h)
        .map(|_| (rng.next() % 4096) as f32 / 64.0 - 9.0)
        .collect();
    let p = dir.path().join("f.tif");
    write_raw_tiff(
        &p,
        &[strip(
            w,
            h,
            1,
            32,
            3,
            vals.iter().flat_map(|v| v.to_le_bytes()).collect(),
        )],
        None,
    );
    let l = parvo::io::load(s(&p), &parvo::io::Limits::default()).unwrap();
    assert_eq!(l.base().channels(), 1);
    assert_eq!(l.base().to_linear(), vals);
    assert!(
        notes(&p)
            .iter()
            .any(|n| n.contains("no PhotometricInterpretation tag: read as grey")),
        "{:?}",
        notes(&p)
    );
    // Three 8-bit channels: RGB; two: R, G data channels, no alpha.
    for (samples, names) in [(3u32, "R,G,B"), (2, "R,G")] {
        let bytes: Vec<u8> = (0..w * h * samples).map(|_| rng.next() as u8).collect();
        let p = dir.path().join(format!("u{samples}.tif"));
        write_raw_tiff(&p, &[strip(w, h, samples, 8, 1, bytes.clone())], None);
        let l = parvo::io::load(s(&p), &parvo::io::Limits::default()).unwrap();
        assert_eq!(l.info.channel_names.join(","), names);
        assert!(!l.base().format().has_alpha());
        let got = l.base().to_linear();
        assert_eq!(got.len(), bytes.len());
        for (g, &b) in got.iter().zip(&bytes) {
            assert!((g - b as f32 / 255.0).abs() < 1e-6, "{g} vs code {b}");
        }
    }
}

#[test]
fn a_looping_page_chain_reads_the_pages_before_the_loop() {
    let dir = tempfile::tempdir().unwrap();
    // Pages of 2x1, 3x1 and 4x1 grey texels; the last points back to
    // page 1.
    let pages: Vec<RawIfd> = (0..3u32)
        .map(|k| {
            let mut d = strip(k + 2, 1, 1, 8, 1, vec![40 * (k as u8 + 1); k as usize + 2]);
            d.entries.push((262, 3, vec![1]));
            d
        })
        .collect();
    let p = dir.path().join("loop.tif");
    write_raw_tiff(&p, &pages, Some(1));
    let n = notes(&p);
    assert!(n.iter().any(|n| n.contains("using page 0 of 3")), "{n:?}");
    assert!(
        n.iter()
            .any(|n| n.contains("loops (page 2 points back to page 1)")),
        "{n:?}"
    );
    let out = dir.path().join("o.exr");
    ok(&parvo(&["mip", s(&p), "-o", s(&out), "--subimage", "2"]));
    let l = parvo::io::load(s(&out), &parvo::io::Limits::default()).unwrap();
    assert_eq!((l.base().width(), l.base().height()), (4, 1));
    assert!(
        l.base()
            .to_linear()
            .iter()
            .all(|&v| (v - 120.0 / 255.0).abs() < 1e-3)
    );
    let r = parvo(&["mip", s(&p), "-o", s(&out), "--subimage", "3"]);
    assert_eq!(r.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&r.stderr).contains("the file has 3 pages"));
    // A page pointing to itself.
    let p = dir.path().join("self.tif");
    write_raw_tiff(&p, &pages[..1], Some(0));
    let l = parvo::io::load(s(&p), &parvo::io::Limits::default()).unwrap();
    assert_eq!(l.base().to_linear(), [40.0 / 255.0; 2]);
}

/// Pillow's file itself: two 10x10 pages of 1-bit palette indices, the
/// second pointing back to the first. Page 0 is decoded here from its
/// bytes (one uncompressed strip, rows of two bytes, most significant bit
/// first) and its colour map (index 0 → 0x0000, 0x8080, 0x0000; index 1
/// → black), and parvo must read the same colours.
#[test]
fn pillow_multipage_frame_loop_reads_page_zero() {
    let path = peer("multipage_multiple_frame_loop.tiff");
    let bytes = std::fs::read(&path).unwrap();
    let strip = &bytes[8..28];
    let mut want = Vec::new();
    for y in 0..10 {
        for x in 0..10 {
            let bit = (strip[y * 2 + x / 8] >> (7 - x % 8)) & 1;
            // 0x8080 / 257 = 128, as OpenImageIO reads the colour map.
            want.extend_from_slice(if bit == 0 { &[0, 128, 0] } else { &[0, 0, 0] });
        }
    }
    let l = parvo::io::load(s(&path), &parvo::io::Limits::default()).unwrap();
    let parvo::Texels::U8(got) = l.base().texels() else {
        panic!("palette pages read as 8-bit RGB");
    };
    assert_eq!(got, &want);
    let n = notes(&path);
    assert!(n.iter().any(|n| n.contains("using page 0 of 2")), "{n:?}");
    assert!(n.iter().any(|n| n.contains("loops")), "{n:?}");
}

/// A 4-bit palette image of odd width (indices straddle no byte, rows end
/// mid-byte): each index maps through the 16-bit colour map, divided by
/// 257 and rounded down (OpenImageIO's reading).
#[test]
fn a_four_bit_palette_maps_through_its_colour_map() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = Rng(4);
    let (w, h) = (5u32, 3u32);
    let map: Vec<u32> = (0..48).map(|_| (rng.next() % 65536) as u32).collect();
    let idx: Vec<u8> = (0..w * h).map(|_| (rng.next() % 16) as u8).collect();
    let mut data = Vec::new();
    for row in idx.chunks(w as usize) {
        let mut packed = vec![0u8; (w as usize).div_ceil(2)];
        for (x, &i) in row.iter().enumerate() {
            packed[x / 2] |= i << if x % 2 == 0 { 4 } else { 0 };
        }
        data.extend_from_slice(&packed);
    }
    let mut d = strip(w, h, 1, 4, 1, data);
    d.entries.push((262, 3, vec![3]));
    d.entries.push((320, 3, map.clone()));
    let p = dir.path().join("pal.tif");
    write_raw_tiff(&p, &[d], None);
    let l = parvo::io::load(s(&p), &parvo::io::Limits::default()).unwrap();
    let want: Vec<u8> = idx
        .iter()
        .flat_map(|&i| {
            let map = &map;
            (0..3).map(move |c| (map[c * 16 + i as usize] / 257) as u8)
        })
        .collect();
    let parvo::Texels::U8(got) = l.base().texels() else {
        panic!("palette read as 8-bit RGB");
    };
    assert_eq!(got, &want);
}
