//! Procedural textures, usable wherever a texture file is
//! (`builtin:checker[:SIZE]`, `builtin:zoneplate[:SIZE]`,
//! `builtin:bumps[:SIZE]`), so every command and test can run without
//! files.
//!
//! - `checker`: an 8×8 board of sRGB RGBA8 squares alternating between two
//!   colours (white and a mid red), square size `SIZE / 8` (at least 1).
//! - `zoneplate`: the circular zone plate `0.5 + 0.5·cos(π·r²/SIZE)` with
//!   `r` measured in texels from the centre, linear RGBA8 grey. Its local
//!   frequency grows linearly with the radius and reaches the Nyquist limit
//!   at the border, so every level of a pyramid shows how much aliasing a
//!   filter lets through.
//! - `bumps`: a normal map (linear RGB8 codes `(n + 1)/2`) of Gaussian
//!   bumps at two scales ([`normals::builtin_bumps`]), for roughness
//!   chains and `parvo render --shade`.
//! - `photo`: a photo-like sRGB RGB8 image: fractal colour noise with
//!   about the same energy in every octave (the 1/f² power spectrum of
//!   natural images), under hard-edged translucent discs, so it has
//!   smooth gradients, fine texture and sharp edges, as photographs do
//!   (the input of the block-compression table; fixed seed, the same for
//!   every run).
//! - `sky`: a lat-long (equirectangular) environment map, `SIZE` wide and
//!   `SIZE / 2` high (y up, directions as [`crate::env::latlong`] maps
//!   them), sRGB RGBA8: a sky darkening from the horizon to the zenith with
//!   a sun disc, soft fractal clouds that wrap around in longitude, thin
//!   meridians every 30° and parallels every 15° that converge on the
//!   pole, and below the horizon a ground plane of unit squares seen from
//!   height 1, whose checker grows finer without end towards the horizon.
//!   Each texel averages 3×3 directions over its cell. The input of the
//!   `sky` and `sphere` scenes ([`crate::scene`]).

pub mod normals;

use crate::error::{Error, Result};
use crate::texel::{ChannelType, ColorSpace, Format};
use crate::texture::Texture;

/// Default size of built-in textures (texels per side).
pub const DEFAULT_SIZE: u32 = 512;

/// Largest accepted built-in size (texels per side).
pub const MAX_SIZE: u32 = 65536;

/// The built-in texture kinds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Builtin {
    /// 8×8 checkerboard.
    Checker,
    /// Circular zone plate.
    ZonePlate,
    /// A normal map of Gaussian bumps.
    Bumps,
    /// A photo-like colour image.
    Photo,
    /// A lat-long environment map (`SIZE × SIZE/2`).
    Sky,
}

/// The width and height of `kind` at `size`: `size × size`, except
/// [`Builtin::Sky`], `size × max(1, size / 2)`.
pub fn dimensions(kind: Builtin, size: u32) -> (u32, u32) {
    match kind {
        Builtin::Sky => (size, (size / 2).max(1)),
        _ => (size, size),
    }
}

/// True if `name` names a built-in texture (starts with `builtin:`).
pub fn is_builtin(name: &str) -> bool {
    name.starts_with("builtin:")
}

/// Parse `builtin:KIND[:SIZE]` and generate the texture.
pub fn load(name: &str) -> Result<Texture> {
    let (kind, size) = parse(name)?;
    generate(kind, size)
}

