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
    /// The unit direction from the plane's point under screen position
    /// `(sx, sy)` towards the camera, in the texture's tangent frame (x
    /// along u, y along v, z the plane's normal); `None` where [`Plane::uv`]
    /// is.
    pub fn view_dir(&self, frame: Frame, sx: f64, sy: f64) -> Option<[f64; 3]> {
        self.uv(frame, sx, sy)?;
        let (w, h) = (frame.width as f64, frame.height as f64);
        let t = (self.fov_y * 0.5).tan();
        let nx = (sx / w * 2.0 - 1.0) * t * (w / h);
        let ny = (1.0 - sy / h * 2.0) * t;
        let (sp, cp) = self.pitch.sin_cos();
        let d = [nx, -sp + ny * cp, cp + ny * sp];
        let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        Some([-d[0] / l, -d[2] / l, -d[1] / l])
    }

    /// Texture coordinate of screen position `(sx, sy)` in pixels, or
    /// `None` when the ray misses the plane or hits beyond `max_distance`.
    pub fn uv(&self, frame: Frame, sx: f64, sy: f64) -> Option<(f64, f64)> {
        let (w, h) = (frame.width as f64, frame.height as f64);
        let t = (self.fov_y * 0.5).tan();
        let nx = (sx / w * 2.0 - 1.0) * t * (w / h);
        let ny = (1.0 - sy / h * 2.0) * t;
        let (sp, cp) = self.pitch.sin_cos();
        // forward (0, −sin, cos), up (0, cos, sin), right (1, 0, 0).
        let dx = nx;
        let dy = -sp + ny * cp;
        let dz = cp + ny * sp;
        if dy >= -1e-9 {
            return None;
        }
        let k = self.camera_height / -dy;
        let (x, z) = (dx * k, dz * k);
        if (x * x + z * z).sqrt() > self.max_distance {
            return None;
        }
        Some((0.5 + x * self.uv_per_unit, z * self.uv_per_unit))
    }
}
