//! Issue 28: the `sampler` fuzz target, built with debug assertions and
//! overflow checks (as `cargo fuzz` builds by default, and as a dependent
//! crate's debug build runs parvo), panicked with "attempt to subtract with
//! overflow" in `floor_fast` (sample/bilinear.rs), reached from
//! `Sampler::sample` through trilinear for a huge coordinate. The fast
//! floor subtracts two `f64` bit patterns as `i64`; for texel positions in
//! (−3·2^52, −1.5·2^52) that difference leaves the `i64` range, which a
//! release build wraps (as intended: the index lands far outside the level
//! and the general path takes over) and a debug build traps on.
//!
//! The trap only exists where overflow checks are on, so CI runs every test
//! with them (`.ci/run`), this file also in the light build's tests (module
//! `debug_build_overflows` of `tests/core`). In a build without overflow
//! checks the sweeps still check the results, but cannot show the trap.
//!
//! Every preset but `sat` (its own fuzz target and tests), every pair of
//! wrap modes, 8-bit and float storage, odd sizes; coordinates on a
//! geometric sweep from 2^40 to 2^80 texels of both signs (through the
//! trapping band), the band's edges, ±f32::MAX, ±∞ and NaN, each with
//! point, magnifying, minifying and anisotropic derivatives. The second
//! sweep puts the same coordinates through the shading-language calls
//! (explicit level, bias, gather, depth compare, load, 2×2 quads) with
//! huge, infinite and NaN levels, biases, references and indices.
//!
//! Properties, each independent of the code under test: no panic; every
//! filtered channel is a convex combination of the chain's texels and the
//! border colour (all these filters weight with non-negative weights), so
//! it lies between their smallest and largest value; a gathered value is
//! one of the level-0 texels' components or the border's; a comparison
//! result lies in [0, 1] (up to the rounding of weights summing to 1); a
//! load returns exactly the decoded texel inside the level and nothing
//! outside it.

use parvo::sample::{CompareOp, Filter, Query, Sampler, SamplerOptions};
use parvo::texel::{ChannelType, ColorSpace, Format};
use parvo::{MipChain, MipOptions, Texture, Wrap, WrapMode, mip};

const BORDER: [f32; 4] = [0.9, -0.5, 2.0, 0.25];

/// A NaN with the sign bit set: what x86 arithmetic makes of ∞ − ∞, and
/// what fuzzed bits give. Bit tricks that assume a non-negative value
/// break on it where `f32::NAN` passes.
fn negative_nan() -> f32 {
    f32::from_bits(0xffc0_0000)
}

fn texture(w: u32, h: u32, ty: ChannelType, seed: u64) -> Texture {
    let mut s = seed | 1;
    let mut next = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        s
    };
    let n = (w * h * 4) as usize;
    match ty {
        ChannelType::U8 => {
            let v = (0..n).map(|_| (next() >> 56) as u8).collect();
            Texture::from_u8(w, h, Format::new(4, ty, ColorSpace::Srgb), v).unwrap()
        }
        _ => {
            let v = (0..n)
                .map(|_| (next() >> 40) as f32 / (1u64 << 24) as f32)
                .collect();
            let f = Format::new(4, ChannelType::F32, ColorSpace::Linear);
            Texture::from_f32(w, h, f, v).unwrap()
        }
    }
}

/// A chain of odd size and the smallest and largest value of each channel
/// over all its levels (decoded) and the border colour.
struct Case {
    w: u32,
    h: u32,
    chain: MipChain,
    lo: [f32; 4],
    hi: [f32; 4],
}

fn cases() -> Vec<Case> {
    [
        (1u32, 1u32, ChannelType::U8),
        (3, 5, ChannelType::F32),
        (24, 7, ChannelType::U8),
        (17, 16, ChannelType::F32),
    ]
    .into_iter()
    .map(|(w, h, ty)| {
        let tex = texture(w, h, ty, u64::from(w * 31 + h));
        let chain = mip::build(tex, &MipOptions::default()).unwrap();
        let (mut lo, mut hi) = (BORDER, BORDER);
        for level in chain.levels() {
            for px in level.to_linear().chunks_exact(4) {
                for c in 0..4 {
                    lo[c] = lo[c].min(px[c]);
                    hi[c] = hi[c].max(px[c]);
                }
            }
        }
        Case {
            w,
            h,
            chain,
            lo,
            hi,
        }
    })
    .collect()
}

