//! Elliptical weighted average (Greene & Heckbert 1986; Heckbert 1989;
//! pbrt's `MIPMap::EWA`), the high-quality reference filter (SPEC.md
//! "EWA").
//!
//! 1. The pixel's footprint ellipse is `{J·p : |p| ≤ 1}` with `J` the two
//!    derivative vectors (level-0 texels) as columns. Its principal
//!    semi-axes are the square roots of the eigenvalues of `J·Jᵀ` (this
//!    handles collinear and zero derivative pairs, where the shorter
//!    *derivative vector* would not be the minor axis).
//! 2. The minor axis is lengthened to at least `major / max_aniso`, which
//!    also gives zero and collinear pairs a proper ellipse.
//! 3. λ = log2(minor) + bias, clamped; the two nearest levels are filtered
//!    and blended linearly (`mip = none` uses level 0 only, `nearest` the
//!    nearest level).
//! 4. In each level (per-axis scale `w_k / w_0`, `h_k / h_0`) the unit
//!    reconstruction variance is added, `Σ = J'J'ᵀ + I`, giving SPEC's
//!    `A = Σtt, B = −2Σst, C = Σss` divided by `F = AC − B²/4`. Texels
//!    with `r² = A·s² + B·s·t + C·t² < 1` get weight `exp(−2r²) − exp(−2)`;
//!    the result is `Σ w·τ / Σ w`. Because Σ ≥ I the ellipse always
//!    contains a texel centre, so `Σ w > 0`.
//!
//! # Speed
//! The weights are a degree-6 polynomial of r² (within 1.4·10⁻⁶ of
//! `exp(−2r²) − exp(−2)`; pbrt uses a 128-entry table for the same
//! purpose; a table measured slower here), r² is stepped along each run by
//! its first and second differences; runs go along rows or down columns,
//! whichever is longer for the ellipse (a grazing plane's ellipses run
//! along v, and the per-run setup is the cost of short runs); runs that lie
//! inside the level are read straight from memory (no wrapping per
//! texel), texels alternating between two sets of `f32` sums; the bounds
//! of each run are solved eight runs at a time. On CPUs with AVX2 and FMA
//! the same code is compiled for them with fused multiply-adds (so the
//! last bits differ from the portable build). Lookups are set up in
//! blocks of 16 (ellipse, λ, levels and their quadratic forms for every
//! query of the block) before any texel is read. On CPUs with AVX-512 (F,
//! BW, DQ, VL, VBMI), lookups of packed RGBA8 chains (traced or not)
//! solve 16 lines at a time, sweep the rows of an ellipse taller than
//! wide instead of gathering down its columns, stage the texels end to
//! end and sum them 16 at a time (`ewa_simd.rs`;
//! [`super::Sampler::set_simd`] and `PARVO_NO_AVX` turn it off). `ewa_exact` (public as
//! [`super::Sampler::sample_ewa_exact`]) keeps the plain form (`exp` per
//! texel, every fetch wrapped, `f64` sums): the reference the tests hold
//! both paths to (within 1e-3).
//!
//! # Bounded work
//! Rows are scanned only over the span where `r² < 1` (solved per row),
//! so the cost is the ellipse's area, not its bounding box. With λ chosen
//! from the minor axis, the finer level sees a minor semi-axis below 2
//! texels and a major one below `2·max_aniso`. When the LOD clamp, a
//! negative bias, `mip = none` or the end of the chain forces a finer level
//! than that, the ellipse at that level is shrunk uniformly so that its
//! larger semi-axis is at most [`MAX_RADIUS`] texels: the result then
//! aliases (as a GPU's would) instead of scanning millions of texels. A
//! 1×1 level without border wrapping is read once (every texel of the
//! ellipse is the same texel). So a query reads at most about
//! 2·π·(MAX_RADIUS + 1)² texels.

use crate::wrap::{WrapMode, fast_floor};

use super::bilinear::split;
use super::fetch::{Addressing, Chain, Pixel, lerp};
use super::footprint::{Lod, clamp_lod, derivatives, levels_for, log2};
use super::{Query, SamplerOptions};
use crate::trace::TexelSink;

