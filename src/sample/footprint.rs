//! Level of detail and anisotropy (SPEC.md "Level of detail", after the
//! Vulkan specification's "Texel Filtering" and
//! EXT_texture_filter_anisotropic).
//!
//! All of it is computed in `f64`: the derivative lengths in level-0 texels
//! of a query with derivatives of 1e30 on a 65536-texel texture are about
//! 1e35, whose squares overflow `f32` but not `f64`.
//!
//! Defined behaviour at the extremes:
//! - zero derivatives: ρ = 0, η = 1, λ = −∞ before the clamp, so the
//!   magnification filter (or `lod_min` when that is above 0);
//! - any NaN or infinite derivative component: the footprint is taken as
//!   unbounded — both derivative vectors are replaced by an isotropic
//!   footprint of [`UNBOUNDED_TEXELS`] level-0 texels, so λ is 64 before
//!   the clamp, the coarsest level allowed is used, and there is one probe;
//! - finite but huge derivatives (1e30) follow the formulas; they select
//!   the coarsest level like the unbounded case, at constant cost.

use super::{MipMode, Query, SamplerOptions};

/// Size in level-0 texels assumed for a footprint with a NaN or infinite
/// derivative (2^64: beyond every level, so the coarsest level applies).
pub const UNBOUNDED_TEXELS: f64 = 18_446_744_073_709_551_616.0;

/// LOD and anisotropy of one query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Footprint {
    /// ρx: length of the x derivative vector in level-0 texels.
    pub rho_x: f64,
    /// ρy: length of the y derivative vector in level-0 texels.
    pub rho_y: f64,
    /// η = min(ρmax/ρmin, maxAniso) (1 when both are 0, maxAniso when only
    /// ρmin is 0).
    pub eta: f64,
    /// λ = clamp(log2(ρmax/η) + bias, lodMin, lodMax); `λ ≤ 0` means
    /// magnification.
    pub lambda: f32,
    /// Number of anisotropic probes, N = ceil(η).
    pub probes: u32,
    /// The longer derivative vector (dx if ρx ≥ ρy, else dy) in normalized
    /// units per pixel, along which the probes are placed.
    pub major: [f64; 2],
}

/// The query's derivative vectors `(dx, dy)` in normalized units, with the
/// non-finite rule of the module docs applied.
#[inline(always)]
pub(crate) fn derivatives(q: &Query, wf: f64, hf: f64) -> ([f64; 2], [f64; 2]) {
    if q.dudx.is_finite() && q.dvdx.is_finite() && q.dudy.is_finite() && q.dvdy.is_finite() {
        (
            [q.dudx as f64, q.dvdx as f64],
            [q.dudy as f64, q.dvdy as f64],
        )
    } else {
        ([UNBOUNDED_TEXELS / wf, 0.0], [0.0, UNBOUNDED_TEXELS / hf])
    }
}

/// λ = clamp(base + bias, lodMin, lodMax) as `f32` (base may be −∞).
#[inline(always)]
pub(crate) fn clamp_lod(base: f64, o: &SamplerOptions) -> f32 {
    (base + o.lod_bias as f64).clamp(o.lod_min as f64, o.lod_max as f64) as f32
}

/// The footprint of `q` on a texture whose level 0 is `width × height`,
/// with the LOD bias, clamp and maximum anisotropy of `o` (isotropic
/// filters have `max_aniso == 1`, so η = 1 and one probe).
#[inline(always)]
pub fn footprint(q: &Query, width: u32, height: u32, o: &SamplerOptions) -> Footprint {
    let (wf, hf) = (width as f64, height as f64);
    let (dx, dy) = derivatives(q, wf, hf);
    // Squared lengths first (plain products, not the `hypot` library
    // call: the squares of finite f32 derivatives times a u32 size stay far
    // inside the f64 range).
    let rx2 = square_len(dx[0] * wf, dx[1] * hf);
    let ry2 = square_len(dy[0] * wf, dy[1] * hf);
    let (rho_x, rho_y) = (rx2.sqrt(), ry2.sqrt());
    let (max2, rho_max, rho_min, major) = if rx2 >= ry2 {
        (rx2, rho_x, rho_y, dx)
    } else {
        (ry2, rho_y, rho_x, dy)
    };
    let n = o.max_aniso.clamp(1, 16) as f64;
    let eta = if rho_max == 0.0 {
        1.0
    } else if rho_min == 0.0 {
        n
    } else {
        (rho_max / rho_min).min(n)
    };
    // log2(ρmax/η) as ½·log2(ρmax²/η²): for η = 1 this is bit for bit the
    // isotropic path's λ, so aniso with η = 1 equals trilinear exactly.
    let lambda = clamp_lod(0.5 * log2(max2 / (eta * eta)), o);
    Footprint {
        rho_x,
        rho_y,
        eta,
        lambda,
        probes: ceil_small(eta),
        major,
    }
}