fn presets() -> Vec<SamplerOptions> {
    Filter::ALL
        .iter()
        .filter(|f| **f != Filter::Sat)
        .map(|f| SamplerOptions::preset(*f, 16))
        .chain([SamplerOptions::aniso(2), SamplerOptions::aniso(4)])
        .collect()
}

/// Texel-space magnitudes from 2^40 to 2^80, both signs, plus the edges of
/// the band (−3·2^52, −1.5·2^52) where the fast floor's subtraction
/// overflowed.
fn texel_positions() -> Vec<f64> {
    let mut v = Vec::new();
    let mut m = 2f64.powi(40);
    while m < 2f64.powi(80) {
        v.push(m);
        v.push(-m);
        m *= 1.19;
    }
    for k in [1.5, 1.5000001, 1.75, 2.0, 2.5, 2.9999999, 3.0] {
        v.push(-k * 2f64.powi(52));
    }
    v
}

/// Normalized coordinates whose texel position (u·w) sweeps the
/// magnitudes, then the non-finite and extreme `f32`s.
fn coords(w: u32) -> Vec<f32> {
    let mut v: Vec<f32> = texel_positions()
        .into_iter()
        .map(|t| (t / f64::from(w)) as f32)
        .collect();
    v.extend([
        f32::MAX,
        -f32::MAX,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NAN,
        negative_nan(),
    ]);
    v
}

fn sampler(case: &Case, base: &SamplerOptions, wu: WrapMode, wv: WrapMode) -> Sampler {
    let o = SamplerOptions {
        wrap: Wrap { u: wu, v: wv },
        border: BORDER,
        ..*base
    };
    Sampler::new(&case.chain, o).unwrap()
}

fn assert_within(case: &Case, got: [f32; 4], what: &dyn Fn() -> String) {
    for c in 0..4 {
        assert!(
            got[c] >= case.lo[c] - 1e-4 && got[c] <= case.hi[c] + 1e-4,
            "{}: {got:?} outside {:?}..{:?}",
            what(),
            case.lo,
            case.hi
        );
    }
}

#[test]
fn huge_coordinates_sample_without_overflow_in_every_preset() {
    let mut queries = 0u64;
    for case in &cases() {
        let (w, h) = (case.w, case.h);
        for base in &presets() {
            for wu in WrapMode::ALL {
                for wv in WrapMode::ALL {
                    let s = sampler(case, base, wu, wv);
                    for &x in &coords(w) {
                        for d in [0.0, 1e-4, 0.3, 40.0] {
                            for q in [
                                Query::new(x, 0.4, d, 0.0, 0.0, d),
                                Query::new(0.6, x, d, 0.0, 0.0, d),
                                Query::new(x, x, d, d * 0.25, 0.0, d * 0.1),
                            ] {
                                let got = s.sample(&q);
                                queries += 1;
                                assert_within(case, got, &|| {
                                    format!("{} wrap {wu}/{wv} {w}x{h} {q:?}", s.options().name())
                                });
                            }
                        }
                    }
                }
            }
        }
    }
    assert!(queries > 100_000, "{queries} queries");
    if !cfg!(debug_assertions) {
        eprintln!(
            "note: built without debug assertions; run as `.ci/run` does (CARGO_PROFILE_RELEASE_OVERFLOW_CHECKS=true)"
        );
    }
}

