//! Summed-area tables (Crow 1984) with accumulators wide enough to be
//! exact, or an error bound where they cannot be; box averages over any
//! rectangle in O(1); the SAT sampler.
//!
//! # Why the accumulator is a type
//!
//! A table's entries are sums of up to `w·h` texels, so they need
//! `value bits + ceil(log2(w·h))` bits (SPEC.md "Summed-area tables"): an
//! 8-bit 4096² level fills a u32 exactly (255·4096² < 2³²), 8192² needs
//! u64, and so does 16-bit 4096². Narrow integer tables silently wrap and
//! float tables silently lose the low bits toward the far corner, where
//! large, nearly equal entries are subtracted. So [`SummedAreaTable`] is
//! generic over an [`Accumulator`]:
//!
//! | kind | stores | exact? | bytes/entry |
//! |------|--------|--------|-------------|
//! | `u32`, `u64`, `u128` | sums of integer codes | yes, or refused at build time | 4, 8, 16 |
//! | `f32` | sums of linear values | no: ≈ 2⁻²⁴·\|S\| per entry | 4 |
//! | `offset-f32` | sums of value − channel mean (Hensley et al. 2005) | no: ≈ 2⁻²⁴·\|S − mean·area\| | 4 |
//! | `f64` | sums of linear values | no: ≈ 2⁻⁵³·\|S\| per entry | 8 |
//!
//! A table holds `(w + 1)·(h + 1)·channels` entries (one zero row and
//! column): a 4096² RGBA level takes 269 MB in u32/f32/offset-f32, 537 MB
//! in u64/f64 and 1.07 GB in u128; a one-channel 4096² level a quarter of
//! that. [`SummedAreaTable::max_entry_error`] gives each float table's
//! bound, computed from its own data.
//!
//! Measured on a 4096² image of uniform random f32 values in [0, 1), the
//! largest absolute error of box averages with a corner in the last 64×64
//! texels (`cargo run --release --example 03_sat_precision`, which prints
//! this table):
//!
//! | accumulator | 1×1 | 2×2 | 4×4 | 1×1 near the origin | stated bound, 1×1 |
//! |---|---|---|---|---|---|
//! | f32 | 9.1e-1 | 2.3e-1 | 5.3e-2 | 2.1e-4 | 2.0 |
//! | offset-f32 | 3.2e-5 | 6.9e-6 | 1.9e-6 | 2.0e-6 | 4.3e-4 |
//! | f64 | 9.3e-10 | 2.3e-10 | 5.8e-11 | 0 | 6.1e-5 |
//!
//! Subtracting the mean makes an f32 table about 30 000 times more
//! accurate at the far corner for the same memory; f64 costs twice the
//! memory and is another 30 000 times better. The example also prints an
//! f32 table summed in f32 (the plain two-pass build): 4.9e-1 at 1×1 —
//! lower than parvo's once-rounded f32 entries, because neighbouring
//! entries share their accumulated rounding and it partly cancels — and
//! worse from 3×3 up (1.3e-1, 8.6e-2). Neither f32 variant is usable at
//! the far corner of a 4096² level; offset-f32 is.
//!
//! # Automatic choice
//!
//! [`choose`] takes the narrowest integer accumulator that SPEC's bit rule
//! proves exact, when the data is 8- or 16-bit and linear (straight alpha
//! doubles the value bits, because colour is summed as colour × alpha).
//! Integer tables sum stored codes; the average is turned into linear light
//! only at the end (code / 255 or / 65535). That is wrong for sRGB data —
//! averaging sRGB codes is not averaging light — so sRGB data and float
//! data get an `f64` table of linear values, accurate to
//! [`SummedAreaTable::max_entry_error`] per entry: for a 4096² level of
//! values in [0, 1] the bound is 2⁻¹⁵ per entry, so 2⁻¹³ on a whole-texel
//! box sum and on a one-texel box average (the worst case); measured
//! errors are far smaller (see
//! `examples/03_sat_precision.rs`). A
//! u128 table is chosen only beyond 2⁴⁸ texels (2³² with straight alpha at
//! 16 bits). A caller that names an accumulator too narrow for the size is
//! refused with an error before anything is allocated; nothing wraps.
//!
//! # Queries
//!
//! [`SummedAreaTable::sum_box`] and [`SummedAreaTable::average`] take a
//! [`Rect`] in texel units of the level: fractional edges weight partial
//! texels by covered area (the table interpolated linearly), and under
//! repeat and mirrored repeat the rectangle may cross edges any number of
//! times — whole periods are counted arithmetically, so cost is constant.
//! Clamp modes and the border colour are handled the same way (see the
//! `axis` module). [`SatSampler`] averages the axis-aligned bounding box of
//! a pixel footprint (SPEC "Coordinates") on level 0.
//!
//! # Example
//!
//! ```
//! use parvo::sat::{self, AccumulatorKind, Rect};
//! use parvo::texel::{ChannelType, ColorSpace, Format};
//! use parvo::{Texture, Wrap, WrapMode};
//!
//! let grey = Format::new(1, ChannelType::U8, ColorSpace::Linear);
//! let tex = Texture::from_u8(4, 2, grey, vec![0, 51, 102, 153, 204, 255, 0, 51])?;
//! let table = sat::build(&tex, None)?; // 8 + 3 bits: u32 is exact
//! assert_eq!(table.kind(), AccumulatorKind::U32);
//! // Texels 1..3 of row 0, and the same columns one period to the left.
//! let a = table.average(Rect::texels(1, 0, 3, 1), Wrap::default(), [0.0; 4]);
//! let b = table.average(Rect::texels(-3, 0, -1, 1), Wrap::default(), [0.0; 4]);
//! assert_eq!((a[0], b[0]), (0.3, 0.3));
//! // Half of texel 3 and half of texel 0, across the edge, mirrored and not.
//! let r = Rect::new(3.5, 0.0, 4.5, 1.0);
//! assert_eq!(table.average(r, Wrap::default(), [0.0; 4])[0], 0.3);
//! assert_eq!(table.average(r, Wrap::both(WrapMode::MirroredRepeat), [0.0; 4])[0], 0.6);
//! # Ok::<(), parvo::Error>(())
//! ```
//!
//! # Build
//!
//! Horizontal bands in parallel (rayon): column totals per band, a short
//! scan, then each band's rows as a row prefix sum added to running column
//! sums. Every entry is written once, from exact integer or f64 running
//! sums, so the build reads the source twice and writes the table once.

