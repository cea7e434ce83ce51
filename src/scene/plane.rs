//! The perspective ground plane: the classic scene that makes footprints
//! anisotropic (grazing angles towards the horizon), shared by the
//! accuracy tests, the benchmarks, the examples and `parvo cachesim`.
//!
//! A pinhole camera at `camera_height` above the plane y = 0 looks down by
//! `pitch` radians. The ray through screen position `(sx, sy)` meets the
//! plane at `(x, z)`; the texture coordinate is
//! `(0.5 + x·uv_per_unit, z·uv_per_unit)`.

use super::Frame;

/// A ground-plane camera (the frame size is given per call).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// Height of the camera above the plane, world units.
    pub camera_height: f64,
    /// Angle of the view direction below the horizon, radians.
    pub pitch: f64,
    /// Vertical field of view, radians.
    pub fov_y: f64,
    /// Texture coordinate units per world unit.
    pub uv_per_unit: f64,
    /// Pixels whose hit point is farther than this (world units) are
    /// skipped, which keeps the footprints bounded near the horizon.
    pub max_distance: f64,
}

impl Default for Plane {
    /// Camera 1 unit high, 20° below the horizon, 60° field of view, 0.25
    /// texture repeats per unit, hits up to 16 units away (footprints up to
    /// about 130 texels of a 512² texture at 320×240, so the reference
    /// image stays affordable).
    fn default() -> Self {
        Plane {
            camera_height: 1.0,
            pitch: 20f64.to_radians(),
            fov_y: 60f64.to_radians(),
            uv_per_unit: 0.25,
            max_distance: 16.0,
        }
    }
}

impl Plane {
    /// The camera of this plane for `frame`: the per-frame constants of
    /// [`Plane::uv`] computed once (see [`PlaneCamera`]).
    pub fn camera(&self, frame: Frame) -> PlaneCamera {
        let (w, h) = (frame.width as f64, frame.height as f64);
        let (sp, cp) = self.pitch.sin_cos();
        PlaneCamera {
            w,
            h,
            tan: (self.fov_y * 0.5).tan(),
            aspect: w / h,
            sp,
            cp,
            height: self.camera_height,
            max_square: square_bound(self.max_distance),
            uv_per_unit: self.uv_per_unit,
        }
    }

    /// The unit direction from the plane's point under screen position
    /// `(sx, sy)` towards the camera, in the texture's tangent frame (x
    /// along u, y along v, z the plane's normal); `None` where [`Plane::uv`]
    /// is.
    pub fn view_dir(&self, frame: Frame, sx: f64, sy: f64) -> Option<[f64; 3]> {
        let cam = self.camera(frame);
        cam.uv(sx, sy)?;
        let nx = cam.nx(sx);
        let ny = cam.ny(sy);
        let d = [nx, -cam.sp + ny * cam.cp, cam.cp + ny * cam.sp];
        let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        Some([-d[0] / l, -d[2] / l, -d[1] / l])
    }

    /// Texture coordinate of screen position `(sx, sy)` in pixels, or
    /// `None` when the ray misses the plane or hits beyond `max_distance`.
    /// (One call sets up the camera; [`Plane::camera`] sets it up once
    /// for a frame, with the same results.)
    pub fn uv(&self, frame: Frame, sx: f64, sy: f64) -> Option<(f64, f64)> {
        self.camera(frame).uv(sx, sy)
    }
}

/// A [`Plane`]'s camera for one frame: the tangent of half the field of
/// view, the sine and cosine of the pitch and the aspect ratio, computed
/// once. Per position it is a few multiplications and additions and three
/// divisions, in the same order as the per-call formula (the distance
/// test compares squares, exactly: `square_bound`), so the results are
/// the same to the last bit
/// (`tests/core/scene_view.rs` compares every pixel with that formula).
///
/// The ray through `(sx, sy)` is `(nx, −sin p + ny·cos p, cos p + ny·sin p)`
/// with `nx` depending on `sx` alone and `ny` on `sy` alone: the plane's
/// coordinate is a projective map of the screen, and [`PlaneGrid`] keeps
/// the column and row terms of a frame's half-pixel grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlaneCamera {
    w: f64,
    h: f64,
    tan: f64,
    aspect: f64,
    sp: f64,
    cp: f64,
    height: f64,
    /// `sqrt(d²) > max_distance ⟺ d² > max_square` (see [`square_bound`]).
    max_square: f64,
    uv_per_unit: f64,
}

