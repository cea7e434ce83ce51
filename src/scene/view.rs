//! A scene prepared for one frame and texture: what its mapping computes
//! once per frame (a camera's tangent, a pitch's sine and cosine, an
//! angle's sine and cosine, the exponent at the frame's left edge) is
//! computed once, so a pixel costs only what depends on the pixel.
//!
//! [`View::uv`] and [`View::query_at`] give the same values as
//! [`Scene::uv`] and [`Scene::query_at`] to the last bit (the same
//! operations in the same order on the same inputs; `tests/core/scene_view.rs`
//! compares every pixel of several frames with the per-call formulas).
//! [`View::query`] of a whole pixel reads the plane's coordinates off a
//! half-pixel grid of column and row terms ([`PlaneGrid`]), again the same
//! values.

use super::plane::{PlaneCamera, PlaneGrid};
use super::{Frame, Scene, Sky, Sphere, Tunnel, Zoom};
use crate::env::latlong::direction_to_st;
use crate::env::vec3::{cross, dot, unit};
use crate::sample::Query;

/// A [`Scene`] set up for one frame and level-0 texture size.
#[derive(Clone, Debug)]
pub struct View {
    kind: Kind,
}

#[derive(Clone, Debug)]
enum Kind {
    Plane(PlaneCamera, Option<PlaneGrid>),
    Tunnel(TunnelView),
    Zoom(ZoomView),
    Rotate(RotateView),
    Env(EnvView),
}

/// A pinhole camera's ray directions, and for a mirror sphere the
/// reflection: both end in a direction looked up as (s, t).
#[derive(Clone, Copy, Debug)]
struct EnvView {
    w: f64,
    h: f64,
    /// tan(fov_y / 2) × aspect, tan(fov_y / 2).
    sx: f64,
    sy: f64,
    forward: [f64; 3],
    right: [f64; 3],
    up: [f64; 3],
    /// The camera's distance from a mirror sphere's centre, on +z; `None`
    /// for the sky.
    sphere: Option<f64>,
}

#[derive(Clone, Copy, Debug)]
struct TunnelView {
    t: Tunnel,
    w: f64,
    h: f64,
    tan: f64,
    aspect: f64,
}

#[derive(Clone, Copy, Debug)]
struct ZoomView {
    z: Zoom,
    half_h: f64,
    tw: f64,
    th: f64,
    k: f64,
    left: f64,
    k_ln2: f64,
}

#[derive(Clone, Copy, Debug)]
struct RotateView {
    scale: f64,
    half_w: f64,
    half_h: f64,
    tw: f64,
    th: f64,
    sn: f64,
    cs: f64,
}

impl View {
    /// `scene` in `frame` over a level-0 texture of `tex` texels; `grid`
    /// also tabulates the plane's half-pixel grid for [`View::query`]
    /// (a few thousand numbers, worth it for a whole frame only).
    pub(super) fn new(scene: &Scene, frame: Frame, tex: (u32, u32), grid: bool) -> Self {
        let (w, h) = (frame.width as f64, frame.height as f64);
        let (tw, th) = (tex.0.max(1) as f64, tex.1.max(1) as f64);
        let kind = match *scene {
            Scene::Plane(p) => {
                let cam = p.camera(frame);
                Kind::Plane(cam, grid.then(|| cam.grid(frame)))
            }
            Scene::Tunnel(t) => Kind::Tunnel(TunnelView {
                t,
                w,
                h,
                tan: (t.fov_y * 0.5).tan(),
                aspect: w / h,
            }),
            Scene::Zoom(z) => {
                let k = (z.lod_right - z.lod_left) / w;
                Kind::Zoom(ZoomView {
                    z,
                    half_h: h * 0.5,
                    tw,
                    th,
                    k,
                    left: z.lod_left.exp2(),
                    k_ln2: k * std::f64::consts::LN_2,
                })
            }
            Scene::Rotate(r) => {
                let (sn, cs) = r.degrees.to_radians().sin_cos();
                Kind::Rotate(RotateView {
                    scale: r.scale,
                    half_w: w * 0.5,
                    half_h: h * 0.5,
                    tw,
                    th,
                    sn,
                    cs,
                })
            }
            Scene::Sky(k) => Kind::Env(EnvView::sky(&k, w, h)),
            Scene::Sphere(k) => Kind::Env(EnvView::sphere(&k, w, h)),
        };
        View { kind }
    }

    /// Texture coordinate of the continuous screen position `(x, y)` (as
    /// [`Scene::uv`]).
    #[inline]
    pub fn uv(&self, x: f64, y: f64) -> Option<(f64, f64)> {
        match &self.kind {
            Kind::Plane(cam, _) => cam.uv(x, y),
            Kind::Tunnel(v) => v.uv(x, y),
            Kind::Zoom(v) => Some(v.uv(x, y)),
            Kind::Rotate(v) => Some(v.uv(x, y)),
            Kind::Env(v) => v.uv(x, y),
        }
    }

    /// The query of a pixel centred at `(x, y)` (as [`Scene::query_at`]).
    #[inline]
    pub fn query_at(&self, x: f64, y: f64) -> Option<Query> {
        let at = |x: f64, y: f64| self.uv(x, y);
        let c = at(x, y)?;
        let (l, r) = (at(x - 0.5, y)?, at(x + 0.5, y)?);
        let (t, b) = (at(x, y - 0.5)?, at(x, y + 0.5)?);
        Some(self.differences(c, l, r, t, b))
    }

