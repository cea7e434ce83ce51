//! Block encoders (feature `encode`): two crates and one fit of our own.
//! - `intel_tex_2` (Intel's ISPC texture compressor: SIMD kernels, with
//!   quality profiles for BC7 and BC6H) for BC4, BC5, BC6H and BC7, and
//!   for BC1 and BC3 as they are at `fast` and as the first guess at
//!   `normal` and `slow`;
//! - a BC1 colour-block fit of our own (the private `colour` module: the
//!   refinement of nvtt and libsquish, least squares on the chosen
//!   indices, the best 5:6:5 rounding, a ±1 search), which refits ISPC's
//!   BC1 blocks and BC3 colour halves at `normal` and `slow` (ISPC's
//!   kernel has no settings, so `fast` and `normal` were once the same
//!   bytes);
//! - a one-channel fit of our own (the private `single` module), which
//!   refits ISPC's BC4 blocks and BC5 halves at `normal` and `slow`;
//! - `texpresso` (a port of libsquish) for BC1 with alpha (its one-bit
//!   punch-through mode: texels with alpha below 128 become transparent,
//!   which ISPC's BC1 does not encode; range fit, cluster fit and
//!   iterative cluster fit per step), and at `slow` one more start for the
//!   fit (its iterative cluster fit).
//!
//! Each step of opaque BC1 and of BC3 keeps, per block, the best of what
//! the step before it found and its own search (measured by the error the
//! fit minimises), so more effort never gives a worse block. `benches/bc_peers.sh` measures
//! the steps beside nvcompress, quicktex and etcpak (the README's table):
//! `normal` is above `nvcompress -fast` on every photo there at about its
//! time on one thread; `slow` costs what libsquish's iterative cluster fit
//! costs.
//!
//! The colour error is the squared difference of the stored codes, each
//! channel weighted alike (what `psnr` and `--stats` report; for sRGB data
//! the codes are already perceptually spaced); straight-alpha BC3 weighs
//! each texel's colour by its alpha.
//!
//! Every encoder reads the level in [`input_format`]: the texels are
//! already filtered and quantised, so the encoder's job is only the block
//! fit. Levels whose sides are not multiples of 4 are stored in whole
//! blocks: texpresso and the colour fit leave the texels outside the level
//! out of the fit; for the ISPC kernels (which read whole blocks) the level
//! is padded by repeating its last column and row, so the outside texels
//! pull the endpoints towards colours the block already has. Large levels
//! are cut into bands of block rows encoded on all threads; the bytes do
//! not depend on the number of threads.

use rayon::prelude::*;

use super::{BlockFormat, Quality, can_encode, input_format};
use crate::error::{Error, Result};
use crate::texel::{AlphaMode, Texels};
use crate::texture::Texture;

mod colour;
mod single;

fn encode_err(reason: impl Into<String>) -> Error {
    Error::Encode {
        format: "block compression",
        reason: reason.into(),
    }
}

/// Where an encoding pass writes its blocks, and whom it tells of the
/// texels done (see [`encode_with`]).
struct Blocks<'a> {
    out: &'a mut [u8],
    tick: &'a (dyn Fn(u64) + Sync),
}

/// The passes over a level [`encode_with`] makes: the fit, and the
/// refits that follow it at normal and slow quality (BC4/BC5's single-
/// channel refit, BC1/BC3's colour refit; BC1 with alpha is one pass).
fn passes(format: BlockFormat, quality: Quality, level: &Texture) -> u64 {
    let refits = match level.texels() {
        Texels::U8(_) if !(format == BlockFormat::Bc1 && level.format().has_alpha()) => {
            let single = format.holds_data() && quality != Quality::Fast;
            let colour =
                matches!(format, BlockFormat::Bc1 | BlockFormat::Bc3) && quality != Quality::Fast;
            single as u64 + colour as u64
        }
        _ => 0,
    };
    1 + refits
}

/// Block rows per parallel band of the ISPC encoders.
const BAND_BLOCK_ROWS: usize = 16;