/// Largest semi-axis, in texels of the level being filtered, that EWA
/// scans; larger ellipses are shrunk (see the module docs).
pub const MAX_RADIUS: f64 = 40.0;

/// Gaussian falloff α of the EWA weight `exp(−α·r²) − exp(−α)`.
const ALPHA: f64 = 2.0;

/// EWA lookups of `queries` into `out` (the fast path, see the module
/// docs): the same code compiled for AVX2 and FMA when the CPU has them
/// (fused multiply-adds there, so results differ from the portable build
/// in the last bits).
///
/// With `avx512` (the sampler's AVX-512 table exists: the CPU has AVX-512
/// F, BW, DQ, VL and VBMI and `PARVO_NO_AVX` is unset) lookups of a
/// packed RGBA8 chain sum their texels with `ewa_simd.rs` (traced or not:
/// both give the same result, bit for bit).
#[allow(clippy::too_many_arguments)]
pub(crate) fn ewa_slice<P: Pixel, S: TexelSink>(
    c: &Chain<P>,
    a: &Addressing,
    lod: &Lod,
    o: &SamplerOptions,
    queries: &[Query],
    out: &mut [[f32; 4]],
    sink: &mut S,
    avx512: bool,
) {
    #[cfg(target_arch = "x86_64")]
    {
        // `P::PACKED_RGBA8` first: a constant, so the AVX-512 kernel is
        // not compiled for the storages it never reads.
        if P::PACKED_RGBA8 && avx512 && vector_texels(c) {
            #[allow(unsafe_code)]
            // SAFETY: the caller's `avx512` says the CPU has AVX-512 F, BW,
            // DQ, VL and VBMI; every AVX-512 CPU also has AVX2 and FMA.
            return unsafe { ewa_avx512(c, a, lod, o, queries, out, sink) };
        }
        if crate::cpu::avx2_fma() {
            #[allow(unsafe_code)]
            // SAFETY: `avx2_fma()` checked that the CPU has AVX2 and FMA,
            // the only features `ewa_avx2` is compiled for.
            return unsafe { ewa_avx2(c, a, lod, o, queries, out, sink) };
        }
    }
    let _ = avx512;
    blocks::<P, S, false, false>(c, a, lod, o, queries, out, sink)
}

