//! Wrap modes: what an integer texel index outside a level means.
//!
//! All wrapping is done on integer texel indices (after the floor of the
//! continuous coordinate), so a coordinate such as u = 1e6 under `repeat`
//! loses no precision: the index is an `i64` and the modulo is exact.
//! [`wrap_index`] is the single implementation every filter calls; the
//! continuous coordinate's reduction into the first period
//! (`reduce_coordinate`) and a mode's [`period`] live here too, so the
//! samplers and the summed-area table state the rule once.

use std::fmt;
use std::str::FromStr;

use crate::error::{Error, Result};

/// Wrap mode of one axis (SPEC.md "Wrap modes").
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum WrapMode {
    /// `i mod size` (floored): the texture tiles. Alias `periodic`.
    #[default]
    Repeat,
    /// Every other tile is mirrored. Name `mirror`.
    MirroredRepeat,
    /// Indices clamp to the first/last texel. Name `clamp`.
    ClampToEdge,
    /// Indices outside the level read the border colour. Name `border`
    /// (`black` is an alias; the colour itself is a sampler option).
    ClampToBorder,
    /// Mirrored once around the origin, then clamped. Name `mirror-clamp`.
    MirrorClampToEdge,
}

impl WrapMode {
    /// Every mode, in declaration order.
    pub const ALL: [WrapMode; 5] = [
        WrapMode::Repeat,
        WrapMode::MirroredRepeat,
        WrapMode::ClampToEdge,
        WrapMode::ClampToBorder,
        WrapMode::MirrorClampToEdge,
    ];

    /// The stable command-line name.
    pub fn name(self) -> &'static str {
        match self {
            WrapMode::Repeat => "repeat",
            WrapMode::MirroredRepeat => "mirror",
            WrapMode::ClampToEdge => "clamp",
            WrapMode::ClampToBorder => "border",
            WrapMode::MirrorClampToEdge => "mirror-clamp",
        }
    }

    /// The name OpenImageIO / maketx use in the `wrapmodes` attribute.
    pub fn oiio_name(self) -> &'static str {
        match self {
            WrapMode::Repeat => "periodic",
            WrapMode::MirroredRepeat => "mirror",
            WrapMode::ClampToEdge => "clamp",
            WrapMode::ClampToBorder => "black",
            WrapMode::MirrorClampToEdge => "mirror",
        }
    }
}

impl fmt::Display for WrapMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for WrapMode {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        Ok(match s.trim().to_ascii_lowercase().as_str() {
            "repeat" | "periodic" => WrapMode::Repeat,
            "mirror" | "mirrored-repeat" => WrapMode::MirroredRepeat,
            "clamp" | "clamp-to-edge" => WrapMode::ClampToEdge,
            "border" | "black" | "clamp-to-border" => WrapMode::ClampToBorder,
            "mirror-clamp" | "mirror-clamp-to-edge" => WrapMode::MirrorClampToEdge,
            _ => {
                return Err(Error::parse(
                    "wrap mode",
                    s,
                    "expected repeat (periodic), mirror, clamp, border (black) or mirror-clamp",
                ));
            }
        })
    }
}

/// Wrap modes of both axes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct Wrap {
    /// Horizontal (u, x) axis.
    pub u: WrapMode,
    /// Vertical (v, y) axis.
    pub v: WrapMode,
}

impl Wrap {
    /// The same mode on both axes.
    pub const fn both(mode: WrapMode) -> Self {
        Wrap { u: mode, v: mode }
    }
}

impl fmt::Display for Wrap {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.u == self.v {
            write!(f, "{}", self.u)
        } else {
            write!(f, "{},{}", self.u, self.v)
        }
    }
}

impl FromStr for Wrap {
    type Err = Error;
    /// `MODE` for both axes or `MODE,MODE` for u and v.
    fn from_str(s: &str) -> Result<Self> {
        let mut parts = s.split(',');
        let u: WrapMode = parts.next().unwrap_or("").parse()?;
        let v = match parts.next() {
            Some(p) => p.parse()?,
            None => u,
        };
        if parts.next().is_some() {
            return Err(Error::parse(
                "wrap modes",
                s,
                "at most two comma-separated modes",
            ));
        }
        Ok(Wrap { u, v })
    }
}

/// mirror(n) = n for n ≥ 0, −(1 + n) otherwise.
#[inline]
fn mirror(n: i64) -> i64 {
    if n >= 0 { n } else { -(1 + n) }
}

/// Map integer texel index `i` of an axis with `size` texels (size ≥ 1) to
/// an index in `[0, size)`, or `None` for "read the border colour".
#[inline]
pub fn wrap_index(mode: WrapMode, i: i64, size: u32) -> Option<u32> {
    let s = size as i64;
    if (0..s).contains(&i) {
        return Some(i as u32);
    }
    let r = match mode {
        WrapMode::Repeat => i.rem_euclid(s),
        WrapMode::MirroredRepeat => (s - 1) - mirror(i.rem_euclid(2 * s) - s),
        WrapMode::ClampToEdge => i.clamp(0, s - 1),
        WrapMode::ClampToBorder => return None,
        WrapMode::MirrorClampToEdge => mirror(i).clamp(0, s - 1),
    };
    Some(r as u32)
}