/// log2 for the LOD, inlined: exact at powers of two, error below 2e-7
/// elsewhere (GPUs keep 4–8 fractional bits of λ).
///
/// `f64::log2` is a library call (which also spills every live vector
/// register around it) and a polynomial is a long dependent chain; both
/// cost more than the rest of a bilinear lookup. Here: the exponent, plus
/// a linear interpolation in a 1024-entry table of log2 over the mantissa
/// (4 KiB, computed at compile time).
#[inline(always)]
pub(crate) fn log2(x: f64) -> f64 {
    if !(f64::MIN_POSITIVE..=f64::MAX).contains(&x) {
        // 0 (→ −∞), subnormals, ∞, NaN: the library handles them.
        return x.log2();
    }
    let bits = x.to_bits();
    let e = ((bits >> 52) as i64 - 1023) as f64;
    let mant = bits & ((1u64 << 52) - 1);
    let i = (mant >> (52 - LOG2_BITS)) as usize;
    let f = (mant & ((1u64 << (52 - LOG2_BITS)) - 1)) as f64
        * (1.0 / (1u64 << (52 - LOG2_BITS)) as f64);
    let a = LOG2_TABLE[i] as f64;
    let b = LOG2_TABLE[i + 1] as f64;
    e + (a + f * (b - a))
}

const LOG2_BITS: u32 = 10;

/// log2(1 + i/1024), i = 0..=1024.
static LOG2_TABLE: [f32; (1 << LOG2_BITS) + 1] = {
    let mut t = [0f32; (1 << LOG2_BITS) + 1];
    let mut i = 0;
    while i < t.len() {
        t[i] = log2_series(1.0 + i as f64 / (1u64 << LOG2_BITS) as f64) as f32;
        i += 1;
    }
    t
};

/// log2(m) for m in [1, 2] by the atanh series (compile time only).
const fn log2_series(m: f64) -> f64 {
    let (m, e) = if m > std::f64::consts::SQRT_2 {
        (m * 0.5, 1.0)
    } else {
        (m, 0.0)
    };
    // ln m = 2·atanh(s), s = (m − 1)/(m + 1), |s| ≤ 0.1716.
    let s = (m - 1.0) / (m + 1.0);
    let s2 = s * s;
    let mut sum = 0.0;
    let mut term = s;
    let mut k = 1.0;
    while k < 40.0 {
        sum += term / k;
        term *= s2;
        k += 2.0;
    }
    e + 2.0 * sum * std::f64::consts::LOG2_E
}

/// λ of an isotropic filter (`max_aniso == 1`): η = 1, so
/// λ = clamp(½·log2(max(ρx², ρy²)) + bias) — no square roots.
#[inline(always)]
pub(crate) fn isotropic_lambda(q: &Query, wf: f64, hf: f64, o: &SamplerOptions) -> f32 {
    let (dx, dy) = derivatives(q, wf, hf);
    let (ax, ay) = (dx[0] * wf, dx[1] * hf);
    let (bx, by) = (dy[0] * wf, dy[1] * hf);
    let r2 = square_len(ax, ay).max(square_len(bx, by));
    clamp_lod(0.5 * log2(r2), o)
}

/// ceil of η ∈ [1, 16] without the `f64::ceil` library call.
#[inline(always)]
fn ceil_small(eta: f64) -> u32 {
    let t = eta as u32;
    if t as f64 == eta { t } else { t + 1 }
}

#[inline(always)]
fn square_len(a: f64, b: f64) -> f64 {
    a * a + b * b
}

/// Nearest mip level for λ > 0 in a chain of `q + 1` levels:
/// d = ceil(d' + 0.5) − 1 with d' = clamp(λ, 0, q) (at d' = k + 0.5 it
/// picks level k).
#[inline(always)]
pub fn mip_nearest(lambda: f32, q: usize) -> usize {
    // d' ≥ 0, so truncation is floor and ceil(x) − 1 = trunc(x) − [x integral].
    // (i32 conversions are one instruction; usize ones are not.)
    let x = lambda.clamp(0.0, q as f32) + 0.5;
    let t = x as i32;
    let d = t - i32::from(t as f32 == x);
    (d.max(0) as usize).min(q)
}

/// Linear mip levels for λ > 0: `(d_hi, d_lo, δ)` with d_hi = floor(d'),
/// d_lo = min(d_hi + 1, q), δ = d' − d_hi; the result is
/// (1 − δ)·τ\[d_hi\] + δ·τ\[d_lo\].
#[inline(always)]
pub fn mip_linear(lambda: f32, q: usize) -> (usize, usize, f32) {
    let d = lambda.clamp(0.0, q as f32);
    // d ≥ 0: truncation is the floor (and `f32::floor` a library call).
    let h = (d as i32 as usize).min(q);
    (h, (h + 1).min(q), d - h as f32)
}

/// Which levels a lookup at λ reads with mip mode `mip` (λ > 0).
#[inline(always)]
pub(crate) fn levels_for(lambda: f32, q: usize, mip: MipMode) -> (usize, usize, f32) {
    match mip {
        MipMode::None => (0, 0, 0.0),
        MipMode::Nearest => {
            let d = mip_nearest(lambda, q);
            (d, d, 0.0)
        }
        MipMode::Linear => mip_linear(lambda, q),
    }
}
