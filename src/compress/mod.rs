//! GPU block-compressed formats (BC1–BC7): what a block holds and how it
//! decodes to texels.
//!
//! Decoding goes through `bcdec_rs` (a pure-Rust port of bcdec, checked
//! against the reference decoders of the D3D and OpenGL specifications), so
//! parvo reads the DDS and KTX2 files other tools compress. A block covers
//! 4×4 texels; levels whose size is not a multiple of 4 are stored in whole
//! blocks and the texels outside the level are dropped on decode.

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::texel::{AlphaMode, ChannelType, ColorSpace, Format, Texels};
use crate::texture::Texture;

/// A block-compressed format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BlockFormat {
    /// BC1 (DXT1): RGB with 1-bit alpha, 8 bytes per block.
    Bc1,
    /// BC2 (DXT3): BC1 colour plus explicit 4-bit alpha, 16 bytes.
    Bc2,
    /// BC3 (DXT5): BC1 colour plus interpolated alpha, 16 bytes.
    Bc3,
    /// BC4 (ATI1): one channel, 8 bytes; `signed` for SNORM.
    Bc4 {
        /// SNORM rather than UNORM.
        signed: bool,
    },
    /// BC5 (ATI2): two channels, 16 bytes; `signed` for SNORM.
    Bc5 {
        /// SNORM rather than UNORM.
        signed: bool,
    },
    /// BC6H: HDR RGB half floats, 16 bytes; `signed` for SF16.
    Bc6h {
        /// SF16 rather than UF16.
        signed: bool,
    },
    /// BC7: RGBA, 16 bytes.
    Bc7,
}

impl BlockFormat {
    /// Bytes per 4×4 block.
    pub fn block_bytes(self) -> usize {
        match self {
            BlockFormat::Bc1 | BlockFormat::Bc4 { .. } => 8,
            _ => 16,
        }
    }

    /// A short name: `BC1` … `BC7`, with `_SNORM`/`_SF16` for the signed
    /// variants.
    pub fn name(self) -> &'static str {
        match self {
            BlockFormat::Bc1 => "BC1",
            BlockFormat::Bc2 => "BC2",
            BlockFormat::Bc3 => "BC3",
            BlockFormat::Bc4 { signed: false } => "BC4",
            BlockFormat::Bc4 { signed: true } => "BC4_SNORM",
            BlockFormat::Bc5 { signed: false } => "BC5",
            BlockFormat::Bc5 { signed: true } => "BC5_SNORM",
            BlockFormat::Bc6h { signed: false } => "BC6H_UF16",
            BlockFormat::Bc6h { signed: true } => "BC6H_SF16",
            BlockFormat::Bc7 => "BC7",
        }
    }

    /// Bytes of a `w × h` level: whole blocks, at least one.
    pub fn level_bytes(self, w: u32, h: u32) -> u64 {
        (w.div_ceil(4).max(1) as u64) * (h.div_ceil(4).max(1) as u64) * self.block_bytes() as u64
    }

    /// The texel format a level decodes to: RGBA8 for BC1/2/3/7 (sRGB when
    /// `srgb`), R8 and RG8 (no alpha) for unsigned BC4/BC5, f32 for the
    /// signed ones (their range is −1..1), RGB f16 for BC6H.
    pub fn decoded_format(self, srgb: bool) -> Format {
        let cs = if srgb {
            ColorSpace::Srgb
        } else {
            ColorSpace::Linear
        };
        match self {
            BlockFormat::Bc1 | BlockFormat::Bc2 | BlockFormat::Bc3 | BlockFormat::Bc7 => {
                Format::new(4, ChannelType::U8, cs)
            }
            BlockFormat::Bc4 { signed: false } => {
                Format::new(1, ChannelType::U8, ColorSpace::Linear)
            }
            BlockFormat::Bc4 { signed: true } => {
                Format::new(1, ChannelType::F32, ColorSpace::Linear)
            }
            BlockFormat::Bc5 { signed: false } => {
                Format::new(2, ChannelType::U8, ColorSpace::Linear).with_alpha(AlphaMode::None)
            }
            BlockFormat::Bc5 { signed: true } => {
                Format::new(2, ChannelType::F32, ColorSpace::Linear).with_alpha(AlphaMode::None)
            }
            BlockFormat::Bc6h { .. } => Format::new(3, ChannelType::F16, ColorSpace::Linear),
        }
    }
}