/// Encode one level (in [`input_format`]) as `format` blocks, row-major,
/// [`BlockFormat::level_bytes`] long.
pub fn encode(format: BlockFormat, quality: Quality, level: &Texture) -> Result<Vec<u8>> {
    encode_with(format, quality, level, &|_| {})
}

/// [`encode`], calling `tick(n)` as the work of `n` more of the level's
/// texels is done (block row by block row; each pass of the encoder, the
/// fit and the refits, counts for its share), so a progress bar advances
/// with the work.
pub fn encode_with(
    format: BlockFormat,
    quality: Quality,
    level: &Texture,
    tick: &(dyn Fn(u64) + Sync),
) -> Result<Vec<u8>> {
    let passes = passes(format, quality, level);
    let tick = |n: u64| tick(n / passes);
    if !can_encode(format) {
        return Err(encode_err(format!("parvo does not encode {format}")));
    }
    let f = level.format();
    let want = input_format(format, f.color_space, f.has_alpha().then_some(f.alpha));
    if f.channels != want.channels || f.channel_type != want.channel_type {
        return Err(encode_err(format!(
            "{format} encodes {} texels, the level is {f}",
            want
        )));
    }
    let (w, h) = (level.width() as usize, level.height() as usize);
    let out_len = format.level_bytes(level.width(), level.height()) as usize;
    let mut out = vec![0u8; out_len];
    match (format, level.texels()) {
        (BlockFormat::Bc1, Texels::U8(v)) if f.has_alpha() => {
            bc1_with_alpha(v, w, h, quality, f.alpha == AlphaMode::Straight, &mut out)?;
            tick((w * h) as u64);
        }
        (_, Texels::U8(v)) => {
            let ch = f.channels as usize;
            let blocks = Blocks {
                out: &mut out,
                tick: &tick,
            };
            ispc_bands(v, w, h, ch, format, blocks, |band, bw, bh, dst| {
                let stride = (bw * ch) as u32;
                let (width, height) = (bw as u32, bh as u32);
                let rgba = intel_tex_2::RgbaSurface {
                    data: band,
                    width,
                    height,
                    stride,
                };
                match format {
                    BlockFormat::Bc1 => intel_tex_2::bc1::compress_blocks_into(&rgba, dst),
                    BlockFormat::Bc3 => intel_tex_2::bc3::compress_blocks_into(&rgba, dst),
                    BlockFormat::Bc4 { .. } => intel_tex_2::bc4::compress_blocks_into(
                        &intel_tex_2::RSurface {
                            data: band,
                            width,
                            height,
                            stride,
                        },
                        dst,
                    ),
                    BlockFormat::Bc5 { .. } => intel_tex_2::bc5::compress_blocks_into(
                        &intel_tex_2::RgSurface {
                            data: band,
                            width,
                            height,
                            stride,
                        },
                        dst,
                    ),
                    _ => {
                        let s = match (quality, f.has_alpha()) {
                            (Quality::Fast, true) => intel_tex_2::bc7::alpha_very_fast_settings(),
                            (Quality::Normal, true) => intel_tex_2::bc7::alpha_basic_settings(),
                            (Quality::Slow, true) => intel_tex_2::bc7::alpha_slow_settings(),
                            (Quality::Fast, false) => intel_tex_2::bc7::opaque_very_fast_settings(),
                            (Quality::Normal, false) => intel_tex_2::bc7::opaque_basic_settings(),
                            (Quality::Slow, false) => intel_tex_2::bc7::opaque_slow_settings(),
                        };
                        intel_tex_2::bc7::compress_blocks_into(&s, &rgba, dst)
                    }
                }
            });
            if format.holds_data() && quality != Quality::Fast {
                let blocks = Blocks {
                    out: &mut out,
                    tick: &tick,
                };
                refine_single(v, w, h, ch, format, quality, blocks);
            }
            if matches!(format, BlockFormat::Bc1 | BlockFormat::Bc3) && quality != Quality::Fast {
                refine_colour(
                    v,
                    w,
                    h,
                    format,
                    quality,
                    f.alpha == AlphaMode::Straight,
                    Blocks {
                        out: &mut out,
                        tick: &tick,
                    },
                );
            }
        }
        (BlockFormat::Bc6h { .. }, Texels::F16(v)) => {
            let blocks = Blocks {
                out: &mut out,
                tick: &tick,
            };
            encode_bc6h(v, w, h, format, quality, blocks)
        }
        _ => return Err(encode_err(format!("{format} cannot encode {f} texels"))),
    }
    Ok(out)
}

