//! Issue 27 item 4: `--quality fast` and `normal` wrote byte-identical
//! BC1 and BC3 files (both were ISPC's one BC1 kernel), and the default
//! BC1 was 0.2–0.6 dB below `nvcompress -fast` on four photos
//! (benches/bc_peers.sh measures the steps beside nvcompress, quicktex and
//! etcpak; the README shows the table).
//!
//! Two photo-like inputs with partial blocks: a 130×98 crop of
//! scikit-image's astronaut photo (tests/data/peer/scikit-image, public
//! domain) and the procedural `builtin:photo` (fixed lattice hash, 194²).
//! On each, the three steps give three different sets of bytes for BC1
//! and for BC3, each at least as good as the one before, and the default
//! BC1 is at least as good as nvcompress -fast's algorithm (nvtt 2.0.8's
//! `QuickCompress::compressDXT1`, ported below from its source: bounding-
//! box diagonal, inset, one least-squares pass; single-colour blocks from
//! its optimal tables; on the astronaut photo the port gives nvcompress's
//! PSNR to 0.001 dB). PSNR is over R, G, B of the visible texels, decoded
//! by `bcdec_rs` (not parvo's decoder path), peak 255.

use std::path::Path;

use parvo::compress::encode::encode;
use parvo::compress::{BlockFormat, Quality, input_format, prepare};
use parvo::texel::{ChannelType, ColorSpace, Format, Texels};
use parvo::texture::Texture;

use super::util::{ok, parvo, s};

/// An input as the BC1/BC3 encoders read it (RGBA8, sRGB codes), with
/// its name, size and texels.
struct Input {
    name: &'static str,
    t: Texture,
    rgba: Vec<u8>,
    w: usize,
    h: usize,
}

fn encoder_input(name: &'static str, t: Texture, format: BlockFormat) -> Input {
    let f = t.format();
    let want = input_format(format, f.color_space, f.has_alpha().then_some(f.alpha));
    let t = prepare(&t, format, want).unwrap();
    let Texels::U8(v) = t.texels() else {
        panic!("RGBA8 expected")
    };
    Input {
        name,
        rgba: v.clone(),
        w: t.width() as usize,
        h: t.height() as usize,
        t,
    }
}

/// The two inputs: the astronaut crop (read with the `png` crate, an
/// 8-bit RGB PNG without colour chunks: sRGB codes) and builtin:photo.
fn inputs(format: BlockFormat) -> Vec<Input> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/peer/scikit-image/astronaut_130x98.png");
    let mut dec = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&path).unwrap()))
        .read_info()
        .unwrap();
    let mut buf = vec![0u8; dec.output_buffer_size().unwrap()];
    let info = dec.next_frame(&mut buf).unwrap();
    assert_eq!(
        (info.color_type, info.bit_depth),
        (png::ColorType::Rgb, png::BitDepth::Eight)
    );
    buf.truncate(info.buffer_size());
    let astronaut = Texture::from_u8(
        info.width,
        info.height,
        Format::new(3, ChannelType::U8, ColorSpace::Srgb),
        buf,
    )
    .unwrap();
    vec![
        encoder_input("astronaut 130x98", astronaut, format),
        encoder_input(
            "builtin:photo:194",
            parvo::builtin::load("builtin:photo:194").unwrap(),
            format,
        ),
    ]
}

/// PSNR over RGB of the visible texels of `blocks` (row-major) decoded by
/// bcdec against `rgba`.
fn psnr(format: BlockFormat, blocks: &[u8], rgba: &[u8], w: usize, h: usize) -> f64 {
    let bb = format.block_bytes();
    let bw = w.div_ceil(4);
    let mut se = 0f64;
    for (k, b) in blocks.chunks_exact(bb).enumerate() {
        let (bx, by) = (k % bw, k / bw);
        let mut out = [0u8; 64];
        match format {
            BlockFormat::Bc1 => bcdec_rs::bc1(b, &mut out, 16),
            BlockFormat::Bc3 => bcdec_rs::bc3(b, &mut out, 16),
            _ => unreachable!(),
        }
        for i in 0..16 {
            let (x, y) = (bx * 4 + i % 4, by * 4 + i / 4);
            if x < w && y < h {
                for c in 0..3 {
                    let d = out[i * 4 + c] as f64 - rgba[(y * w + x) * 4 + c] as f64;
                    se += d * d;
                }
            }
        }
    }
    10.0 * (255.0f64 * 255.0 * (w * h * 3) as f64 / se).log10()
}

