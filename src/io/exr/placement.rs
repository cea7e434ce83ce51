//! OpenEXR's texel placement for environment maps and the centred one
//! the rest of parvo builds in, and the resampling between them.
//!
//! OpenEXR (`ImfEnvmap.cpp`) puts an environment's first and last texel
//! centres on the map's edges: a lat-long map's first row on the +y pole
//! and its last on −y, its first and last columns on the same meridian
//! (`LatLongMap::pixelPosition` scales by `w − 1` and `h − 1`); a cube
//! face's outermost texels on the cube's edges
//! (`CubeMap::faceAndPixelPosition` scales by `sof − 1`). Every filter,
//! mip builder and GPU format parvo writes places texel `i` of `n` at
//! `(i + ½)/n` ([`Placement::Centred`]). Reading an OpenEXR environment
//! for the pipeline therefore resamples each level to centred texels
//! ([`centred_from_edges`]), and writing one resamples back
//! ([`edges_from_centred`]), so the file holds what OpenEXR's readers
//! (exrenvmap, OpenImageIO's `environment()`) expect at every level.
//!
//! Both resample bilinearly at the same size. Cube faces read across
//! their edges where an edge texel lies between two faces (as a seamless
//! GPU lookup does); a lat-long map wraps in longitude, and its pole rows
//! keep the values of the rows nearest the poles, as a centred reader
//! finds them there.
//!
//! maketx's `.tx` environments (`textureformat` without `envmap`) keep
//! maketx's centred placement: OpenImageIO reads those as centred
//! (`oiio:sampleborder` 0), so nothing here touches them.
//!
//! [`Placement::Centred`]: crate::env::Placement::Centred

use crate::env::cube::{face_direction, face_st, select_face};
use crate::error::{Error, Result};
use crate::texture::{ImageKind, Texture};

/// One output texel of a resampled axis: the two input texels it reads
/// and the weight of the second.
#[derive(Clone, Copy, Debug)]
struct Tap {
    i0: i64,
    i1: i64,
    a: f32,
}

/// The taps of output texel `i` reading the input at position `x` (in
/// input texel units, texel `k` at `k`).
fn tap(x: f64) -> Tap {
    let i0 = x.floor();
    Tap {
        i0: i0 as i64,
        i1: i0 as i64 + 1,
        a: (x - i0) as f32,
    }
}

/// Centred texel `i` of `n` read from an edge-placed axis of `n`: at
/// `(i + ½)/n` of the axis, input position `(i + ½)(n − 1)/n`.
fn to_centred(n: usize) -> Vec<Tap> {
    (0..n)
        .map(|i| {
            let mut t = tap((i as f64 + 0.5) * (n as f64 - 1.0) / n as f64);
            t.i1 = t.i1.min(n as i64 - 1);
            t
        })
        .collect()
}

/// Edge-placed texel `i` of `n` (at `i/(n − 1)` of the axis) read from a
/// centred axis of `n`: input position `i·n/(n − 1) − ½`, which reaches
/// half a texel past either end. One texel stays where it is.
fn to_edges(n: usize) -> Vec<Tap> {
    if n < 2 {
        return vec![Tap {
            i0: 0,
            i1: 0,
            a: 0.0,
        }];
    }
    (0..n)
        .map(|i| tap(i as f64 * n as f64 / (n as f64 - 1.0) - 0.5))
        .collect()
}

/// `lin` (`w`×`h`, `ch` channels) resampled separably: output column `x`
/// by `cols[x]`, row `y` by `rows[y]`, input indices mapped into the
/// image by `col_index` and `row_index`.
fn resample(
    lin: &[f32],
    (w, h, ch): (usize, usize, usize),
    cols: &[Tap],
    rows: &[Tap],
    col_index: impl Fn(i64) -> usize,
    row_index: impl Fn(i64) -> usize,
) -> Vec<f32> {
    let mut across = vec![0f32; cols.len() * h * ch];
    for y in 0..h {
        let src = &lin[y * w * ch..(y + 1) * w * ch];
        let dst = &mut across[y * cols.len() * ch..(y + 1) * cols.len() * ch];
        for (x, t) in cols.iter().enumerate() {
            let (p, q) = (col_index(t.i0) * ch, col_index(t.i1) * ch);
            for c in 0..ch {
                dst[x * ch + c] = src[p + c] + (src[q + c] - src[p + c]) * t.a;
            }
        }
    }
    let ow = cols.len();
    let mut out = vec![0f32; ow * rows.len() * ch];
    for (y, t) in rows.iter().enumerate() {
        let (p, q) = (row_index(t.i0) * ow * ch, row_index(t.i1) * ow * ch);
        let dst = &mut out[y * ow * ch..(y + 1) * ow * ch];
        for (k, d) in dst.iter_mut().enumerate() {
            *d = across[p + k] + (across[q + k] - across[p + k]) * t.a;
        }
    }
    out
}