/// BC1 blocks (with their 1-bit alpha) of an RGBA u8 level into `out`,
/// by texpresso (ISPC's BC1 kernel has no alpha).
fn bc1_with_alpha(
    v: &[u8],
    w: usize,
    h: usize,
    quality: Quality,
    by_alpha: bool,
    out: &mut [u8],
) -> Result<()> {
    let fmt = texpresso::Format::Bc1;
    let params = texpresso::Params {
        algorithm: match quality {
            Quality::Fast => texpresso::Algorithm::RangeFit,
            Quality::Normal => texpresso::Algorithm::ClusterFit,
            Quality::Slow => texpresso::Algorithm::IterativeClusterFit,
        },
        weights: texpresso::COLOUR_WEIGHTS_UNIFORM,
        weigh_colour_by_alpha: by_alpha,
    };
    if fmt.compressed_size(w, h) != out.len() {
        return Err(encode_err("block count mismatch"));
    }
    fmt.compress(v, w, h, params, out);
    Ok(())
}

/// BC6H (unsigned half) blocks of an RGB f16 level into `out`.
fn encode_bc6h(
    v: &[half::f16],
    w: usize,
    h: usize,
    format: BlockFormat,
    quality: Quality,
    blocks: Blocks<'_>,
) {
    // ISPC reads RGBA halves; unsigned half has no negatives, and
    // NaN or infinity have no block encoding: clamp to [0, MAX].
    let mut rgba = Vec::with_capacity(w * h * 8);
    for px in v.chunks_exact(3) {
        for c in px.iter().copied().chain([half::f16::ONE]) {
            let x = c.to_f32();
            let x = if x.is_nan() || x <= 0.0 {
                half::f16::ZERO
            } else if x > 65504.0 {
                half::f16::MAX
            } else {
                c
            };
            rgba.extend_from_slice(&x.to_bits().to_le_bytes());
        }
    }
    let s = match quality {
        Quality::Fast => intel_tex_2::bc6h::very_fast_settings(),
        Quality::Normal => intel_tex_2::bc6h::basic_settings(),
        Quality::Slow => intel_tex_2::bc6h::slow_settings(),
    };
    ispc_bands(&rgba, w, h, 8, format, blocks, |band, bw, bh, dst| {
        intel_tex_2::bc6h::compress_blocks_into(
            &s,
            &intel_tex_2::RgbaSurface {
                data: band,
                width: bw as u32,
                height: bh as u32,
                stride: (bw * 8) as u32,
            },
            dst,
        )
    });
}

/// Run an ISPC kernel over bands of [`BAND_BLOCK_ROWS`] block rows in
/// parallel: each band is copied into a buffer padded to whole blocks by
/// repeating the last column and row (`bpp` bytes per texel), and the
/// kernel writes the band's blocks into its slice of `out`.
fn ispc_bands(
    src: &[u8],
    w: usize,
    h: usize,
    bpp: usize,
    format: BlockFormat,
    blocks: Blocks<'_>,
    kernel: impl Fn(&[u8], usize, usize, &mut [u8]) + Sync,
) {
    let Blocks { out, tick } = blocks;
    let bw = w.div_ceil(4);
    let pw = bw * 4;
    let band_bytes = bw * format.block_bytes() * BAND_BLOCK_ROWS;
    out.par_chunks_mut(band_bytes)
        .enumerate()
        .for_each(|(b, dst)| {
            let rows = dst.len() / (bw * format.block_bytes()) * 4;
            let y0 = b * BAND_BLOCK_ROWS * 4;
            let mut buf = vec![0u8; pw * rows * bpp];
            for r in 0..rows {
                let sy = (y0 + r).min(h - 1);
                let line = &src[sy * w * bpp..(sy + 1) * w * bpp];
                let d = &mut buf[r * pw * bpp..(r + 1) * pw * bpp];
                d[..w * bpp].copy_from_slice(line);
                let last = &line[(w - 1) * bpp..];
                for x in w..pw {
                    d[x * bpp..(x + 1) * bpp].copy_from_slice(last);
                }
            }
            kernel(&buf, pw, rows, dst);
            tick((rows.min(h.saturating_sub(y0)) * w) as u64);
        });
}