/// The largest `a` with `sqrt(a) ≤ m` (−1 for a negative `m`, ∞ for NaN
/// or ∞): the square root is correctly rounded and non-decreasing, so
/// `sqrt(a) > m` exactly when `a > square_bound(m)`, for every `a ≥ 0`,
/// ∞ and NaN included. The distance test then needs no square root.
fn square_bound(m: f64) -> f64 {
    if m.is_nan() || m == f64::INFINITY {
        return f64::INFINITY;
    }
    if m < 0.0 {
        return -1.0;
    }
    let mut t = m * m;
    while t > 0.0 && t.sqrt() > m {
        t = t.next_down();
    }
    while t.next_up().sqrt() <= m {
        t = t.next_up();
    }
    t
}

/// The row term of a screen row: the ray's scale to the plane `k` and
/// the hit's `z`, or `None` when rays of the row miss the plane.
type Row = Option<(f64, f64)>;

impl PlaneCamera {
    /// The ray's x slope at screen x.
    #[inline(always)]
    fn nx(&self, sx: f64) -> f64 {
        (sx / self.w * 2.0 - 1.0) * self.tan * self.aspect
    }

    /// The ray's y slope at screen y.
    #[inline(always)]
    fn ny(&self, sy: f64) -> f64 {
        (1.0 - sy / self.h * 2.0) * self.tan
    }

    /// The row term at screen y.
    #[inline(always)]
    fn row(&self, sy: f64) -> Row {
        let ny = self.ny(sy);
        // forward (0, −sin, cos), up (0, cos, sin), right (1, 0, 0).
        let dy = -self.sp + ny * self.cp;
        let dz = self.cp + ny * self.sp;
        if dy >= -1e-9 {
            return None;
        }
        let k = self.height / -dy;
        Some((k, dz * k))
    }

    /// The texture coordinate of the ray with x slope `nx` in a row.
    #[inline(always)]
    fn hit(&self, nx: f64, row: Row) -> Option<(f64, f64)> {
        let (k, z) = row?;
        let x = nx * k;
        if x * x + z * z > self.max_square {
            return None;
        }
        Some((0.5 + x * self.uv_per_unit, z * self.uv_per_unit))
    }

    /// Texture coordinate of screen position `(sx, sy)` (as [`Plane::uv`]).
    #[inline]
    pub fn uv(&self, sx: f64, sy: f64) -> Option<(f64, f64)> {
        self.hit(self.nx(sx), self.row(sy))
    }

    /// The column and row terms of `frame`'s half-pixel grid.
    pub fn grid(&self, frame: Frame) -> PlaneGrid {
        PlaneGrid {
            cols: (0..=2 * frame.width as u64)
                .map(|i| self.nx(i as f64 * 0.5))
                .collect(),
            rows: (0..=2 * frame.height as u64)
                .map(|j| self.row(j as f64 * 0.5))
                .collect(),
        }
    }
}

/// A frame's half-pixel grid of a [`PlaneCamera`]: `nx` of every column
/// `i/2` and the row term of every row `j/2`, so that a pixel's query (its
/// centre and the four half-pixel neighbours, all on the grid) is a few
/// products, no square root and no division.
#[derive(Clone, Debug, PartialEq)]
pub struct PlaneGrid {
    cols: Vec<f64>,
    rows: Vec<Row>,
}

impl PlaneGrid {
    /// The texture coordinate at grid point `(i/2, j/2)` (in range).
    #[inline(always)]
    pub fn uv(&self, cam: &PlaneCamera, i: usize, j: usize) -> Option<(f64, f64)> {
        cam.hit(self.cols[i], self.rows[j])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `a > square_bound(m)` decides `sqrt(a) > m` for every `a`, checked
    /// at and around the bound of many `m` and on a seeded spread.
    #[test]
    fn square_bound_decides_the_square_root_test_exactly() {
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        let mut ms = vec![0.0, 1.0, 16.0, 0.1, 3.0, 1e-300, 1e300, 2f64.sqrt()];
        ms.extend((0..2000).map(|_| f64::from_bits(next() >> 2) % 1e6));
        for m in ms {
            let t = square_bound(m);
            let mut probes = vec![t, t.next_up(), t.next_down(), m * m, 0.0, f64::INFINITY];
            probes.extend((0..20).map(|_| t * (1.0 + (next() % 1000) as f64 * 1e-6)));
            for a in probes.into_iter().filter(|a| *a >= 0.0) {
                assert_eq!(a.sqrt() > m, a > t, "m {m:e} a {a:e} t {t:e}");
            }
        }
        assert_eq!(square_bound(f64::NAN), f64::INFINITY);
        assert_eq!(square_bound(-1.0), -1.0);
    }
}
