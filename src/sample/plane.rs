//! Queries of a perspective ground plane: the classic scene that makes
//! footprints anisotropic (grazing angles towards the horizon). Used by the
//! accuracy tests, the benchmarks and the examples, so they all score the
//! same scene.
//!
//! A pinhole camera at height 1 above the plane y = 0 looks down by
//! `pitch` radians. Pixel `(px, py)` (row 0 at the top) casts a ray through
//! its centre; where it meets the plane at `(x, z)`, the texture coordinate
//! is `(0.5 + x·uv_per_unit, z·uv_per_unit)`. The derivatives are the
//! central differences over one pixel (the coordinate at ±half a pixel),
//! which is what a rasterizer's 2×2 quad differences approximate.

use super::Query;

/// A ground-plane camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GroundPlane {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Angle of the view direction below the horizon, radians.
    pub pitch: f64,
    /// Vertical field of view, radians.
    pub fov_y: f64,
    /// Texture coordinate units per world unit (the camera is 1 unit high).
    pub uv_per_unit: f64,
    /// Pixels whose hit point is farther than this (world units) are
    /// skipped, which keeps the footprints bounded near the horizon.
    pub max_distance: f64,
}

impl Default for GroundPlane {
    /// 256 × 256 pixels, 20° below the horizon, 60° field of view, 0.25
    /// texture repeats per unit, hits up to 40 units away.
    fn default() -> Self {
        GroundPlane {
            width: 256,
            height: 256,
            pitch: 20f64.to_radians(),
            fov_y: 60f64.to_radians(),
            uv_per_unit: 0.25,
            max_distance: 40.0,
        }
    }
}

impl GroundPlane {
    /// Texture coordinate of screen position `(sx, sy)` in pixels, or
    /// `None` when the ray misses the plane or hits beyond `max_distance`.
    fn uv(&self, sx: f64, sy: f64) -> Option<(f64, f64)> {
        let t = (self.fov_y * 0.5).tan();
        let aspect = self.width as f64 / self.height as f64;
        let nx = (sx / self.width as f64 * 2.0 - 1.0) * t * aspect;
        let ny = (1.0 - sy / self.height as f64 * 2.0) * t;
        let (sp, cp) = self.pitch.sin_cos();
        // forward (0, −sin, cos), up (0, cos, sin), right (1, 0, 0).
        let dx = nx;
        let dy = -sp + ny * cp;
        let dz = cp + ny * sp;
        if dy >= -1e-9 {
            return None;
        }
        let k = 1.0 / -dy;
        let (x, z) = (dx * k, dz * k);
        if (x * x + z * z).sqrt() > self.max_distance {
            return None;
        }
        Some((0.5 + x * self.uv_per_unit, z * self.uv_per_unit))
    }

    /// Query of pixel `(px, py)`, or `None` if it (or a half-pixel
    /// neighbour) misses the plane.
    pub fn query(&self, px: u32, py: u32) -> Option<Query> {
        let (x, y) = (px as f64 + 0.5, py as f64 + 0.5);
        let c = self.uv(x, y)?;
        let (l, r) = (self.uv(x - 0.5, y)?, self.uv(x + 0.5, y)?);
        let (t, b) = (self.uv(x, y - 0.5)?, self.uv(x, y + 0.5)?);
        Some(Query::new(
            c.0 as f32,
            c.1 as f32,
            (r.0 - l.0) as f32,
            (r.1 - l.1) as f32,
            (b.0 - t.0) as f32,
            (b.1 - t.1) as f32,
        ))
    }

    /// Queries of every pixel that sees the plane, in raster order, with
    /// their pixel positions.
    pub fn pixels(&self) -> Vec<((u32, u32), Query)> {
        let mut out = Vec::new();
        for py in 0..self.height {
            for px in 0..self.width {
                if let Some(q) = self.query(px, py) {
                    out.push(((px, py), q));
                }
            }
        }
        out
    }

    /// Queries of every pixel that sees the plane, in raster order.
    pub fn queries(&self) -> Vec<Query> {
        self.pixels().into_iter().map(|(_, q)| q).collect()
    }
}

/// Root-mean-square difference over the colour channels (R, G, B) of two
/// equally long lists of results; the accuracy score of a filter against
/// the supersampled reference.
pub fn rmse(reference: &[[f32; 4]], got: &[[f32; 4]]) -> f64 {
    let n = reference.len().min(got.len());
    if n == 0 {
        return 0.0;
    }
    let sum: f64 = reference
        .iter()
        .zip(got)
        .map(|(a, b)| {
            (0..3)
                .map(|c| (a[c] as f64 - b[c] as f64).powi(2))
                .sum::<f64>()
        })
        .sum();
    (sum / (3 * n) as f64).sqrt()
}