/// True when `c`'s texels are packed RGBA8 with one decode table for the
/// colour channels: what [`super::ewa_simd`] reads.
#[inline(always)]
fn vector_texels<P: Pixel>(c: &Chain<P>) -> bool {
    std::mem::size_of::<P>() == 4 && P::packed(&c.lut).is_some_and(|l| l.shared)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi")]
fn ewa_avx512<P: Pixel, S: TexelSink>(
    c: &Chain<P>,
    a: &Addressing,
    lod: &Lod,
    o: &SamplerOptions,
    queries: &[Query],
    out: &mut [[f32; 4]],
    sink: &mut S,
) {
    blocks::<P, S, true, true>(c, a, lod, o, queries, out, sink)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn ewa_avx2<P: Pixel, S: TexelSink>(
    c: &Chain<P>,
    a: &Addressing,
    lod: &Lod,
    o: &SamplerOptions,
    queries: &[Query],
    out: &mut [[f32; 4]],
    sink: &mut S,
) {
    blocks::<P, S, true, false>(c, a, lod, o, queries, out, sink)
}

/// Queries set up together before their texels are read.
const BLOCK: usize = 16;

/// The fast path in two passes per block of [`BLOCK`] queries: first
/// every query's setup (its ellipse, levels and their quadratic forms:
/// long chains of dependent arithmetic, independent between queries, so
/// they overlap), then each query's texels.
#[inline(always)]
fn blocks<P: Pixel, S: TexelSink, const FMA: bool, const VEC: bool>(
    c: &Chain<P>,
    a: &Addressing,
    lod: &Lod,
    o: &SamplerOptions,
    queries: &[Query],
    out: &mut [[f32; 4]],
    sink: &mut S,
) {
    // One query (`Sampler::sample`): no block of set-ups to fill.
    if let ([q], [out]) = (queries, &mut *out) {
        *out = read::<P, S, false, FMA, VEC>(c, a, &setup(c, a, lod, o, q), sink);
        return;
    }
    let mut setups = [Setup::NONE; BLOCK];
    for (qs, os) in queries.chunks(BLOCK).zip(out.chunks_mut(BLOCK)) {
        for (q, st) in qs.iter().zip(setups.iter_mut()) {
            *st = setup(c, a, lod, o, q);
        }
        for (st, o) in setups.iter().zip(os.iter_mut()) {
            *o = read::<P, S, false, FMA, VEC>(c, a, st, sink);
        }
    }
}

/// EWA with the weights computed by `exp` per texel, every fetch wrapped
/// and `f64` sums: the reference the fast path is tested against.
pub(crate) fn ewa_exact<P: Pixel, S: TexelSink>(
    c: &Chain<P>,
    a: &Addressing,
    lod: &Lod,
    o: &SamplerOptions,
    q: &Query,
    sink: &mut S,
) -> [f32; 4] {
    let st = setup(c, a, lod, o, q);
    read::<P, S, true, false, false>(c, a, &st, sink)
}

/// What one lookup reads: one or two levels, blended by `delta`.
#[derive(Clone, Copy)]
struct Setup {
    levels: [LevelSetup; 2],
    two: bool,
    delta: f32,
}

/// One level of a lookup: level `k`, read once at texel (0, 0) when
/// `single`, else its ellipse `Σ = (Σss, Σst, Σtt)` (SPEC's `A, B, C`
/// over `F` in `q`) centred at `base + frac` in texel-centre coordinates.
#[derive(Clone, Copy)]
struct LevelSetup {
    k: usize,
    single: bool,
    sigma: (f64, f64, f64),
    q: (f64, f64, f64),
    base: (i64, i64),
    frac: (f64, f64),
}

impl Setup {
    const NONE: Setup = Setup {
        levels: [LevelSetup {
            k: 0,
            single: true,
            sigma: (1.0, 0.0, 1.0),
            q: (1.0, 0.0, 1.0),
            base: (0, 0),
            frac: (0.0, 0.0),
        }; 2],
        two: false,
        delta: 0.0,
    };
}

/// The levels and ellipses lookup `q` reads (steps 1–3 of the module
/// docs, and step 4 up to the texels).
#[inline(always)]
fn setup<P: Pixel>(
    c: &Chain<P>,
    a: &Addressing,
    lod: &Lod,
    o: &SamplerOptions,
    q: &Query,
) -> Setup {
    let (u, v) = lod.reduce(q);
    let (dx, dy) = derivatives(q, lod.wf, lod.hf);
    let levels = &c.levels[..];
    let (w0, h0) = (levels[0].wf, levels[0].hf);
    // Derivative vectors in level-0 texels.
    let j = [dx[0] * w0, dx[1] * h0, dy[0] * w0, dy[1] * h0];
    let (axes, hi, lo, delta) = lengthened_ellipse(j, o, lod.q);
    let two = delta > 0.0 && lo != hi;
    Setup {
        levels: [
            level_setup(c, hi, a, &axes, u, v),
            level_setup(c, if two { lo } else { hi }, a, &axes, u, v),
        ],
        two,
        delta,
    }
}

/// Steps 1–3 of the module docs for derivative vectors `j = [ax, ay, bx,
/// by]` in level-0 texels: the lengthened ellipse, and the levels read
/// (`hi`, `lo`, the blend `delta`) in a chain whose last level is `last`.
#[inline(always)]
pub(crate) fn lengthened_ellipse(
    j: [f64; 4],
    o: &SamplerOptions,
    last: usize,
) -> (Axes, usize, usize, f32) {
    let [ax, ay, bx, by] = j;
    // M = J·Jᵀ.
    let mss = ax * ax + bx * bx;
    let mst = ax * ay + bx * by;
    let mtt = ay * ay + by * by;
    let mean = 0.5 * (mss + mtt);
    // (The squares of finite derivatives in texels stay far inside the
    // f64 range, so plain square roots need no `hypot`.)
    let hd = 0.5 * (mss - mtt);
    let r = (hd * hd + mst * mst).sqrt();
    // Squared semi-axes (the eigenvalues of M) and the major axis
    // direction as the products of its unit vector's components: the
    // eigenvector of λ₁ = mean + r, from whichever row of M − λ₁I is the
    // better conditioned (no trigonometry, no further square roots).
    let major2 = (mean + r).max(0.0);
    let minor0_2 = (mean - r).max(0.0);
    let (exx, eyy, exy) = if r > 0.0 {
        let (vx, vy) = if mss >= mtt {
            (hd + r, mst)
        } else {
            (mst, r - hd)
        };
        let inv = 1.0 / (vx * vx + vy * vy);
        (vx * vx * inv, vy * vy * inv, vx * vy * inv)
    } else {
        (1.0, 0.0, 0.0)
    };
    let aniso = o.max_aniso.clamp(1, 16) as f64;
    let minor2 = minor0_2.max(major2 / (aniso * aniso));
    // log2(minor) = log2(minor²) / 2.
    let lambda = clamp_lod(0.5 * log2(minor2), o);
    let (hi, lo, delta) = if lambda > 0.0 {
        levels_for(lambda, last, o.mip)
    } else {
        (0, 0, 0.0)
    };
    // The lengthened ellipse's J·Jᵀ = major²·e·eᵀ + minor²·e⊥·e⊥ᵀ.
    let axes = Axes {
        xx: major2 * exx + minor2 * eyy,
        xy: (major2 - minor2) * exy,
        yy: major2 * eyy + minor2 * exx,
    };
    (axes, hi, lo, delta)
}

/// One level's ellipse (step 4 of the module docs): `Σ = J'J'ᵀ + I` in
/// the level's texels (per-axis scale `sx`, `sy` from level 0), shrunk to
/// [`MAX_RADIUS`], and SPEC's `(A, B, C)/F`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Form {
    /// `(Σss, Σst, Σtt)`.
    pub sigma: (f64, f64, f64),
    /// `(A, B, C)/F`: `r² = A·s² + B·s·t + C·t²`.
    pub q: (f64, f64, f64),
}

/// The [`Form`] of `axes` on a level scaled by `(sx, sy)` from level 0.
#[inline(always)]
pub(crate) fn level_form(axes: &Axes, sx: f64, sy: f64) -> Form {
    // J'·J'ᵀ in this level's texels; its trace is the sum of the squared
    // semi-axes.
    let (mut sxx, mut sxy, mut syy) = (axes.xx * sx * sx, axes.xy * sx * sy, axes.yy * sy * sy);
    let size2 = sxx + syy;
    if size2 > MAX_RADIUS * MAX_RADIUS {
        let f = MAX_RADIUS * MAX_RADIUS / size2;
        sxx *= f;
        sxy *= f;
        syy *= f;
    }
    // Σ = J'J'ᵀ + I (unit reconstruction variance).
    let css = sxx + 1.0;
    let cst = sxy;
    let ctt = syy + 1.0;
    // SPEC: A = Σtt, B = −2Σst, C = Σss, divided by F = AC − B²/4 = det Σ.
    let inv_f = 1.0 / (css * ctt - cst * cst);
    Form {
        sigma: (css, cst, ctt),
        q: (ctt * inv_f, -2.0 * cst * inv_f, css * inv_f),
    }
}

/// Read what `st` says and blend.
#[inline(always)]
fn read<P: Pixel, S: TexelSink, const EXACT: bool, const FMA: bool, const VEC: bool>(
    c: &Chain<P>,
    a: &Addressing,
    st: &Setup,
    sink: &mut S,
) -> [f32; 4] {
    let t = ewa_level::<P, S, EXACT, FMA, VEC>(c, a, &st.levels[0], sink);
    if st.two {
        let t2 = ewa_level::<P, S, EXACT, FMA, VEC>(c, a, &st.levels[1], sink);
        lerp(t, t2, st.delta)
    } else {
        t
    }
}

/// The (lengthened) ellipse in level-0 texels as the symmetric matrix
/// `J'·J'ᵀ` whose square-root semi-axes it has.
pub(crate) struct Axes {
    xx: f64,
    xy: f64,
    yy: f64,
}

/// The coefficients of [`weight_poly`], lowest power first.
pub(crate) const WEIGHT_POLY: [f32; 7] = [
    0.864_663_4,
    -1.999_869_1,
    1.997_875_8,
    -1.320_221_6,
    0.627_286_2,
    -0.203_470_2,
    0.033_736_594,
];

/// `exp(−2x) − exp(−2)` on [0, 1] as a degree-6 polynomial (Chebyshev
/// interpolation, converted to powers; within 1.4·10⁻⁶ of the formula),
/// kept above 0 inside the ellipse.
#[inline(always)]
pub(crate) fn weight_poly<const FMA: bool>(x: f32) -> f32 {
    const C: [f32; 7] = WEIGHT_POLY;
    // Estrin's scheme: three multiply-adds deep instead of six.
    let x2 = x * x;
    let p01 = madd::<FMA>(C[1], x, C[0]);
    let p23 = madd::<FMA>(C[3], x, C[2]);
    let p45 = madd::<FMA>(C[5], x, C[4]);
    let p46 = madd::<FMA>(C[6], x2, p45);
    let p26 = madd::<FMA>(p46, x2, p23);
    let p = madd::<FMA>(p26, x2, p01);
    // (A plain comparison: one instruction, where `f32::max` adds NaN
    // handling this polynomial of a finite r² does not need.)
    if p > 1e-12 { p } else { 1e-12 }
}

/// Level `k`'s part of a lookup with the (lengthened) ellipse `axes`
/// centred at `(u, v)`.
#[inline(always)]
fn level_setup<P: Pixel>(
    c: &Chain<P>,
    k: usize,
    a: &Addressing,
    axes: &Axes,
    u: f64,
    v: f64,
) -> LevelSetup {
    let l = &c.levels[k];
    let (sx, sy) = (l.wf / c.levels[0].wf, l.hf / c.levels[0].hf);
    let single = l.w == 1
        && l.h == 1
        && a.wrap.u != WrapMode::ClampToBorder
        && a.wrap.v != WrapMode::ClampToBorder;
    let form = level_form(axes, sx, sy);
    // Centre in texel-centre coordinates, split into an integer base and
    // a fraction so huge coordinates keep their precision.
    let (ib, fs) = split(u * l.wf - 0.5);
    let (jb, ft) = split(v * l.hf - 0.5);
    LevelSetup {
        k,
        single,
        sigma: form.sigma,
        q: form.q,
        base: (ib, jb),
        frac: (fs as f64, ft as f64),
    }
}

/// The filtered value of one level of a lookup.
#[inline(always)]
fn ewa_level<P: Pixel, S: TexelSink, const EXACT: bool, const FMA: bool, const VEC: bool>(
    c: &Chain<P>,
    a: &Addressing,
    ls: &LevelSetup,
    sink: &mut S,
) -> [f32; 4] {
    let k = ls.k;
    let l = &c.levels[k];
    if ls.single {
        return l.at(&c.lut, k as u32, 0, 0, sink);
    }
    let (css, _, ctt) = ls.sigma;
    let (qa, qb, qc) = ls.q;
    let (ib, jb) = ls.base;
    let (fs, ft) = ls.frac;
    if EXACT {
        let form = Form {
            sigma: ls.sigma,
            q: ls.q,
        };
        return exact_scan(&form, (ib, jb), (fs, ft), |x, y| {
            l.fetch(&c.lut, k as u32, x, y, a, sink)
        });
    }
    #[cfg(target_arch = "x86_64")]
    if VEC
        && let Some(lut8) = P::packed(&c.lut)
        && l.w as usize <= (i32::MAX / 16) as usize
    {
        let mut texel = |x: i64, y: i64, value: bool| {
            if value {
                l.fetch(&c.lut, k as u32, x, y, a, sink)
            } else {
                sink.texel(k as u32, x as u32, y as u32);
                [0.0; 4]
            }
        };
        let (w, h) = (l.w as usize, l.h as usize);
        let texels = l.texels.as_ptr().cast();
        let (qa, qb, qc) = (qa as f32, qb as f32, qc as f32);
        let (fs, ft) = (fs as f32, ft as f32);
        use super::ewa_simd::{Ellipse, scan};
        // Runs down columns for an ellipse taller than wide: the roles of
        // x and y swap.
        let columns = css < ctt;
        let (qa, qc) = swap(columns, (qa, qc));
        let e = Ellipse {
            q: (qa, qb, qc),
            base: swap(columns, (ib, jb)),
            frac: swap(columns, (fs, ft)),
            ext: if columns { css } else { ctt }.sqrt(),
            wrap: swap(columns, (a.wrap.u, a.wrap.v)),
            border: a.border,
        };
        #[allow(unsafe_code)]
        // SAFETY: VEC is set only by `ewa_avx512`, run on CPUs with
        // AVX-512 F, BW, DQ, VL and VBMI (and so POPCNT and BMI1), for
        // 4-byte texels (`vector_texels`); `l.texels` holds the level's
        // w·h texels, and 15·w fits an i32 (checked above).
        let (acc, wsum) = unsafe {
            if columns {
                scan::<true>(lut8, texels, (w, h), &e, S::TRACES, &mut texel)
            } else {
                scan::<false>(lut8, texels, (w, h), &e, S::TRACES, &mut texel)
            }
        };
        return if wsum > 0.0 {
            super::map4(acc, |x| x / wsum)
        } else {
            l.fetch(&c.lut, k as u32, ib, jb, a, sink)
        };
    }
    // Scan whichever way gives the longer runs: rows for an ellipse wider
    // than tall, columns otherwise (the per-run setup is the cost of short
    // runs; a grazing plane's ellipses run along v).
    let (acc, wsum) = if css >= ctt {
        scan::<P, S, false, FMA>(
            l,
            c,
            k,
            a,
            (qa, qb, qc),
            (ib, jb),
            (fs, ft),
            ctt.sqrt(),
            sink,
        )
    } else {
        scan::<P, S, true, FMA>(
            l,
            c,
            k,
            a,
            (qc, qb, qa),
            (jb, ib),
            (ft, fs),
            css.sqrt(),
            sink,
        )
    };
    if wsum > 0.0 {
        super::map4(acc, |x| x / wsum)
    } else {
        // Unreachable in exact arithmetic (the ellipse contains a texel
        // centre); kept so rounding can never divide by zero.
        l.fetch(&c.lut, k as u32, ib, jb, a, sink)
    }
}

/// `(b, a)` when `yes`, else `(a, b)`.
#[inline(always)]
fn swap<T>(yes: bool, (a, b): (T, T)) -> (T, T) {
    if yes { (b, a) } else { (a, b) }
}

/// Most lines an ellipse crosses in [`scan`]: its extent across runs is
/// at most `sqrt(MAX_RADIUS² + 1)` either side of the centre.
pub(crate) const MAX_LINES: usize = 2 * (MAX_RADIUS as usize + 2) + 1;

/// `floor(x)` of a small finite `x` (|x| < 2³¹), in a form that vectorises.
#[inline(always)]
fn floor_small<const AVX2: bool>(x: f32) -> f32 {
    if AVX2 {
        // One rounding instruction on these CPUs.
        x.floor()
    } else {
        let t = x as i32 as f32;
        if t > x { t - 1.0 } else { t }
    }
}

/// The fast inner loops: runs of the ellipse `qa·s² + qb·s·t + qc·t² < 1`
/// along the first coordinate (x for rows; with `COLUMNS` the caller has
/// swapped the roles, so runs go down columns), one run per line of the
/// second coordinate within `±ext`. Every run's ends and its starting r²
/// and first difference are solved first, in `f32`, in one loop the
/// compiler vectorises; then r² is stepped along each run, and runs inside
/// the level are read without wrapping.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn scan<P: Pixel, S: TexelSink, const COLUMNS: bool, const FMA: bool>(
    l: &super::fetch::Level<P>,
    c: &Chain<P>,
    lv: usize,
    a: &Addressing,
    (qa, qb, qc): (f64, f64, f64),
    (ib, jb): (i64, i64),
    (fs, ft): (f64, f64),
    ext: f64,
    sink: &mut S,
) -> ([f32; 4], f32) {
    let (mut a0, mut a1, mut a2, mut a3, mut wsum) = (0f32, 0f32, 0f32, 0f32, 0f32);
    let (w, h) = (l.w as i64, l.h as i64);
    // Along a run: s; across runs: t (texel x, y, or y, x with COLUMNS).
    let (len_s, len_t) = if COLUMNS { (h, w) } else { (w, h) };
    let t0 = -fast_floor(ext - ft);
    let t1 = fast_floor(ft + ext);
    let n = ((t1 - t0 + 1).max(0) as usize).min(MAX_LINES);
    let (qa, qb, qc, fs) = (qa as f32, qb as f32, qc as f32, fs as f32);
    let inv2a = 0.5 / qa;
    let tt0 = (t0 as f64 - ft) as f32;
    let dd = 2.0 * qa;
    // Eight lines at a time: their runs solved together (vectorised), then
    // walked one by one.
    for base in (0..n).step_by(8) {
        let mut s0s = [0f32; 8];
        let mut s1s = [0f32; 8];
        let mut r2s = [0f32; 8];
        let mut ds = [0f32; 8];
        for i in 0..8 {
            let tt = tt0 + (base + i) as f32;
            // Solve qa·s² + qb·tt·s + (qc·tt² − 1) < 0 for s.
            let btt = qb * tt;
            let ctt = qc * tt * tt;
            let disc = btt * btt - 4.0 * qa * (ctt - 1.0);
            let half = disc.max(0.0).sqrt() * inv2a;
            let centre = fs - btt * inv2a;
            let s0 = -floor_small::<FMA>(half - centre);
            let s1 = floor_small::<FMA>(centre + half);
            // A line the ellipse misses (or one past the last) gets an
            // empty run.
            s0s[i] = s0;
            s1s[i] = if disc > 0.0 && base + i < n {
                s1
            } else {
                s0 - 1.0
            };
            // r² at s0 and its first difference; the second is 2·qa.
            let ss0 = s0 - fs;
            r2s[i] = qa * ss0 * ss0 + btt * ss0 + ctt;
            ds[i] = qa * (2.0 * ss0 + 1.0) + btt;
        }
        for i in 0..8 {
            let (s0, s1) = (s0s[i] as i64, s1s[i] as i64);
            if s1 < s0 {
                continue;
            }
            let (mut r2, mut d) = (r2s[i], ds[i]);
            let line = jb.saturating_add(t0 + (base + i) as i64);
            let (x0, x1) = (ib.saturating_add(s0), ib.saturating_add(s1));
            if (0..len_t).contains(&line) && x0 >= 0 && x1 < len_s {
                // The whole run lies inside the level: read it directly.
                let n = (x1 - x0) as usize + 1;
                let (start, stride) = if COLUMNS {
                    (line as usize + x0 as usize * w as usize, w as usize)
                } else {
                    ((line * w + x0) as usize, 1)
                };
                let run = &l.texels[start..=start + (n - 1) * stride];
                // Tracing sinks hear of each texel with a weight (the same test
                // as the sum's, on the same r²).
                let mut hit = |k: usize| {
                    let x = x0 + k as i64;
                    let (tx, ty) = if COLUMNS { (line, x) } else { (x, line) };
                    sink.texel(lv as u32, tx as u32, ty as u32);
                };
                let (t, ws) = if stride == 1 {
                    run_sum::<P, S, FMA>(run.iter(), &c.lut, (r2, d, dd), &mut hit)
                } else {
                    let it = run.iter().step_by(stride);
                    run_sum::<P, S, FMA>(it, &c.lut, (r2, d, dd), &mut hit)
                };
                a0 += t[0];
                a1 += t[1];
                a2 += t[2];
                a3 += t[3];
                wsum += ws;
            } else {
                for x in x0..=x1 {
                    if r2 < 1.0 {
                        let wt = weight_poly::<FMA>(r2);
                        let (tx, ty) = if COLUMNS { (line, x) } else { (x, line) };
                        let tex = l.fetch(&c.lut, lv as u32, tx, ty, a, sink);
                        a0 += wt * tex[0];
                        a1 += wt * tex[1];
                        a2 += wt * tex[2];
                        a3 += wt * tex[3];
                        wsum += wt;
                    }
                    r2 += d;
                    d += dd;
                }
            }
        }
    }
    ([a0, a1, a2, a3], wsum)
}

