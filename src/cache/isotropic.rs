//! Address-only isotropic lookups: the texels a nearest, bilinear or
//! trilinear lookup (any magnification, minification and mip filter, one
//! probe: `max_aniso` 1) reads, reported to a sink without reading them.
//!
//! A traced [`Sampler`] fetches, decodes and blends every texel it
//! reports, which a cache simulation throws away; for the isotropic
//! lookups, the bulk of a scene's cache runs, this is most of the work.
//! [`AddressOnly`] follows the sampler's own rules for where it reads,
//! with its LOD rules (the sampler's own `Lod` and `Plan`, not a copy)
//! and the crate's wrap rule, and restates in a few lines only what the
//! sampler's private filter code does with them: the 2×2 block (or the
//! one texel) at `u·w − ½` (`u·w`), the inside-the-level test, and the
//! edge path that wraps each axis once and skips border reads. The other
//! filters (footprint assembly, EWA, supersampling, the summed-area
//! table) are traced by the sampler itself.
//!
//! `tests/core/cache_report/cache_fast_paths.rs` compares the reads with the traced
//! sampler's, read for read, for every filter combination and wrap mode
//! on awkward level sizes and on queries far outside [0, 1), with NaN
//! and infinite coordinates and derivatives.

use super::layout::Lanes;
use crate::sample::Method;
use crate::sample::footprint::{Lod, Plan};
use crate::sample::{MipMode, Query, Sampler, SamplerOptions, TexelFilter, TexelSink};
use crate::wrap::{Wrap, WrapMode, fast_floor, reduce_coordinate, wrap_index};

/// The reads of an isotropic sampler, without its texels (see the module
/// docs).
#[derive(Clone, Debug)]
pub struct AddressOnly {
    lod: Lod,
    options: SamplerOptions,
    wrap: Wrap,
    /// Width, height, and both as `f64`, per level.
    levels: Vec<(u32, u32, f64, f64)>,
    /// Whether [`AddressOnly::trace_all`] plans 8 queries at a time, and
    /// with which mip mode (linear: `true`): on CPUs with the sampler's
    /// AVX-512 paths, for mip mode nearest or linear and the same
    /// magnification and minification filter.
    #[cfg(target_arch = "x86_64")]
    lanes: Option<(crate::sample::simd::Planner, bool)>,
    /// The level sizes as 8-lane tables for [`super::lanes::cells8`]
    /// (with `lanes`, for chains of up to 16 levels).
    #[cfg(target_arch = "x86_64")]
    sizes: Option<super::lanes::Sizes>,
}

impl AddressOnly {
    /// The reads of `sampler`'s lookups, when it is an isotropic texel
    /// filter (`None` otherwise: footprint assembly, EWA, supersampling
    /// and the summed-area table are traced by the sampler).
    pub fn new(sampler: &Sampler) -> Option<Self> {
        let o = *sampler.options();
        if o.method != Method::Texel || o.max_aniso != 1 {
            return None;
        }
        let chain = sampler.chain();
        let levels: Vec<(u32, u32, f64, f64)> = (0..chain.len())
            .map_while(|k| chain.level_size(k))
            .map(|(w, h)| (w, h, w as f64, h as f64))
            .collect();
        let &(_, _, wf, hf) = levels.first()?;
        #[cfg(target_arch = "x86_64")]
        let lanes = crate::sample::simd::Planner::new()
            .filter(|_| o.mag == o.min)
            .and_then(|p| match o.mip {
                MipMode::Linear => Some((p, true)),
                MipMode::Nearest => Some((p, false)),
                MipMode::None => None,
            });
        Some(AddressOnly {
            lod: Lod::new(&o, wf, hf, levels.len()),
            options: o,
            wrap: o.wrap,
            #[cfg(target_arch = "x86_64")]
            sizes: lanes.and_then(|_| super::lanes::Sizes::new(&levels)),
            levels,
            #[cfg(target_arch = "x86_64")]
            lanes,
        })
    }

    /// Report the texels the sampler's lookup of `q` reads to `sink`, in
    /// its order.
    #[inline]
    pub fn trace<S: TexelSink>(&self, q: &Query, sink: &mut S) {
        self.trace_blocks(q, &mut Texels(sink));
    }

    /// [`AddressOnly::trace`] of every query of `qs` in order: on CPUs
    /// with the sampler's AVX-512 paths the level plans and wrapped
    /// coordinates of 8 queries at a time (the same texels, in the same
    /// order).
    pub fn trace_slice<S: TexelSink>(&self, qs: &[Query], sink: &mut S) {
        self.trace_all(qs, &mut Texels(sink));
    }

