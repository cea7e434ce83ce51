//! Lat-long (equirectangular) environment maps, looked up as OpenImageIO's
//! `TextureSystem::environment()` looks them up (OpenImageIO 3.2,
//! `texture3d`'s sibling `environment.cpp`), so that a chain parvo builds
//! and one `maketx --envlatl` builds give the same values.
//!
//! # Directions to (s, t)
//! y is up: `s = atan2(−x, z)/2π + ½`, `t = ½ − atan2(y, hypot(z, x))/π`
//! (the direction is normalised first; a NaN result reads 0). `s` wraps
//! (periodic), `t` is clamped to the edge rows.
//!
//! # The filter
//! The footprint is measured as angles: `xfilt = acos(R·Rx)`, `yfilt =
//! acos(R·Ry)` (at least 1e-8) with `R`, `Rx`, `Ry` the unit vectors along
//! `dir`, `dir + ddx` and `dir + ddy`. The longer is the major axis.
//! - Isotropic (`max_aniso = 1`): one probe at `R`, filter width = the
//!   major length (OpenImageIO's "conservative" filter).
//! - Anisotropic (`max_aniso > 1`): aspect = major/minor clamped to
//!   [1, 10⁶]; above `max_aniso` the lengths are pulled together
//!   (major ← (major + minor·max_aniso)/2, minor ← major/max_aniso); the
//!   filter width is the minor length and `n = max(1, ceil(aspect − ¼))`
//!   probes sit at `R + pos·Rmajor` with `pos = −½ + (i + ½)/n`, each
//!   weighted 1/n. (`Rmajor` is the *unit* vector along `dir + ddx` or
//!   `dir + ddy`, as OpenImageIO has it, so the probes' spread is set by
//!   how far that vector leans from `R`, not by the footprint alone.)
//! - Levels: the first level `m` whose height × width / π is at most one
//!   texel; the lookup blends levels `m − 1` and `m` with weight
//!   `clamp(2·w_m − 1, 0, 1)` on `m` (level 0 alone when `m` = 0, the last
//!   level alone when no level is small enough). Mip mode `nearest` keeps
//!   level `m − 1` alone, `none` level 0.
//! - Each level is read with the sampler's minification filter (OpenImageIO
//!   has one interpolation mode for all levels): bilinear at
//!   `(s·w − ½, t·h − ½)` or the nearest texel. A map placed as OpenEXR
//!   defines it ([`Placement::Edges`], any OpenEXR file with an `envmap`
//!   attribute) is read at `(s·(w − 1), t·(h − 1))` instead: its first and
//!   last rows are the poles, its first and last columns one meridian, so
//!   the lookup interpolates inside the image and never wraps or fades.
//! - Near a pole, bilinear reads of the small levels fade to the pole's
//!   colour (the mean of the level's first or last row), so the coarse
//!   levels converge to one colour at the pole: with `tt = t·h`, weight
//!   `(1 − tt)²` for `tt < 1` and `frac(tt)²` for `tt > h − 1`. OpenImageIO
//!   does this on levels that fit in one tile of the file; parvo on levels
//!   of at most [`POLE_FADE_SIZE`] texels each way (maketx's tile size).
//! - The LOD bias scales the filter width by 2^bias (OpenImageIO has no
//!   bias here; at 0 they agree).
//!
//! The EWA and summed-area-table methods look up `(s, t)` in a 2-D
//! [`Sampler`] (repeat in `s`, clamp in `t`) with `(s, t)`'s derivatives
//! taken by differences as OpenImageIO's `texture()` takes them; the
//! supersampled reference averages n × n bilinear lookups of level 0 at
//! directions over the footprint `dir ± ddx/2 ± ddy/2`.

use std::f64::consts::PI;
use std::sync::Arc;

use crate::error::{Error, Result};
use crate::mip::MipChain;
use crate::sample::{LinearChain, Method, MipMode, Query, Sampler, SamplerOptions, TexelFilter};
use crate::texture::Texture;
use crate::wrap::{Wrap, WrapMode};

