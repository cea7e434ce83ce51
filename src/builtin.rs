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
        _ => {
            return Err(Error::parse(
                "built-in texture",
                name,
                "known textures: builtin:checker[:SIZE], builtin:zoneplate[:SIZE], builtin:bumps[:SIZE]",
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