    /// [`AddressOnly::trace_blocks`] of every query of `qs` in order:
    /// on CPUs with the sampler's AVX-512 paths, the level plans and
    /// wrapped coordinates of 8 queries at a time in registers, and then
    /// the texels (and, for a sink with [`BlockSink::lanes`], their
    /// addresses) of each level choice of the 8 ([`super::lanes`]): the
    /// same operations, so the same reads; the lanes those do not cover,
    /// and the last few queries, one by one.
    #[inline]
    pub(crate) fn trace_all<S: BlockSink>(&self, qs: &[Query], sink: &mut S) {
        #[cfg(target_arch = "x86_64")]
        if let (Some((planner, linear)), Some(sizes)) = (self.lanes, &self.sizes) {
            // The filters are the same either way (`lanes`).
            let bilinear = self.options.min == TexelFilter::Linear;
            let layout = sink.lanes().cloned();
            let (mut fine, mut coarse) = Default::default();
            let (q8s, rest) = qs.as_chunks::<8>();
            for q8 in q8s {
                let p = planner.plans8(&self.lod, &self.options, linear, q8);
                let l = layout.as_ref();
                // SAFETY: a `Planner` exists only on CPUs with AVX-512.
                #[allow(unsafe_code)]
                unsafe {
                    use super::lanes::cells8;
                    cells8(sizes, &p.hi, &p.u, &p.v, bilinear, l, &mut fine);
                    // Mip mode nearest reads one level.
                    if linear {
                        cells8(sizes, &p.lo, &p.u, &p.v, bilinear, l, &mut coarse);
                    }
                }
                for (i, q) in q8.iter().enumerate() {
                    if p.exact >> i & 1 == 0 {
                        self.trace_blocks(q, sink);
                        continue;
                    }
                    let (hi, lo) = (p.hi[i] as usize, p.lo[i] as usize);
                    let lane = (i, p.u[i], p.v[i]);
                    self.put_lane(&fine, hi, lane, bilinear, layout.is_some(), sink);
                    if p.delta[i] > 0.0 && lo != hi {
                        self.put_lane(&coarse, lo, lane, bilinear, layout.is_some(), sink);
                    }
                }
            }
            rest.iter().for_each(|q| self.trace_blocks(q, sink));
            return;
        }
        qs.iter().for_each(|q| self.trace_blocks(q, sink));
    }

    /// Lane `i` of `c` at level `li`: its block or texel (by address when
    /// `addressed`) when inside the level, else the portable filter from
    /// `(u, v)`.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn put_lane<S: BlockSink>(
        &self,
        c: &super::lanes::Cells8,
        li: usize,
        (i, u, v): (usize, f64, f64),
        bilinear: bool,
        addressed: bool,
        sink: &mut S,
    ) {
        if c.inside >> i & 1 == 0 {
            self.filter(false, li, u, v, sink);
            return;
        }
        let level = li as u32;
        match (bilinear, addressed) {
            (true, true) => sink.block_at(level, [c.at[0][i], c.at[1][i], c.at[2][i], c.at[3][i]]),
            (true, false) => sink.block(level, c.x[i] as u32, c.y[i] as u32),
            (false, true) => sink.texel_at(level, c.at[0][i]),
            (false, false) => sink.texel(level, c.x[i] as u32, c.y[i] as u32),
        }
    }

    /// [`AddressOnly::trace`] to a sink that takes a bilinear block at
    /// once.
    #[inline]
    pub(crate) fn trace_blocks<S: BlockSink>(&self, q: &Query, sink: &mut S) {
        let o = &self.options;
        let plan = match o.mip {
            MipMode::None if o.mag == o.min => Plan::MAGNIFY,
            MipMode::None => self.lod.plan_level0(q),
            MipMode::Nearest => self.lod.plan_nearest(q),
            MipMode::Linear => Plan::at(self.lod.lambda(q, o), self.lod.q, MipMode::Linear),
        };
        // Into the first wrap period, as the sampler moves it.
        let (u, v) = self.lod.reduce(q);
        self.filter(plan.magnify, plan.hi, u, v, sink);
        if plan.delta > 0.0 && plan.lo != plan.hi {
            self.filter(false, plan.lo, u, v, sink);
        }
    }

    #[inline(always)]
    fn filter<S: BlockSink>(&self, magnify: bool, li: usize, u: f64, v: f64, sink: &mut S) {
        let f = if magnify {
            self.options.mag
        } else {
            self.options.min
        };
        let Some(&level) = self.levels.get(li) else {
            return;
        };
        match f {
            TexelFilter::Nearest => self.nearest(level, li as u32, u, v, sink),
            TexelFilter::Linear => self.bilinear(level, li as u32, u, v, sink),
        }
    }

    /// The texel `(floor(u·w), floor(v·h))`, wrapped; none for a border.
    #[inline(always)]
    fn nearest<S: BlockSink>(
        &self,
        (w, h, wf, hf): (u32, u32, f64, f64),
        li: u32,
        u: f64,
        v: f64,
        sink: &mut S,
    ) {
        let (_, i) = floor_fast(u * wf);
        let (_, j) = floor_fast(v * hf);
        if (i as u64) < w as u64 && (j as u64) < h as u64 {
            sink.texel(li, i as u32, j as u32);
            return;
        }
        let i = fast_floor(reduce_coordinate(u, self.wrap.u) * wf);
        let j = fast_floor(reduce_coordinate(v, self.wrap.v) * hf);
        if let (Some(x), Some(y)) = (wrap_index(self.wrap.u, i, w), wrap_index(self.wrap.v, j, h)) {
            sink.texel(li, x, y);
        }
    }

    /// The 2×2 texels around `(u·w − ½, v·h − ½)` in the order (i0, j0),
    /// (i1, j0), (i0, j1), (i1, j1), each axis wrapped; none for a border.
    #[inline(always)]
    fn bilinear<S: BlockSink>(
        &self,
        (w, h, wf, hf): (u32, u32, f64, f64),
        li: u32,
        u: f64,
        v: f64,
        sink: &mut S,
    ) {
        let (_, i0) = floor_fast(u * wf - 0.5);
        let (_, j0) = floor_fast(v * hf - 0.5);
        if (i0 as u64) < (w - 1) as u64 && (j0 as u64) < (h - 1) as u64 {
            sink.block(li, i0 as u32, j0 as u32);
            return;
        }
        let i0 = fast_floor(reduce_coordinate(u, self.wrap.u) * wf - 0.5);
        let j0 = fast_floor(reduce_coordinate(v, self.wrap.v) * hf - 0.5);
        let (x0, x1) = axis_pair(self.wrap.u, i0, w);
        let (y0, y1) = axis_pair(self.wrap.v, j0, h);
        for (x, y) in [(x0, y0), (x1, y0), (x0, y1), (x1, y1)] {
            if let (Some(x), Some(y)) = (x, y) {
                sink.texel(li, x, y);
            }
        }
    }
}