use super::vec3::{add, unit};
use super::{DirQuery, Placement};

/// Levels at most this many texels wide and high fade to the pole colour
/// near the poles (module docs).
pub const POLE_FADE_SIZE: u32 = 64;

/// `(s, t)` of a unit direction (y up, module docs).
pub fn direction_to_st(d: [f64; 3]) -> (f64, f64) {
    let s = (-d[0]).atan2(d[2]) / (2.0 * PI) + 0.5;
    let t = 0.5 - d[1].atan2(d[2].hypot(d[0])) / PI;
    (
        if s.is_nan() { 0.0 } else { s },
        if t.is_nan() { 0.0 } else { t },
    )
}

/// The unit direction at `(s, t)` (the inverse of [`direction_to_st`]).
pub fn st_to_direction(s: f64, t: f64) -> [f64; 3] {
    let phi = (s - 0.5) * 2.0 * PI;
    let theta = (0.5 - t) * PI;
    let (sp, cp) = phi.sin_cos();
    [-sp * theta.cos(), theta.sin(), cp * theta.cos()]
}

/// A lat-long environment map sampled by direction (module docs).
#[derive(Clone, Debug)]
pub struct LatLongSampler {
    chain: Arc<LinearChain>,
    options: SamplerOptions,
    /// For EWA and summed-area tables: the 2-D sampler over (s, t).
    plane: Option<Sampler>,
    /// Per level: the mean of its first and of its last row.
    poles: Vec<[[f32; 4]; 2]>,
    /// Where the texels sit (the file's convention).
    placement: Placement,
}

impl LatLongSampler {
    /// A sampler over `chain` (level 0 is the whole sphere: `s` across,
    /// `t` from +y down to −y).
    pub fn new(chain: &MipChain, options: SamplerOptions) -> Result<Self> {
        options.validate()?;
        let linear = Arc::new(LinearChain::new(chain));
        let plane = match options.method {
            Method::Ewa | Method::Sat => {
                let o = SamplerOptions {
                    wrap: Wrap {
                        u: WrapMode::Repeat,
                        v: WrapMode::ClampToEdge,
                    },
                    ..options
                };
                Some(Sampler::from_linear(linear.clone(), o)?)
            }
            _ => None,
        };
        if chain.levels()[0].height() == 0 {
            return Err(Error::InvalidOption("an empty lat-long map".into()));
        }
        let poles = (0..linear.len())
            .map(|k| {
                let (w, h) = linear.level_size(k).unwrap_or((1, 1));
                [0, h - 1].map(|row| {
                    let mut acc = [0f64; 4];
                    for x in 0..w {
                        let t = linear.texel(k, x, row).unwrap_or([0.0; 4]);
                        for c in 0..4 {
                            acc[c] += t[c] as f64;
                        }
                    }
                    acc.map(|a| (a / w as f64) as f32)
                })
            })
            .collect();
        Ok(LatLongSampler {
            chain: linear,
            options,
            plane,
            poles,
            placement: Placement::Centred,
        })
    }

    /// This sampler reading its texels as `placement` places them (the
    /// file's convention: `io::SourceInfo::placement`).
    pub fn with_placement(mut self, placement: Placement) -> Self {
        self.placement = placement;
        self
    }

    /// Where this sampler places the texels.
    pub fn placement(&self) -> Placement {
        self.placement
    }

    /// The options this sampler filters with.
    pub fn options(&self) -> &SamplerOptions {
        &self.options
    }

