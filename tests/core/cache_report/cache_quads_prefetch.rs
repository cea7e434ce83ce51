//! The quad model against brute force and the prefetch model against a
//! trace worked by hand and its two properties.
//!
//! Quads: each quad's texel reads are recorded pixel by pixel with the
//! per-call `Scene::query`, the set of cache lines they touch is taken in
//! first-touch order, and those lines go one by one through the plain
//! cache model; the library's quad run must count the same requests,
//! hits and 3C misses. Prefetching: the model's definition
//! (`cache::prefetch`) followed by hand on five fragments; on random
//! traces and on a scene, a FIFO of depth 0 is the blocking cache (its
//! stall-free hit rate is the hit rate) and a deeper FIFO never takes more
//! cycles.

use parvo::cache::layout::ChainLayout;
use parvo::cache::prefetch::{Prefetch, PrefetchStats, Timing};
use parvo::cache::reference::PlainSimulator;
use parvo::cache::run::{AddressSink, Model, SAT_LEVEL, SceneSetup, unpack};
use parvo::cache::sim::CacheConfig;
use parvo::sample::{Sampler, SamplerOptions};
use parvo::scene::{Frame, Scene};
use parvo::{MipChain, MipOptions, builtin, mip};

fn chain() -> MipChain {
    mip::build(
        builtin::load("builtin:zoneplate:300").unwrap(),
        &MipOptions::default(),
    )
    .unwrap()
}

/// Per quad in the order's quad grid: the distinct lines its pixels'
/// reads touch, first touched first; and the pixels and reads.
fn quad_lines(setup: &SceneSetup<'_>, line: u64) -> (Vec<Vec<u64>>, u64, u64) {
    let tex = setup.sampler.chain().level_size(0).unwrap();
    let f = setup.frame;
    let (mut quads, mut pixels, mut reads) = (Vec::new(), 0, 0);
    for (qx, qy) in setup.order.quads(f) {
        let mut sink = AddressSink::new(setup.layout);
        for (x, y) in [(2 * qx, 2 * qy), (2 * qx + 1, 2 * qy), (2 * qx, 2 * qy + 1)]
            .into_iter()
            .chain([(2 * qx + 1, 2 * qy + 1)])
        {
            if x < f.width
                && y < f.height
                && let Some(q) = setup.scene.query(f, tex, x, y)
            {
                setup.sampler.sample_traced(&q, &mut sink);
                pixels += 1;
            }
        }
        if sink.out.is_empty() {
            continue;
        }
        reads += sink.out.len() as u64;
        let mut lines: Vec<u64> = Vec::new();
        for &a in &sink.out {
            let (addr, level) = unpack(a);
            let bytes = if level == SAT_LEVEL {
                setup.layout.sat_entry().unwrap()
            } else {
                setup.layout.texel()
            };
            for l in addr / line..=(addr + bytes - 1) / line {
                if !lines.contains(&l) {
                    lines.push(l);
                }
            }
        }
        quads.push(lines);
    }
    (quads, pixels, reads)
}

#[test]
fn quad_requests_equal_the_brute_force_set_of_lines_per_quad() {
    let chain = chain();
    let cases = [
        ("trilinear", "plane", "tiled:4x4", "tiled:8", "2K:64:4"),
        ("bilinear", "rotate:33:1.6", "linear", "scanline", "1K:32:2"),
        ("aniso4", "tunnel", "morton", "hilbert", "4K:64:8:fifo"),
        ("sat", "zoom", "tiled:8x8", "tiled:5", "2K:128:1"),
    ];
    for (filter, scene, layout, order, cache) in cases {
        let cache: CacheConfig = cache.parse().unwrap();
        super::with_setup(
            &chain,
            (filter, scene, layout, order),
            Frame::new(45, 31),
            |setup| {
                let (quads, pixels, reads) = quad_lines(setup, cache.line);
                let mut plain = PlainSimulator::new(&cache);
                let mut want = [0u64; 5];
                for lines in &quads {
                    for &l in lines {
                        for (_, o) in plain.access(l * cache.line, 1) {
                            super::tally(&mut want, o);
                        }
                    }
                }
                let model = Model {
                    quads: true,
                    prefetch: Vec::new(),
                };
                let r = setup.run(&cache, None, &model, None, &|_, _| {}).unwrap();
                let t = &r.stats.total;
                let what = format!("{filter} {scene} {layout} {order} {cache}");
                assert_eq!(
                    [t.accesses, t.hits, t.cold, t.capacity, t.conflict],
                    want,
                    "{what}"
                );
                assert_eq!(r.quads, Some(quads.len() as u64), "{what}");
                assert_eq!((r.pixels, r.reads), (pixels, reads), "{what}");
                // Merging only removes requests: fewer than reads, and the quad's
                // four pixels share lines.
                assert!(t.accesses < reads, "{what}");
            },
        );
    }
}

