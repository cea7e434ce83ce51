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
//!
//! The isotropic nearest-mip path does not take the logarithm at all:
//! `Lod` restates SPEC's rounding rule on ρ² (exact at the thresholds).

use crate::wrap::{WrapMode, reduce_coordinate};

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
    if finite(q) {
        (
            [q.dudx as f64, q.dvdx as f64],
            [q.dudy as f64, q.dvdy as f64],
        )
    } else {
        ([UNBOUNDED_TEXELS / wf, 0.0], [0.0, UNBOUNDED_TEXELS / hf])
    }
}

/// True when all four derivatives are finite.
#[inline(always)]
fn finite(q: &Query) -> bool {
    q.dudx.is_finite() && q.dvdx.is_finite() && q.dudy.is_finite() && q.dvdy.is_finite()
}

/// λ = clamp(base + bias, lodMin, lodMax) as `f32` (base may be −∞).
#[inline(always)]
pub(crate) fn clamp_lod(base: f64, o: &SamplerOptions) -> f32 {
    (base + o.lod_bias as f64).clamp(o.lod_min as f64, o.lod_max as f64) as f32
}

/// The footprint of `q` on a texture whose level 0 is `width × height`,
/// with the LOD bias, clamp and maximum anisotropy of `o` (isotropic
/// filters have `max_aniso == 1`, so η = 1 and one probe).
#[inline]
pub fn footprint(q: &Query, width: u32, height: u32, o: &SamplerOptions) -> Footprint {
    footprint_f64(q, width as f64, height as f64, o)
}

/// [`footprint`] with the level-0 size as `f64`.
#[inline(always)]
pub(crate) fn footprint_f64(q: &Query, wf: f64, hf: f64, o: &SamplerOptions) -> Footprint {
    let (dx, dy) = derivatives(q, wf, hf);
    // Squared lengths first (plain products, not the `hypot` library
    // call: the squares of finite f32 derivatives times a u32 size stay far
    // inside the f64 range).
    let (rx2, ry2) = if finite(q) {
        (
            square_len(dx[0] * wf, dx[1] * hf),
            square_len(dy[0] * wf, dy[1] * hf),
        )
    } else {
        // The unbounded footprint, exactly UNBOUNDED_TEXELS texels (as
        // `Lod::rho2` has it).
        (UNBOUNDED_RHO2, UNBOUNDED_RHO2)
    };
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
    // isotropic path's λ (`Lod::lambda`), so aniso with η = 1 equals
    // trilinear exactly.
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

/// log2 for the LOD, inlined: exact at powers of two, error below 2.5e-8
/// elsewhere (GPUs keep 4–8 fractional bits of λ), and never above k for
/// x below 2^k.
///
/// `f64::log2` is a library call (which also spills every live vector
/// register around it). Here: the exponent, plus a quartic in the
/// mantissa's position within one of 8 equal intervals of [1, 2), with the
/// interval's coefficients from [`LOG2_POLY`]. The vector path looks the
/// coefficients up with one in-register permute per table (5 tables of 8)
/// and evaluates the same operations in the same order, so both give the
/// same bits.
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
    let c = &LOG2_POLY;
    // Estrin's scheme: a shorter dependency chain than Horner's rule.
    let f2 = f * f;
    let p = (c[0][i] + c[1][i] * f) + f2 * ((c[2][i] + c[3][i] * f) + c[4][i] * f2);
    // Rounding lifts p up to about 35 ulps above 1 just below the next
    // power of two; capped, log2 never passes that power's exact value, so
    // λ is never positive for ρ < 1 at zero bias (p ≥ 0 holds without a
    // cap).
    e + if p < 1.0 { p } else { 1.0 }
}

/// The mantissa's intervals: 2^`LOG2_BITS` of them.
pub(crate) const LOG2_BITS: u32 = 3;

