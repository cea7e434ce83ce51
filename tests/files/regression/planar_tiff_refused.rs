//! Issue 27 #6: every planar TIFF (PlanarConfiguration 2) was refused
//! ("decoded N samples … planes do not all decode"), strip and tiled, 8
//! and 16 bit, raw and LZW, although the README claimed them: the `tiff`
//! crate's `read_image` decodes only the first plane. Every plane is now
//! read and interleaved.

use super::util::{RawIfd, Rng, peer, s, write_raw_tiff};

const WIDTH: u16 = 256;
const HEIGHT: u16 = 257;
const BITS: u16 = 258;
const PHOTOMETRIC: u16 = 262;
const SAMPLES: u16 = 277;
const ROWS_PER_STRIP: u16 = 278;
const PLANAR: u16 = 284;
const TILE_W: u16 = 322;
const TILE_H: u16 = 323;
const EXTRA: u16 = 338;
const SAMPLE_FORMAT: u16 = 339;

/// A sample type: bits, TIFF SampleFormat, little-endian bytes of a
/// random value, and that value as parvo's linear f32 reads it.
#[derive(Clone, Copy)]
enum Ty {
    U8,
    U16,
    F32,
}

impl Ty {
    fn bits(self) -> u32 {
        match self {
            Ty::U8 => 8,
            Ty::U16 => 16,
            Ty::F32 => 32,
        }
    }
    fn format(self) -> u32 {
        match self {
            Ty::F32 => 3,
            _ => 1,
        }
    }
    /// Bytes of one sample and its value.
    fn sample(self, r: &mut Rng) -> (Vec<u8>, f32) {
        match self {
            Ty::U8 => {
                let v = r.next() as u8;
                (vec![v], v as f32 / 255.0)
            }
            Ty::U16 => {
                let v = r.next() as u16;
                (v.to_le_bytes().to_vec(), v as f32 / 65535.0)
            }
            Ty::F32 => {
                let v = (r.next() % 100_000) as f32 / 997.0 - 20.0;
                (v.to_le_bytes().to_vec(), v)
            }
        }
    }
}

/// A planar TIFF of `w`×`h` texels of `ch` channels (the fourth straight
/// alpha), in strips of `rows` rows or in `tile`×`tile` tiles, and the
/// texels it holds, interleaved.
fn planar(
    path: &std::path::Path,
    w: usize,
    h: usize,
    ch: usize,
    ty: Ty,
    layout: Layout,
) -> Vec<f32> {
    let mut rng = Rng(0x5eed ^ (w * 31 + h * 7 + ch) as u64 ^ ty.bits() as u64);
    let size = ty.bits() as usize / 8;
    // planes[c] = the bytes of channel c, row-major.
    let mut planes = vec![Vec::new(); ch];
    let mut want = vec![0f32; w * h * ch];
    for (c, plane) in planes.iter_mut().enumerate() {
        for i in 0..w * h {
            let (b, v) = ty.sample(&mut rng);
            plane.extend_from_slice(&b);
            want[i * ch + c] = v;
        }
    }
    let mut entries = vec![
        (WIDTH, 4, vec![w as u32]),
        (HEIGHT, 4, vec![h as u32]),
        (BITS, 3, vec![ty.bits(); ch]),
        (PHOTOMETRIC, 3, vec![if ch >= 3 { 2 } else { 1 }]),
        (SAMPLES, 3, vec![ch as u32]),
        (PLANAR, 3, vec![2]),
        (SAMPLE_FORMAT, 3, vec![ty.format(); ch]),
    ];
    if ch == 4 {
        entries.push((EXTRA, 3, vec![2]));
    }
    let mut chunks = Vec::new();
    match layout {
        Layout::Strips(rows) => {
            entries.push((ROWS_PER_STRIP, 4, vec![rows as u32]));
            for plane in &planes {
                for y0 in (0..h).step_by(rows) {
                    let y1 = (y0 + rows).min(h);
                    chunks.push(plane[y0 * w * size..y1 * w * size].to_vec());
                }
            }
        }
        Layout::Tiles(t) => {
            entries.push((TILE_W, 3, vec![t as u32]));
            entries.push((TILE_H, 3, vec![t as u32]));
            for plane in &planes {
                for ty0 in (0..h).step_by(t) {
                    for tx0 in (0..w).step_by(t) {
                        // Tiles are always whole; the padding is zeros.
                        let mut tile = vec![0u8; t * t * size];
                        for y in ty0..(ty0 + t).min(h) {
                            for x in tx0..(tx0 + t).min(w) {
                                let src = (y * w + x) * size;
                                let dst = ((y - ty0) * t + (x - tx0)) * size;
                                tile[dst..dst + size].copy_from_slice(&plane[src..src + size]);
                            }
                        }
                        chunks.push(tile);
                    }
                }
            }
        }
    }
    write_raw_tiff(
        path,
        &[RawIfd {
            entries,
            chunks,
            tiled: matches!(layout, Layout::Tiles(_)),
        }],
        None,
    );
    want
}

#[derive(Clone, Copy, Debug)]
enum Layout {
    Strips(usize),
    Tiles(usize),
}

#[test]
fn planar_strips_and_tiles_read_every_plane() {
    let dir = tempfile::tempdir().unwrap();
    // Awkward sizes: strips that do not divide the height, tiles that
    // overhang the right and bottom edges.
    for (w, h) in [(13, 7), (37, 21)] {
        for ch in [2, 3, 4] {
            for ty in [Ty::U8, Ty::U16, Ty::F32] {
                for layout in [Layout::Strips(3), Layout::Strips(h), Layout::Tiles(16)] {
                    let p = dir.path().join("p.tif");
                    let want = planar(&p, w, h, ch, ty, layout);
                    let what = format!("{w}x{h} {ch} channels, {} bits, {layout:?}", ty.bits());
                    let l = parvo::io::load(s(&p), &parvo::io::Limits::default())
                        .unwrap_or_else(|e| panic!("{what}: {e}"));
                    let t = l.base();
                    assert_eq!(
                        (t.width() as usize, t.height() as usize, t.channels()),
                        (w, h, ch)
                    );
                    let got = t.to_linear();
                    for (i, (g, v)) in got.iter().zip(&want).enumerate() {
                        assert!(
                            (g - v).abs() <= 1e-6 * v.abs().max(1.0),
                            "{what}: texel {} channel {}: {g} != {v}",
                            i / ch,
                            i % ch
                        );
                    }
                }
            }
        }
    }
}

/// Pillow's planar 16-bit RGB files (made by GDAL from one image, LZW in
/// strips and in 256×256 tiles over a 100×40 image) read as Pillow's
/// 8-bit target of that image: the high byte of each sample.
#[test]
fn pillow_planar_16bit_files_read_as_their_target() {
    let target = image::open(peer("tiff_16bit_RGB_target.png"))
        .unwrap()
        .into_rgb8();
    for name in [
        "tiff_strip_planar_16bit_RGB.tiff",
        "tiff_tiled_planar_16bit_RGB.tiff",
    ] {
        let l = parvo::io::load(s(&peer(name)), &parvo::io::Limits::default())
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let t = l.base();
        assert_eq!(
            (t.width(), t.height(), t.channels()),
            (100, 40, 3),
            "{name}"
        );
        let parvo::Texels::U16(v) = t.texels() else {
            panic!("{name}: not 16-bit");
        };
        let high: Vec<u8> = v.iter().map(|&x| (x >> 8) as u8).collect();
        assert_eq!(high, target.as_raw().as_slice(), "{name}");
    }
}