/// Parse `builtin:KIND[:SIZE]`.
pub fn parse(name: &str) -> Result<(Builtin, u32)> {
    let rest = name
        .strip_prefix("builtin:")
        .ok_or_else(|| Error::parse("built-in texture", name, "must start with `builtin:`"))?;
    let mut parts = rest.split(':');
    let kind = match parts.next().unwrap_or("") {
        "checker" => Builtin::Checker,
        "zoneplate" => Builtin::ZonePlate,
        "bumps" => Builtin::Bumps,
        "photo" => Builtin::Photo,
        "sky" => Builtin::Sky,
        _ => {
            return Err(Error::parse(
                "built-in texture",
                name,
                "known textures: builtin:checker[:SIZE], builtin:zoneplate[:SIZE], builtin:bumps[:SIZE], builtin:photo[:SIZE], builtin:sky[:SIZE]",
            ));
        }
    };
    let size = match parts.next() {
        None => DEFAULT_SIZE,
        Some(s) => s
            .parse::<u32>()
            .ok()
            .filter(|&n| (1..=MAX_SIZE).contains(&n))
            .ok_or_else(|| {
                Error::parse(
                    "built-in texture",
                    name,
                    format!("SIZE must be an integer from 1 to {MAX_SIZE}"),
                )
            })?,
    };
    if parts.next().is_some() {
        return Err(Error::parse(
            "built-in texture",
            name,
            "expected builtin:KIND[:SIZE]",
        ));
    }
    Ok((kind, size))
}

/// Generate a built-in texture of `size × size` texels ([`dimensions`]
/// for the lat-long `sky`).
pub fn generate(kind: Builtin, size: u32) -> Result<Texture> {
    let n = size as usize;
    match kind {
        Builtin::Bumps => normals::builtin_bumps(size),
        Builtin::Photo => photo(size),
        Builtin::Sky => sky(size),
        Builtin::Checker => {
            let cell = (n / 8).max(1);
            let mut v = vec![0u8; n * n * 4];
            for (y, row) in v.chunks_exact_mut(n * 4).enumerate() {
                for (x, t) in row.chunks_exact_mut(4).enumerate() {
                    let on = ((x / cell) + (y / cell)).is_multiple_of(2);
                    t.copy_from_slice(if on {
                        &[255, 255, 255, 255]
                    } else {
                        &[180, 30, 40, 255]
                    });
                }
            }
            Texture::from_u8(
                size,
                size,
                Format::new(4, ChannelType::U8, ColorSpace::Srgb),
                v,
            )
        }
        Builtin::ZonePlate => {
            let mut v = vec![0u8; n * n * 4];
            let c = n as f64 / 2.0;
            let k = std::f64::consts::PI / n as f64;
            for (y, row) in v.chunks_exact_mut(n * 4).enumerate() {
                let dy = y as f64 + 0.5 - c;
                for (x, t) in row.chunks_exact_mut(4).enumerate() {
                    let dx = x as f64 + 0.5 - c;
                    let g = 0.5 + 0.5 * (k * (dx * dx + dy * dy)).cos();
                    let g = (g * 255.0).round() as u8;
                    t.copy_from_slice(&[g, g, g, 255]);
                }
            }
            Texture::from_u8(
                size,
                size,
                Format::new(4, ChannelType::U8, ColorSpace::Linear),
                v,
            )
        }
    }
}

