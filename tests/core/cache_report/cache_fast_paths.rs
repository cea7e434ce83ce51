//! The fast paths of the scene runs against the plain ones they replace:
//! the layout's shifted addresses against SPEC.md's formula for every
//! texel, the stand-in of a built-in texture against the chain loaded and
//! mip-mapped from its texels (sizes, format, options), the traces of
//! every filter that does not read values on stand-ins against those on
//! textures of several formats, and a run's counts
//! against a trace recorded query by query and replayed through the plain
//! cache model.

use std::sync::Arc;

use parvo::cache::isotropic::AddressOnly;
use parvo::cache::layout::{ChainLayout, Layout};
use parvo::cache::reference::PlainSimulator;
use parvo::cache::run::{AddressSink, Job, Model, SAT_LEVEL, SceneSetup, unpack};
use parvo::cache::shape::{self, CacheTexture};
use parvo::cache::sim::CacheConfig;
use parvo::sample::{Query, Sampler, SamplerOptions};
use parvo::scene::{Frame, RasterOrder};
use parvo::texel::{ChannelType, ColorSpace, Format};
use parvo::{MipChain, MipOptions, Texture, builtin, mip};

fn layouts() -> Vec<Layout> {
    [
        "linear",
        "tiled:4x4",
        "tiled:8x2",
        "tiled:3x5",
        "morton",
        "morton:8x4",
        "morton:2x16",
        "blocked:4x4:32x32",
        "blocked:2x8:8x16",
        "blocked:3x2:6x4",
    ]
    .iter()
    .map(|l| l.parse().unwrap())
    .collect()
}

#[test]
fn shifted_addresses_equal_the_spec_formula_for_every_texel() {
    let sizes = [(37, 23), (18, 11), (9, 5), (4, 2), (2, 1), (1, 1)];
    for layout in layouts() {
        for c in [
            ChainLayout::new(layout, &sizes, 4),
            ChainLayout::new(layout, &sizes, 12),
            ChainLayout::blocks(layout, &sizes, 16),
        ] {
            for (k, &(w, h)) in sizes.iter().enumerate() {
                for y in 0..h {
                    for x in 0..w {
                        assert_eq!(
                            c.address(k as u32, x, y),
                            c.address_plain(k as u32, x, y),
                            "{layout} level {k} ({x}, {y})"
                        );
                    }
                }
            }
        }
    }
}

fn loaded(name: &str) -> MipChain {
    mip::build(builtin::load(name).unwrap(), &MipOptions::default()).unwrap()
}

fn sizes(c: &MipChain) -> Vec<(u32, u32)> {
    c.levels().iter().map(|l| (l.width(), l.height())).collect()
}

#[test]
fn a_builtin_stand_in_has_the_loaded_chains_sizes_format_and_options() {
    for name in [
        "builtin:checker:100",
        "builtin:checker:1",
        "builtin:zoneplate:37",
        "builtin:bumps:64",
        "builtin:photo:33",
    ] {
        let want = loaded(name);
        let got = CacheTexture::builtin(name).unwrap();
        assert!(got.stand_in && got.blocks.is_none());
        assert_eq!(sizes(&got.chain), sizes(&want), "{name}");
        assert_eq!(got.format(), want.levels()[0].format(), "{name}");
        assert_eq!(got.chain.options(), want.options(), "{name}");
        assert!(CacheTexture::builtin(&name.replace(':', "!")).is_err());
    }
}

/// What `parvo cachesim` loads for a built-in texture (the loader's
/// chain options included) is what the stand-in stands for.
#[cfg(feature = "io")]
#[test]
fn a_builtin_stand_in_matches_what_the_loader_builds() {
    for name in ["builtin:checker:300", "builtin:photo:17"] {
        let (want, blocks) = parvo::io::load(name, &parvo::io::Limits::default())
            .unwrap()
            .into_chain()
            .unwrap();
        assert_eq!(blocks, None);
        let got = CacheTexture::builtin(name).unwrap();
        assert_eq!(sizes(&got.chain), sizes(&want), "{name}");
        assert_eq!(got.format(), want.levels()[0].format(), "{name}");
        assert_eq!(got.chain.options(), want.options(), "{name}");
    }
}

