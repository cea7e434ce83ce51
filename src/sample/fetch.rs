//! Texel fetch: the decoded, linear-light RGBA copy of a chain that every
//! filter reads, and the one function that turns an integer texel index
//! into a colour.
//!
//! # Why a decoded copy
//! Filters work in linear light on RGBA `f32` (sRGB decoded first, as GPUs
//! do; grey replicated, missing alpha 1, as
//! [`crate::texture::expand_to_rgba`] defines). Decoding per fetch would
//! cost a table look-up per channel and a branch per storage type in the
//! innermost loop; decoding the whole chain once makes a fetch a single
//! 16-byte load for every storage type (u8/u16/f16/f32, 1–4 channels), so
//! one code path serves them all at the same speed.
//!
//! The price is memory: 16 bytes per texel, about 4/3 × 16 bytes per
//! level-0 texel for a full chain (85 MiB for a 2048² texture, against
//! 21 MiB for its RGBA8 chain). [`LinearChain`] can be shared between
//! samplers with different options through an `Arc`.

use rayon::prelude::*;

use crate::mip::MipChain;
use crate::texel::Format;
use crate::texture::expand_to_rgba;
use crate::wrap::{Wrap, wrap_index};

use super::trace::TexelSink;

/// One level, decoded to linear RGBA f32, row-major.
#[derive(Clone, Debug)]
pub(crate) struct Level {
    pub w: u32,
    pub h: u32,
    pub wf: f64,
    pub hf: f64,
    pub texels: Box<[[f32; 4]]>,
}

/// A mip chain decoded to linear-light RGBA `f32` (see the module docs for
/// the memory cost).
#[derive(Clone, Debug)]
pub struct LinearChain {
    pub(crate) levels: Vec<Level>,
    format: Format,
}

impl LinearChain {
    /// Decode every level of `chain` (in parallel).
    pub fn new(chain: &MipChain) -> Self {
        let levels = chain
            .levels()
            .iter()
            .map(|t| {
                let ch = t.channels();
                let linear = t.to_linear();
                let texels: Vec<[f32; 4]> = linear
                    .par_chunks_exact(ch)
                    .with_min_len(4096)
                    .map(expand_to_rgba)
                    .collect();
                Level {
                    w: t.width(),
                    h: t.height(),
                    wf: t.width() as f64,
                    hf: t.height() as f64,
                    texels: texels.into_boxed_slice(),
                }
            })
            .collect();
        LinearChain {
            levels,
            format: chain.levels()[0].format(),
        }
    }

    /// Format of the source chain (its channel count decides how many
    /// values the CLI prints).
    pub fn format(&self) -> Format {
        self.format
    }

    /// Number of levels.
    pub fn len(&self) -> usize {
        self.levels.len()
    }

    /// Always false: a chain has level 0.
    pub fn is_empty(&self) -> bool {
        self.levels.is_empty()
    }

    /// Size of level `k`.
    pub fn level_size(&self, k: usize) -> Option<(u32, u32)> {
        self.levels.get(k).map(|l| (l.w, l.h))
    }

    /// Bytes held by the decoded texels.
    pub fn memory_bytes(&self) -> usize {
        self.levels
            .iter()
            .map(|l| l.texels.len() * std::mem::size_of::<[f32; 4]>())
            .sum()
    }

    /// Decoded texel `(x, y)` of level `k`, or `None` out of range.
    pub fn texel(&self, k: usize, x: u32, y: u32) -> Option<[f32; 4]> {
        let l = self.levels.get(k)?;
        (x < l.w && y < l.h).then(|| l.texels[y as usize * l.w as usize + x as usize])
    }
}

/// Everything a fetch needs besides the level: wrap modes and border.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Addressing {
    pub wrap: Wrap,
    pub border: [f32; 4],
}

impl Level {
    /// The texel at integer index `(i, j)` after wrapping, or the border
    /// colour; reports the read to `sink`.
    #[inline(always)]
    pub fn fetch<S: TexelSink>(
        &self,
        li: u32,
        i: i64,
        j: i64,
        a: &Addressing,
        sink: &mut S,
    ) -> [f32; 4] {
        if (0..self.w as i64).contains(&i) && (0..self.h as i64).contains(&j) {
            return self.at(li, i as usize, j as usize, sink);
        }
        match (
            wrap_index(a.wrap.u, i, self.w),
            wrap_index(a.wrap.v, j, self.h),
        ) {
            (Some(x), Some(y)) => {
                sink.texel(li, x, y);
                self.texels[y as usize * self.w as usize + x as usize]
            }
            _ => a.border,
        }
    }

    /// Texel at an in-range index (caller checked `x < w`, `y < h`).
    #[inline(always)]
    pub fn at<S: TexelSink>(&self, li: u32, x: usize, y: usize, sink: &mut S) -> [f32; 4] {
        sink.texel(li, x as u32, y as u32);
        self.texels[y * self.w as usize + x]
    }
}

/// `a·x + b·y` per channel.
#[inline(always)]
pub(crate) fn mix(x: [f32; 4], a: f32, y: [f32; 4], b: f32) -> [f32; 4] {
    [
        x[0] * a + y[0] * b,
        x[1] * a + y[1] * b,
        x[2] * a + y[2] * b,
        x[3] * a + y[3] * b,
    ]
}

/// `(1 − t)·x + t·y`: a convex blend that is exact at t = 0 and t = 1 and
/// cannot overflow for finite inputs.
#[inline(always)]
pub(crate) fn lerp(x: [f32; 4], y: [f32; 4], t: f32) -> [f32; 4] {
    mix(x, 1.0 - t, y, t)
}