/// `LOG2_POLY[k][i]`: coefficient of f^k of interval i, where
/// log2(1 + (i + f)/8) ≈ Σ c_k·f^k for f in [0, 1]. Each quartic
/// interpolates log2 at the five Chebyshev–Lobatto points of its interval
/// (computed at compile time): the end points are among them, so
/// neighbouring intervals meet (to within 1.4e-14: the expanded
/// coefficients round), c₀ of interval 0 is exactly 0 (log2 of a power of
/// two is its exponent) and the error stays below 2.5e-8.
pub(crate) static LOG2_POLY: [[f64; 1 << LOG2_BITS]; 5] = {
    const N: usize = 5;
    let h = std::f64::consts::FRAC_1_SQRT_2 / 2.0;
    let nodes = [0.0, 0.5 - h, 0.5, 0.5 + h, 1.0];
    let n = 1usize << LOG2_BITS;
    let mut t = [[0f64; 1 << LOG2_BITS]; N];
    let mut i = 0;
    while i < n {
        // Lagrange form Σ y_k·L_k(f), expanded into powers of f.
        let mut coef = [0f64; N];
        let mut k = 0;
        while k < N {
            let y = log2_series(1.0 + (i as f64 + nodes[k]) / n as f64);
            // L_k(f) = Π_{j≠k} (f − f_j)/(f_k − f_j), built up one factor
            // at a time (poly[d] is the coefficient of f^d).
            let mut poly = [0f64; N];
            poly[0] = 1.0;
            let mut den = 1.0;
            let mut j = 0;
            while j < N {
                if j != k {
                    let mut d = N - 1;
                    while d > 0 {
                        poly[d] = poly[d - 1] - nodes[j] * poly[d];
                        d -= 1;
                    }
                    poly[0] = -nodes[j] * poly[0];
                    den *= nodes[k] - nodes[j];
                }
                j += 1;
            }
            let mut d = 0;
            while d < N {
                coef[d] += y * poly[d] / den;
                d += 1;
            }
            k += 1;
        }
        let mut d = 0;
        while d < N {
            t[d][i] = coef[d];
            d += 1;
        }
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

/// What an isotropic lookup (or one anisotropic probe) reads: the
/// magnification filter on level 0, or the minification filter on level
/// `hi` blended with level `lo` by `delta` (one level when `delta` is 0 or
/// `lo == hi`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Plan {
    pub magnify: bool,
    pub hi: usize,
    pub lo: usize,
    pub delta: f32,
}

impl Plan {
    /// Magnification: level 0 only.
    pub const MAGNIFY: Plan = Plan {
        magnify: true,
        hi: 0,
        lo: 0,
        delta: 0.0,
    };

    /// The plan for λ with mip mode `mip` in a chain whose last level is
    /// `q` (SPEC "Level of detail").
    #[inline(always)]
    pub fn at(lambda: f32, q: usize, mip: MipMode) -> Plan {
        // λ is never NaN (see `footprint`); the guard costs nothing.
        if lambda <= 0.0 || lambda.is_nan() {
            return Plan::MAGNIFY;
        }
        let (hi, lo, delta) = levels_for(lambda, q, mip);
        Plan {
            magnify: false,
            hi,
            lo,
            delta,
        }
    }
}

/// ρ² of an isotropic footprint with a NaN or infinite derivative:
/// [`UNBOUNDED_TEXELS`]².
const UNBOUNDED_RHO2: f64 = UNBOUNDED_TEXELS * UNBOUNDED_TEXELS;

/// 2^x, exact when `x` is an integer (so thresholds at whole and half
/// LODs are exact), 0 or ∞ beyond the `f64` range. Setup only.
fn exp2_split(x: f64) -> f64 {
    let i = x.floor();
    let i = i.clamp(-1100.0, 1100.0);
    (x - i).clamp(0.0, 1.0).exp2() * 2f64.powi(i as i32)
}

/// The LOD rules of one sampler, prepared once: level-0 size, bias and
/// clamp, and the same rules restated on ρ² for the nearest-mip path.
///
/// # λ without a logarithm (nearest mip mode)
/// λ' = ½·log2(ρ²) + bias = ½·log2(y) with y = ρ²·4^bias, and the clamp
/// to [lodMin, lodMax] is a clamp of y to [4^lodMin, 4^lodMax]. Then with
/// c = ceil(log2 y) (the exponent of y, plus one unless y is a power of
/// two): λ ≤ 0 ⟺ c ≤ 0, and λ ∈ (k − ½, k + ½] ⟺ c ∈ {2k, 2k + 1}, so
/// SPEC's nearest level d = ceil(d' + ½) − 1 is ⌊c/2⌋ clamped to [0, q].
/// At the thresholds themselves (λ = k + ½, i.e. y = 2^(2k+1)) y is an
/// exact power of two whenever the bias and clamps are multiples of ½, so
/// the rounding rule is exact there; elsewhere the answer differs from
/// the logarithm route only by the rounding of one product.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Lod {
    /// Level-0 width and height.
    pub wf: f64,
    pub hf: f64,
    /// Last level index.
    pub q: usize,
    /// 4^bias (clamped so that 0·4^bias stays 0 and ∞ stays ∞).
    pub scale: f64,
    /// 4^lodMin and 4^lodMax.
    pub y_min: f64,
    pub y_max: f64,
    /// The same clamp narrowed to [1, 4^q]: y clamped to these bounds
    /// gives c ∈ [0, 2q], so the nearest level is ⌊c/2⌋ with no clamp of
    /// its own (the vector path's route to the same level; lodMin ≤ lodMax
    /// makes the two clamps nest).
    pub near_min: f64,
    pub near_max: f64,
    /// Wrap modes, for [`Lod::reduce`].
    pub wrap_u: WrapMode,
    pub wrap_v: WrapMode,
}

