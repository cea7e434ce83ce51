//! Sampler throughput in queries per second (criterion).
//!
//! Texture: the 2048² checker (RGBA8 sRGB) and the same converted to RGBA
//! f32 linear, box mips. Query sets:
//! - `incache`: a 200×200 pixel block minified by 1.2 and rotated by 10°,
//!   so the texels it reads (about 240² of level 0 plus level 1) stay in
//!   the L2 cache — the "texture in cache" case of the goals;
//! - `grazing`: a 256×256 perspective ground plane 10° below the horizon,
//!   anisotropy up to 16 (what aniso and EWA are for).
//!
//! Groups: `1t/rgba8` (one thread, no tracing), `1t/rgba8/traced` (a
//! counting sink, to show what tracing costs and that `NoTrace` is free),
//! `1t/rgbaf32`, `mt/rgba8` (`sample_batch` on all threads).
//!
//! Short run: `cargo bench --bench sample -- --warm-up-time 1 --measurement-time 2`.

use std::hint::black_box;
use std::sync::Arc;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use parvo::sample::plane::GroundPlane;
use parvo::sample::{LinearChain, Query, Sampler, SamplerOptions, TexelCounter};
use parvo::texel::{ChannelType, ColorSpace, Format};
use parvo::{MipOptions, builtin, mip};

const SIZE: u32 = 2048;

fn incache() -> Vec<Query> {
    let n = 200;
    let s = 1.2 / SIZE as f64;
    let (sn, cs) = 10f64.to_radians().sin_cos();
    let mut v = Vec::with_capacity(n * n);
    for py in 0..n {
        for px in 0..n {
            let (x, y) = (px as f64, py as f64);
            let u = 0.3 + (x * cs - y * sn) * s;
            let w = 0.3 + (x * sn + y * cs) * s;
            v.push(Query::new(
                u as f32,
                w as f32,
                (cs * s) as f32,
                (sn * s) as f32,
                (-sn * s) as f32,
                (cs * s) as f32,
            ));
        }
    }
    v
}

fn grazing() -> Vec<Query> {
    GroundPlane {
        width: 256,
        height: 256,
        pitch: 10f64.to_radians(),
        uv_per_unit: 0.05,
        max_distance: 60.0,
        ..Default::default()
    }
    .queries()
}

fn chains() -> (Arc<LinearChain>, Arc<LinearChain>) {
    let tex = builtin::load(&format!("builtin:checker:{SIZE}")).unwrap();
    let f32tex = tex
        .convert(Format::new(4, ChannelType::F32, ColorSpace::Linear))
        .unwrap();
    let o = MipOptions::default();
    let c8 = LinearChain::new(&mip::build(tex, &o).unwrap());
    let c32 = LinearChain::new(&mip::build(f32tex, &o).unwrap());
    (Arc::new(c8), Arc::new(c32))
}

fn cases() -> Vec<(&'static str, SamplerOptions, bool)> {
    vec![
        ("nearest/incache", SamplerOptions::nearest(), true),
        ("bilinear/incache", SamplerOptions::bilinear(), true),
        ("trilinear/incache", SamplerOptions::trilinear(), true),
        ("trilinear/grazing", SamplerOptions::trilinear(), false),
        ("aniso4/grazing", SamplerOptions::aniso(4), false),
        ("aniso16/grazing", SamplerOptions::aniso(16), false),
        ("ewa/grazing", SamplerOptions::ewa(), false),
    ]
}

fn bench(c: &mut Criterion) {
    let (c8, c32) = chains();
    let (qi, qg) = (incache(), grazing());
    for (group, chain, mode) in [
        ("1t/rgba8", &c8, 0),
        ("1t/rgba8/traced", &c8, 1),
        ("1t/rgbaf32", &c32, 0),
        ("mt/rgba8", &c8, 2),
    ] {
        let mut g = c.benchmark_group(group);
        for (name, opts, in_cache) in cases() {
            let s = Sampler::from_linear(chain.clone(), opts).unwrap();
            let qs = if in_cache { &qi } else { &qg };
            let mut out = vec![[0f32; 4]; qs.len()];
            g.throughput(Throughput::Elements(qs.len() as u64));
            g.bench_function(name, |b| match mode {
                0 => b.iter(|| s.sample_slice(black_box(qs), &mut out).unwrap()),
                1 => b.iter(|| {
                    let mut sink = TexelCounter::default();
                    s.sample_slice_traced(black_box(qs), &mut out, &mut sink)
                        .unwrap();
                    black_box(sink.count)
                }),
                _ => b.iter(|| s.sample_batch(black_box(qs), &mut out).unwrap()),
            });
        }
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