fn clamp_to(n: usize) -> impl Fn(i64) -> usize {
    move |i| i.clamp(0, n as i64 - 1) as usize
}

/// One level of an OpenEXR lat-long map or one cube face (OpenEXR's
/// placement, GL's orientation) as centred texels of the same size: what
/// parvo's builders and samplers read.
pub fn centred_from_edges(t: &Texture) -> Result<Texture> {
    let (w, h, ch) = (t.width() as usize, t.height() as usize, t.channels());
    let lin = resample(
        &t.to_linear(),
        (w, h, ch),
        &to_centred(w),
        &to_centred(h),
        clamp_to(w),
        clamp_to(h),
    );
    Texture::from_linear(t.width(), t.height(), t.format(), &lin)
}

/// One level of a lat-long map with centred texels as OpenEXR places
/// them: columns wrap in longitude; the pole rows, half a texel past the
/// first and last centred rows, take those rows' values (what a centred
/// reader returns there: OpenImageIO clamps to the first and last rows).
fn latlong_to_edges(t: &Texture) -> Result<Texture> {
    let (w, h, ch) = (t.width() as usize, t.height() as usize, t.channels());
    let lin = resample(
        &t.to_linear(),
        (w, h, ch),
        &to_edges(w),
        &to_edges(h),
        move |i| i.rem_euclid(w as i64) as usize,
        clamp_to(h),
    );
    Texture::from_linear(t.width(), t.height(), t.format(), &lin)
}

/// Where the centre of texel `(i, j)` of face `f` (`n`×`n`), one of `i`,
/// `j` a texel off the face, lands on the face its direction selects:
/// that face and the continuous texel position there (texel `k`'s
/// centre at `k`). Reading that face bilinearly there, rather than the
/// texel the position falls in, keeps an edge texel (the mean of the
/// texels on either side) on its own direction: the nearest texel would
/// move it along the edge by up to a quarter texel near the corners.
fn across(f: usize, n: usize, i: i64, j: i64) -> (usize, f64, f64) {
    let nf = n as f64;
    let d = face_direction(f, (i as f64 + 0.5) / nf, (j as f64 + 0.5) / nf);
    let g = select_face(d);
    let (s, t) = face_st(g, d);
    (g, s * nf - 0.5, t * nf - 0.5)
}