impl Lod {
    /// Prepare the rules of `o` for a chain of `levels` levels whose level
    /// 0 is `wf × hf`.
    pub fn new(o: &SamplerOptions, wf: f64, hf: f64, levels: usize) -> Lod {
        let q = levels - 1;
        let (y_min, y_max) = (
            exp2_split(2.0 * o.lod_min as f64),
            exp2_split(2.0 * o.lod_max as f64),
        );
        let top = 2f64.powi(2 * q as i32);
        Lod {
            wf,
            hf,
            q,
            scale: exp2_split(2.0 * o.lod_bias as f64).clamp(2f64.powi(-1000), 2f64.powi(1000)),
            y_min,
            y_max,
            near_min: y_min.clamp(1.0, top),
            near_max: y_max.clamp(1.0, top),
            wrap_u: o.wrap.u,
            wrap_v: o.wrap.v,
        }
    }

    /// ρmax² = max(ρx², ρy²) in level-0 texels, [`UNBOUNDED_TEXELS`]² when
    /// a derivative is NaN or infinite (the rule of the module docs).
    #[inline(always)]
    pub fn rho2(&self, q: &Query) -> f64 {
        let (ax, ay) = (q.dudx as f64 * self.wf, q.dvdx as f64 * self.hf);
        let (bx, by) = (q.dudy as f64 * self.wf, q.dvdy as f64 * self.hf);
        let rx2 = square_len(ax, ay);
        let ry2 = square_len(bx, by);
        // Finite f32 derivatives times a u32 size square far inside the
        // f64 range, so the sum is finite exactly when all four are.
        if (rx2 + ry2).is_nan() || rx2 + ry2 > f64::MAX {
            return UNBOUNDED_RHO2;
        }
        // Not `f64::max`: neither is NaN here, and a plain compare is one
        // instruction.
        if rx2 >= ry2 { rx2 } else { ry2 }
    }

    /// λ of an isotropic filter (`max_aniso == 1`): η = 1, so
    /// λ = clamp(½·log2(ρmax²) + bias) — the same arithmetic as
    /// [`footprint`] with η = 1, so anisotropic filtering of an isotropic
    /// footprint equals the isotropic filter bit for bit.
    #[inline(always)]
    pub fn lambda(&self, q: &Query, o: &SamplerOptions) -> f32 {
        clamp_lod(0.5 * log2(self.rho2(q)), o)
    }

    /// y = clamp(ρmax²·4^bias, 4^lodMin, 4^lodMax) (never NaN).
    #[inline(always)]
    fn y(&self, q: &Query) -> f64 {
        let y = self.rho2(q) * self.scale;
        let y = if y < self.y_min { self.y_min } else { y };
        if y > self.y_max { self.y_max } else { y }
    }

