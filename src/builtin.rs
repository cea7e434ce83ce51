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
//!   bumps at two scales ([`crate::shade::builtin_bumps`]), for roughness
//!   chains and `parvo render --shade`.
//! - `photo`: a photo-like sRGB RGB8 image: fractal colour noise with
//!   about the same energy in every octave (the 1/f² power spectrum of
//!   natural images), under hard-edged translucent discs, so it has
//!   smooth gradients, fine texture and sharp edges, as photographs do
//!   (the input of the block-compression table; fixed seed, the same for
//!   every run).

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
        _ => {
            return Err(Error::parse(
                "built-in texture",
                name,
                "known textures: builtin:checker[:SIZE], builtin:zoneplate[:SIZE], builtin:bumps[:SIZE], builtin:photo[:SIZE]",
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

/// Generate a built-in texture of `size × size` texels.
pub fn generate(kind: Builtin, size: u32) -> Result<Texture> {
    let n = size as usize;
    match kind {
        Builtin::Bumps => crate::shade::builtin_bumps(size),
        Builtin::Photo => photo(size),
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
    }
}