/// One level of six cube faces (GL's order and orientation, centred
/// texels) as OpenEXR places their texels: edge texels read across the
/// edge from the neighbouring face, corner texels from all three.
fn cube_to_edges(faces: &[Texture]) -> Result<Vec<Texture>> {
    let n = faces[0].width() as usize;
    let ch = faces[0].channels();
    let lin: Vec<Vec<f32>> = faces.iter().map(Texture::to_linear).collect();
    let taps = to_edges(n);
    let ni = n as i64;
    let inside = |i: i64| (0..ni).contains(&i);
    // Texel (i, j) of face f, indices up to one texel off the face.
    let texel = |f: usize, i: i64, j: i64, c: usize| -> f32 {
        let stored = |f: usize, i: i64, j: i64| {
            let (i, j) = (i.clamp(0, ni - 1), j.clamp(0, ni - 1));
            lin[f][(j as usize * n + i as usize) * ch + c]
        };
        let across = |i: i64, j: i64| {
            let (g, x, y) = across(f, n, i, j);
            let (x0, y0) = (x.floor(), y.floor());
            let (a, b) = ((x - x0) as f32, (y - y0) as f32);
            let (x0, y0) = (x0 as i64, y0 as i64);
            let top = stored(g, x0, y0) + (stored(g, x0 + 1, y0) - stored(g, x0, y0)) * a;
            let bottom =
                stored(g, x0, y0 + 1) + (stored(g, x0 + 1, y0 + 1) - stored(g, x0, y0 + 1)) * a;
            top + (bottom - top) * b
        };
        if inside(i) && inside(j) {
            stored(f, i, j)
        } else {
            across(i, j)
        }
    };
    // A corner texel lies on the cube's corner: the mean of the three
    // faces' corner texels, which sit around it symmetrically.
    let corner = |f: usize, i: usize, j: usize, c: usize| -> f32 {
        let at = |k: usize| if k == 0 { 0.0 } else { 1.0 };
        let d = face_direction(f, at(i), at(j));
        let idx = |x: f64| ((x * n as f64).floor() as usize).min(n - 1);
        (0..3)
            .map(|axis| {
                let g = 2 * axis + usize::from(d[axis] < 0.0);
                let (s, t) = face_st(g, d);
                lin[g][(idx(t) * n + idx(s)) * ch + c]
            })
            .sum::<f32>()
            / 3.0
    };
    let is_end = |k: usize| n >= 2 && (k == 0 || k == n - 1);
    (0..6)
        .map(|f| {
            let mut out = vec![0f32; n * n * ch];
            for (j, tj) in taps.iter().enumerate() {
                for (i, ti) in taps.iter().enumerate() {
                    if is_end(i) && is_end(j) {
                        for c in 0..ch {
                            out[(j * n + i) * ch + c] = corner(f, i, j, c);
                        }
                        continue;
                    }
                    for c in 0..ch {
                        let row = |jj: i64| {
                            let a = texel(f, ti.i0, jj, c);
                            a + (texel(f, ti.i1, jj, c) - a) * ti.a
                        };
                        let top = row(tj.i0);
                        out[(j * n + i) * ch + c] = top + (row(tj.i1) - top) * tj.a;
                    }
                }
            }
            Texture::from_linear(n as u32, n as u32, faces[f].format(), &out)
        })
        .collect()
}

/// Every image's levels from `from_level` on (a lat-long map's one
/// image, or a cube map's six faces in GL's order and orientation, with
/// centred texels) resampled to OpenEXR's placement; the levels before
/// `from_level` are kept as they are (already placed as OpenEXR places
/// them).
pub fn edges_from_centred(
    images: &[&[Texture]],
    kind: ImageKind,
    from_level: usize,
) -> Result<Vec<Vec<Texture>>> {
    let mut out: Vec<Vec<Texture>> = images.iter().map(|l| l.to_vec()).collect();
    match kind {
        ImageKind::LatLong => {
            for level in out[0].iter_mut().skip(from_level) {
                *level = latlong_to_edges(level)?;
            }
        }
        ImageKind::Cube if images.len() == 6 => {
            let count = images.iter().map(|l| l.len()).min().unwrap_or(0);
            for k in from_level..count {
                let level: Vec<Texture> = images.iter().map(|l| l[k].clone()).collect();
                for (f, t) in cube_to_edges(&level)?.into_iter().enumerate() {
                    out[f][k] = t;
                }
            }
        }
        _ => {
            return Err(Error::InvalidOption(format!(
                "OpenEXR's texel placement is defined for lat-long and cube maps, not {}",
                kind.describe()
            )));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_taps_put_texels_where_each_placement_says() {
        // Centred texel 0 of 4 at 1/8 of the axis: on an edge-placed
        // axis of 4 (texels at 0, 1/3, 2/3, 1) that is position 3/8.
        let c = to_centred(4);
        assert_eq!((c[0].i0, c[0].i1), (0, 1));
        assert!((c[0].a - 0.375).abs() < 1e-6);
        assert!((c[3].i0, c[3].i1) == (2, 3) && (c[3].a - 0.625).abs() < 1e-6);
        // Edge texel 0 of 4 at 0: half a texel before centred texel 0.
        let e = to_edges(4);
        assert_eq!((e[0].i0, e[0].i1), (-1, 0));
        assert!((e[0].a - 0.5).abs() < 1e-6);
        assert_eq!((e[3].i0, e[3].i1), (3, 4));
        assert!((e[3].a - 0.5).abs() < 1e-6);
    }
}