/// A texture of `format` (values from a seeded generator), mip-mapped.
fn texture(w: u32, h: u32, format: Format, seed: u64) -> MipChain {
    let mut x = seed | 1;
    let n = (w * h) as usize * format.channels as usize;
    let values: Vec<f32> = (0..n)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x % 1000) as f32 / 999.0
        })
        .collect();
    let t = Texture::from_linear(w, h, format, &values).unwrap();
    mip::build(t, &MipOptions::default()).unwrap()
}

fn trace(
    texture: &CacheTexture,
    filter: &str,
    scene: &str,
    frame: Frame,
    layout: &str,
) -> (Vec<u64>, u64) {
    let options = SamplerOptions::from_name(filter).unwrap();
    let sampler = Sampler::shared(texture.chain.clone(), options).unwrap();
    let cl = texture.layout(&sampler, layout.parse().unwrap());
    let t = SceneSetup {
        sampler: &sampler,
        layout: &cl,
        scene: scene.parse().unwrap(),
        frame,
        order: RasterOrder::Hilbert,
    }
    .record();
    (t.accesses, t.texel_bytes)
}

/// Which texels a filter reads does not depend on their values, except
/// for `sat`: a stand-in gives the same trace as the texture, for
/// textures of several formats.
#[test]
fn filters_read_the_same_texels_of_a_stand_in() {
    let textures = [
        loaded("builtin:checker:256"),
        loaded("builtin:bumps:64"),
        texture(
            199,
            77,
            Format::new(2, ChannelType::U16, ColorSpace::Linear),
            3,
        ),
        texture(
            64,
            130,
            Format::new(3, ChannelType::F32, ColorSpace::Linear),
            5,
        ),
        texture(
            50,
            50,
            Format::new(4, ChannelType::F16, ColorSpace::Srgb),
            7,
        ),
        texture(
            33,
            21,
            Format::new(1, ChannelType::U8, ColorSpace::Linear),
            9,
        ),
    ];
    for real in textures {
        let (w, h) = (real.levels()[0].width(), real.levels()[0].height());
        let format = real.levels()[0].format();
        let real = CacheTexture::loaded(Arc::new(real), None);
        let stand_in = CacheTexture {
            chain: Arc::new(shape::stand_in(w, h, format, &MipOptions::default()).unwrap()),
            blocks: None,
            stand_in: true,
        };
        for filter in [
            "nearest",
            "bilinear",
            "bilinear-nomip",
            "trilinear",
            "aniso16",
            "ewa",
            "supersample",
        ] {
            let options = SamplerOptions::from_name(filter).unwrap();
            assert!(!shape::reads_depend_on_values(&options));
            for (scene, layout) in [("plane", "tiled:4x4"), ("rotate:23:2.5", "morton")] {
                let frame = Frame::new(71, 43);
                let a = trace(&real, filter, scene, frame, layout);
                let b = trace(&stand_in, filter, scene, frame, layout);
                assert!(!a.0.is_empty());
                assert!(a == b, "{format} {filter} {scene}: the traces differ");
            }
        }
    }
    assert!(shape::reads_depend_on_values(&SamplerOptions::sat()));
}