/// The shading-language calls (explicit level, bias, gather, depth
/// compare, load, quads) with the same coordinates and extreme levels,
/// biases, references and texel indices. Each wrap mode on both axes
/// (the pairs are the first sweep's business).
#[test]
fn huge_coordinates_levels_and_biases_in_the_shading_language_calls() {
    let levels = [
        f32::NEG_INFINITY,
        -1e30,
        -1.0,
        0.0,
        0.5,
        2.25,
        1e30,
        f32::INFINITY,
        f32::NAN,
        negative_nan(),
    ];
    let biases = [
        f32::NEG_INFINITY,
        -1e30,
        -3.0,
        1.5,
        1e30,
        f32::INFINITY,
        f32::NAN,
        negative_nan(),
    ];
    let references = [
        f32::NEG_INFINITY,
        -1e30,
        0.0,
        0.5,
        1.0,
        1e30,
        f32::INFINITY,
        f32::NAN,
        negative_nan(),
    ];
    let indices = [i64::MIN, -(1 << 62), -1, 0, 1, 16, 17, 1 << 40, i64::MAX];
    let mut calls = 0u64;
    for case in &cases() {
        let (w, h) = (case.w, case.h);
        // Decoded texels of every level, for gather's and load's values.
        let decoded: Vec<Vec<f32>> = case.chain.levels().iter().map(|l| l.to_linear()).collect();
        for base in &presets() {
            for mode in WrapMode::ALL {
                let s = sampler(case, base, mode, mode);
                let name = s.options().name();
                let xs = coords(w);
                for (k, &x) in xs.iter().enumerate() {
                    // The other coordinate: ordinary, or the sweep's
                    // mirror image, so both axes see every value.
                    let y = if k % 2 == 0 {
                        0.4
                    } else {
                        xs[xs.len() - 1 - k]
                    };
                    for &level in &levels {
                        let got = s.sample_level(x, y, level);
                        assert_within(case, got, &|| {
                            format!("{name} {mode} level {level} ({x}, {y})")
                        });
                        for op in [CompareOp::Less, CompareOp::GreaterEqual, CompareOp::Always] {
                            for &r in &references {
                                let got = s.sample_compare_level(x, y, level, r, op);
                                assert!(
                                    (0.0..=1.0).contains(&got),
                                    "{name} {mode} compare level {level} {op} {r} ({x}, {y}): {got}"
                                );
                            }
                        }
                        calls += 1 + 3 * references.len() as u64;
                    }
                    for d in [0.0, 0.3, f32::MAX, f32::INFINITY, f32::NAN, negative_nan()] {
                        let q = Query::new(x, y, d, 0.0, 0.0, d);
                        for &bias in &biases {
                            let got = s.sample_bias(&q, bias);
                            assert_within(case, got, &|| {
                                format!("{name} {mode} bias {bias} {q:?}")
                            });
                        }
                        for op in [CompareOp::LessEqual, CompareOp::NotEqual] {
                            for &r in &references {
                                let got = s.sample_compare(&q, r, op);
                                assert!(
                                    (0.0..=1.0).contains(&got),
                                    "{name} {mode} compare {op} {r} {q:?}: {got}"
                                );
                            }
                        }
                        calls += (biases.len() + 2 * references.len()) as u64;
                    }
                    for comp in [0, 1, 3, usize::MAX] {
                        let c = comp.min(3);
                        for g in s.gather(x, y, comp) {
                            assert!(
                                g == BORDER[c]
                                    || decoded[0]
                                        .chunks_exact(4)
                                        .any(|px| (px[c] - g).abs() <= 1e-6),
                                "{name} {mode} gather {comp} ({x}, {y}): {g} is no texel's"
                            );
                        }
                        calls += 1;
                    }
                    // Quads: one corner at the huge coordinate, so the
                    // derivatives are huge, infinite or NaN too.
                    for quad in [
                        [[x, y], [0.5, 0.5], [0.5, 0.5], [0.5, 0.5]],
                        [[0.5, 0.5], [x, 0.5], [0.5, y], [x, y]],
                        [[x, y], [x, y], [x, y], [x, y]],
                    ] {
                        for (p, got) in s.sample_quad(&quad).into_iter().enumerate() {
                            assert_within(case, got, &|| {
                                format!("{name} {mode} quad {quad:?} pixel {p}")
                            });
                        }
                        calls += 1;
                    }
                }
                // Loads: no wrapping; exactly the decoded texel inside the
                // level, nothing outside it or past the last level.
                let last = case.chain.len() as u32;
                for level in [0, 1, last - 1, last, u32::MAX] {
                    let size = case
                        .chain
                        .level(level as usize)
                        .map(|t| (t.width(), t.height()));
                    for &i in &indices {
                        for &j in &indices {
                            let got = s.load(i, j, level);
                            let want = size.and_then(|(lw, lh)| {
                                let inside = (0..i64::from(lw)).contains(&i)
                                    && (0..i64::from(lh)).contains(&j);
                                inside.then(|| {
                                    let k = (j as usize * lw as usize + i as usize) * 4;
                                    decoded[level as usize][k..k + 4].to_vec()
                                })
                            });
                            match (got, want) {
                                (None, None) => {}
                                (Some(g), Some(t)) => assert!(
                                    g.iter().zip(&t).all(|(a, b)| (a - b).abs() <= 1e-6),
                                    "{w}x{h} load ({i}, {j}) level {level}: {g:?}, decoded {t:?}"
                                ),
                                (g, t) => panic!(
                                    "{w}x{h} load ({i}, {j}) level {level}: {g:?}, want {t:?}"
                                ),
                            }
                            calls += 1;
                        }
                    }
                }
            }
        }
    }
    assert!(calls > 100_000, "{calls} calls");
}
