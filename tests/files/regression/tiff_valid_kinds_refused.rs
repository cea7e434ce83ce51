//! Found by the peer corpus (issue 53): valid TIFFs OpenImageIO reads were
//! refused — 10-, 12-, 14-, 24- and 32-bit unsigned samples, signed
//! integers, CMYK and YCbCr. Each file here is written byte by byte (not
//! by the `tiff` crate nor by parvo) and checked against the definition:
//! TIFF's bit packing (most significant bit first, rows on byte
//! boundaries), OpenImageIO's widening (`v · (2^16 − 1) / (2^bits − 1)`
//! rounded down), JFIF's YCbCr formula, CMYK's `(1 − C)(1 − K)`.

use super::util::{RawIfd, Rng, parvo, s, write_raw_tiff};
use parvo::Texels;

/// `codes` of `bits` bits each, packed most significant bit first, each
/// row of `per_row` codes starting on a byte.
fn pack(codes: &[u32], bits: u32, per_row: usize) -> Vec<u8> {
    let mut out = Vec::new();
    for row in codes.chunks(per_row) {
        let (mut acc, mut n) = (0u64, 0u32);
        for &c in row {
            acc = (acc << bits) | c as u64;
            n += bits;
            while n >= 8 {
                out.push((acc >> (n - 8)) as u8);
                n -= 8;
            }
        }
        if n > 0 {
            out.push((acc << (8 - n)) as u8);
        }
    }
    out
}

fn load(path: &std::path::Path) -> parvo::texture::Texture {
    parvo::io::load(s(path), &Default::default())
        .unwrap()
        .base()
        .clone()
}

fn widen(v: u32, bits: u32, to: u32) -> u64 {
    v as u64 * ((1u64 << to) - 1) / ((1u64 << bits) - 1)
}

#[test]
fn samples_of_odd_sizes_widen_as_openimageio_in_strips_and_planes() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = Rng(0x5eed_0053);
    let (w, h) = (13u32, 5u32);
    // (bits, samples, planar, photometric)
    for (bits, samples, planar, photometric) in [
        (12u32, 3u32, false, 2u32),
        (10, 3, true, 2),
        (14, 1, false, 0),
        (24, 1, false, 1),
        (5, 3, false, 2),
    ] {
        let max = (1u32 << bits) - 1;
        let codes: Vec<u32> = (0..w * h * samples)
            .map(|_| (rng.next() as u32) & max)
            .collect();
        // Two rows per strip; planar data plane after plane.
        let rows = 2usize;
        let mut chunks = Vec::new();
        if planar {
            for c in 0..samples as usize {
                let plane: Vec<u32> = codes
                    .iter()
                    .skip(c)
                    .step_by(samples as usize)
                    .copied()
                    .collect();
                for strip in plane.chunks(rows * w as usize) {
                    chunks.push(pack(strip, bits, w as usize));
                }
            }
        } else {
            let per_row = (w * samples) as usize;
            for strip in codes.chunks(rows * per_row) {
                chunks.push(pack(strip, bits, per_row));
            }
        }
        let path = dir.path().join(format!("{bits}-{samples}-{planar}.tif"));
        write_raw_tiff(
            &path,
            &[RawIfd {
                entries: vec![
                    (256, 4, vec![w]),
                    (257, 4, vec![h]),
                    (258, 3, vec![bits; samples as usize]),
                    (262, 3, vec![photometric]),
                    (277, 3, vec![samples]),
                    (278, 4, vec![rows as u32]),
                    (284, 3, vec![if planar { 2 } else { 1 }]),
                ],
                chunks,
                tiled: false,
            }],
            None,
        );
        let t = load(&path);
        let what = format!("{bits}-bit, {samples} samples, planar {planar}");
        assert_eq!((t.width(), t.height()), (w, h), "{what}");
        assert_eq!(t.format().channels as u32, samples, "{what}");
        let invert = |v: u64, to: u32| {
            if photometric == 0 {
                (1u64 << to) - 1 - v
            } else {
                v
            }
        };
        match t.texels() {
            Texels::U16(v) => {
                let want: Vec<u16> = codes
                    .iter()
                    .map(|&c| invert(widen(c, bits, 16), 16) as u16)
                    .collect();
                assert_eq!(v, &want, "{what}");
            }
            Texels::U8(v) => {
                let want: Vec<u8> = codes.iter().map(|&c| widen(c, bits, 8) as u8).collect();
                assert_eq!(v, &want, "{what}");
            }
            Texels::F32(v) => {
                for (&got, &c) in v.iter().zip(&codes) {
                    let want = c as f64 / max as f64;
                    assert!((got as f64 - want).abs() <= 1e-7, "{what}: {got} vs {want}");
                }
            }
            _ => panic!("{what}: {}", t.format()),
        }
    }
}

