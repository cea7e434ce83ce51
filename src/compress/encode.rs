//! Block encoders (feature `encode`), from two crates:
//! - `intel_tex_2` (Intel's ISPC texture compressor: SIMD kernels, with
//!   quality profiles for BC7 and BC6H) for BC4, BC5, BC6H and BC7, and for
//!   BC1 and BC3 at `fast` and `normal`;
//! - `texpresso` (a port of libsquish) for BC1 with alpha (its one-bit
//!   punch-through mode: texels with alpha below 128 become transparent,
//!   which ISPC's BC1 does not encode) and for BC1/BC3 at `slow` (iterative
//!   cluster fit).
//!
//! Measured on the 1024² `builtin:photo` (2-core Zen 4 VM): ISPC's BC1
//! gives 38.74 dB in 3 ms on one thread, texpresso's cluster fit 38.92 dB
//! in 1.2 s on two: 400× the time for 0.2 dB, so ISPC is the default.
//!
//! Every encoder reads the level in [`input_format`]: the texels are
//! already filtered and quantised, so the encoder's job is only the block
//! fit. Levels whose sides are not multiples of 4 are stored in whole
//! blocks: texpresso masks the texels outside the level out of the fit;
//! for the ISPC kernels (which read whole blocks) the level is padded by
//! repeating its last column and row, so the outside texels pull the
//! endpoints towards colours the block already has. Large levels are cut
//! into bands of block rows encoded on all threads; the bytes do not
//! depend on the number of threads.

use rayon::prelude::*;

use super::{BlockFormat, Quality, can_encode, input_format};
use crate::error::{Error, Result};
use crate::texel::{AlphaMode, ColorSpace, Texels};
use crate::texture::Texture;

fn encode_err(reason: impl Into<String>) -> Error {
    Error::Encode {
        format: "block compression",
        reason: reason.into(),
    }
}

/// Block rows per parallel band of the ISPC encoders.
const BAND_BLOCK_ROWS: usize = 16;

/// Encode one level (in [`input_format`]) as `format` blocks, row-major,
/// [`BlockFormat::level_bytes`] long.
pub fn encode(format: BlockFormat, quality: Quality, level: &Texture) -> Result<Vec<u8>> {
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
        (BlockFormat::Bc1 | BlockFormat::Bc3, Texels::U8(v))
            if quality == Quality::Slow || (format == BlockFormat::Bc1 && f.has_alpha()) =>
        {
            let fmt = if format == BlockFormat::Bc1 {
                texpresso::Format::Bc1
            } else {
                texpresso::Format::Bc3
            };
            let params = texpresso::Params {
                algorithm: match quality {
                    Quality::Fast => texpresso::Algorithm::RangeFit,
                    Quality::Normal => texpresso::Algorithm::ClusterFit,
                    Quality::Slow => texpresso::Algorithm::IterativeClusterFit,
                },
                weights: if f.color_space == ColorSpace::Srgb {
                    texpresso::COLOUR_WEIGHTS_PERCEPTUAL
                } else {
                    texpresso::COLOUR_WEIGHTS_UNIFORM
                },
                weigh_colour_by_alpha: f.alpha == AlphaMode::Straight,
            };
            if fmt.compressed_size(w, h) != out_len {
                return Err(encode_err("block count mismatch"));
            }
            fmt.compress(v, w, h, params, &mut out);
        }
        (_, Texels::U8(v)) => {
            let ch = f.channels as usize;
            ispc_bands(v, w, h, ch, format, &mut out, |band, bw, bh, dst| {
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
        }
        (BlockFormat::Bc6h { .. }, Texels::F16(v)) => {
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
            ispc_bands(&rgba, w, h, 8, format, &mut out, |band, bw, bh, dst| {
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
        _ => return Err(encode_err(format!("{format} cannot encode {f} texels"))),
    }
    Ok(out)
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
    out: &mut [u8],
    kernel: impl Fn(&[u8], usize, usize, &mut [u8]) + Sync,
) {
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
        });
}