/// A sink that may take the 2×2 block of a bilinear lookup inside a level
/// at once: texels `(x, y)`, `(x + 1, y)`, `(x, y + 1)`, `(x + 1, y + 1)`
/// in that order (the default reports them one by one).
pub(crate) trait BlockSink: TexelSink {
    #[inline(always)]
    fn block(&mut self, level: u32, x: u32, y: u32) {
        self.texel(level, x, y);
        self.texel(level, x + 1, y);
        self.texel(level, x, y + 1);
        self.texel(level, x + 1, y + 1);
    }

    /// The sink's layout, when it takes texels by address
    /// ([`BlockSink::texel_at`], [`BlockSink::block_at`]) and
    /// [`ChainLayout::lanes`](super::layout::ChainLayout::lanes) covers
    /// it; `None` (the default) when it takes them by coordinates only.
    fn lanes(&self) -> Option<&Lanes> {
        None
    }

    /// The texel of `level` at address `a` of [`BlockSink::lanes`]'s
    /// layout (called only when that is given).
    fn texel_at(&mut self, level: u32, a: u64) {
        let _ = (level, a);
        unreachable!("texel_at on a sink without lanes");
    }

    /// The 2×2 block of `level` at addresses `a` of [`BlockSink::lanes`]'s
    /// layout, in [`BlockSink::block`]'s order (called only when that is
    /// given).
    fn block_at(&mut self, level: u32, a: [u64; 4]) {
        let _ = (level, a);
        unreachable!("block_at on a sink without lanes");
    }
}

/// Any sink, its blocks reported texel by texel.
struct Texels<'a, S>(&'a mut S);

impl<S: TexelSink> TexelSink for Texels<'_, S> {
    #[inline(always)]
    fn texel(&mut self, level: u32, x: u32, y: u32) {
        self.0.texel(level, x, y);
    }
}

impl<S: TexelSink> BlockSink for Texels<'_, S> {}

/// 1.5·2^52: adding and subtracting it rounds an `f64` of magnitude below
/// 2^51 to an integer.
const MAGIC: f64 = 6_755_399_441_055_744.0;

/// The sampler's fast floor: exact below 2^51, and far outside every
/// level (so the edge path) for NaN, infinite and huge values.
#[inline(always)]
fn floor_fast(x: f64) -> (f64, i64) {
    let r = (x + MAGIC) - MAGIC;
    let r = r - if r > x { 1.0 } else { 0.0 };
    let i = ((r + MAGIC).to_bits() as i64).wrapping_sub(MAGIC.to_bits() as i64);
    (r, i)
}

/// Indices `i` and `i + 1` of an axis of `size` texels after wrapping
/// (`None`: the border).
#[inline(always)]
fn axis_pair(mode: WrapMode, i: i64, size: u32) -> (Option<u32>, Option<u32>) {
    let s = size as i64;
    match mode {
        WrapMode::Repeat => {
            let x = if (0..s).contains(&i) {
                i
            } else if (-s..0).contains(&i) {
                i + s
            } else {
                i.rem_euclid(s)
            };
            let x1 = if x + 1 == s { 0 } else { x + 1 };
            (Some(x as u32), Some(x1 as u32))
        }
        _ => (wrap_index(mode, i, size), wrap_index(mode, i + 1, size)),
    }
}