#[test]
fn subsampled_ycbcr_converts_by_the_jfif_formula_with_one_chroma_per_block() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = Rng(0xcbc4);
    // A width and height that leave partial blocks at the right and bottom.
    let (w, h, sh, sv) = (7u32, 5u32, 2u32, 2u32);
    let (bw, bh) = (w.div_ceil(sh), h.div_ceil(sv));
    let mut blocks = Vec::new();
    let mut data = Vec::new();
    for _ in 0..bw * bh {
        let b: Vec<u8> = (0..sh * sv + 2).map(|_| rng.next() as u8).collect();
        data.extend_from_slice(&b);
        blocks.push(b);
    }
    // Four image rows (two rows of blocks) per strip.
    let per_strip = (2 * bw * (sh * sv + 2)) as usize;
    let chunks: Vec<Vec<u8>> = data.chunks(per_strip).map(|c| c.to_vec()).collect();
    let path = dir.path().join("ycbcr.tif");
    write_raw_tiff(
        &path,
        &[RawIfd {
            entries: vec![
                (256, 4, vec![w]),
                (257, 4, vec![h]),
                (258, 3, vec![8, 8, 8]),
                (262, 3, vec![6]),
                (277, 3, vec![3]),
                (278, 4, vec![4]),
                (530, 3, vec![sh, sv]),
            ],
            chunks,
            tiled: false,
        }],
        None,
    );
    let t = load(&path);
    assert_eq!((t.width(), t.height(), t.format().channels), (w, h, 3));
    let Texels::U8(v) = t.texels() else {
        panic!("u8 expected, got {}", t.format());
    };
    for y in 0..h {
        for x in 0..w {
            let b = &blocks[((y / sv) * bw + x / sh) as usize];
            let luma = b[((y % sv) * sh + x % sh) as usize] as f64;
            let (cb, cr) = (b[4] as f64 - 128.0, b[5] as f64 - 128.0);
            let want = [
                luma + 1.402 * cr,
                luma - 0.344136 * cb - 0.714136 * cr,
                luma + 1.772 * cb,
            ];
            let i = ((y * w + x) * 3) as usize;
            for c in 0..3 {
                let d = (v[i + c] as f64 - want[c].clamp(0.0, 255.0)).abs();
                assert!(
                    d <= 1.0,
                    "({x}, {y}) channel {c}: {} vs {:.2}",
                    v[i + c],
                    want[c]
                );
            }
        }
    }
}

#[test]
fn cmyk_and_signed_samples_convert_as_openimageio() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = Rng(0xc3c3);
    let (w, h) = (9u32, 4u32);
    let inks: Vec<u8> = (0..w * h * 4).map(|_| rng.next() as u8).collect();
    let path = dir.path().join("cmyk.tif");
    write_raw_tiff(
        &path,
        &[RawIfd {
            entries: vec![
                (256, 4, vec![w]),
                (257, 4, vec![h]),
                (258, 3, vec![8; 4]),
                (262, 3, vec![5]),
                (277, 3, vec![4]),
                (278, 4, vec![h]),
            ],
            chunks: vec![inks.clone()],
            tiled: false,
        }],
        None,
    );
    let t = load(&path);
    assert_eq!(t.format().channels, 3, "{}", t.format());
    let Texels::U8(v) = t.texels() else {
        panic!("u8 expected, got {}", t.format());
    };
    for (px, rgb) in inks.chunks(4).zip(v.chunks(3)) {
        let k = 1.0 - px[3] as f64 / 255.0;
        for c in 0..3 {
            let want = (1.0 - px[c] as f64 / 255.0) * k * 255.0;
            assert!(
                (rgb[c] as f64 - want).abs() <= 0.5 + 1e-3,
                "{px:?} -> {rgb:?}"
            );
        }
    }
    // Signed 16-bit grey: v / 32767 as f32.
    let codes: Vec<i16> = (0..w * h).map(|_| rng.next() as i16).collect();
    let path = dir.path().join("i16.tif");
    write_raw_tiff(
        &path,
        &[RawIfd {
            entries: vec![
                (256, 4, vec![w]),
                (257, 4, vec![h]),
                (258, 3, vec![16]),
                (262, 3, vec![1]),
                (278, 4, vec![h]),
                (339, 3, vec![2]),
            ],
            chunks: vec![codes.iter().flat_map(|c| c.to_le_bytes()).collect()],
            tiled: false,
        }],
        None,
    );
    let t = load(&path);
    let Texels::F32(v) = t.texels() else {
        panic!("f32 expected, got {}", t.format());
    };
    for (&got, &c) in v.iter().zip(&codes) {
        assert_eq!(got, (c as f64 / 32767.0) as f32);
    }
}

#[test]
fn kinds_still_refused_are_named_with_what_to_convert_to() {
    let dir = tempfile::tempdir().unwrap();
    for (photometric, compression, words) in [
        (
            8u32,
            1u32,
            "L*a*b* TIFF is not supported: convert it to RGB",
        ),
        (
            32845,
            1,
            "LogLuv (SGI log-encoded high dynamic range) TIFF is not supported",
        ),
        (6, 6, "old-style JPEG compression (Compression 6"),
    ] {
        let path = dir.path().join(format!("p{photometric}.tif"));
        write_raw_tiff(
            &path,
            &[RawIfd {
                entries: vec![
                    (256, 4, vec![4]),
                    (257, 4, vec![2]),
                    (258, 3, vec![8, 8, 8]),
                    (259, 3, vec![compression]),
                    (262, 3, vec![photometric]),
                    (277, 3, vec![3]),
                    (278, 4, vec![2]),
                ],
                chunks: vec![vec![0; 24]],
                tiled: false,
            }],
            None,
        );
        let o = parvo(&["info", s(&path)]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{err}");
        assert!(err.contains(words), "{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert_eq!(err.matches(s(&path)).count(), 1, "the path once: {err}");
    }
}
