//! Found by the `sampler` fuzz target built with overflow checks (fuzz
//! smoke, issue 28): `Sampler::sample_bias` with a NaN bias whose sign bit
//! is set (what x86 makes of ∞ − ∞, and what fuzzed bits give) panicked
//! with "attempt to add with overflow" in `Lod::plan_nearest`
//! (sample/footprint.rs), on every preset with nearest mip selection
//! (`nearest`, `bilinear`). The bias was added to the sampler's without the
//! check `SamplerOptions::validate` makes (finite), so 4^bias became NaN
//! and so did ρ²·4^bias, whose bit pattern the nearest-level rule adds a
//! mask to on the promise that it is a non-negative number. A release
//! build wrapped and magnified at level 0 whatever the footprint; a NaN
//! with the sign bit clear went the other way through the same rule.
//!
//! Now a NaN bias reads as 0 (as a NaN coordinate does) and an infinite
//! one saturates λ at the sampler's LOD clamp, as GL's clamp of
//! λbase + bias does. Checked against `sample` itself (no bias) and
//! against the 1×1 last level, read by `load`. CI runs it with overflow
//! checks on (`.ci/run`, and `tests/core`'s `debug_build_overflows` in the
//! light build), where the trap exists.

use parvo::sample::{Query, Sampler, SamplerOptions};
use parvo::texel::{ChannelType, ColorSpace, Format};
use parvo::{MipOptions, Texture, mip};

#[test]
fn nan_bias_reads_as_zero_and_infinite_bias_saturates_at_the_clamp() {
    let (w, h) = (13u32, 6u32);
    let texels: Vec<u8> = (0..w * h * 4).map(|i| (i * 37 % 251) as u8).collect();
    let tex = Texture::from_u8(
        w,
        h,
        Format::new(4, ChannelType::U8, ColorSpace::Srgb),
        texels,
    )
    .unwrap();
    let chain = mip::build(tex, &MipOptions::default()).unwrap();
    let last = chain.len() as u32 - 1;
    let negative_nan = f32::from_bits(0xffc0_0000);
    for o in [
        SamplerOptions::nearest(),
        SamplerOptions::bilinear(),
        SamplerOptions::trilinear(),
    ] {
        let s = Sampler::new(&chain, o).unwrap();
        let smallest = s.load(0, 0, last).unwrap();
        for (u, v) in [(0.3, 0.7), (-2.6, 11.1), (0.99, 0.01)] {
            for d in [0.0, 1e-3, 0.05, 0.4] {
                let q = Query::new(u, v, d, 0.0, 0.0, d);
                let plain = s.sample(&q);
                for nan in [f32::NAN, negative_nan] {
                    assert_eq!(
                        s.sample_bias(&q, nan),
                        plain,
                        "{} bias {nan} {q:?}",
                        o.name()
                    );
                }
                // λ = lodMax (1000, past the last level): the 1×1 level,
                // whatever the filter and position. A zero footprint has
                // λbase = −∞, which no bias moves: level 0 as unbiased.
                let got = s.sample_bias(&q, f32::INFINITY);
                let want = if d == 0.0 { plain } else { smallest };
                for c in 0..4 {
                    assert!(
                        (got[c] - want[c]).abs() <= 1e-6,
                        "{} bias ∞ {q:?}: {got:?}, want {want:?}",
                        o.name()
                    );
                }
                // λ = lodMin (−1000): magnification on level 0, as a zero
                // footprint gives.
                let point = s.sample(&Query::point(u, v));
                assert_eq!(
                    s.sample_bias(&q, f32::NEG_INFINITY),
                    point,
                    "{} bias −∞ {q:?}",
                    o.name()
                );
            }
        }
    }
}