/// Floor of a float coordinate as an `i64` index, saturating: NaN maps to
/// 0 and ±Inf or huge values to ±2^62, which every wrap mode handles
/// without overflow.
#[inline]
pub fn floor_index(x: f64) -> i64 {
    const LIM: f64 = (1u64 << 62) as f64;
    if x.is_nan() {
        return 0;
    }
    x.floor().clamp(-LIM, LIM) as i64
}

/// Texels in one period of `mode` on an axis of `size ≥ 1` texels: `size`
/// for `repeat`, `2 · size` for `mirror` (a tile and its mirror image),
/// `None` for the modes that do not repeat. Index `i` and `i + k · period`
/// read the same texel; the summed-area table splits a position into
/// whole periods and a rest with it.
#[inline]
pub fn period(mode: WrapMode, size: i64) -> Option<i64> {
    match mode {
        WrapMode::Repeat => Some(size),
        WrapMode::MirroredRepeat => Some(2 * size),
        _ => None,
    }
}

/// Below this magnitude the truncating cast gives the floor directly.
pub(crate) const FAST: f64 = 4_503_599_627_370_496.0; // 2^52

/// `floor(x)` as an index, saturating like [`floor_index`] (NaN → 0).
///
/// `f64::floor` is a library call on the x86-64 baseline (no SSE4.1
/// `roundsd`); a truncating cast and a compare are a few cycles.
#[inline(always)]
pub(crate) fn fast_floor(x: f64) -> i64 {
    if x.abs() < FAST {
        let i = x as i64;
        i - i64::from((i as f64) > x)
    } else {
        floor_index(x)
    }
}

/// A normalised coordinate moved into the first period of `repeat`
/// (period 1) or `mirror` (period 2), exactly (`x − floor(x)` has no
/// rounding in `f64`), so every level's texel index moves by a whole
/// number of periods and [`wrap_index`] maps it to the same texel; NaN
/// reads as 0, infinities and the other modes pass through.
#[inline(always)]
pub(crate) fn reduce_coordinate(x: f64, mode: WrapMode) -> f64 {
    let x = if x.is_nan() { 0.0 } else { x };
    match mode {
        WrapMode::Repeat if x.is_finite() => x - fast_floor(x) as f64,
        WrapMode::MirroredRepeat if x.is_finite() => x - 2.0 * fast_floor(0.5 * x) as f64,
        _ => x,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Plain restatement of the SPEC formulas.
    fn reference(mode: WrapMode, i: i64, size: i64) -> Option<i64> {
        let m = |n: i64| if n >= 0 { n } else { -(1 + n) };
        let modp = |a: i64, b: i64| ((a % b) + b) % b;
        match mode {
            WrapMode::Repeat => Some(modp(i, size)),
            WrapMode::MirroredRepeat => Some((size - 1) - m(modp(i, 2 * size) - size)),
            WrapMode::ClampToEdge => Some(i.max(0).min(size - 1)),
            WrapMode::ClampToBorder => (0..size).contains(&i).then_some(i),
            WrapMode::MirrorClampToEdge => Some(m(i).max(0).min(size - 1)),
        }
    }

    #[test]
    fn every_mode_matches_the_spec_formula_at_negative_and_large_indices() {
        for mode in WrapMode::ALL {
            for size in [1i64, 2, 3, 5, 8, 13] {
                let extra = [-(1i64 << 40) - 3, (1i64 << 40) + 7, -(1 << 62), 1 << 62];
                for i in (-40..40).chain(extra) {
                    let got = wrap_index(mode, i, size as u32).map(|v| v as i64);
                    assert_eq!(got, reference(mode, i, size), "{mode} i={i} size={size}");
                }
            }
        }
        // Mirrored repeat reflects: -1 -> 0, size -> size-1.
        assert_eq!(wrap_index(WrapMode::MirroredRepeat, -1, 4), Some(0));
        assert_eq!(wrap_index(WrapMode::MirroredRepeat, 4, 4), Some(3));
        assert_eq!(wrap_index(WrapMode::MirroredRepeat, 8, 4), Some(0));
    }

    /// A period moves no index: `i` and `i + k · period` read the same
    /// texel, and the modes without a period have none.
    #[test]
    fn a_period_maps_to_the_same_texel() {
        for mode in WrapMode::ALL {
            for size in [1i64, 2, 3, 7, 16] {
                let Some(p) = period(mode, size) else {
                    assert!(!matches!(mode, WrapMode::Repeat | WrapMode::MirroredRepeat));
                    continue;
                };
                for i in -50..50 {
                    for k in [-3i64, -1, 1, 5] {
                        let a = wrap_index(mode, i, size as u32);
                        assert_eq!(a, wrap_index(mode, i + k * p, size as u32), "{mode} {i}");
                    }
                }
            }
        }
    }

    #[test]
    fn names_round_trip() {
        for s in ["repeat", "mirror", "clamp", "border", "mirror-clamp"] {
            assert_eq!(s.parse::<WrapMode>().unwrap().to_string(), s);
        }
        let w: Wrap = "periodic,clamp".parse().unwrap();
        assert_eq!(w.to_string(), "repeat,clamp");
        assert!("repeat,clamp,clamp".parse::<Wrap>().is_err());
        assert!("bogus".parse::<Wrap>().is_err());
    }
}
