//! Samples the `tiff` crate does not unpack, unpacked by parvo as libtiff
//! and OpenImageIO unpack them:
//! - unsigned integers of 9–15 and 17–31 bits (10-, 12-, 14- and 24-bit
//!   scans), widened to 16 or 32 bits as OpenImageIO's TIFF reader widens
//!   them (`v · (2^16 − 1) / (2^bits − 1)` rounded down); 17–31-bit ones
//!   load as f32 in 0..1, OpenImageIO's value for its 32-bit reading;
//! - samples of 1–7 bits of more than one channel, and WhiteIsZero grey
//!   of 3, 5, 6 or 7 bits, which the crate does not invert (widened to 8
//!   bits the same way). WhiteIsZero is inverted at every depth, as TIFF
//!   defines it (0 is white); OpenImageIO inverts 8-bit results only and
//!   leaves 9- to 32-bit WhiteIsZero as stored, which reads white as black;
//! - YCbCr without JPEG compression, subsampled or not, converted to RGB
//!   by libtiff's `TIFFYCbCrtoRGB`, which OpenImageIO reads YCbCr through
//!   (its RGBA interface): the same fixed-point tables built from the
//!   file's `YCbCrCoefficients` and `ReferenceBlackWhite`, each chroma
//!   pair applied to its whole block of luma samples.
//!
//! The decoder is handed such a directory as rows of bytes (8-bit grey,
//! one sample per pixel, or one per plane for planar data, with the bytes
//! of a row as the width): it decompresses them, and [`View::decode`]
//! unpacks the samples from the bit stream (most significant bit first,
//! as TIFF packs samples that are not whole bytes).

use std::fs::File;

use super::chain::{Dir, Entry, Layout, rationals, tag, values};
use crate::texel::Texels;

/// What parvo unpacks itself in one directory (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct View {
    pub width: u32,
    pub height: u32,
    pub bits: u16,
    pub samples: u16,
    pub planar: bool,
    /// `PhotometricInterpretation`: 0 WhiteIsZero, 1 BlackIsZero, 2 RGB,
    /// 6 YCbCr.
    pub photometric: u16,
    /// The first `ExtraSamples` value.
    pub extra: Option<u16>,
    /// Pixels of one chunk column: the tile width, or the width.
    chunk_width: u32,
    /// Bytes of one row of one chunk column (of one plane when planar).
    row_bytes: u32,
    chunks_across: u32,
    /// YCbCr subsampling, horizontal and vertical ((1, 1) otherwise).
    sub: (u32, u32),
    rows_per_strip: Option<u32>,
    tiled: bool,
    /// YCbCr's luma coefficients (red, green, blue).
    luma: [f32; 3],
    /// YCbCr's `ReferenceBlackWhite`.
    black_white: [f32; 6],
}

