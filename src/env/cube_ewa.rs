//! EWA on a cube map: the 2-D EWA's ellipse, levels and weights
//! ([`crate::sample::ewa`]'s exact form: `exp` per texel, `f64` sums) on
//! the face of the centre direction, with every texel read seamlessly
//! (texels past an edge come from the neighbour face).

use crate::sample::Query;
use crate::sample::ewa::{exact_scan, lengthened_ellipse, level_form};
use crate::sample::footprint::derivatives;

use super::cube::CubeSampler;

/// EWA lookup of face query `fq` on face `f`.
pub(super) fn ewa(c: &CubeSampler, f: usize, fq: &Query) -> [f32; 4] {
    let n0 = c.face_size() as f64;
    let (dx, dy) = derivatives(fq, n0, n0);
    let j = [dx[0] * n0, dx[1] * n0, dy[0] * n0, dy[1] * n0];
    let (axes, hi, lo, delta) = lengthened_ellipse(j, c.options(), c.last_level());
    let (s, t) = (fq.u as f64, fq.v as f64);
    let a = level(c, f, hi, &axes, s, t);
    if delta > 0.0 && lo != hi {
        let b = level(c, f, lo, &axes, s, t);
        std::array::from_fn(|k| a[k] + (b[k] - a[k]) * delta)
    } else {
        a
    }
}

/// One level's weighted sum over the ellipse.
fn level(
    c: &CubeSampler,
    f: usize,
    k: usize,
    axes: &crate::sample::ewa::Axes,
    s: f64,
    t: f64,
) -> [f32; 4] {
    let n = c.level_size(k) as f64;
    let scale = n / c.face_size() as f64;
    let form = level_form(axes, scale, scale);
    let (x, y) = (s * n - 0.5, t * n - 0.5);
    let (xb, yb) = (x.floor(), y.floor());
    exact_scan(&form, (xb as i64, yb as i64), (x - xb, y - yb), |i, j| {
        c.texel(f, k, i, j)
    })
}