    /// Filtered linear RGBA in direction `q.dir` (module docs).
    pub fn sample(&self, q: &DirQuery) -> [f32; 4] {
        let d = q.dir.map(f64::from);
        let dx = q.ddx.map(f64::from);
        let dy = q.ddy.map(f64::from);
        if let Some(p) = &self.plane {
            let mut q = st_query(d, dx, dy);
            if self.placement == Placement::Edges {
                // The 2-D sampler places texel i at (i + ½)/w: level 0's
                // edge-placed texel i, at s = i/(w − 1), is found there by
                // s' = (s·(w − 1) + ½)/w (exact on level 0; the smaller
                // levels are a fraction of a texel off).
                let (w, h) = self.chain.level_size(0).unwrap_or((1, 1));
                let (fw, fh) = (w.max(2) as f32, h.max(2) as f32);
                let (sx, sy) = ((fw - 1.0) / fw, (fh - 1.0) / fh);
                q = Query::new(
                    q.u * sx + 0.5 / fw,
                    q.v * sy + 0.5 / fh,
                    q.dudx * sx,
                    q.dvdx * sy,
                    q.dudy * sx,
                    q.dvdy * sy,
                );
            }
            return p.sample(&q);
        }
        if self.options.method == Method::Supersample {
            return self.supersample(q);
        }
        self.environment(d, dx, dy)
    }

    /// OpenImageIO's lookup (module docs).
    fn environment(&self, d: [f64; 3], dx: [f64; 3], dy: [f64; 3]) -> [f32; 4] {
        let r = unit(d);
        let rx = unit(add(d, dx));
        let ry = unit(add(d, dy));
        // The footprint's angles, aspect and probe count in f32 as
        // OpenImageIO computes them: the probe count and the levels are
        // steps, and f64 would move a few of their thresholds.
        let r32 = unit32(d);
        let angle = |e: [f64; 3]| {
            let e = unit32(add(d, e));
            (r32[0] * e[0] + r32[1] * e[1] + r32[2] * e[2])
                .clamp(-1.0, 1.0)
                .acos()
                .max(1e-8)
        };
        let (xf, yf) = (angle(dx), angle(dy));
        let (rmajor, mut major, mut minor) = if xf >= yf { (rx, xf, yf) } else { (ry, yf, xf) };
        let o = &self.options;
        let (width, n) = if o.max_aniso > 1 {
            let limit = o.max_aniso as f32;
            let aspect = (major / minor).clamp(1.0, 1e6);
            let aspect = if aspect > limit {
                major = 0.5 * (major + minor * limit);
                minor = major / limit;
                limit
            } else {
                aspect
            };
            (minor as f64, ((aspect - 0.25).ceil() as u32).max(1))
        } else {
            (major as f64, 1)
        };
        let width = width * (o.lod_bias as f64).exp2();
        let (hi, lo, blend) = self.levels(width);
        let inv = 1.0 / n as f64;
        let mut acc = [0.0f64; 4];
        let mut pos = -0.5 + 0.5 * inv;
        for _ in 0..n {
            let (s, t) = direction_to_st(unit(add(r, rmajor.map(|c| pos * c))));
            for (k, w) in [(hi, 1.0 - blend), (lo, blend)] {
                if w == 0.0 {
                    continue;
                }
                let v = self.read(o.min, k, s, t);
                for c in 0..4 {
                    acc[c] += w * inv * v[c] as f64;
                }
            }
            pos += inv;
        }
        acc.map(|x| x as f32)
    }

    /// The two levels and the weight of the second for a filter `width`
    /// radians wide (module docs).
    fn levels(&self, width: f64) -> (usize, usize, f64) {
        let o = &self.options;
        let count = self.chain.len();
        let mut pick = (count - 1, count - 1, 0.0);
        for m in 0..count {
            let h = self.chain.level_size(m).map_or(1, |(_, h)| h) as f64;
            // Rows per π radians: h, or h − 1 between edge-placed rows.
            let rows = match self.placement {
                Placement::Centred => h,
                Placement::Edges => (h - 1.0).max(1.0),
            };
            let ras = rows * width / PI;
            if ras <= 1.0 {
                pick = if m == 0 {
                    (0, 0, 0.0)
                } else {
                    (m - 1, m, (2.0 * ras - 1.0).clamp(0.0, 1.0))
                };
                break;
            }
        }
        match o.mip {
            MipMode::None => (0, 0, 0.0),
            MipMode::Nearest => (pick.0, pick.0, 0.0),
            MipMode::Linear => pick,
        }
    }