impl View {
    /// The view directory `d` needs (`photometric` as the decoder is
    /// told it), or `None` when the crate reads it or parvo refuses it.
    pub(super) fn of(f: &mut File, l: &Layout, d: &Dir, photometric: Option<u64>) -> Option<View> {
        let compression = d.unsigned(l, tag::COMPRESSION).unwrap_or(1);
        let first = |f: &mut File, t: u16, default: u64| match d.entry(t) {
            Some(e) => values(f, l, e).and_then(|v| {
                let first = *v.first()?;
                v.iter().all(|&x| x == first).then_some(first)
            }),
            None => Some(default),
        };
        let bits = first(f, tag::BITS_PER_SAMPLE, 1)?;
        let format = first(f, tag::SAMPLE_FORMAT, 1)?;
        let samples = d.unsigned(l, tag::SAMPLES_PER_PIXEL).unwrap_or(1);
        let planar = d.unsigned(l, tag::PLANAR_CONFIGURATION) == Some(2);
        let tile = d
            .unsigned(l, tag::TILE_WIDTH)
            .zip(d.unsigned(l, tag::TILE_LENGTH));
        let photometric = photometric?;
        let ycbcr = photometric == 6 && bits == 8 && samples == 3 && !planar && tile.is_none();
        // Sub-byte samples of more than one channel, too.
        let odd = (matches!(bits, 9..=15 | 17..=31) || (bits < 8 && samples > 1))
            && matches!(photometric, 0..=2);
        let white = photometric == 0 && samples == 1 && matches!(bits, 3 | 5 | 6 | 7);
        // JPEG data is the crate's (or refused); libtiff reads no
        // predictor with samples of these sizes.
        let predictor = d.unsigned(l, tag::PREDICTOR).unwrap_or(1);
        if !(ycbcr || ((odd || white) && format == 1 && (1..=4).contains(&samples)))
            || matches!(compression, 6 | 7)
            || (predictor != 1 && compression != 1)
        {
            return None;
        }
        let width = u32::try_from(d.unsigned(l, tag::IMAGE_WIDTH)?).ok()?;
        let height = u32::try_from(d.unsigned(l, tag::IMAGE_LENGTH)?).ok()?;
        let rows_per_strip = d
            .unsigned(l, tag::ROWS_PER_STRIP)
            .map(|r| r.min(u32::MAX as u64) as u32);
        let sub = if ycbcr {
            let s = match d.entry(tag::YCBCR_SUBSAMPLING) {
                Some(e) => values(f, l, e)?,
                None => vec![2, 2],
            };
            match s[..] {
                [h @ (1 | 2 | 4), v @ (1 | 2 | 4)] => (h as u32, v as u32),
                _ => return None,
            }
        } else {
            (1, 1)
        };
        // A strip of YCbCr holds whole rows of blocks.
        if rows_per_strip.is_some_and(|r| r < height && r % sub.1 != 0) {
            return None;
        }
        let (chunk_width, per) = match tile {
            Some((tw, _)) => (
                u32::try_from(tw).ok()?.max(1),
                if planar { 1 } else { samples },
            ),
            None => (width.max(1), if planar { 1 } else { samples }),
        };
        let row_bytes = if ycbcr {
            (width.div_ceil(sub.0) as u64) * (sub.0 * sub.1 + 2) as u64
        } else {
            (chunk_width as u64 * per * bits).div_ceil(8)
        };
        let chunks_across = width.div_ceil(chunk_width).max(1);
        let row_bytes = u32::try_from(row_bytes).ok()?;
        u32::try_from(row_bytes as u64 * chunks_across as u64).ok()?;
        let rationals_of = |f: &mut File, t: u16, n: usize| {
            d.entry(t)
                .and_then(|e| rationals(f, l, e))
                .filter(|v| v.len() == n)
        };
        let mut luma = [0.299, 0.587, 0.114];
        if let Some(v) = rationals_of(f, 529, 3) {
            luma = [v[0] as f32, v[1] as f32, v[2] as f32];
        }
        let mut black_white = [0.0, 255.0, 128.0, 255.0, 128.0, 255.0];
        if let Some(v) = rationals_of(f, tag::REFERENCE_BLACK_WHITE, 6) {
            for (b, v) in black_white.iter_mut().zip(v) {
                *b = v as f32;
            }
        }
        let extra = match d.entry(tag::EXTRA_SAMPLES) {
            Some(e) => values(f, l, e).and_then(|v| v.first().map(|&x| x as u16)),
            None => None,
        };
        Some(View {
            width,
            height,
            bits: bits as u16,
            samples: samples as u16,
            planar,
            photometric: photometric as u16,
            extra,
            chunk_width,
            row_bytes,
            chunks_across,
            sub,
            rows_per_strip,
            tiled: tile.is_some(),
            luma,
            black_white,
        })
    }

    pub(super) fn is_ycbcr(&self) -> bool {
        self.photometric == 6
    }

    /// Rows of bytes the decoder returns per plane.
    fn rows(&self) -> u32 {
        self.height.div_ceil(self.sub.1)
    }

    /// Bytes of one row the decoder returns.
    fn row_len(&self) -> usize {
        self.row_bytes as usize * self.chunks_across as usize
    }

