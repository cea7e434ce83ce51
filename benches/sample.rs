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
//! Groups:
//! - `1t/rgba8`, `1t/rgbaf32`: one thread, no tracing (the AVX-512 path
//!   where the CPU has it);
//! - `1t/rgba8/portable`: the portable code (`Sampler::set_simd(false)`),
//!   no sink (`NoTrace`);
//! - `1t/rgba8/portable/empty-sink`: the same code through a sink whose
//!   `texel` does nothing: equal to the line above when the no-op sink
//!   compiles away;
//! - `1t/rgba8/traced`: a counting sink (what tracing costs);
//! - `mt/rgba8`: `sample_batch` on all threads.
//!
//! Short run: `cargo bench --bench sample -- --warm-up-time 1 --measurement-time 2`.

use std::hint::black_box;
use std::sync::Arc;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use parvo::sample::{LinearChain, Query, Sampler, SamplerOptions, TexelCounter, TexelSink};
use parvo::scene::{Frame, Plane, RasterOrder, Scene};
use parvo::texel::{ChannelType, ColorSpace, Format};
use parvo::{MipOptions, builtin, mip};

const SIZE: u32 = 2048;

/// A sink that is told every texel and does nothing with it (a tracing
/// sink as far as the sampler knows: `TRACES` keeps its default).
struct EmptySink;

impl TexelSink for EmptySink {
    #[inline(always)]
    fn texel(&mut self, _level: u32, _x: u32, _y: u32) {}
}

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
    Scene::Plane(Plane {
        pitch: 10f64.to_radians(),
        uv_per_unit: 0.05,
        max_distance: 60.0,
        ..Plane::default()
    })
    .queries(Frame::new(256, 256), (SIZE, SIZE), RasterOrder::Scanline)
    .into_iter()
    .map(|(_, q)| q)
    .collect()
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
        ("1t/rgba8/portable", &c8, 3),
        ("1t/rgba8/portable/empty-sink", &c8, 4),
        ("1t/rgba8/traced", &c8, 1),
        ("1t/rgbaf32", &c32, 0),
        ("mt/rgba8", &c8, 2),
    ] {
        let mut g = c.benchmark_group(group);
        for (name, opts, in_cache) in cases() {
            let mut s = Sampler::from_linear(chain.clone(), opts).unwrap();
            s.set_simd(mode != 3 && mode != 4);
            let qs = if in_cache { &qi } else { &qg };
            let mut out = vec![[0f32; 4]; qs.len()];
            g.throughput(Throughput::Elements(qs.len() as u64));
            g.bench_function(name, |b| match mode {
                1 => b.iter(|| {
                    let mut sink = TexelCounter::default();
                    s.sample_slice_traced(black_box(qs), &mut out, &mut sink)
                        .unwrap();
                    black_box(sink.count)
                }),
                4 => b.iter(|| {
                    s.sample_slice_traced(black_box(qs), &mut out, &mut EmptySink)
                        .unwrap()
                }),
                2 => b.iter(|| s.sample_batch(black_box(qs), &mut out).unwrap()),
                _ => b.iter(|| s.sample_slice(black_box(qs), &mut out).unwrap()),
            });
        }
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