    /// Level `k` at `(s, t)`: `s` periodic, `t` clamped.
    fn read(&self, filter: TexelFilter, k: usize, s: f64, t: f64) -> [f32; 4] {
        let (w, h) = self.chain.level_size(k).unwrap_or((1, 1));
        let (w, h) = (w as i64, h as i64);
        if self.placement == Placement::Edges {
            return self.read_edges(filter, k, (w, h), s, t);
        }
        let texel = |i: i64, j: i64| {
            self.chain
                .texel(k, i.rem_euclid(w) as u32, j.clamp(0, h - 1) as u32)
                .unwrap_or([0.0; 4])
        };
        let (x, y) = (s * w as f64, t * h as f64);
        if filter == TexelFilter::Nearest {
            return texel(x.floor() as i64, y.floor() as i64);
        }
        let (x, y) = (x - 0.5, y - 0.5);
        let (x0, y0) = (x.floor(), y.floor());
        let (a, b) = ((x - x0) as f32, (y - y0) as f32);
        let (i, j) = (x0 as i64, y0 as i64);
        let top = mix(texel(i, j), texel(i + 1, j), a);
        let bottom = mix(texel(i, j + 1), texel(i + 1, j + 1), a);
        let v = mix(top, bottom, b);
        if w > POLE_FADE_SIZE as i64 || h > POLE_FADE_SIZE as i64 {
            return v;
        }
        let tt = t * h as f64;
        let (pole, colour) = if tt < 1.0 {
            (1.0 - tt, self.poles[k][0])
        } else if tt > (h - 1) as f64 {
            (tt - tt.floor(), self.poles[k][1])
        } else {
            return v;
        };
        let p = pole.clamp(0.0, 1.0);
        mix(v, colour, (p * p) as f32)
    }

    /// Level `k` (`w`×`h`) at `(s, t)` with OpenEXR's placement: the
    /// continuous texel position `(s·(w − 1), t·(h − 1))`
    /// (`LatLongMap::pixelPosition`), read inside the image (the last
    /// column is the first's meridian, the edge rows the poles).
    fn read_edges(
        &self,
        filter: TexelFilter,
        k: usize,
        (w, h): (i64, i64),
        s: f64,
        t: f64,
    ) -> [f32; 4] {
        let texel = |i: i64, j: i64| {
            self.chain
                .texel(k, i.clamp(0, w - 1) as u32, j.clamp(0, h - 1) as u32)
                .unwrap_or([0.0; 4])
        };
        let x = s.clamp(0.0, 1.0) * (w - 1) as f64;
        let y = t.clamp(0.0, 1.0) * (h - 1) as f64;
        if filter == TexelFilter::Nearest {
            return texel(x.round() as i64, y.round() as i64);
        }
        let (x0, y0) = (x.floor(), y.floor());
        let (a, b) = ((x - x0) as f32, (y - y0) as f32);
        let (i, j) = (x0 as i64, y0 as i64);
        let top = mix(texel(i, j), texel(i + 1, j), a);
        let bottom = mix(texel(i, j + 1), texel(i + 1, j + 1), a);
        mix(top, bottom, b)
    }

    /// The supersampled reference (module docs).
    fn supersample(&self, q: &DirQuery) -> [f32; 4] {
        super::grid_average(q, self.options.supersample, |p| {
            let (s, t) = direction_to_st(unit(p));
            self.read(TexelFilter::Linear, 0, s, t)
        })
    }
}

/// `(s, t)` and their differences along `dx` and `dy` as a 2-D query (a
/// difference across the `s` seam is taken the short way round).
fn st_query(d: [f64; 3], dx: [f64; 3], dy: [f64; 3]) -> Query {
    let (s, t) = direction_to_st(unit(d));
    let diff = |e: [f64; 3]| {
        let (s2, t2) = direction_to_st(unit(add(d, e)));
        let mut ds = s2 - s;
        if ds > 0.5 {
            ds -= 1.0;
        } else if ds < -0.5 {
            ds += 1.0;
        }
        (ds, t2 - t)
    };
    let (dsdx, dtdx) = diff(dx);
    let (dsdy, dtdy) = diff(dy);
    Query::new(
        s as f32,
        t as f32,
        dsdx as f32,
        dtdx as f32,
        dsdy as f32,
        dtdy as f32,
    )
}