mod accum;
mod axis;
mod sampler;
mod table;

pub use accum::{Accumulator, AccumulatorKind, OffsetF32};
pub use sampler::{EXTENT_LIMIT, SatSampler};
pub use table::{BoxSum, SummedAreaTable, Units};

use crate::error::Result;
use crate::texel::{AlphaMode, ChannelType, ColorSpace, Format};
use crate::texture::Texture;
use crate::wrap::Wrap;

/// A rectangle `[x0, x1) × [y0, y1)` in texel units of a level (texel
/// `(i, j)` covers `[i, i+1) × [j, j+1)`); it may lie partly or wholly
/// outside the level, where the wrap mode decides what it reads.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rect {
    /// Left edge.
    pub x0: f64,
    /// Top edge.
    pub y0: f64,
    /// Right edge (exclusive).
    pub x1: f64,
    /// Bottom edge (exclusive).
    pub y1: f64,
}

/// Coordinates beyond this magnitude (in texels) are clamped to it: below
/// 2⁵² an f64 still resolves whole texels, and every index stays exact in
/// the i64 arithmetic of the queries.
pub const COORD_LIMIT: f64 = (1u64 << 52) as f64;

impl Rect {
    /// A rectangle from its edges.
    pub const fn new(x0: f64, y0: f64, x1: f64, y1: f64) -> Self {
        Rect { x0, y0, x1, y1 }
    }

    /// The texel rectangle `[x0, x1) × [y0, y1)`.
    pub fn texels(x0: i64, y0: i64, x1: i64, y1: i64) -> Self {
        Rect::new(x0 as f64, y0 as f64, x1 as f64, y1 as f64)
    }