fn timing(depth: u32, latency: u32, request_cycles: u32) -> Timing {
    Timing {
        depth,
        latency,
        request_cycles,
    }
}

fn run_model(fragments: &[Vec<(u64, bool)>], timings: &[Timing]) -> Vec<PrefetchStats> {
    let mut p = Prefetch::new(timings, 64).unwrap();
    for f in fragments {
        p.fragment(f);
    }
    p.stats()
}

/// Five fragments worked by hand from the model's definition (latency
/// 10, a request per cycle): A missed, A hit, B and C missed, A hit, B
/// hit.
#[test]
fn the_model_follows_a_hand_worked_trace() {
    let (a, b, c) = (1, 2, 3);
    let frags = vec![
        vec![(a, true)],
        vec![(a, false)],
        vec![(b, true), (c, true)],
        vec![(a, false)],
        vec![(b, false)],
    ];
    let s = run_model(
        &frags,
        &[timing(0, 10, 1), timing(1, 10, 1), timing(4, 10, 1)],
    );
    // D = 0: F0 enters at 0, A back at 10, leaves 11; F1 enters 11, leaves
    // 12; F2 enters 12, B requested 12 (back 22), C 13 (back 23), leaves
    // 24; F3 leaves 25, F4 26.
    // D = 1: F1 enters 1 and starts at 11 (leaves 12); F2 may enter when F0
    // has left (11): B back 21, C 22, starts 12, leaves 23; F3 enters 12,
    // starts 23, leaves 24; F4 enters 23, starts 24, leaves 25.
    // D = 4: all enter at once (0..4): B requested 2 (back 12), C 3 (13);
    // F2 starts 12 with B there and C not, leaves 14; F3 15, F4 16.
    let got: Vec<(u64, u64, u64)> = s
        .iter()
        .map(|p| (p.cycles, p.stalled_fragments, p.stall_free_requests))
        .collect();
    assert_eq!(got, vec![(26, 2, 3), (25, 2, 3), (16, 2, 4)]);
    for p in &s {
        assert_eq!((p.fragments, p.requests, p.misses), (5, 6, 3));
        assert_eq!(p.blocking_cycles, 26);
    }
    assert_eq!(s[2].stall_cycles(), 11);
    assert!((s[2].latency_hidden() - 10.0 / 21.0).abs() < 1e-12);
    // Two cycles per request: C is requested at 4, back at 14; F2 leaves
    // 15, F3 16, F4 17.
    assert_eq!(run_model(&frags, &[timing(4, 10, 2)])[0].cycles, 17);
    // Without latency only bandwidth stalls: F2's two requests take two
    // cycles (C back at 3, F2 leaves 4), so the frame takes 6.
    let z = &run_model(&frags, &[timing(0, 0, 1)])[0];
    assert_eq!(
        (z.cycles, z.stalled_fragments, z.stall_free_requests),
        (6, 1, 5)
    );
    // A fragment's repeat of a line it requested is that request.
    let mut again = frags.clone();
    again[2].push((b, false));
    again[0].push((a, false));
    assert_eq!(
        run_model(&again, &[timing(4, 10, 1)]),
        run_model(&frags, &[timing(4, 10, 1)])
    );
}