    /// Directory `entries` as the decoder is to read them: 8-bit grey
    /// rows of bytes.
    pub(super) fn entries(&self, l: &Layout, entries: Vec<Entry>) -> Vec<Entry> {
        let mut drop = vec![
            tag::PHOTOMETRIC,
            tag::BITS_PER_SAMPLE,
            tag::SAMPLES_PER_PIXEL,
            tag::PREDICTOR,
            tag::SAMPLE_FORMAT,
            tag::EXTRA_SAMPLES,
            tag::YCBCR_SUBSAMPLING,
            tag::IMAGE_WIDTH,
            tag::IMAGE_LENGTH,
        ];
        if self.tiled {
            drop.push(tag::TILE_WIDTH);
        }
        if self.is_ycbcr() {
            drop.push(tag::ROWS_PER_STRIP);
        }
        let mut out: Vec<Entry> = entries
            .into_iter()
            .filter(|e| !drop.contains(&e.tag))
            .collect();
        let planes = if self.planar { self.samples } else { 1 };
        out.push(Entry::short(l, tag::PHOTOMETRIC, 1));
        out.push(Entry::short(l, tag::BITS_PER_SAMPLE, 8));
        out.push(Entry::short(l, tag::SAMPLES_PER_PIXEL, planes));
        out.push(Entry::long(l, tag::IMAGE_WIDTH, self.row_len() as u32));
        out.push(Entry::long(l, tag::IMAGE_LENGTH, self.rows()));
        if self.tiled {
            out.push(Entry::long(l, tag::TILE_WIDTH, self.row_bytes));
        }
        if self.is_ycbcr()
            && let Some(r) = self.rows_per_strip
        {
            out.push(Entry::long(l, tag::ROWS_PER_STRIP, r.div_ceil(self.sub.1)));
        }
        out
    }

    /// Bytes the texels take once unpacked.
    pub(super) fn texel_bytes(&self) -> u64 {
        let (n, per) = (self.width as u64 * self.height as u64, self.samples as u64);
        match self.bits {
            _ if self.is_ycbcr() => n * 3,
            0..=8 => n * per,
            9..=16 => n * per * 2,
            _ => n * per * 4,
        }
    }

    /// The texels from the rows of bytes the decoder returned.
    pub(super) fn decode(&self, bytes: &[u8]) -> Result<Texels, String> {
        let planes = if self.planar {
            self.samples as usize
        } else {
            1
        };
        let plane = self.row_len() * self.rows() as usize;
        if bytes.len() < plane * planes {
            return Err(format!(
                "the decoder returned {} bytes of samples, the tags declare {}",
                bytes.len(),
                plane * planes
            ));
        }
        if self.is_ycbcr() {
            return Ok(Texels::U8(self.ycbcr(bytes)));
        }
        let bits = self.bits as u32;
        let invert = self.photometric == 0;
        let codes = self.codes(bytes, plane);
        // Widened first, then inverted at the widened depth, as
        // OpenImageIO's `bit_convert` and `invert_photometric` do.
        let out = |to: u32, v: u32| {
            let max = (1u64 << to) - 1;
            let w = widen(v, bits, to) as u64;
            (if invert { max - w } else { w }) as u32
        };
        Ok(match bits {
            0..=8 => Texels::U8(codes.map(|v| out(8, v) as u8).collect()),
            9..=16 => Texels::U16(codes.map(|v| out(16, v) as u16).collect()),
            _ => Texels::F32(
                codes
                    .map(|v| (out(32, v) as f64 / u32::MAX as f64) as f32)
                    .collect(),
            ),
        })
    }

    /// Every sample's code, pixel after pixel, channel after channel.
    fn codes<'a>(&'a self, bytes: &'a [u8], plane: usize) -> impl Iterator<Item = u32> + 'a {
        let (w, s) = (self.width as usize, self.samples as usize);
        let (cw, bits) = (self.chunk_width as usize, self.bits as usize);
        let row_len = self.row_len();
        (0..self.height as usize).flat_map(move |y| {
            (0..w).flat_map(move |x| {
                (0..s).map(move |c| {
                    let (p, i) = if self.planar {
                        (c, x % cw)
                    } else {
                        (0, (x % cw) * s + c)
                    };
                    let row = &bytes[p * plane + y * row_len..][..row_len];
                    let bit = (x / cw) * self.row_bytes as usize * 8 + i * bits;
                    read_bits(row, bit, bits as u32)
                })
            })
        })
    }