/// `a·b + c`, fused when `FMA` (the caller is compiled for FMA).
#[inline(always)]
fn madd<const FMA: bool>(a: f32, b: f32, c: f32) -> f32 {
    if FMA { a.mul_add(b, c) } else { a * b + c }
}

/// The weighted sum of one in-level run: r² starts at `r2` and steps by
/// `d`, which steps by `dd`; texels with r² < 1 count, each reported to
/// `hit` (by its index in the run) when `S` traces. Local sums, no bounds
/// checks, weights without branches; texels alternate between two sets of
/// sums and r² steps two texels at a time, so no chain of dependent
/// additions is longer than half the run.
#[inline(always)]
fn run_sum<'a, P: Pixel + 'a, S: TexelSink, const FMA: bool>(
    mut texels: impl Iterator<Item = &'a P>,
    lut: &P::Lut,
    (mut r2, mut d, dd): (f32, f32, f32),
    hit: &mut impl FnMut(usize),
) -> ([f32; 4], f32) {
    let mut acc = [[0f32; 4]; 2];
    let mut wsum = [0f32; 2];
    let (dd2, mut k) = (2.0 * dd, 0);
    let mut add = |set: usize, k: usize, r2: f32, t: &P| {
        let inside = r2 < 1.0;
        if S::TRACES && inside {
            hit(k);
        }
        let wt = if inside { weight_poly::<FMA>(r2) } else { 0.0 };
        let tex = t.decode(lut);
        for ch in 0..4 {
            acc[set][ch] = madd::<FMA>(wt, tex[ch], acc[set][ch]);
        }
        wsum[set] += wt;
    };
    while let Some(t) = texels.next() {
        add(0, k, r2, t);
        let Some(t) = texels.next() else { break };
        add(1, k + 1, r2 + d, t);
        // r²(k + 2) = r²(k) + 2·d(k) + dd; d(k + 2) = d(k) + 2·dd.
        r2 += 2.0 * d + dd;
        d += dd2;
        k += 2;
    }
    let [x, y] = acc;
    (
        [x[0] + y[0], x[1] + y[1], x[2] + y[2], x[3] + y[3]],
        wsum[0] + wsum[1],
    )
}

