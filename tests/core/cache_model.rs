//! The cache model against independent references: hand-worked hit/miss
//! sequences, the plain model (access by access, every policy and
//! associativity, both index kinds), the 3C identities, and the layouts'
//! and raster orders' bijectivity.

use std::collections::HashSet;

use parvo::cache::layout::{ChainLayout, Layout};
use parvo::cache::reference::PlainSimulator;
use parvo::cache::sim::{AddressSpace, CacheConfig, Outcome, Policy, Simulator};
use parvo::scene::{Frame, RasterOrder};

use crate::common;
use common::Rng;

use Outcome::{Capacity, Cold, Conflict, Hit};

/// Outcomes of line-sized accesses to the given lines.
fn run(c: CacheConfig, lines: &[u64]) -> Vec<Outcome> {
    let mut sim = Simulator::new(&c, None, AddressSpace::Any, true).unwrap();
    let mut out = Vec::new();
    for &l in lines {
        sim.access_with(l * c.line, c.line, 0, &mut |_, o| out.push(o));
    }
    out
}

#[test]
fn lru_on_a_hand_worked_trace() {
    // One set of two ways (fully associative): A B A C B.
    // C evicts B (A was used more recently); B then misses, and a fully
    // associative cache of two lines misses too: capacity.
    let c = CacheConfig::new(128, 64, 2);
    assert_eq!(run(c, &[0, 1, 0, 2, 1]), [Cold, Cold, Hit, Cold, Capacity]);
    // Four ways over lines 0..5 cycled twice: LRU thrashes.
    let c = CacheConfig::new(256, 64, 4);
    let mut want = vec![Cold; 5];
    want.extend([Capacity; 5]);
    assert_eq!(run(c, &[0, 1, 2, 3, 4, 0, 1, 2, 3, 4]), want);
}

#[test]
fn fifo_on_a_hand_worked_trace() {
    // A B A C A: the hit on A does not refresh it, so C evicts A (the
    // oldest) and A misses; LRU would have kept A: a conflict miss by the
    // 3C definition (the fully associative LRU shadow hits).
    let mut c = CacheConfig::new(128, 64, 2);
    c.policy = Policy::Fifo;
    assert_eq!(run(c, &[0, 1, 0, 2, 0]), [Cold, Cold, Hit, Cold, Conflict]);
}

#[test]
fn direct_mapped_lines_of_one_set_conflict() {
    // Two sets, one way: lines 0 and 2 share set 0.
    let c = CacheConfig::new(128, 64, 1);
    assert_eq!(run(c, &[0, 2, 0, 1, 0]), [Cold, Cold, Conflict, Cold, Hit]);
}

#[test]
fn sectors_fetch_only_what_is_missing() {
    let mut c = CacheConfig::new(1024, 128, 2);
    c.sector = Some(32);
    let mut sim = Simulator::new(&c, None, AddressSpace::Any, true).unwrap();
    let mut out = Vec::new();
    for (a, b) in [(0u64, 4u64), (32, 4), (0, 4), (60, 8)] {
        sim.access_with(a, b, 0, &mut |_, o| out.push(o));
    }
    // (60, 8) spans sectors 1 and 2 of line 0: sector 2 is missing.
    assert_eq!(out, [Cold, Cold, Hit, Cold]);
    assert_eq!(sim.stats().total.bytes_fetched, 3 * 32);
    // An access spanning two lines touches both.
    let mut sim = Simulator::new(
        &CacheConfig::new(1024, 64, 2),
        None,
        AddressSpace::Any,
        true,
    )
    .unwrap();
    sim.access(60, 8, 0);
    assert_eq!(sim.stats().total.accesses, 2);
}

#[test]
fn a_second_level_sees_the_first_levels_misses() {
    let l1 = CacheConfig::new(128, 64, 2);
    let l2 = CacheConfig::new(1024, 64, 4);
    let mut sim = Simulator::new(&l1, Some(&l2), AddressSpace::Any, true).unwrap();
    for l in [0u64, 1, 2, 0, 1, 2] {
        sim.access(l * 64, 4, 0);
    }
    let s = sim.stats();
    // L1 (two lines) misses all six; L2 holds all three after the first
    // round: 3 misses, 3 hits.
    assert_eq!(s.total.misses, 6);
    let l2s = s.l2.unwrap();
    assert_eq!((l2s.accesses, l2s.misses, l2s.hits), (6, 3, 3));
    assert_eq!(s.bytes_from_memory(), 3 * 64);
}