/// A seeded stream of fragments as a cache would report them: a line's
/// first request is a miss, later ones miss with some probability.
fn random_fragments(seed: u64, n: usize) -> Vec<Vec<(u64, bool)>> {
    let mut x = seed | 1;
    let mut next = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    let mut seen = [false; 64];
    (0..n)
        .map(|_| {
            (0..next() % 5)
                .map(|_| {
                    let l = next() % 64;
                    let miss = !seen[l as usize] || next() % 4 == 0;
                    seen[l as usize] = true;
                    (l, miss)
                })
                .collect()
        })
        .collect()
}

fn assert_properties(s: &[PrefetchStats], what: &str) {
    let d0 = &s[0];
    assert_eq!(d0.timing.depth, 0);
    assert_eq!(d0.cycles, d0.blocking_cycles, "{what}");
    if d0.timing.latency > 0 {
        assert_eq!(
            d0.stall_free_requests,
            d0.requests - d0.misses,
            "{what}: depth 0 is the plain cache"
        );
    }
    for w in s.windows(2) {
        assert!(w[0].timing.depth < w[1].timing.depth);
        assert!(
            w[1].cycles <= w[0].cycles,
            "{what}: depth {} takes {} cycles, depth {} {}",
            w[1].timing.depth,
            w[1].cycles,
            w[0].timing.depth,
            w[0].cycles
        );
    }
    for p in s {
        assert!(p.cycles >= p.fragments, "{what}");
        assert!((0.0..=1.0).contains(&p.latency_hidden()), "{what}");
    }
}

#[test]
fn depth_zero_is_the_plain_cache_and_deeper_fifos_never_take_longer() {
    let depths = [0, 1, 2, 3, 7, 16, 100, 5000];
    for seed in [1, 7, 12345, 0xdead_beef] {
        let frags = random_fragments(seed, 3000);
        for (latency, every) in [(1, 1), (37, 1), (200, 3), (0, 2)] {
            let t: Vec<Timing> = depths.iter().map(|&d| timing(d, latency, every)).collect();
            let s = run_model(&frags, &t);
            assert_properties(&s, &format!("seed {seed} latency {latency}/{every}"));
        }
    }
}

#[test]
fn a_scene_run_reports_the_properties_for_pixels_and_quads() {
    let chain = chain();
    let sampler = Sampler::new(&chain, SamplerOptions::trilinear()).unwrap();
    let cl = ChainLayout::for_sampler(&chain, &sampler, "tiled:4x4".parse().unwrap());
    let setup = SceneSetup {
        sampler: &sampler,
        layout: &cl,
        scene: Scene::default(),
        frame: Frame::new(64, 48),
        order: "tiled:8".parse().unwrap(),
    };
    let cache: CacheConfig = "1K:64:4".parse().unwrap();
    let plain = setup
        .run(&cache, None, &Model::default(), None, &|_, _| {})
        .unwrap();
    for quads in [false, true] {
        let model = Model {
            quads,
            prefetch: [0, 4, 32, 256].map(|d| timing(d, 100, 1)).to_vec(),
        };
        let r = setup.run(&cache, None, &model, None, &|_, _| {}).unwrap();
        let t = &r.stats.total;
        for p in &r.prefetch {
            assert_eq!(p.misses, t.misses);
        }
        if !quads {
            // Timing changes nothing the cache counts; a pixel's repeats
            // of a line are one request.
            assert_eq!(r.stats, plain.stats);
            assert_eq!(r.prefetch[0].fragments, r.pixels);
            assert!(r.prefetch[0].requests < t.accesses);
        } else {
            // A quad's requests are distinct lines already.
            assert_eq!(Some(r.prefetch[0].fragments), r.quads);
            assert_eq!(r.prefetch[0].requests, t.accesses);
        }
        assert_properties(&r.prefetch, &format!("quads {quads}"));
        assert!(r.prefetch[3].stall_cycles() < r.prefetch[0].stall_cycles());
    }
}
