//! Peer corpus: Pillow's `1_trns.png` (1-bit grey, `tRNS` grey 0x00FF)
//! loaded with alpha 1 everywhere, where OpenImageIO and Pillow make the
//! white texels transparent. A `tRNS` sample is stored in 16 bits and, at
//! bit depths below 16, only its low bits count (libpng keeps
//! `gray & (2^depth − 1)`); the `png` decoder compared the whole low byte
//! with the 1-, 2- or 4-bit sample and so never matched a value beyond the
//! depth. Every colour type and depth that can carry `tRNS` is checked
//! here against the PNG specification's reading of samples the test
//! makes itself (OpenImageIO agrees on all of them: see the report of the
//! change).

use std::path::Path;

use super::util::{ok, parvo, png_u16, s};
use parvo::io::{Limits, load};
use parvo::texel::Texels;

/// The PNG specification's reading of a file: RGBA (or grey + alpha)
/// samples as 16-bit codes, each sample expanded to the full range
/// (`v · 65535 / (2^depth − 1)`), alpha 0 where the `tRNS` rule says.
struct Case {
    name: String,
    depth: u8,
    colour: png::ColorType,
    /// Samples as stored, `channels` per texel (palette: indices).
    samples: Vec<u16>,
    trns: Vec<u8>,
    palette: Option<Vec<u8>>,
}

const W: u32 = 37;
const H: u32 = 23;

/// A small deterministic generator (xorshift), so the cases are the same
/// on every run.
struct Rng(u64);
impl Rng {
    fn next(&mut self, n: u32) -> u32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 % n as u64) as u32
    }
}

fn write(case: &Case, path: &Path) {
    let file = std::fs::File::create(path).unwrap();
    let mut enc = png::Encoder::new(std::io::BufWriter::new(file), W, H);
    enc.set_color(case.colour);
    enc.set_depth(match case.depth {
        1 => png::BitDepth::One,
        2 => png::BitDepth::Two,
        4 => png::BitDepth::Four,
        8 => png::BitDepth::Eight,
        _ => png::BitDepth::Sixteen,
    });
    if let Some(p) = &case.palette {
        enc.set_palette(p.clone());
    }
    enc.set_trns(case.trns.clone());
    let mut w = enc.write_header().unwrap();
    let spp = case.samples.len() / (W * H) as usize;
    let mut data = Vec::new();
    for row in case.samples.chunks_exact(W as usize * spp) {
        match case.depth {
            16 => data.extend(row.iter().flat_map(|v| v.to_be_bytes())),
            8 => data.extend(row.iter().map(|&v| v as u8)),
            d => {
                let per = 8 / d as usize;
                for chunk in row.chunks(per) {
                    let mut byte = 0u8;
                    for (j, &v) in chunk.iter().enumerate() {
                        byte |= (v as u8) << (8 - d as usize * (j + 1));
                    }
                    data.push(byte);
                }
            }
        }
    }
    w.write_image_data(&data).unwrap();
}

/// The texels the specification defines, as 16-bit codes with the channel
/// count parvo keeps (grey + alpha, RGBA).
fn expected(case: &Case) -> (usize, Vec<u16>) {
    let max = (1u32 << case.depth) - 1;
    let widen = |v: u16| (v as u32 * 65535 / max) as u16;
    let be = |i: usize| u16::from_be_bytes([case.trns[2 * i], case.trns[2 * i + 1]]);
    let mut out = Vec::new();
    match case.colour {
        png::ColorType::Grayscale => {
            let t = be(0) & max as u16;
            for &v in &case.samples {
                out.extend([widen(v), if v == t { 0 } else { 65535 }]);
            }
            (2, out)
        }
        png::ColorType::Rgb => {
            let t = [be(0), be(1), be(2)].map(|c| c & max as u16);
            for px in case.samples.chunks_exact(3) {
                out.extend(px.iter().map(|&v| widen(v)));
                out.push(if px == t { 0 } else { 65535 });
            }
            (4, out)
        }
        _ => {
            let p = case.palette.as_ref().unwrap();
            // A tRNS longer than the palette is invalid: ignored whole
            // (libpng's reading, and the `png` decoder's).
            let trns: &[u8] = if case.trns.len() <= p.len() / 3 {
                &case.trns
            } else {
                &[]
            };
            for &i in &case.samples {
                let i = i as usize;
                out.extend(p[3 * i..3 * i + 3].iter().map(|&c| c as u16 * 257));
                out.push(trns.get(i).map_or(65535, |&a| a as u16 * 257));
            }
            (4, out)
        }
    }
}