/// The effort of the colour fit per quality step (see [`colour`]).
/// `normal`: least squares from the best start until the error stops
/// falling (at most 4 rounds), about nvcompress -fast's time; `slow`:
/// every start refined in both BC1 modes, with the ±1 endpoint search.
fn colour_effort(quality: Quality) -> colour::Effort {
    match quality {
        Quality::Fast | Quality::Normal => colour::Effort {
            least_squares: 4,
            neighbour_passes: 0,
            refine_all_starts: false,
            three_colour: false,
        },
        Quality::Slow => colour::Effort {
            least_squares: 8,
            neighbour_passes: 32,
            refine_all_starts: true,
            three_colour: true,
        },
    }
}

/// Refit the colour blocks ISPC wrote into `out` (BC1, or BC3's colour
/// halves) with [`colour::fit`], ISPC's endpoints among the starts, and at
/// `slow` libsquish's iterative cluster fit (texpresso) too. `v` is the
/// level's RGBA texels; `by_alpha` weighs each texel's colour error by its
/// straight alpha (BC3).
/// ISPC's BC4 blocks (BC5's two halves: R, then G) refitted
/// ([`single::refine`]), block rows on all threads.
fn refine_single(
    v: &[u8],
    w: usize,
    h: usize,
    ch: usize,
    format: BlockFormat,
    quality: Quality,
    blocks: Blocks<'_>,
) {
    let Blocks { out, tick } = blocks;
    let radius = if quality == Quality::Slow { 4 } else { 1 };
    let bb = format.block_bytes();
    let bw = w.div_ceil(4);
    out.par_chunks_mut(bw * bb)
        .enumerate()
        .for_each(|(by, row)| {
            // This block row's texels, counted as it starts.
            tick((4.min(h - by * 4) * w) as u64);
            for (bx, blk) in row.chunks_exact_mut(bb).enumerate() {
                for c in 0..bb / 8 {
                    let mut values = [0u8; 16];
                    let mut mask = 0u16;
                    for (i, value) in values.iter_mut().enumerate() {
                        let (x, y) = (bx * 4 + i % 4, by * 4 + i / 4);
                        if x < w && y < h {
                            mask |= 1 << i;
                        }
                        let (x, y) = (x.min(w - 1), y.min(h - 1));
                        *value = v[(y * w + x) * ch + c];
                    }
                    single::refine(&values, mask, radius, &mut blk[c * 8..c * 8 + 8]);
                }
            }
        });
}

