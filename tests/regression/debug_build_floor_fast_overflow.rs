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
//! The trap only exists where overflow checks are on, so CI runs this file
//! in the `ci-debug` profile (release speed, debug assertions and overflow
//! checks; `.ci/run`), as its own test target `debug_build_overflows` in the
//! light build. In a build without overflow checks the sweep still checks
//! the results, but cannot show the trap.
//!
//! Every preset but `sat` (its own fuzz target and tests), every pair of
//! wrap modes, 8-bit and float storage, odd sizes; coordinates on a
//! geometric sweep from 2^40 to 2^80 texels of both signs (through the
//! trapping band), the band's edges, ±f32::MAX, ±∞ and NaN, each with
//! point, magnifying, minifying and anisotropic derivatives. Property: no
//! panic, and every channel is a convex combination of the texels and the
//! border colour (all these filters weight with non-negative weights), so
//! it lies between their smallest and largest value.

use parvo::sample::{Filter, Query, Sampler, SamplerOptions};
use parvo::texel::{ChannelType, ColorSpace, Format};
use parvo::{MipOptions, Texture, Wrap, WrapMode, mip};

/// Whether this test binary traps on integer overflow (so whether the
/// sweep below can show the finding at all).
fn overflow_checks_on() -> bool {
    let max = std::hint::black_box(i64::MAX);
    std::panic::catch_unwind(|| std::hint::black_box(max + std::hint::black_box(1))).is_err()
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

#[test]
fn huge_coordinates_sample_without_overflow_in_every_preset() {
    let checked = overflow_checks_on();
    let border = [0.9, -0.5, 2.0, 0.25];
    let presets: Vec<SamplerOptions> = Filter::ALL
        .iter()
        .filter(|f| **f != Filter::Sat)
        .map(|f| SamplerOptions::preset(*f, 16))
        .chain([SamplerOptions::aniso(2), SamplerOptions::aniso(4)])
        .collect();
    let mut queries = 0u64;
    for (w, h, ty) in [
        (1u32, 1u32, ChannelType::U8),
        (3, 5, ChannelType::F32),
        (24, 7, ChannelType::U8),
        (17, 16, ChannelType::F32),
    ] {
        let tex = texture(w, h, ty, u64::from(w * 31 + h));
        let lin = tex.to_linear();
        let (mut lo, mut hi) = ([f32::INFINITY; 4], [f32::NEG_INFINITY; 4]);
        for px in lin.chunks_exact(4) {
            for c in 0..4 {
                lo[c] = lo[c].min(px[c]).min(border[c]);
                hi[c] = hi[c].max(px[c]).max(border[c]);
            }
        }
        let chain = mip::build(tex, &MipOptions::default()).unwrap();
        // Normalized coordinates whose texel position (u·w) sweeps the
        // magnitudes, on whichever axis; the other axis stays ordinary.
        let mut coords: Vec<f32> = texel_positions()
            .into_iter()
            .map(|t| (t / f64::from(w)) as f32)
            .collect();
        coords.extend([
            f32::MAX,
            -f32::MAX,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
        ]);
        for base in &presets {
            for wu in WrapMode::ALL {
                for wv in WrapMode::ALL {
                    let o = SamplerOptions {
                        wrap: Wrap { u: wu, v: wv },
                        border,
                        ..*base
                    };
                    let s = Sampler::new(&chain, o).unwrap();
                    for &x in &coords {
                        for d in [0.0, 1e-4, 0.3, 40.0] {
                            for q in [
                                Query::new(x, 0.4, d, 0.0, 0.0, d),
                                Query::new(0.6, x, d, 0.0, 0.0, d),
                                Query::new(x, x, d, d * 0.25, 0.0, d * 0.1),
                            ] {
                                let got = s.sample(&q);
                                queries += 1;
                                for c in 0..4 {
                                    assert!(
                                        got[c] >= lo[c] - 1e-4 && got[c] <= hi[c] + 1e-4,
                                        "{} wrap {wu}/{wv} {w}x{h} {q:?}: {got:?} outside \
                                         {lo:?}..{hi:?}",
                                        o.name()
                                    );
                                }
                            }
                        }
                    }
                }
            }
        }
    }
    assert!(queries > 100_000, "{queries} queries");
    if !checked {
        eprintln!(
            "note: built without overflow checks; run in the ci-debug profile to test the trap"
        );
    }
}
