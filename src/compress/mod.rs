//! GPU block-compressed formats (BC1–BC7): what a block holds and how it
//! decodes to texels.
//!
//! Decoding goes through `bcdec_rs` (a pure-Rust port of bcdec, checked
//! against the reference decoders of the D3D and OpenGL specifications), so
//! parvo reads the DDS and KTX2 files other tools compress. A block covers
//! 4×4 texels; levels whose size is not a multiple of 4 are stored in whole
//! blocks and the texels outside the level are dropped on decode.

use rayon::prelude::*;

#[cfg(feature = "encode")]
pub mod encode;

use crate::error::{Error, Result};
use crate::texel::{AlphaMode, ChannelType, ColorSpace, Format, Texels};
use crate::texture::Texture;

/// Encoder effort: what `--quality` selects. Each step of opaque BC1 and
/// of BC3 keeps, per block, the best of the step before it and its own search,
/// so a step never gives a worse block than the one before (by the
/// squared error of the RGB codes).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Quality {
    /// BC7 and BC6H: ISPC's "very fast" profile; BC1/BC3: ISPC's kernel
    /// (BC1 with alpha: texpresso's range fit).
    Fast,
    /// BC7 and BC6H: ISPC's "basic" profile; BC1/BC3: ISPC's blocks
    /// refitted (least squares on the chosen indices, the best 5:6:5
    /// rounding; see `encode`), about `nvcompress -fast`'s time (BC1 with
    /// alpha: texpresso's cluster fit).
    #[default]
    Normal,
    /// BC7 and BC6H: ISPC's "slow" profile; BC1/BC3: the refit from every
    /// start (ISPC's, the principal axis, libsquish's iterative cluster
    /// fit), a ±1 search over the endpoints and, for opaque BC1, the
    /// three-colour mode too (BC1 with alpha: texpresso's iterative
    /// cluster fit).
    Slow,
}

impl Quality {
    /// `fast`, `normal` or `slow`.
    pub fn name(self) -> &'static str {
        match self {
            Quality::Fast => "fast",
            Quality::Normal => "normal",
            Quality::Slow => "slow",
        }
    }
}

impl std::fmt::Display for Quality {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Quality {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        Ok(match s.to_ascii_lowercase().as_str() {
            "fast" => Quality::Fast,
            "normal" => Quality::Normal,
            "slow" => Quality::Slow,
            _ => {
                return Err(Error::parse("quality", s, "expected fast, normal or slow"));
            }
        })
    }
}

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

    /// True for the formats that hold data rather than colour: BC4 and
    /// BC5 have no sRGB variant and store roughness, heights, masks and
    /// normals, so an input's stored codes go into them as they are.
    pub fn holds_data(self) -> bool {
        matches!(self, BlockFormat::Bc4 { .. } | BlockFormat::Bc5 { .. })
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
/// `alpha` as the alpha convention of the 4-channel formats
/// ([`AlphaMode::None`]: opaque, alpha reads as 1).
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
    // Opaque data (BC1 without alpha, a DDS marked opaque): the alpha the
    // blocks decode to is not part of the texture (BC1's three-colour mode
    // decodes black as alpha 0; ISPC's opaque BC7 modes leave some texels
    // at 254), so it reads as 1.
    let opaque = tf.channels == 4 && alpha == AlphaMode::None;
    if tf.channels == 4 {
        tf = tf.with_alpha(if opaque { AlphaMode::Straight } else { alpha });
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
            if opaque {
                out.iter_mut().skip(3).step_by(4).for_each(|a| *a = u8::MAX);
            }
            Texels::U8(out)
        }
    };
    Texture::from_texels(w as u32, h as u32, tf, texels)
}

/// The formats parvo encodes: the unsigned variants of BC1, BC3, BC4,
/// BC5, BC6H and BC7.
pub fn can_encode(format: BlockFormat) -> bool {
    matches!(
        format,
        BlockFormat::Bc1
            | BlockFormat::Bc3
            | BlockFormat::Bc4 { signed: false }
            | BlockFormat::Bc5 { signed: false }
            | BlockFormat::Bc6h { signed: false }
            | BlockFormat::Bc7
    )
}