/// Seeded queries: most inside a few periods, some far outside, some
/// with NaN or infinite coordinates or derivatives, footprints from
/// magnification to minification beyond the last level.
fn queries(seed: u64, n: usize) -> Vec<Query> {
    let mut x = seed | 1;
    let mut next = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n)
        .map(|k| {
            let c = |r: f64| (r * 6.0 - 3.0) as f32;
            let d = |r: f64| ((r * 24.0 - 14.0).exp2() * if r > 0.5 { 1.0 } else { -1.0 }) as f32;
            let mut q = Query::new(
                c(next()),
                c(next()),
                d(next()),
                d(next()),
                d(next()),
                d(next()),
            );
            match k % 23 {
                0 => q.u = f32::NAN,
                1 => q.v = f32::INFINITY,
                2 => q.dudx = f32::NAN,
                3 => q.dvdy = f32::NEG_INFINITY,
                4 => q = q.at(1e7, -3e6),
                5 => q = q.at(0.5, 0.5),
                6 => q = Query::point(q.u, q.v),
                _ => {}
            }
            q
        })
        .collect()
}

/// The address-only isotropic lookups read what the traced sampler
/// reads, read for read, one query at a time and a slice at once, for every magnification, minification and mip
/// filter, every wrap mode on each axis, LOD bias and clamps, and level
/// sizes down to one texel.
#[test]
fn address_only_lookups_read_what_the_sampler_reads() {
    use parvo::sample::{MipMode, TexelFilter, TexelRecorder};
    use parvo::wrap::{Wrap, WrapMode};
    let qs = queries(0x5eed, 700);
    let chains = [
        texture(37, 5, Format::new(4, ChannelType::U8, ColorSpace::Srgb), 1),
        texture(
            1,
            1,
            Format::new(1, ChannelType::F32, ColorSpace::Linear),
            2,
        ),
        texture(
            64,
            64,
            Format::new(2, ChannelType::U16, ColorSpace::Linear),
            3,
        ),
    ];
    let filters = [TexelFilter::Nearest, TexelFilter::Linear];
    let mut combinations = 0;
    for chain in &chains {
        for (k, &wu) in WrapMode::ALL.iter().enumerate() {
            let wv = WrapMode::ALL[(k + 2) % WrapMode::ALL.len()];
            for mag in filters {
                for min in filters {
                    for mip in [MipMode::None, MipMode::Nearest, MipMode::Linear] {
                        for (bias, lo, hi) in [(0.0, 0.0, 1000.0), (0.7, 0.5, 3.0)] {
                            let mut o = SamplerOptions::trilinear();
                            (o.mag, o.min, o.mip) = (mag, min, mip);
                            (o.lod_bias, o.lod_min, o.lod_max) = (bias, lo, hi);
                            o.wrap = Wrap { u: wu, v: wv };
                            let sampler = Sampler::new(chain, o).unwrap();
                            let a = AddressOnly::new(&sampler).unwrap();
                            let mut every = Vec::new();
                            for q in &qs {
                                let mut want = TexelRecorder::new();
                                sampler.sample_traced(q, &mut want);
                                let mut got = TexelRecorder::new();
                                a.trace(q, &mut got);
                                assert_eq!(got.reads, want.reads, "{o:?} {q:?}");
                                every.extend(want.reads);
                            }
                            // The whole slice at once (8 plans at a time
                            // where the CPU can), in the same order.
                            let mut all = TexelRecorder::new();
                            a.trace_slice(&qs, &mut all);
                            assert!(all.reads == every, "{o:?}: the slice's reads differ");
                            combinations += 1;
                        }
                    }
                }
            }
        }
    }
    assert_eq!(combinations, 3 * WrapMode::ALL.len() * 4 * 3 * 2);
    for f in ["aniso2", "ewa", "sat", "supersample"] {
        let s = Sampler::new(&chains[2], SamplerOptions::from_name(f).unwrap()).unwrap();
        assert!(AddressOnly::new(&s).is_none(), "{f}");
    }
}