#[test]
fn bc1_and_bc3_quality_steps_are_distinct_and_each_no_worse() {
    for format in [BlockFormat::Bc1, BlockFormat::Bc3] {
        for i in inputs(format) {
            let steps = [Quality::Fast, Quality::Normal, Quality::Slow];
            let blocks: Vec<Vec<u8>> = steps
                .iter()
                .map(|&q| encode(format, q, &i.t).unwrap())
                .collect();
            let p: Vec<f64> = blocks
                .iter()
                .map(|b| psnr(format, b, &i.rgba, i.w, i.h))
                .collect();
            let what = format!("{format} {}", i.name);
            println!(
                "{what}: fast {:.3}, normal {:.3}, slow {:.3} dB",
                p[0], p[1], p[2]
            );
            for k in 0..2 {
                assert_ne!(
                    blocks[k],
                    blocks[k + 1],
                    "{what}: {} and {} wrote the same bytes",
                    steps[k],
                    steps[k + 1]
                );
                // Each step keeps the better block per block (by the fit's
                // exact palette; bcdec rounds the interpolated colours,
                // which can move a block's error by a hair).
                assert!(
                    p[k + 1] >= p[k] - 0.005,
                    "{what}: {} {:.3} dB is worse than {} {:.3} dB",
                    steps[k + 1],
                    p[k + 1],
                    steps[k],
                    p[k]
                );
            }
            // And the steps are worth their time: a real gain each.
            assert!(
                p[1] > p[0] + 0.1 && p[2] > p[1] + 0.05,
                "{what}: fast {:.3}, normal {:.3}, slow {:.3} dB",
                p[0],
                p[1],
                p[2]
            );
        }
    }
}

#[test]
fn default_bc1_is_no_worse_than_nvcompress_fast_algorithm() {
    let format = BlockFormat::Bc1;
    for i in inputs(format) {
        let ours = psnr(
            format,
            &encode(format, Quality::default(), &i.t).unwrap(),
            &i.rgba,
            i.w,
            i.h,
        );
        let nvtt = psnr(
            format,
            &nvtt_fast::encode(&i.rgba, i.w, i.h),
            &i.rgba,
            i.w,
            i.h,
        );
        println!(
            "BC1 {}: default {ours:.3} dB, nvcompress -fast's algorithm {nvtt:.3} dB",
            i.name
        );
        // The bound is the peer table's: nvcompress -fast is the encoder of
        // comparable time the default must match (on the four photos the
        // default is 0.1 to 0.5 dB above it).
        assert!(
            ours >= nvtt,
            "{}: default BC1 {ours:.3} dB < nvcompress -fast's algorithm {nvtt:.3} dB",
            i.name
        );
    }
}

/// The CLI's `--quality` reaches the encoder: fast and normal BC1 files
/// differ (they were byte-identical).
#[test]
fn cli_fast_and_normal_bc1_files_differ() {
    let dir = tempfile::tempdir().unwrap();
    let mut files = Vec::new();
    for q in ["fast", "normal"] {
        let out = dir.path().join(format!("{q}.dds"));
        ok(&parvo(&[
            "mip",
            "builtin:photo:64",
            "-o",
            s(&out),
            "--compress",
            "bc1",
            "--quality",
            q,
        ]));
        files.push(std::fs::read(&out).unwrap());
    }
    assert_ne!(
        files[0], files[1],
        "fast and normal BC1 files are identical"
    );
}

/// nvtt 2.0.8's `QuickCompress::compressDXT1` (src/nvtt/QuickCompressDXT.cpp,
/// MIT licence, Ignacio Castaño / NVIDIA), what `nvcompress -fast -bc1`
/// runs per block, ported line by line; partial blocks repeat the level's
/// last column and row.
mod nvtt_fast {
    type V3 = [f32; 3];