/// A trace with locality: a random walk over lines, with jumps.
fn trace(rng: &mut Rng, n: usize, span: u64) -> Vec<(u64, u64)> {
    let mut pos = 0i64;
    (0..n)
        .map(|_| {
            let r = rng.next_u64();
            if r.is_multiple_of(16) {
                pos = (rng.next_u64() % span) as i64;
            } else {
                pos += (r % 9) as i64 - 4;
            }
            let a = (pos.rem_euclid(span as i64) as u64) * 4;
            let bytes = [4u64, 4, 8, 16, 2][(r >> 8) as usize % 5];
            (a, bytes)
        })
        .collect()
}

#[test]
fn the_fast_simulator_matches_the_plain_model_access_by_access() {
    let mut rng = Rng(0xcac4e);
    let mut configs = Vec::new();
    for (size, line) in [(1024u64, 16u64), (4096, 64), (2048, 8)] {
        let lines = size / line;
        for ways in [1, 2, 4, 8, 32, lines] {
            if lines % ways != 0 {
                continue;
            }
            for policy in [Policy::Lru, Policy::Fifo, Policy::Random] {
                for sector in [None, Some(line / 4).filter(|&s| s >= 2)] {
                    let mut c = CacheConfig::new(size, line, ways);
                    c.policy = policy;
                    c.sector = sector;
                    c.seed = rng.next_u64();
                    configs.push(c);
                }
            }
        }
    }
    assert!(configs.len() > 80);
    for c in configs {
        let t = trace(&mut rng, 6000, 3000);
        for space in [AddressSpace::Any, AddressSpace::Bounded(3000 * 4 + 64)] {
            let mut fast = Simulator::new(&c, None, space, true).unwrap();
            let mut plain = PlainSimulator::new(&c);
            for (i, &(a, b)) in t.iter().enumerate() {
                let mut got = Vec::new();
                fast.access_with(a, b, 0, &mut |l, o| got.push((l, o)));
                let want = plain.access(a, b);
                assert_eq!(got, want, "{c} {space:?}: access {i} ({a}, {b})");
            }
            // The 3C identities.
            let s = fast.stats().total;
            assert_eq!(s.cold + s.capacity + s.conflict, s.misses, "{c}");
            assert_eq!(s.hits + s.misses, s.accesses, "{c}");
            let distinct: HashSet<u64> = t
                .iter()
                .flat_map(|&(a, b)| (a / c.line)..=((a + b - 1) / c.line))
                .collect();
            assert_eq!(s.lines_touched, distinct.len() as u64, "{c}");
            if c.sector.is_none() {
                assert_eq!(
                    s.cold,
                    distinct.len() as u64,
                    "{c}: cold misses are distinct lines"
                );
            }
        }
    }
}

#[test]
fn cache_specs_parse_and_impossible_caches_name_the_rule() {
    for (s, want) in [
        ("16384:64:4", (16384, 64, 4)),
        ("16K:64:4", (16384, 64, 4)),
        ("16KiB:64:4:fifo", (16384, 64, 4)),
        ("4M:128:16", (4 << 20, 128, 16)),
        ("16M:4:16", (16 << 20, 4, 16)),
        ("1K:64:full", (1024, 64, 16)),
    ] {
        let c: CacheConfig = s.parse().unwrap();
        assert_eq!((c.size, c.line, c.ways), want, "{s}");
    }
    for (s, rule) in [
        ("16K:48:4", "not a power of two"),
        ("16K:64:3", "not a multiple of line × ways"),
        ("0:64:1", "at least 1"),
        ("16K:64", "SIZE:LINE:WAYS"),
        ("16K:64:4:mru", "lru, fifo or random"),
        // 2^32 · 2^32 wrapped to 0 (a panic with overflow checks).
        ("16K:4G:4294967296", "overflows"),
    ] {
        let e = s.parse::<CacheConfig>().unwrap_err().to_string();
        assert!(e.contains(rule), "{s}: {e}");
    }
}

