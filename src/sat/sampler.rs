//! [`SatSampler`]: box filtering of pixel footprints with a summed-area
//! table of level 0 (no mip chain needed).
//!
//! The single-box filter averages the footprint's axis-aligned bounding
//! box (SPEC "Coordinates"): exact for axis-aligned footprints, blurrier
//! the more a footprint is both elongated and diagonal, because the box of
//! a thin diagonal parallelogram is mostly empty of it. The anisotropic
//! variant ([`SatSampler::sample_aniso`]) cuts the parallelogram into `N`
//! slices along its longer axis and averages their boxes, which hugs a
//! diagonal footprint with `N` times the reads.

use super::{AccumulatorKind, AnySat, BoxSum, COORD_LIMIT, Rect, build};
use crate::error::Result;
use crate::texture::{Texture, expand_to_rgba};
use crate::trace::TexelSink;
use crate::wrap::Wrap;
use std::sync::Arc;

/// Half-extents (in texels) beyond this are clamped: under repeat the box
/// already averages ~2⁵²/size whole periods, so the result is the level
/// average to f32 precision, computed in constant time.
pub const EXTENT_LIMIT: f64 = (1u64 << 51) as f64;

/// Box filtering with a summed-area table of level 0.
#[derive(Clone, Debug)]
pub struct SatSampler {
    table: Arc<AnySat>,
    wrap: Wrap,
    border: [f32; 4],
    channels: usize,
}

/// A finite, bounded value: NaN becomes 0, ±Inf and huge values clamp.
#[inline]
fn tame(v: f64, limit: f64) -> f64 {
    if v.is_nan() {
        0.0
    } else {
        v.clamp(-limit, limit)
    }
}

impl SatSampler {
    /// Build the table of `tex` with the automatic accumulator
    /// ([`super::choose`]). `border` is the linear RGBA border colour used
    /// by clamp to border.
    pub fn new(tex: &Texture, wrap: Wrap, border: [f32; 4]) -> Result<Self> {
        Self::with_accumulator(tex, None, wrap, border)
    }

    /// Build with a chosen accumulator (`None`: automatic). A kind that
    /// cannot be exact for this texture is an error (see
    /// [`super::SummedAreaTable::build`]).
    pub fn with_accumulator(
        tex: &Texture,
        accumulator: Option<AccumulatorKind>,
        wrap: Wrap,
        border: [f32; 4],
    ) -> Result<Self> {
        Ok(Self::from_table(build(tex, accumulator)?, wrap, border))
    }

    /// Wrap an existing table.
    pub fn from_table(table: AnySat, wrap: Wrap, border: [f32; 4]) -> Self {
        let channels = table.channels();
        SatSampler {
            table: Arc::new(table),
            wrap,
            border,
            channels,
        }
    }

    /// The table.
    pub fn table(&self) -> &AnySat {
        &self.table
    }

    /// The same table with other addressing: the table holds sums of the
    /// texels alone, so samplers with any wrap modes and border colours
    /// share it (the wrap acts when a rectangle is read).
    pub fn with_addressing(&self, wrap: Wrap, border: [f32; 4]) -> Self {
        SatSampler {
            table: Arc::clone(&self.table),
            wrap,
            border,
            channels: self.channels,
        }
    }

    /// The wrap modes.
    pub fn wrap(&self) -> Wrap {
        self.wrap
    }

    /// The footprint's axis-aligned bounding box in level-0 texels: centre
    /// `(u·w, v·h)`, half-extents `(|du/dx| + |du/dy|)/2 · w` and
    /// `(|dv/dx| + |dv/dy|)/2 · h`. NaN inputs count as 0, centres are
    /// clamped to ±[`COORD_LIMIT`] texels and half-extents to
    /// [`EXTENT_LIMIT`].
    pub fn footprint_box(
        &self,
        u: f32,
        v: f32,
        dudx: f32,
        dvdx: f32,
        dudy: f32,
        dvdy: f32,
    ) -> Rect {
        let (w, h) = (self.table.width() as f64, self.table.height() as f64);
        let cx = tame(tame(u as f64, f64::MAX) * w, COORD_LIMIT);
        let cy = tame(tame(v as f64, f64::MAX) * h, COORD_LIMIT);
        let half = |a: f32, b: f32, size: f64| {
            let e = (tame(a as f64, f64::MAX).abs() + tame(b as f64, f64::MAX).abs()) * 0.5 * size;
            e.min(EXTENT_LIMIT)
        };
        let (ex, ey) = (half(dudx, dudy, w), half(dvdx, dvdy, h));
        Rect::new(cx - ex, cy - ey, cx + ex, cy + ey).sanitized()
    }

