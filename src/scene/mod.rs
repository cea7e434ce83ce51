//! Scenes: a W×H frame of pixels mapped to texture coordinates by exact
//! geometry, turned into per-pixel queries (SPEC.md, "Scenes, raster orders
//! and the reference image"), and the raster orders that visit the pixels.
//!
//! A [`Scene`] is a value with defaults that parses from and prints to its
//! name: `plane`, `tunnel`, `zoom`, `rotate:DEG[:SCALE]`. Its mapping
//! ([`Scene::uv`]) takes a continuous screen position in pixels, so the
//! reference image can integrate the exact mapping over a pixel; its
//! queries ([`Scene::query`]) take the value at the pixel's centre and the
//! derivatives as central differences over one pixel (what a rasterizer's
//! 2×2 quad differences approximate). Scenes whose scale is given in
//! texels (zoom, rotate) need the level-0 texture size. A [`View`] is a
//! scene set up for one frame (its camera's constants computed once), with
//! the same values.
//!
//! - [`plane`]: a pinhole camera above a textured ground plane (footprints
//!   grow and stretch towards the horizon);
//! - [`Tunnel`]: a camera on the axis of a textured cylinder (footprints of
//!   every orientation around the circle, shrinking into the distance);
//! - [`Zoom`]: one frame sweeping from 8× magnification at the left edge to
//!   1/256 minification at the right (λ from −3 to 8);
//! - [`Rotate`]: a screen-filling texture turned by an angle, a fixed
//!   number of texels per pixel (λ = log2(scale) everywhere);
//! - [`Sky`]: a pinhole camera looking up at the sky of a lat-long
//!   environment map (the texture read as one: s around, t from the north
//!   pole down, [`crate::env::latlong`]'s mapping), horizon and ground in
//!   the lower part of the frame, the stretched rows near the pole at the
//!   top;
//! - [`Sphere`]: a mirror sphere reflecting a lat-long environment map,
//!   every direction at once, squeezed towards the silhouette (pixels off
//!   the sphere show no texture).
//!
//! The environment scenes look the map up as a 2-D texture with the exact
//! derivatives of (s, t), as OpenImageIO's `texture()` and parvo's EWA
//! and summed-area lookups by direction do: s repeats, t clamps
//! ([`Scene::wrap`]); differences across the s = 0 seam take the short
//! way.

pub mod metrics;
pub mod order;
pub mod plane;
pub mod reference;
pub mod render;
pub mod view;

use std::fmt;
use std::str::FromStr;

use crate::error::{Error, Result};
use crate::sample::Query;

pub use order::RasterOrder;
pub use plane::Plane;
pub use reference::{PixelFilter, Reference};
pub use view::View;

/// A frame size in pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Frame {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
}

impl Frame {
    /// A `width × height` frame.
    pub const fn new(width: u32, height: u32) -> Self {
        Frame { width, height }
    }

    /// Number of pixels.
    pub fn pixels(&self) -> u64 {
        self.width as u64 * self.height as u64
    }
}

impl fmt::Display for Frame {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}x{}", self.width, self.height)
    }
}

impl FromStr for Frame {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        let bad = || {
            Error::parse(
                "frame size",
                s,
                "expected WxH, e.g. 512x384, 1 to 16384 each",
            )
        };
        let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
        let p = |t: &str| {
            t.trim()
                .parse::<u32>()
                .ok()
                .filter(|n| (1..=16384).contains(n))
                .ok_or_else(bad)
        };
        Ok(Frame::new(p(w)?, p(h)?))
    }
}

/// Inside a textured cylinder of radius 1, looking down its axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tunnel {
    /// Vertical field of view, radians.
    pub fov_y: f64,
    /// Texture repeats around the circumference (u).
    pub repeats_around: f64,
    /// Texture repeats per unit of depth (v).
    pub v_per_unit: f64,
    /// Pixels that see the wall farther than this are skipped.
    pub max_distance: f64,
}

impl Default for Tunnel {
    /// 90° field of view, 2 repeats around, 0.25 per unit, up to 12 deep.
    fn default() -> Self {
        Tunnel {
            fov_y: 90f64.to_radians(),
            repeats_around: 2.0,
            v_per_unit: 0.25,
            max_distance: 12.0,
        }
    }
}

/// Texels per pixel growing exponentially from left to right.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Zoom {
    /// log2 of level-0 texels per pixel at the left edge (−3: 8×
    /// magnification).
    pub lod_left: f64,
    /// log2 of texels per pixel at the right edge (8: 1/256).
    pub lod_right: f64,
}

impl Default for Zoom {
    fn default() -> Self {
        Zoom {
            lod_left: -3.0,
            lod_right: 8.0,
        }
    }
}