fn refine_colour(
    v: &[u8],
    w: usize,
    h: usize,
    format: BlockFormat,
    quality: Quality,
    by_alpha: bool,
    blocks: Blocks<'_>,
) {
    let Blocks { out, tick } = blocks;
    let effort = colour_effort(quality);
    let bb = format.block_bytes();
    let off = if format == BlockFormat::Bc3 { 8 } else { 0 };
    let bw = w.div_ceil(4);
    let squish = quality == Quality::Slow;
    let squish_params = texpresso::Params {
        algorithm: texpresso::Algorithm::IterativeClusterFit,
        weights: texpresso::COLOUR_WEIGHTS_UNIFORM,
        weigh_colour_by_alpha: by_alpha,
    };
    let three = format == BlockFormat::Bc1;
    out.par_chunks_mut(bw * bb)
        .enumerate()
        .for_each(|(by, row)| {
            // This block row's texels, counted as it starts.
            tick((4.min(h - by * 4) * w) as u64);
            for (bx, blk) in row.chunks_exact_mut(bb).enumerate() {
                let mut px = colour::BlockTexels::default();
                let mut rgba = [[0u8; 4]; 16];
                let mut mask = 0u32;
                for (i, texel) in rgba.iter_mut().enumerate() {
                    let (x, y) = (bx * 4 + i % 4, by * 4 + i / 4);
                    let inside = x < w && y < h;
                    let (x, y) = (x.min(w - 1), y.min(h - 1));
                    let t = &v[(y * w + x) * 4..(y * w + x) * 4 + 4];
                    texel.copy_from_slice(t);
                    px.r[i] = t[0] as f32;
                    px.g[i] = t[1] as f32;
                    px.b[i] = t[2] as f32;
                    px.w[i] = match (inside, by_alpha) {
                        (false, _) => 0.0,
                        (true, false) => 1.0,
                        (true, true) => (t[3] as f32 + 1.0) / 256.0,
                    };
                    if inside {
                        mask |= 1 << i;
                    }
                }
                let endpoints = |b: &[u8]| {
                    (
                        u16::from_le_bytes([b[0], b[1]]),
                        u16::from_le_bytes([b[2], b[3]]),
                    )
                };
                let mut starts = [(0u16, 0u16); 2];
                starts[0] = endpoints(&blk[off..off + 4]);
                let n = if squish {
                    let mut sq = [0u8; 16];
                    let fmt = if three {
                        texpresso::Format::Bc1
                    } else {
                        texpresso::Format::Bc3
                    };
                    fmt.compress_block_masked(rgba, mask, squish_params, &mut sq);
                    starts[1] = endpoints(&sq[off..off + 4]);
                    2
                } else {
                    1
                };
                let c = colour::fit(&px, &starts[..n], &effort, three);
                blk[off..off + 8].copy_from_slice(&c);
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texel::{ChannelType, ColorSpace, Format};
    use std::sync::Mutex;

    /// The progress an encode reports comes block row by block row, in
    /// every pass (the ISPC fit and the refits), and adds up to the
    /// level's texels without passing them.
    #[test]
    fn progress_comes_row_by_row_and_adds_up_to_the_level() {
        let (w, h) = (300u32, 260u32);
        let mut s = 0x9e37_79b9u32;
        let noise: Vec<u8> = (0..w * h * 4)
            .map(|_| {
                s ^= s << 13;
                s ^= s >> 17;
                s ^= s << 5;
                s as u8
            })
            .collect();
        let level = Texture::from_u8(
            w,
            h,
            Format::new(4, ChannelType::U8, ColorSpace::Srgb),
            noise,
        )
        .unwrap();
        for (format, quality, passes) in [
            (BlockFormat::Bc7, Quality::Fast, 1u64),
            (BlockFormat::Bc3, Quality::Normal, 2),
        ] {
            let level = crate::compress::prepare(
                &level,
                format,
                input_format(format, ColorSpace::Srgb, None),
            )
            .unwrap();
            let ticks = Mutex::new(Vec::new());
            let tick = |n: u64| ticks.lock().unwrap().push(n);
            let with = encode_with(format, quality, &level, &tick).unwrap();
            assert_eq!(with, encode(format, quality, &level).unwrap());
            let ticks = ticks.into_inner().unwrap();
            let total: u64 = ticks.iter().sum();
            let texels = (w * h) as u64;
            // ISPC bands of 16 block rows (5 bands), then one call per
            // block row (65) in each refit.
            let calls = 5 + 65 * (passes - 1);
            assert_eq!(ticks.len() as u64, calls, "{format}");
            assert!(
                total <= texels && total + calls >= texels,
                "{format}: {total} of {texels}"
            );
        }
    }
}
