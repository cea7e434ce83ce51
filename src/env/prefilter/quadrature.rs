//! Deterministic quadrature of a lobe over a cube map's level 0.
//!
//! The integral `∫ L(l)·w(n, l) dl / ∫ w(n, l) dl` (the module docs of
//! [`super`]) is a sum over the level-0 texels, each a constant radiance
//! over its exact solid angle: the "brute-force integral over level 0".
//! Summing every texel for every output texel costs `6n²` terms each; the
//! sum here visits a quadtree of each face instead (Barnes–Hut style):
//!
//! - every node (a square block of one face's level-0 texels) holds the
//!   exact sums of its texels' solid angles `ΣΩ`, radiant fluxes `ΣL·Ω`
//!   (per channel) and `Σ|L|·Ω` (the node's brightness), the solid-angle
//!   centroid direction, the brightness centroid direction, and a cone
//!   around the first that holds the whole block (from its corners);
//! - a node is summed whole — its flux times the weight at its brightness
//!   centroid, its solid angle times the weight at its solid-angle
//!   centroid — when the weight's curvature across its cone, times its
//!   importance `max(ΣΩ, Σ|L|Ω / mean |L|)`, is below a tolerance times
//!   the lobe's total weight (`|w(θ−r) + w(θ+r) − 2w(θ)|`, θ the angle from
//!   n to the block's centroid, r its cone's radius); otherwise its four
//!   children are visited. A block whose cone holds n is always opened. Leaves
//!   are the level-0 texels themselves, so the sum over a narrow lobe's
//!   core is the brute-force sum.
//!
//! Summing a block at its centroid makes the error of the block second
//! order in its size: the first-order term, the weight's gradient times
//! the offset of the light from where the weight is read, is zero for the
//! brightness (and a bright sun inside a coarse block is weighted where it
//! is, not at the block's centre). A constant environment gives itself
//! exactly (numerator and denominator are then the same sum). Nothing is
//! truncated: blocks wholly below the horizon (`n·l ≤ 0`, weight 0) are the
//! only ones skipped.

use rayon::prelude::*;

use super::super::cube::face_direction;
use super::super::vec3::unit;
use super::{texel_direction, texel_solid_angle};
use crate::mip::MipChain;
use crate::texture::expand_to_rgba;

/// One block of a face's level-0 texels.
#[derive(Clone, Copy, Debug, Default)]
struct Node {
    /// `Σ L·Ω` per channel (linear RGBA).
    flux: [f32; 4],
    /// `Σ Ω`.
    omega: f32,
    /// `Σ |L|·Ω` (the RGB magnitudes).
    bright: f32,
    /// Unit `Σ Ω·d`.
    axis: [f32; 3],
    /// Unit `Σ |L|·Ω·d` (the axis where the block is black).
    centroid: [f32; 3],
    /// Cosine and sine of the half-angle of a cone around `axis` holding
    /// the block.
    cos_r: f32,
    sin_r: f32,
}

/// The sums of a block in f64 while the tree is built.
#[derive(Clone, Copy, Default)]
struct Acc {
    flux: [f64; 4],
    omega: f64,
    bright: f64,
    sd: [f64; 3],
    sbd: [f64; 3],
}

impl Acc {
    fn add(&mut self, o: &Acc) {
        for c in 0..4 {
            self.flux[c] += o.flux[c];
        }
        self.omega += o.omega;
        self.bright += o.bright;
        for c in 0..3 {
            self.sd[c] += o.sd[c];
            self.sbd[c] += o.sbd[c];
        }
    }
}

/// The quadtrees of a cube map's six level-0 faces.
pub(super) struct Tree {
    /// Blocks per face side at each tree level (`⌈n / 2^L⌉`).
    dims: Vec<u32>,
    /// Index of face 0's first block at each tree level.
    offsets: Vec<usize>,
    nodes: Vec<Node>,
    /// `Σ|L|Ω / 4π`.
    mean_bright: f64,
}

