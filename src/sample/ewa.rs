//! Elliptical weighted average (Greene & Heckbert 1986; Heckbert 1989;
//! pbrt's `MIPMap::EWA`), the high-quality reference filter (SPEC.md
//! "EWA").
//!
//! 1. The pixel's footprint ellipse is `{J·p : |p| ≤ 1}` with `J` the two
//!    derivative vectors (level-0 texels) as columns. Its principal
//!    semi-axes are the square roots of the eigenvalues of `J·Jᵀ` (this
//!    handles collinear and zero derivative pairs, where the shorter
//!    *derivative vector* would not be the minor axis).
//! 2. The minor axis is lengthened to at least `major / max_aniso`, which
//!    also gives zero and collinear pairs a proper ellipse.
//! 3. λ = log2(minor) + bias, clamped; the two nearest levels are filtered
//!    and blended linearly (`mip = none` uses level 0 only, `nearest` the
//!    nearest level).
//! 4. In each level (per-axis scale `w_k / w_0`, `h_k / h_0`) the unit
//!    reconstruction variance is added, `Σ = J'J'ᵀ + I`, giving SPEC's
//!    `A = Σtt, B = −2Σst, C = Σss` divided by `F = AC − B²/4`. Texels
//!    with `r² = A·s² + B·s·t + C·t² < 1` get weight `exp(−2r²) − exp(−2)`;
//!    the result is `Σ w·τ / Σ w`. Because Σ ≥ I the ellipse always
//!    contains a texel centre, so `Σ w > 0`.
//!
//! # Bounded work
//! Rows are scanned only over the span where `r² < 1` (solved per row),
//! so the cost is the ellipse's area, not its bounding box. With λ chosen
//! from the minor axis, the finer level sees a minor semi-axis below 2
//! texels and a major one below `2·max_aniso`. When the LOD clamp, a
//! negative bias, `mip = none` or the end of the chain forces a finer level
//! than that, the ellipse at that level is shrunk uniformly so that its
//! larger semi-axis is at most [`MAX_RADIUS`] texels: the result then
//! aliases (as a GPU's would) instead of scanning millions of texels. A
//! 1×1 level without border wrapping is read once (every texel of the
//! ellipse is the same texel). So a query reads at most about
//! 2·π·(MAX_RADIUS + 1)² texels.

use crate::wrap::WrapMode;

use super::bilinear::{fast_floor, split};
use super::fetch::{Addressing, Chain, Pixel, lerp};
use super::footprint::{Lod, clamp_lod, derivatives, levels_for, log2};
use super::trace::TexelSink;
use super::{Query, SamplerOptions};

/// Largest semi-axis, in texels of the level being filtered, that EWA
/// scans; larger ellipses are shrunk (see the module docs).
pub const MAX_RADIUS: f64 = 40.0;

/// Gaussian falloff α of the EWA weight `exp(−α·r²) − exp(−α)`.
const ALPHA: f64 = 2.0;

/// EWA lookup of `q`.
pub(crate) fn ewa<P: Pixel, S: TexelSink>(
    c: &Chain<P>,
    a: &Addressing,
    lod: &Lod,
    o: &SamplerOptions,
    q: &Query,
    sink: &mut S,
) -> [f32; 4] {
    let (u, v) = lod.reduce(q);
    let (dx, dy) = derivatives(q, lod.wf, lod.hf);
    let levels = &c.levels[..];
    let (w0, h0) = (levels[0].wf, levels[0].hf);
    // Derivative vectors in level-0 texels.
    let (ax, ay) = (dx[0] * w0, dx[1] * h0);
    let (bx, by) = (dy[0] * w0, dy[1] * h0);
    // M = J·Jᵀ.
    let mss = ax * ax + bx * bx;
    let mst = ax * ay + bx * by;
    let mtt = ay * ay + by * by;
    let mean = 0.5 * (mss + mtt);
    let r = (0.5 * (mss - mtt)).hypot(mst);
    let major = (mean + r).max(0.0).sqrt();
    let minor0 = (mean - r).max(0.0).sqrt();
    // Unit vector of the major axis (any direction when isotropic).
    let (ex, ey) = if r > 0.0 {
        let th = 0.5 * (2.0 * mst).atan2(mss - mtt);
        (th.cos(), th.sin())
    } else {
        (1.0, 0.0)
    };
    let minor = minor0.max(major / o.max_aniso.clamp(1, 16) as f64);
    let lambda = clamp_lod(log2(minor), o);
    let (hi, lo, delta) = if lambda > 0.0 {
        levels_for(lambda, lod.q, o.mip)
    } else {
        (0, 0, 0.0)
    };
    let axes = Axes {
        major,
        minor,
        ex,
        ey,
    };
    let t = ewa_level(c, hi, a, &axes, u, v, sink);
    if delta > 0.0 && lo != hi {
        let t2 = ewa_level(c, lo, a, &axes, u, v, sink);
        lerp(t, t2, delta)
    } else {
        t
    }
}