    /// Filter one query (SPEC "Coordinates"; derivatives in normalized
    /// units per pixel): the average of the footprint's bounding box, as
    /// linear RGBA (grey expands to RGB, missing alpha is 1).
    ///
    /// Defined for every input, never panics, and never returns NaN for
    /// finite texels: NaN coordinates or derivatives count as 0; ±Inf and
    /// huge values are clamped (coordinates to ±2⁵² texels, half-extents
    /// to 2⁵¹ texels, where repeat gives the whole-level average). A
    /// zero-area footprint returns the texel under `(u, v)` (as `nearest`
    /// does); a zero extent on one axis averages the texels the other axis
    /// spans within the row or column under the centre. Footprints larger
    /// than the texture cost what small ones do: whole periods are counted,
    /// not visited.
    pub fn sample(&self, u: f32, v: f32, dudx: f32, dvdx: f32, dudy: f32, dvdy: f32) -> [f32; 4] {
        self.sample_traced(u, v, dudx, dvdx, dudy, dvdy, &mut crate::trace::NoTrace)
    }

    /// [`Self::sample`], reporting every table entry it reads to `sink`
    /// ([`TexelSink::sat_entry`]; four corners per rectangle inside the
    /// level), so the cache model sees the table as memory.
    #[allow(clippy::too_many_arguments)] // `sample`'s query plus the sink
    pub fn sample_traced<S: TexelSink>(
        &self,
        u: f32,
        v: f32,
        dudx: f32,
        dvdx: f32,
        dudy: f32,
        dvdy: f32,
        sink: &mut S,
    ) -> [f32; 4] {
        let r = self.footprint_box(u, v, dudx, dvdx, dudy, dvdy);
        if S::TRACES {
            self.table
                .entries_read(r, self.wrap, &mut |x, y| sink.sat_entry(x, y));
        }
        let avg = self.table.average(r, self.wrap, self.border);
        expand_to_rgba(&avg[..self.channels])
    }

    /// The anisotropic variant: the footprint parallelogram is cut into
    /// `N = min(ceil(major / minor), max_rects)` equal slices along its
    /// longer derivative vector, and the slices' bounding boxes are
    /// averaged with equal weights. `max_rects ≤ 1` is [`Self::sample`].
    #[allow(clippy::too_many_arguments)] // `sample`'s query plus the slice cap
    pub fn sample_aniso(
        &self,
        u: f32,
        v: f32,
        dudx: f32,
        dvdx: f32,
        dudy: f32,
        dvdy: f32,
        max_rects: u32,
    ) -> [f32; 4] {
        let (w, h) = (self.table.width() as f64, self.table.height() as f64);
        let t = |x: f32| tame(x as f64, f64::MAX);
        let (ax, ay) = (t(dudx) * w, t(dvdx) * h);
        let (bx, by) = (t(dudy) * w, t(dvdy) * h);
        let (la, lb) = (ax.hypot(ay), bx.hypot(by));
        let ((mx, my), (nx, ny), lmaj, lmin) = if la >= lb {
            ((ax, ay), (bx, by), la, lb)
        } else {
            ((bx, by), (ax, ay), lb, la)
        };
        let ratio = if lmin > 0.0 {
            lmaj / lmin
        } else {
            f64::INFINITY
        };
        let n = if ratio.is_finite() {
            ratio.ceil().clamp(1.0, max_rects.max(1) as f64) as u32
        } else if lmaj > 0.0 && lmaj.is_finite() {
            max_rects.max(1)
        } else {
            1
        };
        if n <= 1 {
            return self.sample(u, v, dudx, dvdx, dudy, dvdy);
        }
        let cx = tame(t(u) * w, COORD_LIMIT);
        let cy = tame(t(v) * h, COORD_LIMIT);
        let nf = n as f64;
        // One slice: spanned by major/N and the minor vector.
        let ex = ((mx / nf).abs() + nx.abs()) * 0.5;
        let ey = ((my / nf).abs() + ny.abs()) * 0.5;
        // Equal slices: adding their sums and areas weights them equally,
        // and straight alpha is divided out once, over the whole footprint.
        let mut total = BoxSum {
            sum: [0.0; 4],
            area: 0.0,
            border: 0.0,
            error: 0.0,
        };
        for k in 0..n {
            let s = (k as f64 + 0.5) / nf - 0.5;
            let (sx, sy) = (cx + s * mx, cy + s * my);
            let r = Rect::new(sx - ex, sy - ey, sx + ex, sy + ey).widened();
            let b = self.table.sum_box(r, self.wrap);
            for (a, v) in total.sum.iter_mut().zip(b.sum) {
                *a += v;
            }
            total.area += b.area;
            total.border += b.border;
            total.error += b.error;
        }
        let avg = self.table.finish(&total, self.border);
        expand_to_rgba(&avg[..self.channels])
    }
}