    fn sub(a: V3, b: V3) -> V3 {
        [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
    }

    fn dist(a: V3, b: V3) -> f32 {
        let d = sub(a, b);
        d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
    }

    fn lerp(a: V3, b: V3, t: f32) -> V3 {
        [0, 1, 2].map(|k| a[k] + (b[k] - a[k]) * t)
    }

    /// `roundAndExpand`: 5:6:5 rounding, and the endpoint expanded back.
    fn round_and_expand(v: &mut V3) -> u16 {
        let r = ((v[0] * (31.0 / 255.0)).clamp(0.0, 31.0) + 0.5) as u32;
        let g = ((v[1] * (63.0 / 255.0)).clamp(0.0, 63.0) + 0.5) as u32;
        let b = ((v[2] * (31.0 / 255.0)).clamp(0.0, 31.0) + 0.5) as u32;
        let w = ((r << 11) | (g << 5) | b) as u16;
        *v = [
            ((r << 3) | (r >> 2)) as f32,
            ((g << 2) | (g >> 4)) as f32,
            ((b << 3) | (b >> 2)) as f32,
        ];
        w
    }

    fn compute_indices4(block: &[V3; 16], max: V3, min: V3) -> u32 {
        let pal = [
            max,
            min,
            lerp(max, min, 1.0 / 3.0),
            lerp(max, min, 2.0 / 3.0),
        ];
        let mut indices = 0u32;
        for (i, &c) in block.iter().enumerate() {
            let d = pal.map(|p| dist(p, c));
            let b0 = (d[0] > d[3]) as u32;
            let b1 = (d[1] > d[2]) as u32;
            let b2 = (d[0] > d[2]) as u32;
            let b3 = (d[1] > d[3]) as u32;
            let b4 = (d[2] > d[3]) as u32;
            let x0 = b1 & b2;
            let x1 = b0 & b3;
            let x2 = b0 & b4;
            indices |= (x2 | ((x0 | x1) << 1)) << (2 * i);
        }
        indices
    }

    fn optimize_end_points4(block: &[V3; 16], blk: &mut (u16, u16, u32)) {
        let (mut a2, mut b2, mut ab) = (0f32, 0f32, 0f32);
        let (mut ax, mut bx) = ([0f32; 3], [0f32; 3]);
        for (i, c) in block.iter().enumerate() {
            let bits = blk.2 >> (2 * i);
            let mut beta = (bits & 1) as f32;
            if bits & 2 != 0 {
                beta = (1.0 + beta) / 3.0;
            }
            let alpha = 1.0 - beta;
            a2 += alpha * alpha;
            b2 += beta * beta;
            ab += alpha * beta;
            for k in 0..3 {
                ax[k] += alpha * c[k];
                bx[k] += beta * c[k];
            }
        }
        let denom = a2 * b2 - ab * ab;
        if denom.abs() <= 0.0001 {
            return;
        }
        let f = 1.0 / denom;
        let mut a = [0, 1, 2].map(|k| ((ax[k] * b2 - bx[k] * ab) * f).clamp(0.0, 255.0));
        let mut b = [0, 1, 2].map(|k| ((bx[k] * a2 - ax[k] * ab) * f).clamp(0.0, 255.0));
        let mut c0 = round_and_expand(&mut a);
        let mut c1 = round_and_expand(&mut b);
        if c0 < c1 {
            std::mem::swap(&mut a, &mut b);
            std::mem::swap(&mut c0, &mut c1);
        }
        *blk = (c0, c1, compute_indices4(block, a, b));
    }

    /// `PrepareOptTable` (SingleColorLookup.h): per 8-bit value the pair
    /// (max, min) whose 2/3·max + 1/3·min is nearest, preferring close
    /// pairs.
    fn opt_table(bits: u32) -> Vec<(u16, u16)> {
        let size = 1u16 << bits;
        let expand = |v: u16| -> i32 {
            if bits == 5 {
                ((v << 3) | (v >> 2)) as i32
            } else {
                ((v << 2) | (v >> 4)) as i32
            }
        };
        let mul8 = |a: i32, b: i32| {
            let t = a * b + 128;
            (t + (t >> 8)) >> 8
        };
        (0..256)
            .map(|i| {
                let mut best = (256f32, (0, 0));
                for min in 0..size {
                    for max in 0..size {
                        let (mine, maxe) = (expand(min), expand(max));
                        let err = (maxe + mul8(mine - maxe, 0x55) - i).abs() as f32
                            + 0.03 * (max as f32 - min as f32).abs();
                        if err < best.0 {
                            best = (err, (max, min));
                        }
                    }
                }
                best.1
            })
            .collect()
    }

    /// One block of 16 RGB texels.
    fn block(px: &[[u8; 3]; 16], t5: &[(u16, u16)], t6: &[(u16, u16)]) -> [u8; 8] {
        let mut blk;
        if px.iter().all(|c| c == &px[0]) {
            // OptimalCompress::compressDXT1.
            let c = px[0];
            let (r, g, b) = (t5[c[0] as usize], t6[c[1] as usize], t5[c[2] as usize]);
            blk = (
                (r.0 << 11) | (g.0 << 5) | b.0,
                (r.1 << 11) | (g.1 << 5) | b.1,
                0xAAAA_AAAAu32,
            );
            if blk.0 < blk.1 {
                blk = (blk.1, blk.0, blk.2 ^ 0x5555_5555);
            }
        } else {
            let block: [V3; 16] = px.map(|c| c.map(|x| x as f32));
            let mut max = [0f32; 3];
            let mut min = [255f32; 3];
            for c in &block {
                for k in 0..3 {
                    max[k] = max[k].max(c[k]);
                    min[k] = min[k].min(c[k]);
                }
            }
            // selectDiagonal
            let center = [0, 1, 2].map(|k| (max[k] + min[k]) * 0.5);
            let (mut cx, mut cy) = (0f32, 0f32);
            for c in &block {
                let t = sub(*c, center);
                cx += t[0] * t[2];
                cy += t[1] * t[2];
            }
            if cx < 0.0 {
                std::mem::swap(&mut max[0], &mut min[0]);
            }
            if cy < 0.0 {
                std::mem::swap(&mut max[1], &mut min[1]);
            }
            // insetBBox
            let inset = [0, 1, 2].map(|k| (max[k] - min[k]) / 16.0 - (8.0 / 255.0) / 16.0);
            max = [0, 1, 2].map(|k| (max[k] - inset[k]).clamp(0.0, 255.0));
            min = [0, 1, 2].map(|k| (min[k] + inset[k]).clamp(0.0, 255.0));
            let mut c0 = round_and_expand(&mut max);
            let mut c1 = round_and_expand(&mut min);
            if c0 < c1 {
                std::mem::swap(&mut max, &mut min);
                std::mem::swap(&mut c0, &mut c1);
            }
            blk = (c0, c1, compute_indices4(&block, max, min));
            optimize_end_points4(&block, &mut blk);
        }
        let mut out = [0u8; 8];
        out[0..2].copy_from_slice(&blk.0.to_le_bytes());
        out[2..4].copy_from_slice(&blk.1.to_le_bytes());
        out[4..8].copy_from_slice(&blk.2.to_le_bytes());
        out
    }

    /// A whole RGBA8 level, blocks row-major.
    pub fn encode(rgba: &[u8], w: usize, h: usize) -> Vec<u8> {
        let (t5, t6) = (opt_table(5), opt_table(6));
        let mut out = Vec::new();
        for by in 0..h.div_ceil(4) {
            for bx in 0..w.div_ceil(4) {
                let px: [[u8; 3]; 16] = std::array::from_fn(|i| {
                    let x = (bx * 4 + i % 4).min(w - 1);
                    let y = (by * 4 + i / 4).min(h - 1);
                    let o = (y * w + x) * 4;
                    [rgba[o], rgba[o + 1], rgba[o + 2]]
                });
                out.extend_from_slice(&block(&px, &t5, &t6));
            }
        }
        out
    }
}