    /// RGB from blocks of subsampled YCbCr, as libtiff converts them.
    fn ycbcr(&self, bytes: &[u8]) -> Vec<u8> {
        let table = Ycc::new(self.luma, self.black_white);
        let (sh, sv) = (self.sub.0 as usize, self.sub.1 as usize);
        let block = sh * sv + 2;
        let row_len = self.row_len();
        let mut out = Vec::with_capacity(self.width as usize * self.height as usize * 3);
        for y in 0..self.height as usize {
            let row = &bytes[(y / sv) * row_len..][..row_len];
            for x in 0..self.width as usize {
                let b = &row[(x / sh) * block..][..block];
                let luma = b[(y % sv) * sh + x % sh];
                out.extend_from_slice(&table.rgb(luma, b[sh * sv], b[sh * sv + 1]));
            }
        }
        out
    }
}

/// `bits` bits at bit `at` of `row`, most significant bit first.
fn read_bits(row: &[u8], at: usize, bits: u32) -> u32 {
    let (first, last) = (at / 8, (at + bits as usize - 1) / 8);
    let mut v = 0u64;
    for &b in &row[first..=last] {
        v = (v << 8) | b as u64;
    }
    let shift = (last - first + 1) * 8 - at % 8 - bits as usize;
    ((v >> shift) & ((1u64 << bits) - 1)) as u32
}

/// A `from`-bit code widened to `to` bits, `v · (2^to − 1) / (2^from −
/// 1)` rounded down, as OpenImageIO's TIFF reader widens samples of
/// unusual sizes (`bit_convert`).
pub(super) fn widen(v: u32, from: u32, to: u32) -> u32 {
    let (max_in, max_out) = ((1u64 << from) - 1, (1u64 << to) - 1);
    (v as u64 * max_out / max_in) as u32
}

/// libtiff's YCbCr-to-RGB tables (`TIFFYCbCrToRGBInit`), which libjpeg's
/// own conversion equals for the default coefficients and reference
/// values.
pub(super) struct Ycc {
    y: [i32; 256],
    cr_r: [i32; 256],
    cb_b: [i32; 256],
    cr_g: [i32; 256],
    cb_g: [i32; 256],
}

impl Ycc {
    const SHIFT: u32 = 16;

    /// The tables for luma coefficients `luma` and `ReferenceBlackWhite`
    /// `bw`; [`Ycc::jpeg`] for JPEG's.
    pub(super) fn new(luma: [f32; 3], bw: [f32; 6]) -> Ycc {
        let fix = |x: f32| (x.clamp(0.0, 2.0) as f64 * (1i64 << Self::SHIFT) as f64 + 0.5) as i32;
        let [red, green, blue] = luma;
        let f1 = 2.0 - 2.0 * red;
        let f3 = 2.0 - 2.0 * blue;
        let (d1, d2) = (fix(f1), -fix(red * f1 / green));
        let (d3, d4) = (fix(f3), -fix(blue * f3 / green));
        let code = |c: i32, rb: f32, rw: f32, cr: f32| {
            let span = if rw != rb { rw - rb } else { 1.0 };
            ((c - rb as i32) as f32 * cr / span).clamp(-128.0 * 32.0, 128.0 * 32.0) as i32
        };
        let half = 1i32 << (Self::SHIFT - 1);
        let mut t = Ycc {
            y: [0; 256],
            cr_r: [0; 256],
            cb_b: [0; 256],
            cr_g: [0; 256],
            cb_g: [0; 256],
        };
        for i in 0..256 {
            let x = i as i32 - 128;
            let cr = code(x, bw[4] - 128.0, bw[5] - 128.0, 127.0);
            let cb = code(x, bw[2] - 128.0, bw[3] - 128.0, 127.0);
            t.cr_r[i] = (d1.wrapping_mul(cr).wrapping_add(half)) >> Self::SHIFT;
            t.cb_b[i] = (d3.wrapping_mul(cb).wrapping_add(half)) >> Self::SHIFT;
            t.cr_g[i] = d2.wrapping_mul(cr);
            t.cb_g[i] = d4.wrapping_mul(cb).wrapping_add(half);
            t.y[i] = code(x + 128, bw[0], bw[1], 255.0);
        }
        t
    }

