//! Fuzzing (`fuzz/fuzz_targets/sat.rs`) found a rectangle edge at
//! −2.01·10⁻¹¹³ read as −1: `x − floor(x)` is `−2·10⁻¹¹³ + 1`, which
//! rounds to 1 in `f64`, and the fraction was then dropped, so the edge
//! moved a whole texel left. On a 1×1 grey+alpha texture the box
//! `[−0.212, −2·10⁻¹¹³) × [0.0094, 2.26)` came out with a negative area
//! and averaged to 0 instead of the texel. Every accumulator kind, every
//! wrap mode, against brute force.

use parvo::sat::{self, AccumulatorKind, Rect};
use parvo::texel::{ChannelType, ColorSpace, Format};
use parvo::wrap::wrap_index;
use parvo::{Texture, Wrap, WrapMode};

#[test]
fn the_fuzzer_rectangle_averages_to_the_texel() {
    let tex = Texture::from_u8(
        1,
        1,
        Format::new(2, ChannelType::U8, ColorSpace::Srgb),
        vec![0, 0xae],
    )
    .unwrap();
    let r = Rect::new(
        -2.0100221416519876e-113,
        2.2607276961212177,
        -0.21234908076735926,
        0.009425879972292717,
    );
    for k in AccumulatorKind::ALL {
        let Ok(t) = sat::build(&tex, Some(k)) else {
            continue;
        };
        let got = t.average(r, Wrap::both(WrapMode::ClampToEdge), [0.0; 4]);
        assert!(
            (got[1] - 0xae as f32 / 255.0).abs() < 1e-6,
            "{k:?}: alpha {}",
            got[1]
        );
    }
}

#[test]
fn edges_just_below_zero_match_brute_force_in_every_mode() {
    let v = [10u8, 60, 110, 160, 210];
    let tex = Texture::from_u8(
        5,
        1,
        Format::new(1, ChannelType::U8, ColorSpace::Linear),
        v.to_vec(),
    )
    .unwrap();
    let border = [0.5f32; 4];
    for tiny in [1e-300f64, 2e-113, 1e-20, 1e-17] {
        for (x0, x1) in [(-2.5, -tiny), (-tiny, 3.25), (-7.75, -tiny), (-tiny, 0.5)] {
            for mode in WrapMode::ALL {
                // Brute force: the texels cut by [x0, x1), each weighted
                // by the length it covers.
                let (mut sum, mut len) = (0f64, 0f64);
                let mut i = x0.floor() as i64;
                while (i as f64) < x1 {
                    let w = (x1.min(i as f64 + 1.0) - x0.max(i as f64)).max(0.0);
                    let t = wrap_index(mode, i, 5)
                        .map_or(border[0] as f64, |x| v[x as usize] as f64 / 255.0);
                    sum += w * t;
                    len += w;
                    i += 1;
                }
                let want = sum / len;
                for k in AccumulatorKind::ALL {
                    let Ok(t) = sat::build(&tex, Some(k)) else {
                        continue;
                    };
                    let got = t.average(Rect::new(x0, 0.0, x1, 1.0), Wrap::both(mode), border);
                    assert!(
                        (got[0] as f64 - want).abs() < 1e-5,
                        "{k:?} {mode:?} [{x0}, {x1}): {} vs brute force {want}",
                        got[0]
                    );
                }
            }
        }
    }
}