    /// The nearest-mip plan of an isotropic footprint, without a logarithm
    /// (see the type docs).
    #[inline(always)]
    pub fn plan_nearest(&self, q: &Query) -> Plan {
        // y ≥ 0, so its bits order like the value; adding the mantissa
        // mask carries into the exponent exactly when y is not a power of
        // two: the exponent field is then c + 1023.
        let e = ((self.y(q).to_bits() + ((1u64 << 52) - 1)) >> 52) as i64;
        let c = e - 1023;
        let d = ((c >> 1).max(0) as usize).min(self.q);
        Plan {
            magnify: c <= 0,
            hi: d,
            lo: d,
            delta: 0.0,
        }
    }

    /// Magnification or minification, both on level 0 (mip mode none).
    #[inline(always)]
    pub fn plan_level0(&self, q: &Query) -> Plan {
        let y = self.y(q);
        Plan {
            magnify: y <= 1.0,
            ..Plan::MAGNIFY
        }
    }

    /// `(u, v)` moved into the first period of the `repeat` (or `mirror`)
    /// wrap mode of each axis, exactly: for an `f32` coordinate `u − k`
    /// (k an integer, or an even integer for `mirror`) has no rounding in
    /// `f64`, and every level's texel index moves by a whole number of
    /// periods. After it, only footprints that really cross an edge take
    /// the wrapping path. NaN reads as 0; infinite coordinates stay as
    /// they are (and saturate later).
    #[inline(always)]
    pub fn reduce(&self, q: &Query) -> (f64, f64) {
        (reduce(q.u, self.wrap_u), reduce(q.v, self.wrap_v))
    }
}

#[inline(always)]
fn reduce(x: f32, mode: WrapMode) -> f64 {
    reduce_coordinate(x as f64, mode)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against the library log2 over [1, 2) on a dense grid and with
    /// exponents from the whole normal range: error below 2.5e-8.
    #[test]
    fn log2_is_close_to_the_library() {
        let mut worst = 0f64;
        let n = 1 << 18;
        for k in 0..n {
            let m = 1.0 + (k as f64 + 0.37) / n as f64;
            for e in [-1000, -3, 0, 1, 17, 1000] {
                let x = m * 2f64.powi(e);
                worst = worst.max((log2(x) - x.log2()).abs());
            }
        }
        assert!(worst < 2.5e-8, "worst error {worst:e}");
    }

    /// log2(2^k) = k exactly, so λ lands exactly on k at ρ = 2^k and on
    /// k + 0.5 at ρ² = 2^(2k+1).
    #[test]
    fn log2_is_exact_at_powers_of_two() {
        for k in -1022..=1023 {
            assert_eq!(log2(2f64.powi(k)), k as f64, "2^{k}");
        }
    }

    /// Never above k just below 2^k (so λ ≤ 0, magnification, whenever
    /// ρ < 1 at zero bias), and non-decreasing on a grid of [1, 2] (not at
    /// the last bit: at the joins of the intervals the pieces meet only to
    /// within 1.4e-14).
    #[test]
    fn log2_stays_below_the_next_power_of_two() {
        for k in -1021..=1023 {
            let below = f64::from_bits(2f64.powi(k).to_bits() - 1);
            for x in [below, f64::from_bits(below.to_bits() - 1)] {
                assert!(log2(x) <= k as f64, "{x:e}");
            }
        }
        let xs: Vec<f64> = (0..=200_000).map(|k| 1.0 + k as f64 / 200_000.0).collect();
        for w in xs.windows(2) {
            assert!(log2(w[0]) <= log2(w[1]), "{} {}", w[0], w[1]);
        }
    }

    #[test]
    fn log2_hands_the_rest_to_the_library() {
        assert_eq!(log2(0.0), f64::NEG_INFINITY);
        assert_eq!(log2(f64::INFINITY), f64::INFINITY);
        assert!(log2(f64::NAN).is_nan());
        let sub = f64::MIN_POSITIVE / 4.0;
        assert_eq!(log2(sub), sub.log2());
    }
}
