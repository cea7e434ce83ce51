//! The rest of the shading languages' texture calls: explicit level
//! (`textureLod`, WGSL `textureSampleLevel`), bias (`texture(…, bias)`,
//! `textureSampleBias`), gather (`textureGather`), depth comparison
//! (`texture`/`textureGrad`/`textureLod` on a shadow sampler,
//! `textureSampleCompare`), texel load (`texelFetch`, `textureLoad`), and
//! the 2×2 quad a rasterizer has its derivatives from.
//!
//! # Rules (OpenGL 4.6 §8.14–8.23, Vulkan "Texel Filtering")
//! - **Explicit level**: λbase = the given level; the sampler's bias and
//!   clamps apply as for any lookup (λ = clamp(λbase + bias, lodMin,
//!   lodMax)); there is no anisotropy. Magnification when λ ≤ 0.
//! - **Bias**: added to the sampler's bias before the clamp.
//! - **Gather**: component `c` of the four texels a bilinear lookup of
//!   level 0 (the base level) would read, in GL's order
//!   (T_i0j1, T_i1j1, T_i1j0, T_i0j0), j growing with v (row 0 of the image
//!   is v = 0, as the image is uploaded first row first); after wrapping,
//!   a texel outside the level under `border` is the border colour's
//!   component `c`. Values are decoded (sRGB to linear), as GL decodes
//!   before gathering.
//! - **Compare**: channel 0 is the depth D of each texel; each texel the
//!   filter reads gives 1 when `ref OP D` holds, 0 otherwise (the border
//!   colour's channel 0 outside the level under `border`), and the
//!   results are filtered with the sampler's magnification, minification
//!   and mip filters as colours would be. The reference is clamped to
//!   [0, 1] for normalised (integer) textures, as GL clamps it for
//!   fixed-point depth formats, and taken as it is for float textures.
//!   Comparison lookups are isotropic: anisotropy, EWA, the summed-area
//!   table and the supersampled reference do not apply to them (their
//!   mag/min/mip filters do).
//! - **Load**: the texel at an integer position of a level, decoded; no
//!   wrapping, nothing outside the level (`None`).
//! - **Quad**: four positions of a 2×2 pixel quad (top-left, top-right,
//!   bottom-left, bottom-right) with the derivatives a GPU's coarse
//!   `dFdx`/`dFdy` take from them: d/dx = top-right − top-left, d/dy =
//!   bottom-left − top-left, shared by the four pixels.
//!
//! The bilinear taps here are the same arithmetic as the filters' own
//! (`sample/bilinear.rs`): `floor(u·w − ½)` and its fraction in `f64`,
//! after the coordinate is moved into its first wrap period.

use std::fmt;
use std::str::FromStr;

use crate::error::{Error, Result};
use crate::wrap::{fast_floor, reduce_coordinate, wrap_index};

use super::bilinear::split;
use super::fetch::{Addressing, Chain, Level, Pixel};
use super::footprint::{Lod, Plan};
use super::{MipMode, Query, SamplerOptions, TexelFilter};
use crate::trace::NoTrace;

/// A depth comparison function (GL's `GL_TEXTURE_COMPARE_FUNC`, Vulkan's
/// `VkCompareOp`, WGSL's `sampler_comparison`): the texel passes when
/// `reference OP texel` holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CompareOp {
    /// Never passes (0).
    Never,
    /// `reference < texel`.
    Less,
    /// `reference == texel`.
    Equal,
    /// `reference <= texel`.
    LessEqual,
    /// `reference > texel`.
    Greater,
    /// `reference != texel`.
    NotEqual,
    /// `reference >= texel`.
    GreaterEqual,
    /// Always passes (1).
    Always,
}

impl CompareOp {
    /// Every function, in GL's enumeration order.
    pub const ALL: [CompareOp; 8] = [
        CompareOp::Never,
        CompareOp::Less,
        CompareOp::Equal,
        CompareOp::LessEqual,
        CompareOp::Greater,
        CompareOp::NotEqual,
        CompareOp::GreaterEqual,
        CompareOp::Always,
    ];