/// The texel format the encoder of `format` reads, for a source with
/// colour space `cs` and alpha `alpha`: RGBA u8 for BC1/BC3/BC7 (sRGB
/// kept, so the `_SRGB` formats are written; a source without alpha gets
/// an opaque one and [`AlphaMode::None`]), one u8 channel for BC4, two
/// for BC5 (linear data), RGB f16 for BC6H (linear).
pub fn input_format(format: BlockFormat, cs: ColorSpace, alpha: Option<AlphaMode>) -> Format {
    match format {
        BlockFormat::Bc4 { .. } => {
            Format::new(1, ChannelType::U8, ColorSpace::Linear).with_alpha(AlphaMode::None)
        }
        BlockFormat::Bc5 { .. } => {
            Format::new(2, ChannelType::U8, ColorSpace::Linear).with_alpha(AlphaMode::None)
        }
        BlockFormat::Bc6h { .. } => {
            Format::new(3, ChannelType::F16, ColorSpace::Linear).with_alpha(AlphaMode::None)
        }
        _ => Format::new(4, ChannelType::U8, cs).with_alpha(alpha.unwrap_or(AlphaMode::None)),
    }
}

/// A mip chain of block-compressed levels, as the KTX2 and DDS writers
/// take it.
#[derive(Clone, Debug, PartialEq)]
pub struct BlockChain {
    /// The block format.
    pub format: BlockFormat,
    /// The `_SRGB` variant (BC1, BC2, BC3, BC7).
    pub srgb: bool,
    /// The alpha of the 4-channel formats: straight, premultiplied, or
    /// [`AlphaMode::None`] for opaque data (BC1 without alpha).
    pub alpha: AlphaMode,
    /// Level 0's size.
    pub width: u32,
    /// Level 0's size.
    pub height: u32,
    /// The levels' blocks, level 0 first, sizes rounding down.
    pub levels: Vec<Vec<u8>>,
}

impl BlockChain {
    /// Check that every level holds the bytes its size needs.
    pub fn validate(&self) -> Result<()> {
        if self.levels.is_empty() {
            return Err(Error::InvalidOption("nothing to write: no levels".into()));
        }
        for (k, l) in self.levels.iter().enumerate() {
            let (w, h) = crate::mip::level_size(
                self.width,
                self.height,
                k as u32,
                crate::mip::Rounding::Down,
            );
            let need = self.format.level_bytes(w, h);
            if l.len() as u64 != need {
                return Err(Error::InvalidOption(format!(
                    "level {k} ({w}x{h} {}) has {} bytes, needs {need}",
                    self.format,
                    l.len()
                )));
            }
        }
        Ok(())
    }

    /// Decode every level (see [`decode`]).
    pub fn decode(&self) -> Result<Vec<Texture>> {
        self.levels
            .iter()
            .enumerate()
            .map(|(k, l)| {
                let (w, h) = crate::mip::level_size(
                    self.width,
                    self.height,
                    k as u32,
                    crate::mip::Rounding::Down,
                );
                decode(self.format, self.srgb, self.alpha, w, h, l)
            })
            .collect()
    }
}

/// Encode every level of a chain as `format` and decode it again (by the
/// independent decoder): the texels a GPU would filter from the
/// compressed chain, and the bytes of its blocks.
#[cfg(feature = "encode")]
pub fn round_trip(
    levels: &[Texture],
    format: BlockFormat,
    quality: Quality,
) -> Result<(Vec<Texture>, u64)> {
    let first = levels
        .first()
        .ok_or_else(|| Error::InvalidOption("nothing to encode: no levels".into()))?;
    let f = first.format();
    let want = input_format(format, f.color_space, f.has_alpha().then_some(f.alpha));
    let out: Vec<(Texture, u64)> = levels
        .par_iter()
        .map(|l| {
            let input = prepare(l, format, want)?;
            let blocks = encode::encode(format, quality, &input)?;
            let d = decode(
                format,
                want.color_space == ColorSpace::Srgb,
                want.alpha,
                l.width(),
                l.height(),
                &blocks,
            )?;
            Ok((d, blocks.len() as u64))
        })
        .collect::<Result<Vec<_>>>()?;
    let bytes = out.iter().map(|x| x.1).sum();
    Ok((out.into_iter().map(|x| x.0).collect(), bytes))
}