    /// NaN edges become 0, edges are clamped to ±[`COORD_LIMIT`], and
    /// swapped edges are put in order. Every query does this first.
    pub fn sanitized(self) -> Self {
        let f = |v: f64| {
            if v.is_nan() {
                0.0
            } else {
                v.clamp(-COORD_LIMIT, COORD_LIMIT)
            }
        };
        let (x0, x1, y0, y1) = (f(self.x0), f(self.x1), f(self.y0), f(self.y1));
        Rect {
            x0: x0.min(x1),
            x1: x0.max(x1),
            y0: y0.min(y1),
            y1: y0.max(y1),
        }
    }

    /// [`Self::sanitized`], then an axis of zero length becomes the texel
    /// containing it (the limit of ever thinner boxes).
    pub fn widened(self) -> Self {
        let mut r = self.sanitized();
        for (lo, hi) in [(&mut r.x0, &mut r.x1), (&mut r.y0, &mut r.y1)] {
            if *hi <= *lo {
                *lo = lo.floor();
                *hi = *lo + 1.0;
            }
        }
        r
    }

    /// Width times height.
    pub fn area(&self) -> f64 {
        (self.x1 - self.x0) * (self.y1 - self.y0)
    }
}

/// Bits of one summand: the texel bits, doubled for straight alpha (colour
/// is summed as colour × alpha). Float types report 0 (no integer table).
pub fn value_bits(format: &Format) -> u32 {
    let bits = match format.channel_type {
        ChannelType::U8 => 8,
        ChannelType::U16 => 16,
        ChannelType::F16 | ChannelType::F32 => return 0,
    };
    if format.has_alpha() && format.alpha == AlphaMode::Straight {
        2 * bits
    } else {
        bits
    }
}

/// SPEC's rule: a table of `w × h` summands of `value_bits` bits is exact
/// in `value_bits + ceil(log2(w·h))` bits.
pub fn required_bits(value_bits: u32, width: u32, height: u32) -> u32 {
    let n = width as u64 * height as u64;
    let log = if n <= 1 {
        0
    } else {
        64 - (n - 1).leading_zeros()
    };
    value_bits + log
}

/// The automatic accumulator for a texture: the narrowest exact integer
/// kind for linear 8/16-bit data, else f64 (see the module docs).
pub fn choose(format: &Format, width: u32, height: u32) -> AccumulatorKind {
    let srgb = format.color_space == ColorSpace::Srgb && format.color_channels() > 0;
    let bits = value_bits(format);
    if bits == 0 || srgb {
        return AccumulatorKind::F64;
    }
    match required_bits(bits, width, height) {
        0..=32 => AccumulatorKind::U32,
        33..=64 => AccumulatorKind::U64,
        _ => AccumulatorKind::U128,
    }
}

/// A table of any accumulator kind, as [`build`] returns it.
#[derive(Clone, Debug)]
pub enum AnySat {
    /// u32 entries.
    U32(SummedAreaTable<u32>),
    /// u64 entries.
    U64(SummedAreaTable<u64>),
    /// u128 entries.
    U128(SummedAreaTable<u128>),
    /// f32 entries.
    F32(SummedAreaTable<f32>),
    /// Offset f32 entries.
    OffsetF32(SummedAreaTable<OffsetF32>),
    /// f64 entries.
    F64(SummedAreaTable<f64>),
}

macro_rules! dispatch {
    ($self:expr, $t:ident => $e:expr) => {
        match $self {
            AnySat::U32($t) => $e,
            AnySat::U64($t) => $e,
            AnySat::U128($t) => $e,
            AnySat::F32($t) => $e,
            AnySat::OffsetF32($t) => $e,
            AnySat::F64($t) => $e,
        }
    };
}