#[test]
fn every_layout_is_bijective_and_in_bounds() {
    let layouts: Vec<Layout> = [
        "linear",
        "tiled:4x4",
        "tiled:8x2",
        "morton",
        "morton:4x4",
        "morton:8x2",
        "blocked:4x4:32x32",
        "blocked:2x4:8x8",
    ]
    .iter()
    .map(|s| s.parse().unwrap())
    .collect();
    for (w, h) in [(1u32, 1u32), (3, 5), (257, 129), (4096, 16)] {
        let sizes = parvo::mip::level_sizes(w, h, parvo::Rounding::Down, None);
        for &l in &layouts {
            for texel in [4u64, 12, 16] {
                let c = ChainLayout::new(l, &sizes, texel).with_sat(w, h, 16);
                let mut all = Vec::new();
                for (k, &(lw, lh)) in sizes.iter().enumerate() {
                    let base = c.level_base(k);
                    assert_eq!(base % 4096, 0);
                    for y in 0..lh {
                        for x in 0..lw {
                            let a = c.address(k as u32, x, y);
                            assert_eq!((a - base) % texel, 0);
                            assert!(
                                a + texel <= c.total_bytes(),
                                "{l} {w}x{h} level {k} ({x},{y})"
                            );
                            assert_eq!(c.level_of(a), Some(k as u32));
                            all.push(a);
                        }
                    }
                }
                // Distinct, non-overlapping byte ranges [a, a + texel).
                all.sort_unstable();
                assert!(
                    all.windows(2).all(|p| p[1] >= p[0] + texel),
                    "{l} {w}x{h} texel {texel}: overlap"
                );
                // Table entries after the chain, distinct and in bounds.
                let mut sat = HashSet::new();
                for y in [0, h / 2, h] {
                    for x in [0, w / 2, w] {
                        let a = c.sat_address(x, y).unwrap();
                        assert!(a + 16 <= c.total_bytes() && c.level_of(a).is_none());
                        sat.insert(a);
                    }
                }
            }
        }
    }
}

#[test]
fn raster_orders_visit_every_pixel_exactly_once() {
    for (w, h) in [(1u32, 1u32), (7, 5), (33, 17), (100, 3), (3, 100)] {
        for order in ["scanline", "tiled:4", "tiled:8", "morton", "hilbert"] {
            let o: RasterOrder = order.parse().unwrap();
            let px: Vec<(u32, u32)> = o.pixels(Frame::new(w, h)).collect();
            let set: HashSet<(u32, u32)> = px.iter().copied().collect();
            assert_eq!(px.len(), (w * h) as usize, "{order} {w}x{h}");
            assert_eq!(set.len(), px.len(), "{order} {w}x{h}");
            assert!(px.iter().all(|&(x, y)| x < w && y < h));
        }
    }
    // tiled:2 on 3x3 visits the 2x2 tile first, then the partial ones.
    let px: Vec<(u32, u32)> = RasterOrder::Tiled(2).pixels(Frame::new(3, 3)).collect();
    assert_eq!(&px[..5], &[(0, 0), (1, 0), (0, 1), (1, 1), (2, 0)]);
}

/// A `sat` sampler's table reads have no addresses in a layout of the
/// chain alone: the run is refused, not simulated without them; the
/// sampler's own layout lays the table out and runs.
#[test]
fn sat_sampler_with_a_layout_without_its_table_is_refused() {
    use parvo::cache::run::SceneSetup;
    use parvo::sample::{Sampler, SamplerOptions};
    use parvo::{MipOptions, builtin, mip};
    let chain = mip::build(
        builtin::load("builtin:checker:64").unwrap(),
        &MipOptions::default(),
    )
    .unwrap();
    let sampler = Sampler::new(&chain, SamplerOptions::sat()).unwrap();
    let cache: CacheConfig = "16K:64:4".parse().unwrap();
    let without = ChainLayout::of_chain(&chain, Layout::Linear);
    let with = ChainLayout::for_sampler(&chain, &sampler, Layout::Linear);
    assert_eq!(without.sat_address(0, 0), None);
    assert!(with.sat_address(0, 0).is_some());
    for (layout, ok) in [(&without, false), (&with, true)] {
        let setup = SceneSetup {
            sampler: &sampler,
            layout,
            scene: "plane".parse().unwrap(),
            frame: Frame::new(32, 24),
            order: RasterOrder::Scanline,
        };
        let r = setup.simulate(&cache, None, &mut |_| Ok(()), &|_, _| {});
        assert_eq!(r.is_ok(), ok, "{:?}", r.err());
    }
}
