//! Polyphase weights of one axis: for each destination texel, the source
//! texels it reads and their normalised weights.
//!
//! The destination texel `x` of an axis reduced from `src` to `dst` texels
//! covers `[x·s, (x+1)·s)` in source coordinates, `s = src / dst`.
//! - Box: the weight of source texel `i` is the length of `[i, i+1)` ∩ that
//!   interval, divided by `s`. For `src = 2n` this is the 2-tap average; for
//!   `src = 2n+1, dst = n` it is exactly the polyphase box of SPEC.md:
//!   `(n − x, n, x + 1) / (2n + 1)`; rounding up (`dst = n + 1`) falls out of
//!   the same rule. No half-texel shift, no dropped row or column.
//! - Other kernels are stretched by `s` and evaluated at source texel
//!   centres relative to the destination centre `(x + ½)·s`, then
//!   normalised. Taps outside the level are resolved by the wrap mode; under
//!   `border` they are dropped (and the rest renormalised), because baking a
//!   border colour into the levels would darken every edge.
//! - An axis that does not shrink (`src == dst`, e.g. the 1-texel axis of an
//!   N×1 level) is the identity.

use crate::mip::MipFilter;
use crate::wrap::{WrapMode, wrap_index};

/// Weights of one axis in a flat, fixed-tap layout (padded with zero
/// weights) so inner loops have a constant trip count.
#[derive(Clone, Debug)]
pub struct AxisWeights {
    /// Taps per destination texel.
    pub taps: usize,
    /// Source index of each tap, `dst · taps` entries.
    pub index: Vec<u32>,
    /// Weight of each tap (sums to 1 per destination texel).
    pub weight: Vec<f32>,
}

impl AxisWeights {
    /// Per destination texel: the first source index when its `taps`
    /// indices are consecutive (no padding, no wrap), else `None`.
    pub fn contiguous_runs(&self) -> Vec<Option<u32>> {
        self.index
            .chunks_exact(self.taps)
            .map(|idx| idx.windows(2).all(|p| p[1] == p[0] + 1).then_some(idx[0]))
            .collect()
    }

    /// (index, weight) pairs of destination texel `x`, zero weights skipped.
    pub fn of(&self, x: usize) -> impl Iterator<Item = (u32, f32)> + '_ {
        let r = x * self.taps..(x + 1) * self.taps;
        self.index[r.clone()]
            .iter()
            .copied()
            .zip(self.weight[r].iter().copied())
            .filter(|&(_, w)| w != 0.0)
    }
}

/// The exact (f64) weights of every destination texel.
pub fn exact(filter: MipFilter, src: u32, dst: u32, wrap: WrapMode) -> Vec<Vec<(u32, f64)>> {
    (0..dst)
        .map(|x| {
            let mut taps: Vec<(i64, f64)> = Vec::new();
            if src == dst {
                taps.push((x as i64, 1.0));
            } else if filter == MipFilter::Box {
                // Exact integer overlap: scale both intervals by `dst` so
                // source texel i is [i·dst, (i+1)·dst) and destination x is
                // [x·src, (x+1)·src); no rounding can add or drop a tap.
                let (src64, dst64) = (src as u64, dst as u64);
                let (lo, hi) = (x as u64 * src64, (x as u64 + 1) * src64);
                for i in lo / dst64..hi.div_ceil(dst64) {
                    let o = hi.min((i + 1) * dst64).saturating_sub(lo.max(i * dst64));
                    if o > 0 {
                        taps.push((i as i64, o as f64 / src as f64));
                    }
                }
            } else {
                // The kernel is stretched by the reduction factor, never
                // narrowed: an enlarged axis (`--resize-to`) keeps the
                // kernel's own width in source texels.
                let ratio = src as f64 / dst as f64;
                let s = ratio.max(1.0);
                let k = filter.kernel();
                let c = (x as f64 + 0.5) * ratio;
                let r = k.radius() * s;
                for i in (c - r - 0.5).floor() as i64..=(c + r + 0.5).ceil() as i64 {
                    let w = k.evaluate((i as f64 + 0.5 - c) / s);
                    if w != 0.0 {
                        taps.push((i, w));
                    }
                }
            }
            let mut out: Vec<(u32, f64)> = Vec::with_capacity(taps.len());
            for (i, w) in taps {
                if let Some(j) = wrap_index(wrap, i, src) {
                    match out.iter_mut().find(|(k, _)| *k == j) {
                        Some(e) => e.1 += w,
                        None => out.push((j, w)),
                    }
                }
            }
            let sum: f64 = out.iter().map(|t| t.1).sum();
            if sum.abs() > 1e-12 {
                for t in &mut out {
                    t.1 /= sum;
                }
            } else {
                // Cannot happen for the kernels here (the centre tap is always
                // inside and positive), but never divide by zero.
                out = vec![(x.min(src - 1), 1.0)];
            }
            out
        })
        .collect()
}

/// Weights of one axis in the flat layout the filters use.
pub fn axis(filter: MipFilter, src: u32, dst: u32, wrap: WrapMode) -> AxisWeights {
    let exact = exact(filter, src, dst, wrap);
    let taps = exact.iter().map(Vec::len).max().unwrap_or(1).max(1);
    let mut index = Vec::with_capacity(exact.len() * taps);
    let mut weight = Vec::with_capacity(exact.len() * taps);
    for t in &exact {
        for k in 0..taps {
            let (i, w) = t.get(k).copied().unwrap_or((t[0].0, 0.0));
            index.push(i);
            weight.push(w as f32);
        }
    }
    AxisWeights {
        taps,
        index,
        weight,
    }
}