impl AnySat {
    /// The accumulator kind.
    pub fn kind(&self) -> AccumulatorKind {
        dispatch!(self, t => t.kind())
    }
    /// Level width in texels.
    pub fn width(&self) -> u32 {
        dispatch!(self, t => t.width())
    }
    /// Level height in texels.
    pub fn height(&self) -> u32 {
        dispatch!(self, t => t.height())
    }
    /// Channels per entry.
    pub fn channels(&self) -> usize {
        dispatch!(self, t => t.channels())
    }
    /// Bytes held by the entries.
    pub fn memory_bytes(&self) -> usize {
        dispatch!(self, t => t.memory_bytes())
    }
    /// See [`SummedAreaTable::max_entry_error`].
    pub fn max_entry_error(&self) -> f64 {
        dispatch!(self, t => t.max_entry_error())
    }
    /// See [`SummedAreaTable::units`].
    pub fn units(&self) -> Units {
        dispatch!(self, t => t.units())
    }
    /// See [`SummedAreaTable::sum_box`].
    pub fn sum_box(&self, rect: Rect, wrap: Wrap) -> BoxSum {
        dispatch!(self, t => t.sum_box(rect, wrap))
    }
    /// See [`SummedAreaTable::finish`].
    pub fn finish(&self, s: &BoxSum, border: [f32; 4]) -> [f32; 4] {
        dispatch!(self, t => t.finish(s, border))
    }
    /// Bytes of one entry (all channels), as the cache model reads it.
    pub fn entry_bytes(&self) -> u64 {
        let per = match self.kind() {
            AccumulatorKind::U32 | AccumulatorKind::F32 | AccumulatorKind::OffsetF32 => 4,
            AccumulatorKind::U64 | AccumulatorKind::F64 => 8,
            AccumulatorKind::U128 => 16,
        };
        per * self.channels() as u64
    }
    /// Call `read(x, y)` for every table entry [`Self::average`] reads for
    /// `rect` under `wrap` (four corners for a rectangle inside the level;
    /// more where repeat or mirror split it), in the order it reads them.
    pub fn entries_read(&self, rect: Rect, wrap: Wrap, read: &mut dyn FnMut(u32, u32)) {
        let r = rect.widened().sanitized();
        let ax = axis::Axis::new(wrap.u, r.x0, r.x1, self.width());
        let ay = axis::Axis::new(wrap.v, r.y0, r.y1, self.height());
        for (iy, _) in ay.terms() {
            for (ix, _) in ax.terms() {
                read(ix, iy);
            }
        }
    }
    /// See [`SummedAreaTable::average`].
    pub fn average(&self, rect: Rect, wrap: Wrap, border: [f32; 4]) -> [f32; 4] {
        dispatch!(self, t => t.average(rect, wrap, border))
    }
}

/// Build a table of `tex` with the given accumulator, or the automatic
/// choice ([`choose`]) for `None`.
pub fn build(tex: &Texture, accumulator: Option<AccumulatorKind>) -> Result<AnySat> {
    let kind = accumulator.unwrap_or_else(|| choose(&tex.format(), tex.width(), tex.height()));
    Ok(match kind {
        AccumulatorKind::U32 => AnySat::U32(SummedAreaTable::build(tex)?),
        AccumulatorKind::U64 => AnySat::U64(SummedAreaTable::build(tex)?),
        AccumulatorKind::U128 => AnySat::U128(SummedAreaTable::build(tex)?),
        AccumulatorKind::F32 => AnySat::F32(SummedAreaTable::build(tex)?),
        AccumulatorKind::OffsetF32 => AnySat::OffsetF32(SummedAreaTable::build(tex)?),
        AccumulatorKind::F64 => AnySat::F64(SummedAreaTable::build(tex)?),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bit_rule_matches_the_spec_examples() {
        let g8 = Format::new(1, ChannelType::U8, ColorSpace::Linear);
        let g16 = Format::new(1, ChannelType::U16, ColorSpace::Linear);
        assert_eq!(required_bits(8, 4096, 4096), 32);
        assert_eq!(choose(&g8, 4096, 4096), AccumulatorKind::U32);
        assert_eq!(choose(&g8, 8192, 8192), AccumulatorKind::U64);
        assert_eq!(choose(&g16, 4096, 4096), AccumulatorKind::U64);
        assert_eq!(choose(&g16, 65536, 256), AccumulatorKind::U64);
        assert_eq!(required_bits(8, 1, 1), 8);
        assert_eq!(required_bits(8, 1, 2), 9);
        assert_eq!(required_bits(8, 3, 1), 10);
        let srgb = Format::new(4, ChannelType::U8, ColorSpace::Srgb);
        assert_eq!(choose(&srgb, 16, 16), AccumulatorKind::F64);
        let rgba16 = Format::new(4, ChannelType::U16, ColorSpace::Linear);
        assert_eq!(choose(&rgba16, 65536, 65536), AccumulatorKind::U64);
        assert_eq!(choose(&rgba16, 65536, 65537), AccumulatorKind::U128);
    }
}