/// Every read of the frame, one query at a time in raster order through
/// the per-call `Scene::query`, and the pixels that issued one.
fn trace_one_by_one(setup: &SceneSetup<'_>) -> (Vec<u64>, u64) {
    let tex = setup.sampler.chain().level_size(0).unwrap();
    let mut sink = AddressSink::new(setup.layout);
    let mut pixels = 0;
    for (x, y) in setup.order.pixels(setup.frame) {
        if let Some(q) = setup.scene.query(setup.frame, tex, x, y) {
            setup.sampler.sample_traced(&q, &mut sink);
            pixels += 1;
        }
    }
    (sink.out, pixels)
}

/// (accesses, hits, cold, capacity, conflict) of the plain model.
fn plain(accesses: &[u64], cache: &CacheConfig, texel: u64, sat: u64) -> [u64; 5] {
    let mut sim = PlainSimulator::new(cache);
    let mut c = [0; 5];
    for &a in accesses {
        let (addr, level) = unpack(a);
        let bytes = if level == SAT_LEVEL { sat } else { texel };
        for (_, o) in sim.access(addr, bytes) {
            super::tally(&mut c, o);
        }
    }
    c
}

/// The overlapped run (chunks sampled in parallel, queries from the
/// per-frame view, addresses by shifts) counts what the plain model
/// counts on the one-by-one trace, with and without a trace written.
#[test]
fn a_scene_run_equals_the_plain_model_on_a_one_by_one_trace() {
    let chain = loaded("builtin:checker:512");
    let cases = [
        ("trilinear", "plane", "tiled:4x4", "tiled:8", "2K:64:4"),
        ("aniso8", "tunnel", "blocked:4x4:16x16", "morton", "4K:32:2"),
        ("sat", "zoom", "linear", "scanline", "1K:64:1"),
        (
            "bilinear",
            "rotate:41:3",
            "morton:4x4",
            "hilbert",
            "2K:64:32:fifo",
        ),
        ("trilinear", "rotate:17:2.2", "linear", "tiled:4", "4K:64:4"),
        ("nearest", "zoom", "tiled:8x2", "scanline", "1K:32:2"),
        ("bilinear", "plane", "tiled:2x2", "morton", "2K:16:4"),
    ];
    for (filter, scene, layout, order, cache) in cases {
        let cache: CacheConfig = cache.parse().unwrap();
        super::with_setup(
            &chain,
            (filter, scene, layout, order),
            Frame::new(97, 61),
            |setup| {
                let (trace, pixels) = trace_one_by_one(setup);
                let want = plain(
                    &trace,
                    &cache,
                    setup.layout.texel(),
                    setup.layout.sat_entry().unwrap_or(setup.layout.texel()),
                );
                let mut written = Vec::new();
                let runs = [
                    setup
                        .run(&cache, None, &Model::default(), None, &|_, _| {})
                        .unwrap(),
                    setup
                        .simulate(
                            &cache,
                            None,
                            &mut |a| {
                                written.push(a);
                                Ok(())
                            },
                            &|_, _| {},
                        )
                        .unwrap(),
                ];
                assert!(
                    written == trace,
                    "{filter} {scene}: the written trace differs"
                );
                for r in runs {
                    let t = &r.stats.total;
                    assert_eq!(
                        [t.accesses, t.hits, t.cold, t.capacity, t.conflict],
                        want,
                        "{filter} {scene} {layout} {order} {cache}"
                    );
                    assert_eq!((r.pixels, r.reads), (pixels, trace.len() as u64));
                    assert_eq!((r.quads, r.prefetch.len()), (None, 0));
                }
            },
        );
    }
}

/// Per level (index = level tag, the table's entries last) and in total:
/// (accesses, hits, cold, capacity, conflict) of the plain model.
fn plain_per_level(accesses: &[u64], cache: &CacheConfig, levels: usize) -> Vec<[u64; 5]> {
    let mut sim = PlainSimulator::new(cache);
    let mut c = vec![[0u64; 5]; levels + 1];
    for &a in accesses {
        let (addr, level) = unpack(a);
        let k = if level == SAT_LEVEL {
            levels
        } else {
            level as usize
        };
        for (_, o) in sim.access(addr, 4) {
            super::tally(&mut c[k], o);
        }
    }
    c
}