/// `a` scaled to unit length in `f32` (as OpenImageIO normalises).
fn unit32(a: [f64; 3]) -> [f32; 3] {
    let a = a.map(|c| c as f32);
    let l = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    if l > 0.0 && l.is_finite() {
        a.map(|c| c / l)
    } else {
        a
    }
}

fn mix(a: [f32; 4], b: [f32; 4], t: f32) -> [f32; 4] {
    std::array::from_fn(|c| a[c] + (b[c] - a[c]) * t)
}

/// A lat-long map's mip chain: each level from the one before by an
/// area-weighted box — a coarse texel averages the finer texels it covers
/// (fractional overlaps at odd sizes), each finer row weighted by the
/// solid angle of its band, `sin(π·(row + ½)/height)`, so the rows near
/// the poles, which cover little of the sphere, count for little (as
/// `maketx --envlatl` weights them; for even sizes this is its 2 × 2
/// filter exactly). Columns wrap nothing: a coarse texel covers whole
/// finer columns. Levels are computed in `f32` from the unrounded level
/// before and stored once in the base's format; level sizes round down.
pub fn build_chain(base: Texture) -> Result<MipChain> {
    let format = base.format();
    let ch = format.channels as usize;
    let (mut w, mut h) = (base.width(), base.height());
    let mut cur = base.to_linear();
    let mut levels = vec![base];
    while w > 1 || h > 1 {
        let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
        let cols = box_weights(w, nw, |_| 1.0);
        let rows = box_weights(h, nh, |r| (PI * (r as f64 + 0.5) / h as f64).sin());
        let mut next = vec![0f32; nw as usize * nh as usize * ch];
        for (j, rw) in rows.iter().enumerate() {
            for (i, cw) in cols.iter().enumerate() {
                let mut acc = [0f64; 4];
                for &(r, wr) in rw {
                    for &(c, wc) in cw {
                        let at = (r * w as usize + c) * ch;
                        for k in 0..ch {
                            acc[k] += wr * wc * cur[at + k] as f64;
                        }
                    }
                }
                let at = (j * nw as usize + i) * ch;
                for k in 0..ch {
                    next[at + k] = acc[k] as f32;
                }
            }
        }
        levels.push(Texture::from_linear(nw, nh, format, &next)?);
        (w, h, cur) = (nw, nh, next);
    }
    MipChain::from_levels(levels, crate::mip::MipOptions::default())
}

/// For each of `m` coarse cells over `n` fine ones: the fine indices it
/// overlaps and their normalised weights (overlap × `weight(index)`).
fn box_weights(n: u32, m: u32, weight: impl Fn(usize) -> f64) -> Vec<Vec<(usize, f64)>> {
    let scale = n as f64 / m as f64;
    (0..m)
        .map(|j| {
            let (a, b) = (j as f64 * scale, (j + 1) as f64 * scale);
            let mut v: Vec<(usize, f64)> = (a.floor() as usize
                ..(b.ceil() as usize).min(n as usize))
                .map(|r| {
                    let overlap = (b.min(r as f64 + 1.0) - a.max(r as f64)).max(0.0);
                    (r, overlap * weight(r))
                })
                .filter(|&(_, x)| x > 0.0)
                .collect();
            let sum: f64 = v.iter().map(|&(_, x)| x).sum();
            if sum > 0.0 {
                v.iter_mut().for_each(|(_, x)| *x /= sum);
            } else {
                // A band of zero solid angle cannot happen (row centres
                // are inside (0, π)); kept so the weights always sum to 1.
                let r = (a.floor() as usize).min(n as usize - 1);
                v = vec![(r, 1.0)];
            }
            v
        })
        .collect()
}
