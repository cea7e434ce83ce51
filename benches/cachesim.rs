//! The cache simulator's core on a recorded texel trace (accesses/s, one
//! thread): the 1920×1080 trilinear `plane` frame of a 4096² checker in a
//! tiled:4x4 layout, about 13 M texel reads, replayed through 16K:64:4
//! LRU with and without the 3C classification (the fully associative
//! shadow), plus a direct-mapped and a FIFO cache, and the end-to-end scene
//! run (sampling and simulation, both threads).
//!
//! ```text
//! cargo bench --bench cachesim -- --warm-up-time 1 --measurement-time 3
//! ```
//! For scale, pycachesim's C core (`scripts/interop/cache_pycachesim.py`
//! prints its bulk-load speed on the same trace).

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use parvo::cache::layout::ChainLayout;
use parvo::cache::run::{SceneSetup, Trace, unpack};
use parvo::cache::sim::{AddressSpace, CacheConfig, Simulator};
use parvo::sample::{Sampler, SamplerOptions};
use parvo::scene::{Frame, RasterOrder, Scene};
use parvo::{MipOptions, builtin, mip};

fn setup() -> (Trace, u64) {
    let chain = mip::build(
        builtin::load("builtin:checker:4096").unwrap(),
        &MipOptions::default(),
    )
    .unwrap();
    let sampler = Sampler::new(&chain, SamplerOptions::trilinear()).unwrap();
    let layout = ChainLayout::for_sampler(&chain, &sampler, "tiled:4x4".parse().unwrap());
    let s = SceneSetup {
        sampler: &sampler,
        layout: &layout,
        scene: Scene::default(),
        frame: Frame::new(1920, 1080),
        order: RasterOrder::Scanline,
    };
    (s.record(), layout.total_bytes())
}

fn replay(trace: &Trace, c: &CacheConfig, space: AddressSpace, classify: bool) -> u64 {
    let mut sim = Simulator::new(c, None, space, classify).unwrap();
    for &a in &trace.accesses {
        let (addr, level) = unpack(a);
        sim.access(addr, trace.texel_bytes, level);
    }
    sim.stats().total.misses
}

fn core(c: &mut Criterion) {
    let (trace, total) = setup();
    let n = trace.accesses.len() as u64;
    let mut g = c.benchmark_group("cachesim");
    g.throughput(Throughput::Elements(n));
    g.sample_size(10);
    let bounded = AddressSpace::Bounded(total);
    for (name, spec, classify) in [
        ("16K:64:4 lru", "16K:64:4", false),
        ("16K:64:4 lru 3c", "16K:64:4", true),
        ("16K:64:1 direct", "16K:64:1", false),
        ("16K:64:8 fifo", "16K:64:8:fifo", false),
    ] {
        let cfg: CacheConfig = spec.parse().unwrap();
        g.bench_function(name, |b| {
            b.iter(|| black_box(replay(&trace, &cfg, bounded, classify)))
        });
    }
    let cfg: CacheConfig = "16K:64:4".parse().unwrap();
    g.bench_function("16K:64:4 lru, hashed index (trace mode)", |b| {
        b.iter(|| black_box(replay(&trace, &cfg, AddressSpace::Any, true)))
    });
    g.finish();
}

criterion_group!(benches, core);
criterion_main!(benches);