/// Runs keep reads of the last few distinct lines as counts (a window as
/// long as the fewest ways of an all-LRU set of caches, one line
/// otherwise): every counter of every level equals the plain model's on
/// the one-by-one trace, for one cache and for a sweep of caches with
/// mixed ways and policies, on frames of several sampling chunks (the
/// window restarts at each chunk), and a second level sees the same
/// misses as a run of the unmerged trace.
#[test]
fn merged_runs_count_what_the_plain_model_counts_per_level() {
    let chain = loaded("builtin:checker:512");
    let caches: Vec<CacheConfig> = [
        "4K:64:4",
        "2K:64:2",
        "1K:64:1",
        "2K:64:32",
        "4K:32:8",
        "2K:64:4:fifo",
        "2K:64:4:random",
        "8K:128:16",
    ]
    .iter()
    .map(|c| c.parse().unwrap())
    .collect();
    let cases = [
        ("trilinear", "plane", "tiled:4x4", "tiled:8", 211, 97),
        ("trilinear", "rotate:23:1.7", "morton", "scanline", 190, 120),
        ("bilinear", "zoom", "linear", "hilbert", 150, 130),
        ("nearest", "plane", "tiled:8x2", "tiled:4", 200, 90),
    ];
    for (filter, scene, layout, order, w, h) in cases {
        super::with_setup(
            &chain,
            (filter, scene, layout, order),
            Frame::new(w, h),
            |setup| {
                assert!(w * h > 2 * 8192, "the frame spans several chunks");
                let (trace, pixels) = trace_one_by_one(setup);
                let levels = chain.len();
                let check = |r: &parvo::cache::run::RunStats, cache: &CacheConfig, what: &str| {
                    let want = plain_per_level(&trace, cache, levels);
                    for (k, c) in r.stats.per_level.iter().enumerate() {
                        assert_eq!(
                            [c.accesses, c.hits, c.cold, c.capacity, c.conflict],
                            want[k],
                            "{what}: {filter} {scene} {layout} {order} {cache} level {k}"
                        );
                    }
                    let counted: u64 = r.stats.per_level.iter().map(|c| c.accesses).sum();
                    assert_eq!(counted, trace.len() as u64, "{what} {cache}");
                    assert_eq!((r.pixels, r.reads), (pixels, trace.len() as u64));
                };
                for cache in &caches {
                    let r = setup
                        .run(cache, None, &Model::default(), None, &|_, _| {})
                        .unwrap();
                    check(&r, cache, "one cache");
                }
                // Every cache at once (window: the fewest ways, or one line for
                // the FIFO and random ones), and the LRU ones alone (window 4).
                let layouts = [setup.layout];
                for set in [&caches[..], &[caches[0], caches[3], caches[7]][..]] {
                    let jobs: Vec<Job> = set
                        .iter()
                        .map(|&l1| Job {
                            layout: 0,
                            l1,
                            l2: None,
                        })
                        .collect();
                    let runs = setup
                        .run_jobs(&layouts, &jobs, &Model::default(), &|_, _| {})
                        .unwrap();
                    for (r, j) in runs.iter().zip(&jobs) {
                        check(r, &j.l1, "sweep");
                    }
                }
                // A second level behind a 4-way LRU first level.
                let (l1, l2): (CacheConfig, CacheConfig) =
                    ("2K:64:4".parse().unwrap(), "16K:64:8".parse().unwrap());
                let merged = setup
                    .run(&l1, Some(&l2), &Model::default(), None, &|_, _| {})
                    .unwrap();
                let unmerged = setup
                    .simulate(&l1, Some(&l2), &mut |_| Ok(()), &|_, _| {})
                    .unwrap();
                assert_eq!(
                    merged.stats, unmerged.stats,
                    "{filter} {scene}: with a second level"
                );
            },
        );
    }
}
