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
    // Plain sqrt, not `hypot` (a library call): the squares of finite f32
    // derivatives times a u32 size stay far inside the f64 range.
    let rho_x = length(dx[0] * wf, dx[1] * hf);
    let rho_y = length(dy[0] * wf, dy[1] * hf);
    let (rho_max, rho_min, major) = if rho_x >= rho_y {
        (rho_x, rho_y, dx)
    } else {
        (rho_y, rho_x, dy)
    };
    let n = o.max_aniso.clamp(1, 16) as f64;
    let eta = if rho_max == 0.0 {
        1.0
    } else if rho_min == 0.0 {
        n
    } else {
        (rho_max / rho_min).min(n)
    };
    let lambda = clamp_lod(log2(rho_max / eta), o);
    Footprint {
        rho_x,
        rho_y,
        eta,
        lambda,
        probes: ceil_small(eta),
        major,
    }
}

/// log2 for the LOD, inlined: exact at powers of two, error below 1e-10
/// elsewhere (GPUs keep 4–8 fractional bits of λ). `f64::log2` is a
/// library call, which also forces every live vector register to be
/// spilled around it; inlined, the whole lookup stays in registers.
#[inline(always)]
pub(crate) fn log2(x: f64) -> f64 {
    if !(x >= f64::MIN_POSITIVE && x <= f64::MAX) {
        // 0 (→ −∞), subnormals, ∞, NaN: the library handles them.
        return x.log2();
    }
    let bits = x.to_bits();
    let mut e = ((bits >> 52) as i64) - 1023;
    let mut m = f64::from_bits((bits & ((1u64 << 52) - 1)) | (1023u64 << 52));
    if m > std::f64::consts::SQRT_2 {
        m *= 0.5;
        e += 1;
    }
    // ln m = 2·atanh(s), s = (m − 1)/(m + 1), |s| ≤ 0.1716.
    let s = (m - 1.0) / (m + 1.0);
    let s2 = s * s;
    let p = s
        * (2.0
            + s2 * (2.0 / 3.0
                + s2 * (2.0 / 5.0 + s2 * (2.0 / 7.0 + s2 * (2.0 / 9.0 + s2 * (2.0 / 11.0))))));
    e as f64 + p * std::f64::consts::LOG2_E
}

/// λ of an isotropic filter (`max_aniso == 1`): η = 1, so
/// λ = clamp(½·log2(max(ρx², ρy²)) + bias) — no square roots.
#[inline(always)]
pub(crate) fn isotropic_lambda(q: &Query, wf: f64, hf: f64, o: &SamplerOptions) -> f32 {
    let (dx, dy) = derivatives(q, wf, hf);
    let (ax, ay) = (dx[0] * wf, dx[1] * hf);
    let (bx, by) = (dy[0] * wf, dy[1] * hf);
    let r2 = (ax * ax + ay * ay).max(bx * bx + by * by);
    clamp_lod(0.5 * log2(r2), o)
}

/// ceil of η ∈ [1, 16] without the `f64::ceil` library call.
#[inline(always)]
fn ceil_small(eta: f64) -> u32 {
    let t = eta as u32;
    if t as f64 == eta { t } else { t + 1 }
}

#[inline(always)]
fn length(a: f64, b: f64) -> f64 {
    (a * a + b * b).sqrt()
}

/// Nearest mip level for λ > 0 in a chain of `q + 1` levels:
/// d = ceil(d' + 0.5) − 1 with d' = clamp(λ, 0, q) (at d' = k + 0.5 it
/// picks level k).
#[inline(always)]
pub fn mip_nearest(lambda: f32, q: usize) -> usize {
    // d' ≥ 0, so truncation is floor and ceil(x) − 1 = trunc(x) − [x integral].
    let x = lambda.clamp(0.0, q as f32) + 0.5;
    let t = x as usize;
    let d = if t as f32 == x { t - 1 } else { t };
    d.min(q)
}

/// Linear mip levels for λ > 0: `(d_hi, d_lo, δ)` with d_hi = floor(d'),
/// d_lo = min(d_hi + 1, q), δ = d' − d_hi; the result is
/// (1 − δ)·τ[d_hi] + δ·τ[d_lo].
#[inline(always)]
pub fn mip_linear(lambda: f32, q: usize) -> (usize, usize, f32) {
    let d = lambda.clamp(0.0, q as f32);
    // d ≥ 0: truncation is the floor (and `f32::floor` a library call).
    let h = (d as usize).min(q);
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