/// A hash of lattice point `(x, y)` of octave `o`, channel `c`, to
/// [-1, 1) (SplitMix64's finaliser).
fn lattice(x: u64, y: u64, o: u64, c: u64) -> f64 {
    let mut z = x
        .wrapping_mul(0x9E37_79B9_7F4A_7C15)
        .wrapping_add(y.wrapping_mul(0xC2B2_AE3D_27D4_EB4F))
        .wrapping_add(o << 40)
        .wrapping_add(c << 56);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

/// The `photo` built-in (see the module docs).
fn photo(size: u32) -> Result<Texture> {
    use rayon::prelude::*;
    let n = size as usize;
    // Octaves from a period of half the image down to 2 texels, with
    // amplitudes falling slowly towards the fine ones (equal amplitudes
    // would be the 1/f² spectrum; interpolated lattice noise puts a little
    // less than its share into the band it is made for).
    let mut periods = Vec::new();
    let mut p = (n as f64 / 2.0).max(2.0);
    while p >= 2.0 {
        periods.push(p);
        p /= 2.0;
    }
    let weight = |p: f64| (p / n as f64).powf(0.15);
    let norm: f64 = periods.iter().map(|&p| weight(p)).sum::<f64>().max(1e-9);
    // Discs: centre, radius, colour (fixed pseudo-random).
    let discs: Vec<([f64; 3], [f64; 3])> = (0..48u64)
        .map(|i| {
            let r = |k: u64| 0.5 + 0.5 * lattice(i, k, 99, 7);
            (
                [
                    r(0) * n as f64,
                    r(1) * n as f64,
                    (0.02 + 0.12 * r(2)) * n as f64,
                ],
                [r(3), r(4), r(5)],
            )
        })
        .collect();
    let smooth = |t: f64| t * t * (3.0 - 2.0 * t);
    let mut v = vec![0u8; n * n * 3];
    v.par_chunks_mut(n * 3).enumerate().for_each(|(y, row)| {
        for (x, t) in row.chunks_exact_mut(3).enumerate() {
            let mut ch = [0f64; 3];
            for (o, &p) in periods.iter().enumerate() {
                let (fx, fy) = (x as f64 / p, y as f64 / p);
                let (ix, iy) = (fx.floor(), fy.floor());
                let (sx, sy) = (smooth(fx - ix), smooth(fy - iy));
                let (ix, iy) = (ix as u64, iy as u64);
                let amp = 1.6 * weight(p) / norm;
                for (c, out) in ch.iter_mut().enumerate() {
                    let g = |dx: u64, dy: u64| lattice(ix + dx, iy + dy, o as u64, c as u64);
                    let top = g(0, 0) + (g(1, 0) - g(0, 0)) * sx;
                    let bot = g(0, 1) + (g(1, 1) - g(0, 1)) * sx;
                    *out += amp * (top + (bot - top) * sy);
                }
            }
            // Luminance and two weaker chroma axes to RGB.
            let (l, a, b) = (0.5 + 0.45 * ch[0], 0.25 * ch[1], 0.25 * ch[2]);
            let mut rgb = [l + a, l - 0.5 * a - 0.3 * b, l + 1.2 * b];
            let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
            for (d, col) in &discs {
                let (dx, dy) = (px - d[0], py - d[1]);
                if dx * dx + dy * dy < d[2] * d[2] {
                    for c in 0..3 {
                        rgb[c] = 0.35 * rgb[c] + 0.65 * col[c];
                    }
                }
            }
            for c in 0..3 {
                t[c] = (rgb[c].clamp(0.0, 1.0) * 255.0).round() as u8;
            }
        }
    });
    Texture::from_u8(
        size,
        size,
        Format::new(3, ChannelType::U8, ColorSpace::Srgb),
        v,
    )
}

/// Linear RGB of the `sky` built-in in unit direction `d` (module docs).
fn sky_radiance(d: [f64; 3], s: f64) -> [f64; 3] {
    let elev = d[1].clamp(-1.0, 1.0).asin();
    if d[1] < 0.0 {
        // The ground: unit squares on the plane y = -1.
        let k = -1.0 / d[1];
        let (gx, gz) = (d[0] * k, d[2] * k);
        let on = ((gx.floor() + gz.floor()) as i64).rem_euclid(2) == 0;
        let haze = (-k / 40.0).exp();
        let c = if on {
            [0.30, 0.24, 0.16]
        } else {
            [0.09, 0.11, 0.06]
        };
        let h = [0.55, 0.62, 0.72];
        return [0, 1, 2].map(|i| c[i] * haze + h[i] * (1.0 - haze));
    }
    let a = (elev / std::f64::consts::FRAC_PI_2).clamp(0.0, 1.0);
    let mut rgb = [
        0.60 + (0.06 - 0.60) * a.sqrt(),
        0.70 + (0.16 - 0.70) * a.sqrt(),
        0.85 + (0.55 - 0.85) * a.sqrt(),
    ];
    // Clouds: value noise periodic in longitude (8 cells around at the
    // coarsest octave), thinning towards the zenith.
    let mut n = 0.0;
    let mut amp = 0.5;
    for o in 0..5u64 {
        let cells = 8u64 << o;
        let (fx, fy) = (s * cells as f64, a * cells as f64 / 4.0);
        let (ix, iy) = (fx.floor(), fy.floor());
        let (tx, ty) = (fx - ix, fy - iy);
        let (tx, ty) = (tx * tx * (3.0 - 2.0 * tx), ty * ty * (3.0 - 2.0 * ty));
        let g = |dx: u64, dy: u64| lattice(((ix as u64) + dx) % cells, iy as u64 + dy, o + 11, 3);
        let top = g(0, 0) + (g(1, 0) - g(0, 0)) * tx;
        let bot = g(0, 1) + (g(1, 1) - g(0, 1)) * tx;
        n += amp * (top + (bot - top) * ty);
        amp *= 0.5;
    }
    let cloud = ((n - 0.05) * 2.5).clamp(0.0, 1.0) * (1.0 - a * a);
    for c in rgb.iter_mut() {
        *c += (0.92 - *c) * cloud;
    }
    // Meridians every 30° and parallels every 15°, about 0.3° wide.
    let lon = (s * 360.0).rem_euclid(30.0);
    let lat = elev.to_degrees().rem_euclid(15.0);
    let width = 0.3 / elev.cos().max(1e-3);
    if lon.min(30.0 - lon) < width || lat.min(15.0 - lat) < 0.3 {
        rgb = [0.05, 0.08, 0.25];
    }
    // The sun: 2° across, 30° up, at s = 0.42.
    let sun = crate::env::latlong::st_to_direction(0.42, 1.0 / 3.0);
    let cos = d[0] * sun[0] + d[1] * sun[1] + d[2] * sun[2];
    if cos > 1f64.to_radians().cos() {
        rgb = [1.0, 0.97, 0.85];
    }
    rgb
}

/// The `sky` built-in (see the module docs).
fn sky(size: u32) -> Result<Texture> {
    use rayon::prelude::*;
    let (w, h) = dimensions(Builtin::Sky, size);
    let (wn, hn) = (w as usize, h as usize);
    let encode = |v: f64| {
        let v = v.clamp(0.0, 1.0);
        let e = if v <= 0.003_130_8 {
            12.92 * v
        } else {
            1.055 * v.powf(1.0 / 2.4) - 0.055
        };
        (e * 255.0).round() as u8
    };
    let mut v = vec![0u8; wn * hn * 4];
    v.par_chunks_mut(wn * 4).enumerate().for_each(|(y, row)| {
        for (x, t) in row.chunks_exact_mut(4).enumerate() {
            let mut acc = [0f64; 3];
            for j in 0..3 {
                for i in 0..3 {
                    let s = (x as f64 + (i as f64 + 0.5) / 3.0) / w as f64;
                    let tt = (y as f64 + (j as f64 + 0.5) / 3.0) / h as f64;
                    let c = sky_radiance(crate::env::latlong::st_to_direction(s, tt), s);
                    for k in 0..3 {
                        acc[k] += c[k] / 9.0;
                    }
                }
            }
            t.copy_from_slice(&[encode(acc[0]), encode(acc[1]), encode(acc[2]), 255]);
        }
    });
    Texture::from_u8(w, h, Format::new(4, ChannelType::U8, ColorSpace::Srgb), v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse_and_bad_names_are_errors() {
        assert_eq!(parse("builtin:checker").unwrap(), (Builtin::Checker, 512));
        assert_eq!(
            parse("builtin:zoneplate:1024").unwrap(),
            (Builtin::ZonePlate, 1024)
        );
        for bad in [
            "builtin:",
            "builtin:checker:0",
            "builtin:checker:x",
            "builtin:nope",
            "checker",
        ] {
            assert!(parse(bad).is_err(), "{bad}");
        }
        let t = load("builtin:checker:16").unwrap();
        assert_eq!((t.width(), t.height()), (16, 16));
        let t = load("builtin:sky:16").unwrap();
        assert_eq!((t.width(), t.height()), (16, 8));
        assert_eq!(
            (t.width(), t.height()),
            dimensions(Builtin::Sky, 16),
            "dimensions() is what generate() makes"
        );
    }
}