    /// The query of pixel `(px, py)` (as [`Scene::query`]).
    #[inline]
    pub fn query(&self, px: u32, py: u32) -> Option<Query> {
        let Kind::Plane(cam, Some(grid)) = &self.kind else {
            return self.query_at(px as f64 + 0.5, py as f64 + 0.5);
        };
        // The centre px + 1/2 and its neighbours px and px + 1 are grid
        // columns 2px + 1, 2px and 2px + 2 (exact in f64), as for rows.
        let (i, j) = (2 * px as usize, 2 * py as usize);
        let c = grid.uv(cam, i + 1, j + 1)?;
        let (l, r) = (grid.uv(cam, i, j + 1)?, grid.uv(cam, i + 2, j + 1)?);
        let (t, b) = (grid.uv(cam, i + 1, j)?, grid.uv(cam, i + 1, j + 2)?);
        Some(self.differences(c, l, r, t, b))
    }

    /// The query from the coordinates at the centre and at the half-pixel
    /// neighbours: central differences over one pixel.
    #[inline(always)]
    fn differences(
        &self,
        c: (f64, f64),
        l: (f64, f64),
        r: (f64, f64),
        t: (f64, f64),
        b: (f64, f64),
    ) -> Query {
        // The tunnel's u wraps around the circle, a lat-long map's s
        // around the horizon: difference across the seam by the short way.
        let d = |a: f64, b: f64| {
            let p = match &self.kind {
                Kind::Tunnel(v) => v.t.repeats_around,
                Kind::Env(_) => 1.0,
                _ => return b - a,
            };
            let mut d = b - a;
            d -= (d / p).round() * p;
            d
        };
        Query::new(
            c.0 as f32,
            c.1 as f32,
            d(l.0, r.0) as f32,
            (r.1 - l.1) as f32,
            d(t.0, b.0) as f32,
            (b.1 - t.1) as f32,
        )
    }
}

impl TunnelView {
    #[inline]
    fn uv(&self, x: f64, y: f64) -> Option<(f64, f64)> {
        let nx = (x / self.w * 2.0 - 1.0) * self.tan * self.aspect;
        let ny = (1.0 - y / self.h * 2.0) * self.tan;
        let r = (nx * nx + ny * ny).sqrt();
        if r < 1e-12 {
            return None;
        }
        let z = 1.0 / r;
        if z > self.t.max_distance {
            return None;
        }
        let angle = ny.atan2(nx) / std::f64::consts::TAU + 0.5;
        Some((angle * self.t.repeats_around, z * self.t.v_per_unit))
    }
}

impl ZoomView {
    #[inline]
    fn uv(&self, x: f64, y: f64) -> (f64, f64) {
        let s = (self.z.lod_left + self.k * x).exp2();
        let u = if self.k.abs() < 1e-15 {
            s * x
        } else {
            (s - self.left) / self.k_ln2
        };
        (u / self.tw, 0.5 + (y - self.half_h) * s / self.th)
    }
}

impl RotateView {
    #[inline]
    fn uv(&self, x: f64, y: f64) -> (f64, f64) {
        let (dx, dy) = (x - self.half_w, y - self.half_h);
        (
            0.5 + (self.cs * dx - self.sn * dy) * self.scale / self.tw,
            0.5 + (self.sn * dx + self.cs * dy) * self.scale / self.th,
        )
    }
}

impl EnvView {
    fn camera(w: f64, h: f64, fov_y: f64, forward: [f64; 3], up: [f64; 3]) -> Self {
        let tan = (fov_y * 0.5).tan();
        // right = forward × up: +x on the screen turns towards larger s.
        let right = cross(forward, up);
        EnvView {
            w,
            h,
            sx: tan * w / h,
            sy: tan,
            forward,
            right,
            up,
            sphere: None,
        }
    }

    fn sky(k: &Sky, w: f64, h: f64) -> Self {
        let (sp, cp) = k.pitch.sin_cos();
        let (sy, cy) = k.yaw.sin_cos();
        // Longitude `yaw` from +z towards -x (s grows that way, see
        // `direction_to_st`), elevation `pitch`.
        let forward = [-sy * cp, sp, cy * cp];
        let up = [sy * sp, cp, -cy * sp];
        Self::camera(w, h, k.fov_y, forward, up)
    }

    fn sphere(k: &Sphere, w: f64, h: f64) -> Self {
        let mut v = Self::camera(w, h, k.fov_y, [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]);
        v.sphere = Some(k.distance);
        v
    }

    #[inline]
    fn uv(&self, x: f64, y: f64) -> Option<(f64, f64)> {
        let nx = (x / self.w * 2.0 - 1.0) * self.sx;
        let ny = (1.0 - y / self.h * 2.0) * self.sy;
        let d = unit(std::array::from_fn(|i| {
            self.forward[i] + nx * self.right[i] + ny * self.up[i]
        }));
        let Some(dist) = self.sphere else {
            return Some(direction_to_st(d));
        };
        // The ray from (0, 0, dist) along d meets the unit sphere where
        // t² + 2bt + c = 0, b = o·d, c = |o|² − 1.
        let b = dist * d[2];
        let disc = b * b - (dist * dist - 1.0);
        if disc < 0.0 {
            return None;
        }
        let t = -b - disc.sqrt();
        let n = [t * d[0], t * d[1], dist + t * d[2]];
        let dn = dot(d, n);
        Some(direction_to_st(std::array::from_fn(|i| {
            d[i] - 2.0 * dn * n[i]
        })))
    }
}