impl Tree {
    /// The tree of level 0 of six square faces (any format).
    pub(super) fn new(faces: &[MipChain]) -> Tree {
        let level0: Vec<_> = faces.iter().map(|c| &c.levels()[0]).collect();
        let n = level0[0].width();
        let mut dims = vec![n];
        let mut m = n;
        while m > 1 {
            m = m.div_ceil(2);
            dims.push(m);
        }
        // Level 0: one block per texel.
        let mut accs: Vec<Acc> = Vec::with_capacity(6 * (n * n) as usize);
        for (f, t) in level0.iter().enumerate() {
            let lin = t.to_linear();
            let ch = t.channels();
            for j in 0..n {
                for i in 0..n {
                    let d = texel_direction(f, n, i, j);
                    let k = (j as usize * n as usize + i as usize) * ch;
                    let l = expand_to_rgba(&lin[k..k + ch]);
                    let omega = texel_solid_angle(n, i, j);
                    let b = (l[0].abs() + l[1].abs() + l[2].abs()) as f64 * omega;
                    accs.push(Acc {
                        flux: l.map(|x| x as f64 * omega),
                        omega,
                        bright: b,
                        sd: d.map(|x| x * omega),
                        sbd: d.map(|x| x * b),
                    });
                }
            }
        }
        let mut levels = vec![accs];
        for lv in 1..dims.len() {
            let (m, pm) = (dims[lv] as usize, dims[lv - 1] as usize);
            let prev = &levels[lv - 1];
            let mut cur = vec![Acc::default(); 6 * m * m];
            for f in 0..6 {
                for pj in 0..pm {
                    for pi in 0..pm {
                        let child = &prev[f * pm * pm + pj * pm + pi];
                        cur[f * m * m + (pj / 2) * m + pi / 2].add(child);
                    }
                }
            }
            levels.push(cur);
        }
        let mut offsets = Vec::with_capacity(dims.len());
        let mut nodes = Vec::with_capacity(levels.iter().map(Vec::len).sum());
        for (lv, accs) in levels.iter().enumerate() {
            offsets.push(nodes.len());
            let m = dims[lv] as usize;
            let span = 1u64 << lv;
            for (k, a) in accs.iter().enumerate() {
                let (f, r) = (k / (m * m), k % (m * m));
                let (j, i) = ((r / m) as u64, (r % m) as u64);
                let x = [i * span, ((i + 1) * span).min(n as u64)];
                let y = [j * span, ((j + 1) * span).min(n as u64)];
                nodes.push(node(a, f, x, y, n));
            }
        }
        let bright: f64 = levels[0].iter().map(|a| a.bright).sum();
        Tree {
            dims,
            offsets,
            nodes,
            mean_bright: bright / (4.0 * std::f64::consts::PI),
        }
    }

    /// `(Σ L·w·Ω, Σ w·Ω)` around unit `dir` for the weight `w(n·l)`
    /// (called with `n·l > 0` only), whose integral over the sphere is
    /// `total`, each block's error below `tolerance·total` (module docs).
    /// `stack` is scratch space.
    fn sum(
        &self,
        dir: [f32; 3],
        w: &impl Fn(f32) -> f32,
        limit: f32,
        stack: &mut Vec<(u8, u32)>,
    ) -> ([f64; 4], f64) {
        let top = self.dims.len() - 1;
        // 1/mean brightness, or 0 when the environment is black.
        let inv_mean = if self.mean_bright > 0.0 {
            (1.0 / self.mean_bright) as f32
        } else {
            0.0
        };
        let dot = |a: [f32; 3]| dir[0] * a[0] + dir[1] * a[1] + dir[2] * a[2];
        let w = |c: f32| if c > 0.0 { w(c) } else { 0.0 };
        let mut num = [0f64; 4];
        let mut den = 0f64;
        stack.clear();
        for f in 0..6u32 {
            stack.push((top as u8, f));
        }
        while let Some((lv, k)) = stack.pop() {
            let lv = lv as usize;
            let m = self.dims[lv];
            let (f, r) = (k / (m * m), k % (m * m));
            let node = &self.nodes[self.offsets[lv] + k as usize];
            let c = dot(node.axis);
            let s = (1.0 - c * c).max(0.0).sqrt();
            // cos(θ − r) and cos(θ + r).
            let near = c * node.cos_r + s * node.sin_r;
            let far = c * node.cos_r - s * node.sin_r;
            if c < node.cos_r && near <= 0.0 {
                // Wholly below the horizon.
                continue;
            }
            if lv > 0 && c > node.cos_r {
                // The cone holds n, where the lobe peaks.
                let (j, i) = (r / m, r % m);
                let pm = self.dims[lv - 1];
                for cj in 2 * j..(2 * j + 2).min(pm) {
                    for ci in 2 * i..(2 * i + 2).min(pm) {
                        stack.push(((lv - 1) as u8, f * pm * pm + cj * pm + ci));
                    }
                }
                continue;
            }
            if lv > 0 {
                let curve = (w(near) + w(far) - 2.0 * w(c)).abs();
                let importance = node.omega.max(node.bright * inv_mean);
                if curve * importance > limit {
                    let (j, i) = (r / m, r % m);
                    let pm = self.dims[lv - 1];
                    for cj in 2 * j..(2 * j + 2).min(pm) {
                        for ci in 2 * i..(2 * i + 2).min(pm) {
                            stack.push(((lv - 1) as u8, f * pm * pm + cj * pm + ci));
                        }
                    }
                    continue;
                }
            }
            let wl = w(dot(node.centroid)) as f64;
            for (acc, flux) in num.iter_mut().zip(node.flux) {
                *acc += flux as f64 * wl;
            }
            den += node.omega as f64 * w(c) as f64;
        }
        (num, den)
    }
}