/// The first `n` channels of `t` (no alpha among them unless all of a
/// 2- or 4-channel texture's are kept).
pub fn first_channels(t: &Texture, n: u8) -> Result<Texture> {
    let f = t.format();
    if n == 0 || n > f.channels {
        return Err(Error::InvalidOption(format!(
            "cannot take {n} channels of {f}"
        )));
    }
    if n == f.channels {
        return Ok(t.clone());
    }
    fn take<T: Copy>(v: &[T], from: usize, n: usize) -> Vec<T> {
        v.chunks_exact(from)
            .flat_map(|p| p[..n].iter().copied())
            .collect()
    }
    let (from, k) = (f.channels as usize, n as usize);
    let texels = match t.texels() {
        Texels::U8(v) => Texels::U8(take(v, from, k)),
        Texels::U16(v) => Texels::U16(take(v, from, k)),
        Texels::F16(v) => Texels::F16(take(v, from, k)),
        Texels::F32(v) => Texels::F32(take(v, from, k)),
    };
    let format = Format {
        channels: n,
        alpha: AlphaMode::None,
        ..f
    };
    Texture::from_texels(t.width(), t.height(), format, texels)
}

/// `level` in the texel format the encoder of `format` reads
/// (`encode::input_format`): channels taken or widened (grey to RGB, an
/// opaque alpha added), then converted (type, and colour space: BC4, BC5
/// and BC6H store linear values).
pub fn prepare(level: &Texture, format: BlockFormat, want: Format) -> Result<Texture> {
    let f = level.format();
    let shaped = if f.channels > want.channels {
        first_channels(level, want.channels)?
    } else if f.channels < want.channels {
        if f.channels == 1 && want.channels == 2 {
            return Err(Error::InvalidOption(format!(
                "{format} stores two channels; the input has one (use bc4)"
            )));
        }
        level.expand_channels(want.channels)?
    } else {
        level.clone()
    };
    let sf = shaped.format();
    let target = Format {
        channels: sf.channels,
        // An alpha channel added by widening is opaque, not alpha data.
        alpha: if f.has_alpha() && sf.has_alpha() {
            sf.alpha
        } else {
            want.alpha
        },
        ..want
    };
    let converted =
        if sf.channel_type == target.channel_type && sf.color_space == target.color_space {
            shaped
        } else {
            shaped.convert(Format {
                alpha: sf.alpha,
                ..target
            })?
        };
    converted.reinterpret(target)
}

/// Peak signal-to-noise ratio, in dB, of `got` against `reference` (same
/// size, same channel count): over the first `channels` channels of the
/// stored values, integers scaled to 0..1 with peak 1, floats with the
/// reference's largest magnitude (at least 1) as the peak. Infinite for
/// identical levels.
pub fn psnr(reference: &Texture, got: &Texture, channels: usize) -> Result<f64> {
    let (rf, gf) = (reference.format(), got.format());
    if (reference.width(), reference.height()) != (got.width(), got.height())
        || rf.channels != gf.channels
        || channels == 0
        || channels > rf.channels as usize
    {
        return Err(Error::InvalidOption(format!(
            "PSNR of a {}x{} {rf} level against a {}x{} {gf} one",
            reference.width(),
            reference.height(),
            got.width(),
            got.height()
        )));
    }
    let ch = rf.channels as usize;
    let values = |t: &Texture| -> Vec<f64> {
        match t.texels() {
            Texels::U8(v) => v.iter().map(|&x| x as f64 / 255.0).collect(),
            Texels::U16(v) => v.iter().map(|&x| x as f64 / 65535.0).collect(),
            Texels::F16(v) => v.iter().map(|x| x.to_f64()).collect(),
            Texels::F32(v) => v.iter().map(|&x| x as f64).collect(),
        }
    };
    let (a, b) = (values(reference), values(got));
    let peak = if rf.channel_type.is_float() {
        a.iter()
            .filter(|x| x.is_finite())
            .fold(1.0f64, |m, x| m.max(x.abs()))
    } else {
        1.0
    };
    let (mut se, mut n) = (0.0f64, 0u64);
    for (pa, pb) in a.chunks_exact(ch).zip(b.chunks_exact(ch)) {
        for c in 0..channels {
            let d = pa[c] - pb[c];
            if d.is_finite() {
                se += d * d;
            }
            n += 1;
        }
    }
    let mse = se / n.max(1) as f64;
    Ok(if mse == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (peak * peak / mse).log10()
    })
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