/// A screen-filling texture turned by `degrees`, `scale` level-0 texels
/// per pixel along each screen axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rotate {
    /// Angle of the texture's u axis to the screen's x axis, degrees.
    pub degrees: f64,
    /// Level-0 texels per pixel along each screen axis (λ = log2 scale).
    pub scale: f64,
}

/// Looking up at a lat-long sky from the ground.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sky {
    /// Vertical field of view, radians.
    pub fov_y: f64,
    /// Elevation of the view direction above the horizon, radians.
    pub pitch: f64,
    /// Longitude of the view direction, radians (0: looking along +z, the
    /// middle of the map).
    pub yaw: f64,
}

impl Default for Sky {
    /// 100° field of view, 35° up (the horizon near the bottom edge, 85°
    /// at the top edge's middle and the pole past the top corners), 20°
    /// round from the middle of the map.
    fn default() -> Self {
        Sky {
            fov_y: 100f64.to_radians(),
            pitch: 35f64.to_radians(),
            yaw: 20f64.to_radians(),
        }
    }
}

/// A mirror sphere of radius 1 seen from `distance` along +z.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Camera distance from the sphere's centre (more than 1).
    pub distance: f64,
    /// Vertical field of view, radians.
    pub fov_y: f64,
}

impl Default for Sphere {
    /// 3 radii away, the sphere 85 % of the frame's height.
    fn default() -> Self {
        let distance = 3.0;
        Sphere {
            distance,
            fov_y: 2.0 * (1.0 / distance).asin() / 0.85,
        }
    }
}

/// The scenes (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Scene {
    /// A ground plane below a pinhole camera.
    Plane(Plane),
    /// Inside a cylinder.
    Tunnel(Tunnel),
    /// 8× magnification to 1/256 minification across the frame.
    Zoom(Zoom),
    /// A rotated, uniformly scaled texture.
    Rotate(Rotate),
    /// A lat-long sky seen through a camera.
    Sky(Sky),
    /// A lat-long environment in a mirror sphere.
    Sphere(Sphere),
}

impl Default for Scene {
    fn default() -> Self {
        Scene::Plane(Plane::default())
    }
}

impl fmt::Display for Scene {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Scene::Plane(_) => f.write_str("plane"),
            Scene::Tunnel(_) => f.write_str("tunnel"),
            Scene::Zoom(_) => f.write_str("zoom"),
            Scene::Sky(_) => f.write_str("sky"),
            Scene::Sphere(_) => f.write_str("sphere"),
            Scene::Rotate(r) if r.scale == 1.0 => write!(f, "rotate:{}", r.degrees),
            Scene::Rotate(r) => write!(f, "rotate:{}:{}", r.degrees, r.scale),
        }
    }
}

impl FromStr for Scene {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        let expected = "expected plane, tunnel, zoom, rotate:DEG[:SCALE], sky or sphere";
        let t = s.trim().to_ascii_lowercase();
        let mut parts = t.split(':');
        let scene = match parts.next().unwrap_or("") {
            "plane" => Scene::Plane(Plane::default()),
            "tunnel" => Scene::Tunnel(Tunnel::default()),
            "zoom" => Scene::Zoom(Zoom::default()),
            "sky" => Scene::Sky(Sky::default()),
            "sphere" => Scene::Sphere(Sphere::default()),
            "rotate" => {
                let num = |p: Option<&str>, what: &str| -> Result<Option<f64>> {
                    match p {
                        None => Ok(None),
                        Some(v) => v
                            .parse::<f64>()
                            .ok()
                            .filter(|x| x.is_finite())
                            .map(Some)
                            .ok_or_else(|| {
                                Error::parse("scene", s, format!("{what} `{v}` is not a number"))
                            }),
                    }
                };
                let degrees = num(parts.next(), "angle")?.ok_or_else(|| {
                    Error::parse("scene", s, "rotate needs an angle: rotate:DEG[:SCALE]")
                })?;
                let scale = num(parts.next(), "scale")?.unwrap_or(1.0);
                if !(scale > 0.0 && scale <= 1e6) {
                    return Err(Error::parse(
                        "scene",
                        s,
                        "the scale must be above 0 (texels per pixel)",
                    ));
                }
                Scene::Rotate(Rotate { degrees, scale })
            }
            _ => return Err(Error::parse("scene", s, expected)),
        };
        if parts.next().is_some() {
            return Err(Error::parse("scene", s, expected));
        }
        Ok(scene)
    }
}

impl Scene {
    /// True for the scenes that read their texture as a lat-long
    /// environment map ([`Sky`], [`Sphere`]).
    pub fn is_environment(&self) -> bool {
        matches!(self, Scene::Sky(_) | Scene::Sphere(_))
    }