/// The plain inner loops of [`ewa_exact`]: every texel with `r² < 1`
/// around the centre `base + frac` (texel-centre coordinates), read with
/// `fetch(x, y)` and weighted `exp(−2r²) − exp(−2)`, summed in `f64`. The
/// cube map's EWA reads its texels across face edges through `fetch`.
pub(crate) fn exact_scan(
    form: &Form,
    (ib, jb): (i64, i64),
    (fs, ft): (f64, f64),
    mut fetch: impl FnMut(i64, i64) -> [f32; 4],
) -> [f32; 4] {
    let (qa, qb, qc) = form.q;
    // Extent in t of the ellipse r² < 1 is sqrt(Σtt).
    let t_ext = form.sigma.2.sqrt();
    let t0 = -fast_floor(t_ext - ft);
    let t1 = fast_floor(ft + t_ext);
    let e_alpha = (-ALPHA).exp();
    let mut acc = [0.0f64; 4];
    let mut wsum = 0.0f64;
    for jt in t0..=t1 {
        let tt = jt as f64 - ft;
        let centre = -qb * tt / (2.0 * qa);
        let disc = (qb * tt) * (qb * tt) - 4.0 * qa * (qc * tt * tt - 1.0);
        if disc <= 0.0 {
            continue;
        }
        let half = disc.sqrt() / (2.0 * qa);
        let s0 = -fast_floor(half - fs - centre);
        let s1 = fast_floor(fs + centre + half);
        for is in s0..=s1 {
            let ss = is as f64 - fs;
            let r2 = qa * ss * ss + qb * ss * tt + qc * tt * tt;
            if r2 < 1.0 {
                let w = (-ALPHA * r2).exp() - e_alpha;
                let tex = fetch(ib.saturating_add(is), jb.saturating_add(jt));
                for c in 0..4 {
                    acc[c] += w * tex[c] as f64;
                }
                wsum += w;
            }
        }
    }
    if wsum > 0.0 {
        super::map4(acc, |x| (x / wsum) as f32)
    } else {
        // Unreachable in exact arithmetic (the ellipse contains a texel
        // centre); kept so rounding can never divide by zero.
        fetch(ib, jb)
    }
}