fn cases() -> Vec<Case> {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut cases = Vec::new();
    let n = (W * H) as usize;
    for depth in [1u8, 2, 4, 8, 16] {
        let max = (1u32 << depth) - 1;
        // Values the samples take: all of them at low depths, a few
        // (among them the tRNS values below) at 8 and 16 bits.
        let pool: Vec<u16> = if depth < 8 {
            (0..=max as u16).collect()
        } else {
            vec![
                0,
                (max / 2) as u16,
                (max / 3) as u16,
                max as u16,
                0x55,
                0x7f,
            ]
        };
        let samples: Vec<u16> = (0..n)
            .map(|_| pool[rng.next(pool.len() as u32) as usize])
            .collect();
        // In range; the maximum; 0x00FF (1_trns.png's value, beyond 1, 2
        // and 4 bits); a high byte set.
        let mut values = vec![max / 2, max, 0x00ff];
        if depth < 16 {
            values.push(0x0100 | (max / 3));
        }
        for t in values {
            cases.push(Case {
                name: format!("grey {depth}-bit, tRNS {t:#06x}"),
                depth,
                colour: png::ColorType::Grayscale,
                samples: samples.clone(),
                trns: (t as u16).to_be_bytes().to_vec(),
                palette: None,
            });
        }
    }
    for depth in [8u8, 16] {
        let max = (1u32 << depth) - 1;
        let step = (max / 3) as u16;
        let samples: Vec<u16> = (0..n * 3).map(|_| rng.next(4) as u16 * step).collect();
        for t in [[step, 0, max as u16], [0x100 | step, 0, 0x200 | step]] {
            cases.push(Case {
                name: format!("RGB {depth}-bit, tRNS {t:x?}"),
                depth,
                colour: png::ColorType::Rgb,
                samples: samples.clone(),
                trns: t.iter().flat_map(|c| c.to_be_bytes()).collect(),
                palette: None,
            });
        }
    }
    for depth in [1u8, 2, 4, 8] {
        // At 8 bits a palette of 200 entries, so that a tRNS one entry
        // longer than it still fits the chunk's 256.
        let entries = if depth == 8 { 200 } else { 1u32 << depth };
        let samples: Vec<u16> = (0..n).map(|_| rng.next(entries) as u16).collect();
        let palette: Vec<u8> = (0..entries * 3).map(|_| rng.next(256) as u8).collect();
        for len in [1, entries.div_ceil(2), entries, entries + 1] {
            cases.push(Case {
                name: format!("palette {depth}-bit, {len} tRNS entries for {entries} colours"),
                depth,
                colour: png::ColorType::Indexed,
                samples: samples.clone(),
                trns: (0..len).map(|_| rng.next(256) as u8).collect(),
                palette: Some(palette.clone()),
            });
        }
    }
    cases
}

fn codes(t: &parvo::texture::Texture) -> Vec<u16> {
    match t.texels() {
        Texels::U8(v) => v.iter().map(|&x| x as u16 * 257).collect(),
        Texels::U16(v) => v.clone(),
        other => panic!("a PNG loads as integer codes, not {other:?}"),
    }
}

#[test]
fn every_trns_colour_type_and_depth_reads_as_the_specification_says() {
    let dir = tempfile::tempdir().unwrap();
    let mut failures = Vec::new();
    let mut transparent_total = 0;
    for (k, case) in cases().iter().enumerate() {
        let p = dir.path().join(format!("c{k}.png"));
        write(case, &p);
        let (ch, want) = expected(case);
        transparent_total += want.chunks_exact(ch).filter(|px| px[ch - 1] == 0).count();
        let l = load(s(&p), &Limits::default()).unwrap();
        let b = l.base();
        assert_eq!((b.width(), b.height()), (W, H), "{}", case.name);
        if b.channels() != ch {
            failures.push(format!(
                "{}: {} channels, expected {ch}",
                case.name,
                b.channels()
            ));
            continue;
        }
        let got = codes(b);
        let bad = got.iter().zip(&want).filter(|(a, b)| a != b).count();
        if bad > 0 {
            let i = got.iter().zip(&want).position(|(a, b)| a != b).unwrap();
            failures.push(format!(
                "{}: {bad} of {} values differ (first at texel {}: {:?}, expected {:?})",
                case.name,
                want.len(),
                i / ch,
                &got[i / ch * ch..i / ch * ch + ch],
                &want[i / ch * ch..i / ch * ch + ch]
            ));
        }
    }
    // The cases do exercise transparency.
    assert!(transparent_total > 1000, "{transparent_total}");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The peer file itself: its samples read with the `png` crate without
/// any transformation (packed bits, unpacked here), alpha 0 exactly where
/// the sample is 1 (0x00FF's low bit), through the library and through
/// `parvo mip`'s PNG levels.
#[test]
fn pillow_1_trns_makes_its_white_texels_transparent() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/peer/pillow/1_trns.png");
    let mut dec = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&path).unwrap()));
    dec.set_transformations(png::Transformations::IDENTITY);
    let mut r = dec.read_info().unwrap();
    let (w, h) = r.info().size();
    assert_eq!(r.info().bit_depth, png::BitDepth::One);
    let mut buf = vec![0; r.output_buffer_size().unwrap()];
    let frame = r.next_frame(&mut buf).unwrap();
    let stride = frame.line_size;
    let bits: Vec<u16> = (0..h as usize)
        .flat_map(|y| {
            let row = &buf[y * stride..(y + 1) * stride];
            (0..w as usize).map(move |x| ((row[x / 8] >> (7 - x % 8)) & 1) as u16)
        })
        .collect();
    let want: Vec<u16> = bits
        .iter()
        .flat_map(|&b| [b * 65535, if b == 1 { 0 } else { 65535 }])
        .collect();
    let white = bits.iter().filter(|&&b| b == 1).count();
    assert!(white > 0 && white < bits.len(), "{white}");

    let l = load(s(&path), &Limits::default()).unwrap();
    assert_eq!(l.base().channels(), 2);
    assert_eq!(codes(l.base()), want, "library load");

    let dir = tempfile::tempdir().unwrap();
    let tpl = dir.path().join("l_{level}.png");
    ok(&parvo(&["mip", s(&path), "-o", s(&tpl)]));
    let (lw, lh, ch, v) = png_u16(&dir.path().join("l_0.png"));
    assert_eq!((lw, lh, ch), (w, h, 2));
    assert_eq!(v, want, "parvo mip's level 0");
}