impl std::fmt::Display for BlockFormat {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Decode one `w × h` level of `format` blocks (row-major blocks, as DDS and
/// KTX2 store them) to a texture of [`BlockFormat::decoded_format`], with
/// `alpha` as the alpha convention of the 4-channel formats.
pub fn decode(
    format: BlockFormat,
    srgb: bool,
    alpha: AlphaMode,
    w: u32,
    h: u32,
    data: &[u8],
) -> Result<Texture> {
    let need = format.level_bytes(w, h);
    if (data.len() as u64) < need {
        return Err(Error::Decode {
            format: "block-compressed texture",
            reason: format!(
                "a {w}x{h} {format} level needs {need} bytes, {} are there",
                data.len()
            ),
        });
    }
    let mut tf = format.decoded_format(srgb);
    if tf.channels == 4 {
        tf = tf.with_alpha(alpha);
    }
    let ch = tf.channels as usize;
    let bw = w.div_ceil(4) as usize;
    let (w, h) = (w as usize, h as usize);
    let bb = format.block_bytes();
    let row_blocks = bw * bb;
    // One band of four texel rows per block row, decoded in parallel.
    fn bands<T: Copy + Default + Send>(
        out: &mut [T],
        band: usize,
        data: &[u8],
        row_blocks: usize,
        f: impl Fn(&[u8], &mut [T]) + Sync,
    ) {
        out.par_chunks_mut(band)
            .zip(data.par_chunks(row_blocks))
            .for_each(|(o, d)| f(d, o));
    }
    let band = w * 4 * ch;
    let texels = match format {
        BlockFormat::Bc6h { signed } => {
            let mut out = vec![0u16; w * h * ch];
            bands(&mut out, band, data, row_blocks, |d, o| {
                let rows = o.len() / (w * ch);
                for bx in 0..bw {
                    let mut tmp = [0u16; 48];
                    bcdec_rs::bc6h_half(&d[bx * bb..bx * bb + bb], &mut tmp, 12, signed);
                    copy_block(&tmp, 4 * ch, o, w * ch, bx * 4 * ch, ch, w - bx * 4, rows);
                }
            });
            Texels::F16(out.into_iter().map(half::f16::from_bits).collect())
        }
        BlockFormat::Bc4 { signed: true } | BlockFormat::Bc5 { signed: true } => {
            let mut out = vec![0f32; w * h * ch];
            bands(&mut out, band, data, row_blocks, |d, o| {
                let rows = o.len() / (w * ch);
                for bx in 0..bw {
                    let mut tmp = [0f32; 32];
                    let b = &d[bx * bb..bx * bb + bb];
                    if ch == 1 {
                        bcdec_rs::bc4_float(b, &mut tmp, 4, true);
                    } else {
                        bcdec_rs::bc5_float(b, &mut tmp, 8, true);
                    }
                    copy_block(&tmp, 4 * ch, o, w * ch, bx * 4 * ch, ch, w - bx * 4, rows);
                }
            });
            Texels::F32(out)
        }
        _ => {
            let mut out = vec![0u8; w * h * ch];
            bands(&mut out, band, data, row_blocks, |d, o| {
                let rows = o.len() / (w * ch);
                for bx in 0..bw {
                    let mut tmp = [0u8; 64];
                    let b = &d[bx * bb..bx * bb + bb];
                    let pitch = 4 * ch;
                    match format {
                        BlockFormat::Bc1 => bcdec_rs::bc1(b, &mut tmp, pitch),
                        BlockFormat::Bc2 => bcdec_rs::bc2(b, &mut tmp, pitch),
                        BlockFormat::Bc3 => bcdec_rs::bc3(b, &mut tmp, pitch),
                        BlockFormat::Bc7 => bcdec_rs::bc7(b, &mut tmp, pitch),
                        BlockFormat::Bc4 { .. } => bcdec_rs::bc4(b, &mut tmp, pitch, false),
                        BlockFormat::Bc5 { .. } => bcdec_rs::bc5(b, &mut tmp, pitch, false),
                        BlockFormat::Bc6h { .. } => unreachable!("decoded above"),
                    }
                    copy_block(&tmp, pitch, o, w * ch, bx * 4 * ch, ch, w - bx * 4, rows);
                }
            });
            Texels::U8(out)
        }
    };
    Texture::from_texels(w as u32, h as u32, tf, texels)
}

/// Copy the visible part of a decoded 4×4 block (`pitch` values per block
/// row) into `rows` rows of `out` (`stride` values per row) at value
/// offset `x0`, at most `cols` texels wide.
#[allow(clippy::too_many_arguments)]
fn copy_block<T: Copy>(
    block: &[T],
    pitch: usize,
    out: &mut [T],
    stride: usize,
    x0: usize,
    ch: usize,
    cols: usize,
    rows: usize,
) {
    let n = cols.min(4) * ch;
    for r in 0..rows.min(4) {
        out[r * stride + x0..r * stride + x0 + n].copy_from_slice(&block[r * pitch..r * pitch + n]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A BC1 block with colour endpoints c0 > c1 (four-colour mode): texel
    /// indices 0..3 select c0, c1, 2/3 c0 + 1/3 c1, 1/3 c0 + 2/3 c1
    /// (Microsoft's BC1 documentation).
    #[test]
    fn bc1_four_colour_block_decodes_to_the_documented_palette() {
        // c0 = pure red (565: 0xF800), c1 = pure blue (0x001F).
        let mut block = [0u8; 8];
        block[0..2].copy_from_slice(&0xF800u16.to_le_bytes());
        block[2..4].copy_from_slice(&0x001Fu16.to_le_bytes());
        // Row 0: indices 0,1,2,3; other rows index 0.
        block[4] = 0b11_10_01_00;
        let t = decode(BlockFormat::Bc1, false, AlphaMode::Straight, 3, 2, &block).unwrap();
        let Texels::U8(v) = t.texels() else { panic!() };
        assert_eq!(t.width(), 3);
        assert_eq!(&v[0..4], &[255, 0, 0, 255]);
        assert_eq!(&v[4..8], &[0, 0, 255, 255]);
        // 2/3 red + 1/3 blue (bcdec rounds (2·255 + 0)/3 = 170, 85).
        assert_eq!(&v[8..12], &[170, 0, 85, 255]);
        // Second row: index 0 everywhere.
        assert_eq!(&v[12..16], &[255, 0, 0, 255]);
    }

    #[test]
    fn short_data_is_an_error() {
        assert!(decode(BlockFormat::Bc3, false, AlphaMode::Straight, 5, 5, &[0; 63]).is_err());
        assert!(decode(BlockFormat::Bc3, false, AlphaMode::Straight, 5, 5, &[0; 64]).is_ok());
    }
}