/// The (lengthened) ellipse in level-0 texels: semi-axes and the major
/// axis direction.
struct Axes {
    major: f64,
    minor: f64,
    ex: f64,
    ey: f64,
}

fn ewa_level<P: Pixel, S: TexelSink>(
    c: &Chain<P>,
    k: usize,
    a: &Addressing,
    axes: &Axes,
    u: f64,
    v: f64,
    sink: &mut S,
) -> [f32; 4] {
    let l = &c.levels[k];
    let (sx, sy) = (l.wf / c.levels[0].wf, l.hf / c.levels[0].hf);
    if l.w == 1
        && l.h == 1
        && a.wrap.u != WrapMode::ClampToBorder
        && a.wrap.v != WrapMode::ClampToBorder
    {
        return l.at(&c.lut, k as u32, 0, 0, sink);
    }
    // Semi-axis vectors in this level's texels.
    let (mut p1x, mut p1y) = (axes.major * axes.ex * sx, axes.major * axes.ey * sy);
    let (mut p2x, mut p2y) = (-axes.minor * axes.ey * sx, axes.minor * axes.ex * sy);
    let size = (p1x * p1x + p1y * p1y + p2x * p2x + p2y * p2y).sqrt();
    if size > MAX_RADIUS {
        let f = MAX_RADIUS / size;
        p1x *= f;
        p1y *= f;
        p2x *= f;
        p2y *= f;
    }
    // Σ = J'J'ᵀ + I (unit reconstruction variance).
    let css = p1x * p1x + p2x * p2x + 1.0;
    let cst = p1x * p1y + p2x * p2y;
    let ctt = p1y * p1y + p2y * p2y + 1.0;
    // SPEC: A = Σtt, B = −2Σst, C = Σss, divided by F = AC − B²/4 = det Σ.
    let f = css * ctt - cst * cst;
    let (qa, qb, qc) = (ctt / f, -2.0 * cst / f, css / f);
    // Centre in texel-centre coordinates, split into an integer base and
    // a fraction so huge coordinates keep their precision.
    let (ib, fs) = split(u * l.wf - 0.5);
    let (jb, ft) = split(v * l.hf - 0.5);
    let (fs, ft) = (fs as f64, ft as f64);
    // Extent in t of the ellipse r² < 1 is sqrt(Σtt).
    let t_ext = ctt.sqrt();
    let t0 = -fast_floor(t_ext - ft);
    let t1 = fast_floor(ft + t_ext);
    let e_alpha = (-ALPHA).exp();
    let mut acc = [0.0f64; 4];
    let mut wsum = 0.0f64;
    for jt in t0..=t1 {
        let tt = jt as f64 - ft;
        // Solve qa·s² + qb·tt·s + (qc·tt² − 1) < 0 for s.
        let centre = -qb * tt / (2.0 * qa);
        let disc = (qb * tt) * (qb * tt) - 4.0 * qa * (qc * tt * tt - 1.0);
        if disc <= 0.0 {
            continue;
        }
        let half = disc.sqrt() / (2.0 * qa);
        let s0 = -fast_floor(half - fs - centre);
        let s1 = fast_floor(fs + centre + half);
        for is in s0..=s1 {
            let ss = is as f64 - fs;
            let r2 = qa * ss * ss + qb * ss * tt + qc * tt * tt;
            if r2 < 1.0 {
                let w = (-ALPHA * r2).exp() - e_alpha;
                let tex = l.fetch(
                    &c.lut,
                    k as u32,
                    ib.saturating_add(is),
                    jb.saturating_add(jt),
                    a,
                    sink,
                );
                for c in 0..4 {
                    acc[c] += w * tex[c] as f64;
                }
                wsum += w;
            }
        }
    }
    if wsum > 0.0 {
        acc.map(|x| (x / wsum) as f32)
    } else {
        // Unreachable in exact arithmetic (the ellipse contains a texel
        // centre); kept so rounding can never divide by zero.
        l.fetch(&c.lut, k as u32, ib, jb, a, sink)
    }
}