    /// The addressing the scene's mapping needs, if it needs one: a
    /// lat-long map repeats in s (around the horizon) and clamps in t (at
    /// the poles). `None`: the texture's own.
    pub fn wrap(&self) -> Option<crate::wrap::Wrap> {
        use crate::wrap::{Wrap, WrapMode};
        self.is_environment().then_some(Wrap {
            u: WrapMode::Repeat,
            v: WrapMode::ClampToEdge,
        })
    }

    /// This scene set up for `frame` and a level-0 texture of `tex` texels:
    /// the per-frame constants computed once, for a frame's worth of
    /// [`View::query`] calls (same values as [`Scene::query`]).
    pub fn view(&self, frame: Frame, tex: (u32, u32)) -> View {
        View::new(self, frame, tex, true)
    }

    /// Texture coordinate of the continuous screen position `(x, y)` (in
    /// pixels, row 0 at the top), for a level-0 texture of `tex` texels;
    /// `None` where the scene shows no texture. (Each call sets the scene
    /// up for the frame; [`Scene::view`] does it once.)
    pub fn uv(&self, frame: Frame, tex: (u32, u32), x: f64, y: f64) -> Option<(f64, f64)> {
        View::new(self, frame, tex, false).uv(x, y)
    }

    /// The query of pixel `(px, py)`: the coordinate at its centre and the
    /// central differences over one pixel, or `None` if the centre or a
    /// half-pixel neighbour shows no texture.
    pub fn query(&self, frame: Frame, tex: (u32, u32), px: u32, py: u32) -> Option<Query> {
        self.query_at(frame, tex, px as f64 + 0.5, py as f64 + 0.5)
    }

    /// The query of a pixel centred at `(x, y)` (a pixel's centre plus a
    /// camera offset, for the flicker metric).
    pub fn query_at(&self, frame: Frame, tex: (u32, u32), x: f64, y: f64) -> Option<Query> {
        View::new(self, frame, tex, false).query_at(x, y)
    }

    /// Every pixel that shows texture, in `order`, with its query.
    pub fn queries(
        &self,
        frame: Frame,
        tex: (u32, u32),
        order: RasterOrder,
    ) -> Vec<((u32, u32), Query)> {
        let view = self.view(frame, tex);
        order
            .pixels(frame)
            .filter_map(|(px, py)| view.query(px, py).map(|q| ((px, py), q)))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_bad_names_are_errors() {
        for n in [
            "plane",
            "tunnel",
            "zoom",
            "rotate:30",
            "rotate:12.5:4",
            "sky",
            "sphere",
        ] {
            assert_eq!(n.parse::<Scene>().unwrap().to_string(), n);
        }
        for bad in ["", "rotate", "rotate:x", "rotate:30:0", "plane:3", "cube"] {
            assert!(bad.parse::<Scene>().is_err(), "{bad}");
        }
    }

    #[test]
    fn rotate_has_its_scale_in_texels_per_pixel_everywhere() {
        let s: Scene = "rotate:30:4".parse().unwrap();
        let f = Frame::new(33, 17);
        for (px, py) in [(0, 0), (16, 8), (32, 16)] {
            let q = s.query(f, (256, 128), px, py).unwrap();
            let ax = ((q.dudx * 256.0).hypot(q.dvdx * 128.0)) as f64;
            let ay = ((q.dudy * 256.0).hypot(q.dvdy * 128.0)) as f64;
            assert!(
                (ax - 4.0).abs() < 1e-4 && (ay - 4.0).abs() < 1e-4,
                "{ax} {ay}"
            );
        }
    }

    #[test]
    fn zoom_spans_eight_times_magnification_to_one_256th() {
        let s = Scene::Zoom(Zoom::default());
        let f = Frame::new(1100, 64);
        let rho = |px: u32| {
            let q = s.query(f, (512, 512), px, 32).unwrap();
            (q.dudx as f64 * 512.0).hypot(q.dvdx as f64 * 512.0)
        };
        assert!((rho(0).log2() + 3.0).abs() < 0.01, "{}", rho(0).log2());
        assert!(
            (rho(1099).log2() - 8.0).abs() < 0.01,
            "{}",
            rho(1099).log2()
        );
    }

    #[test]
    fn tunnel_differences_cross_the_seam_the_short_way() {
        let s = Scene::Tunnel(Tunnel::default());
        let f = Frame::new(64, 64);
        // Left of the centre, the seam (angle ±π) runs along the row.
        for py in 0..64 {
            for px in 0..64 {
                if let Some(q) = s.query(f, (64, 64), px, py) {
                    assert!(
                        q.dudx.abs() < 0.5 && q.dudy.abs() < 0.5,
                        "({px}, {py}): {q:?}"
                    );
                }
            }
        }
    }
}