    /// JPEG's (JFIF's) conversion: BT.601 coefficients, full range.
    pub(super) fn jpeg() -> Ycc {
        Ycc::new(
            [0.299, 0.587, 0.114],
            [0.0, 255.0, 128.0, 255.0, 128.0, 255.0],
        )
    }

    /// One pixel (`TIFFYCbCrtoRGB`).
    pub(super) fn rgb(&self, y: u8, cb: u8, cr: u8) -> [u8; 3] {
        let (y, cb, cr) = (self.y[y as usize], cb as usize, cr as usize);
        let g = (self.cb_g[cb].wrapping_add(self.cr_g[cr])) >> Self::SHIFT;
        [
            (y + self.cr_r[cr]).clamp(0, 255) as u8,
            (y + g).clamp(0, 255) as u8,
            (y + self.cb_b[cb]).clamp(0, 255) as u8,
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn widening_scales_and_rounds_down_as_openimageio() {
        // bit_convert's definition, by hand: v · 255 / 63 = 181.4...
        assert_eq!(widen(0b1, 1, 8), 0xFF);
        assert_eq!(widen(45, 6, 8), 182);
        assert_eq!(widen(44, 6, 8), 178);
        assert_eq!(widen(0xABC, 12, 16), 43_978);
        assert_eq!(widen(1, 10, 16), 64);
        assert_eq!(widen(0x3FF, 10, 16), 0xFFFF);
        assert_eq!(widen(0x123456, 24, 32), 0x1234_5612);
        for bits in [3, 10, 12, 14, 24] {
            let to = if bits > 16 { 32 } else { 16 };
            assert_eq!(widen(0, bits, to), 0);
            assert_eq!(widen((1 << bits) - 1, bits, to) as u64, (1u64 << to) - 1);
        }
    }

    #[test]
    fn bits_read_most_significant_first_across_bytes() {
        // Three 12-bit codes 0xABC, 0xDEF, 0x123 packed MSB first.
        let row = [0xAB, 0xCD, 0xEF, 0x12, 0x30];
        assert_eq!(read_bits(&row, 0, 12), 0xABC);
        assert_eq!(read_bits(&row, 12, 12), 0xDEF);
        assert_eq!(read_bits(&row, 24, 12), 0x123);
        assert_eq!(read_bits(&row, 4, 10), 0b10_1111_0011);
    }

    #[test]
    fn jpeg_conversion_matches_the_jfif_formula_within_rounding() {
        // JFIF: R = Y + 1.402 (Cr − 128), G = Y − 0.344136 (Cb − 128) −
        // 0.714136 (Cr − 128), B = Y + 1.772 (Cb − 128).
        let t = Ycc::jpeg();
        let mut seed = 0x2545_f491_u32;
        for _ in 0..5000 {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            let [y, cb, cr, _] = seed.to_le_bytes();
            let (yf, b, r) = (y as f64, cb as f64 - 128.0, cr as f64 - 128.0);
            let want = [
                yf + 1.402 * r,
                yf - 0.344136 * b - 0.714136 * r,
                yf + 1.772 * b,
            ];
            let got = t.rgb(y, cb, cr);
            for (g, w) in got.iter().zip(want) {
                assert!(
                    (*g as f64 - w.clamp(0.0, 255.0)).abs() <= 1.0,
                    "{y} {cb} {cr}: {got:?} vs {want:?}"
                );
            }
        }
        assert_eq!(t.rgb(128, 128, 128), [128, 128, 128]);
        assert_eq!(t.rgb(255, 128, 128), [255, 255, 255]);
    }
}