/// The node of block `x × y` (level-0 texel ranges) of face `f` from its
/// sums.
fn node(a: &Acc, f: usize, x: [u64; 2], y: [u64; 2], n: u32) -> Node {
    let axis = unit(a.sd);
    let centroid = if a.bright > 0.0 { unit(a.sbd) } else { axis };
    let mut cos_r = 1f64;
    for cx in x {
        for cy in y {
            let d = unit(face_direction(
                f,
                cx as f64 / n as f64,
                cy as f64 / n as f64,
            ));
            cos_r = cos_r.min(d[0] * axis[0] + d[1] * axis[1] + d[2] * axis[2]);
        }
    }
    // f32 rounding must not shrink the cone.
    let cos_r = (cos_r - 1e-6).max(-1.0);
    Node {
        flux: a.flux.map(|v| v as f32),
        omega: a.omega as f32,
        bright: a.bright as f32,
        axis: axis.map(|v| v as f32),
        centroid: centroid.map(|v| v as f32),
        cos_r: cos_r as f32,
        sin_r: (1.0 - cos_r * cos_r).max(0.0).sqrt() as f32,
    }
}

/// `∫ w(n·l) dl` over the sphere, `2π ∫₋₁¹ w(c) dc`, by the midpoint rule
/// on intervals that shrink geometrically towards c = 1 (where the narrow
/// lobes peak).
pub(super) fn total_weight(w: impl Fn(f64) -> f64) -> f64 {
    let mut sum = 0.0;
    // t = 1 − c from 2 down to 1e-12 in 4,000 geometric steps.
    let steps = 4000;
    let ratio = (2e-12f64 / 2.0).powf(1.0 / steps as f64);
    let mut t = 2.0;
    for _ in 0..steps {
        let t1 = t * ratio;
        let mid = 0.5 * (t + t1);
        sum += w(1.0 - mid) * (t - t1);
        t = t1;
    }
    2.0 * std::f64::consts::PI * sum
}

/// The six `m × m` faces of an output level: each texel centre's
/// `Σ L·w / Σ w` over `tree` (RGBA, row by row; `w` and `total` as
/// [`Tree::sum`] takes them), rows in parallel.
pub(super) fn cube(
    tree: &Tree,
    m: u32,
    w: impl Fn(f32) -> f32 + Sync,
    total: f64,
    tolerance: f64,
) -> Vec<Vec<f32>> {
    let limit = (tolerance * total) as f32;
    let row = (m * 4) as usize;
    let mut out = vec![0f32; 6 * row * m as usize];
    out.par_chunks_mut(row).enumerate().for_each_init(
        || Vec::with_capacity(64),
        |stack, (fj, row)| {
            let (f, j) = (fj / m as usize, (fj % m as usize) as u32);
            for i in 0..m as usize {
                let d = texel_direction(f, m, i as u32, j);
                let (num, den) = tree.sum(d.map(|x| x as f32), &w, limit, stack);
                for c in 0..4 {
                    row[i * 4 + c] = if den > 0.0 {
                        (num[c] / den) as f32
                    } else {
                        0.0
                    };
                }
            }
        },
    );
    out.chunks_exact(row * m as usize)
        .map(<[f32]>::to_vec)
        .collect()
}
