//! The supersampled reference: the ground truth the accuracy tables score
//! every other filter against.
//!
//! n × n positions, one at the centre of each cell of an n × n grid over
//! the pixel's footprint parallelogram (corners at centre ± dx/2 ± dy/2,
//! SPEC.md "Coordinates"), each a bilinear lookup of level 0, averaged
//! with equal weights. The grid is the stratified pattern without jitter,
//! so the reference is deterministic. It approximates the box filter over
//! the parallelogram well while the cell size stays below about half a
//! texel (footprints up to n/2 texels across); beyond that it aliases like
//! any point sampling.
//!
//! Cost is n² bilinear lookups whatever the footprint (n ≤ 64).

use super::bilinear::bilinear;
use super::fetch::{Addressing, Chain, Pixel};
use super::footprint::{Lod, derivatives};
use super::{Query, SamplerOptions};
use crate::trace::TexelSink;

/// Supersampled lookup of `q` with `n × n` positions.
pub(crate) fn supersample<P: Pixel, S: TexelSink>(
    c: &Chain<P>,
    a: &Addressing,
    lod: &Lod,
    o: &SamplerOptions,
    q: &Query,
    sink: &mut S,
) -> [f32; 4] {
    let (u, v) = lod.reduce(q);
    let (dx, dy) = derivatives(q, lod.wf, lod.hf);
    let n = o.supersample.clamp(1, 64);
    let inv = 1.0 / n as f64;
    let mut acc = [0.0f64; 4];
    for j in 0..n {
        let ty = (j as f64 + 0.5) * inv - 0.5;
        for i in 0..n {
            let tx = (i as f64 + 0.5) * inv - 0.5;
            let pu = u + tx * dx[0] + ty * dy[0];
            let pv = v + tx * dx[1] + ty * dy[1];
            let t = bilinear(c, 0, pu, pv, a, sink);
            for c in 0..4 {
                acc[c] += t[c] as f64;
            }
        }
    }
    // Sums in f64: 4096 f32 additions would lose up to ~1e-4 relative.
    let s = 1.0 / (n * n) as f64;
    super::map4(acc, |x| (x * s) as f32)
}