    /// GL's name without the prefix: `never`, `less`, `equal`, `lequal`,
    /// `greater`, `notequal`, `gequal`, `always`.
    pub fn name(self) -> &'static str {
        match self {
            CompareOp::Never => "never",
            CompareOp::Less => "less",
            CompareOp::Equal => "equal",
            CompareOp::LessEqual => "lequal",
            CompareOp::Greater => "greater",
            CompareOp::NotEqual => "notequal",
            CompareOp::GreaterEqual => "gequal",
            CompareOp::Always => "always",
        }
    }

    /// Whether `reference OP texel` holds (NaN compares false, as IEEE
    /// comparisons do; `never` and `always` ignore the values).
    #[inline(always)]
    pub fn passes(self, reference: f32, texel: f32) -> bool {
        match self {
            CompareOp::Never => false,
            CompareOp::Less => reference < texel,
            CompareOp::Equal => reference == texel,
            CompareOp::LessEqual => reference <= texel,
            CompareOp::Greater => reference > texel,
            CompareOp::NotEqual => reference != texel,
            CompareOp::GreaterEqual => reference >= texel,
            CompareOp::Always => true,
        }
    }
}

impl fmt::Display for CompareOp {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for CompareOp {
    type Err = Error;
    /// GL's names (`lequal`, …), and WGSL's/Vulkan's spelled out
    /// (`less-equal`, `not-equal`, `greater-equal`, with `_` or `-`).
    fn from_str(s: &str) -> Result<Self> {
        let t = s.trim().to_ascii_lowercase().replace('_', "-");
        Ok(match t.as_str() {
            "never" => CompareOp::Never,
            "less" => CompareOp::Less,
            "equal" => CompareOp::Equal,
            "lequal" | "less-equal" | "less-or-equal" => CompareOp::LessEqual,
            "greater" => CompareOp::Greater,
            "notequal" | "not-equal" => CompareOp::NotEqual,
            "gequal" | "greater-equal" | "greater-or-equal" => CompareOp::GreaterEqual,
            "always" => CompareOp::Always,
            _ => {
                return Err(Error::parse(
                    "compare function",
                    s,
                    "expected never, less, equal, lequal, greater, notequal, gequal or always",
                ));
            }
        })
    }
}

/// The four queries of a 2×2 pixel quad at `uv` (top-left, top-right,
/// bottom-left, bottom-right) with the coarse derivatives of the module
/// docs.
pub fn quad_queries(uv: &[[f32; 2]; 4]) -> [Query; 4] {
    let dx = [uv[1][0] - uv[0][0], uv[1][1] - uv[0][1]];
    let dy = [uv[2][0] - uv[0][0], uv[2][1] - uv[0][1]];
    uv.map(|[u, v]| Query::new(u, v, dx[0], dx[1], dy[0], dy[1]))
}

/// The plan of an explicit level: λ = clamp(level + bias, lodMin, lodMax).
pub(crate) fn level_plan(lod: &Lod, o: &SamplerOptions, level: f32) -> Plan {
    let lambda = super::footprint::clamp_lod(level as f64, o);
    match o.mip {
        MipMode::None => Plan {
            magnify: lambda <= 0.0 || lambda.is_nan(),
            ..Plan::MAGNIFY
        },
        mip => Plan::at(lambda, lod.q, mip),
    }
}

/// The plan of a lookup with gradients, isotropic (η = 1), with `bias`
/// added to the sampler's.
pub(crate) fn gradient_plan(lod: &Lod, o: &SamplerOptions, q: &Query, bias: f32) -> Plan {
    let base = 0.5 * super::footprint::log2(lod.rho2(q)) + bias as f64;
    level_plan(lod, o, base as f32)
}

/// Up to four texel indices (`None` = border), their weights, and how
/// many are used.
type Taps = ([Option<(u32, u32)>; 4], [f32; 4], usize);

/// Taps of one texel filter at `(u, v)` (already in the first wrap
/// period) on level `l`: up to four wrapped indices (`None` = border) and
/// their weights, in the bilinear order (i0,j0), (i1,j0), (i0,j1),
/// (i1,j1); nearest has one tap of weight 1.
#[inline]
fn taps<P: Pixel>(l: &Level<P>, filter: TexelFilter, u: f64, v: f64, a: &Addressing) -> Taps {
    let at = |i: i64, j: i64| match (wrap_index(a.wrap.u, i, l.w), wrap_index(a.wrap.v, j, l.h)) {
        (Some(x), Some(y)) => Some((x, y)),
        _ => None,
    };
    match filter {
        TexelFilter::Nearest => {
            let i = fast_floor(u * l.wf);
            let j = fast_floor(v * l.hf);
            ([at(i, j), None, None, None], [1.0, 0.0, 0.0, 0.0], 1)
        }
        TexelFilter::Linear => {
            let (i0, al) = split(u * l.wf - 0.5);
            let (j0, be) = split(v * l.hf - 0.5);
            let (i1, j1) = (i0.wrapping_add(1), j0.wrapping_add(1));
            (
                [at(i0, j0), at(i1, j0), at(i0, j1), at(i1, j1)],
                [
                    (1.0 - al) * (1.0 - be),
                    al * (1.0 - be),
                    (1.0 - al) * be,
                    al * be,
                ],
                4,
            )
        }
    }
}

/// `(u, v)` moved into the first wrap period (NaN read as 0).
#[inline]
fn reduced(a: &Addressing, u: f32, v: f32) -> (f64, f64) {
    (
        reduce_coordinate(u as f64, a.wrap.u),
        reduce_coordinate(v as f64, a.wrap.v),
    )
}

/// Component `comp` (0..=3) of the four texels of the bilinear footprint
/// of level 0 at `(u, v)`, in GL's gather order.
pub(crate) fn gather<P: Pixel>(
    c: &Chain<P>,
    a: &Addressing,
    u: f32,
    v: f32,
    comp: usize,
) -> [f32; 4] {
    let l = &c.levels[0];
    let (u, v) = reduced(a, u, v);
    let (t, _, _) = taps(l, TexelFilter::Linear, u, v, a);
    let comp = comp.min(3);
    let value = |t: Option<(u32, u32)>| match t {
        Some((x, y)) => l.at(&c.lut, 0, x as usize, y as usize, &mut NoTrace)[comp],
        None => a.border[comp],
    };
    // Taps are (i0,j0), (i1,j0), (i0,j1), (i1,j1); GL's order is
    // (i0,j1), (i1,j1), (i1,j0), (i0,j0).
    [value(t[2]), value(t[3]), value(t[1]), value(t[0])]
}

/// The filtered comparison of `reference` against channel 0 of the texels
/// `plan` reads at `(u, v)` (see the module docs).
#[allow(clippy::too_many_arguments)]
pub(crate) fn compare<P: Pixel>(
    c: &Chain<P>,
    a: &Addressing,
    o: &SamplerOptions,
    plan: &Plan,
    u: f32,
    v: f32,
    reference: f32,
    op: CompareOp,
    normalised: bool,
) -> f32 {
    let reference = if normalised {
        reference.clamp(0.0, 1.0)
    } else {
        reference
    };
    let (u, v) = reduced(a, u, v);
    let one = |li: usize, filter: TexelFilter| -> f32 {
        let l = &c.levels[li];
        let (t, w, n) = taps(l, filter, u, v, a);
        let mut sum = 0.0f32;
        for k in 0..n {
            let d = match t[k] {
                Some((x, y)) => l.at(&c.lut, li as u32, x as usize, y as usize, &mut NoTrace)[0],
                None => a.border[0],
            };
            if op.passes(reference, d) {
                sum += w[k];
            }
        }
        sum
    };
    let filter = if plan.magnify { o.mag } else { o.min };
    let hi = one(plan.hi, filter);
    let r = if plan.delta > 0.0 && plan.lo != plan.hi {
        let lo = one(plan.lo, o.min);
        hi * (1.0 - plan.delta) + lo * plan.delta
    } else {
        hi
    };
    // The weights sum to 1 only up to rounding; a shadow lookup's result
    // is a fraction in [0, 1] (never 1.0000001).
    r.min(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn compare_ops_follow_gl_and_parse_every_spelling() {
        for op in CompareOp::ALL {
            assert_eq!(op.name().parse::<CompareOp>().unwrap(), op);
        }
        assert_eq!(
            "LESS_EQUAL".parse::<CompareOp>().unwrap(),
            CompareOp::LessEqual
        );
        assert_eq!(
            "greater-equal".parse::<CompareOp>().unwrap(),
            CompareOp::GreaterEqual
        );
        assert!("lteq".parse::<CompareOp>().is_err());
        // reference OP texel.
        assert!(CompareOp::Less.passes(0.25, 0.5));
        assert!(!CompareOp::Less.passes(0.5, 0.5));
        assert!(CompareOp::LessEqual.passes(0.5, 0.5));
        assert!(CompareOp::Greater.passes(0.75, 0.5));
        assert!(CompareOp::Always.passes(f32::NAN, 0.0));
        assert!(!CompareOp::Equal.passes(f32::NAN, f32::NAN));
    }

    #[test]
    fn quad_derivatives_are_the_coarse_differences() {
        let q = quad_queries(&[[0.1, 0.2], [0.15, 0.21], [0.09, 0.3], [0.2, 0.4]]);
        for x in q {
            assert!((x.dudx - 0.05).abs() < 1e-7 && (x.dvdx - 0.01).abs() < 1e-7);
            assert!((x.dudy + 0.01).abs() < 1e-7 && (x.dvdy - 0.1).abs() < 1e-7);
        }
        assert_eq!((q[3].u, q[3].v), (0.2, 0.4));
    }
}
