//! Cache simulation of arbitrary configurations and traces, and texel
//! addresses of arbitrary layouts and chain sizes: a configuration either
//! validates or is refused; the fast simulator reports, access by access,
//! what the plain model reports (for both address-space modes), with the
//! 3C identities; every layout maps each texel of a chain to a distinct
//! address inside the chain.
//!
//! The body of `fuzz/fuzz_targets/cachesim.rs`, shared with the replay test
//! (`tests/core/fuzz_replay.rs` or `tests/cli/fuzz_replay.rs`), which runs it
//! over `fuzz/seeds/cachesim` and every kept artifact in the checks-on test build.

use std::collections::HashSet;

use parvo::cache::layout::{ChainLayout, Layout};
use parvo::cache::reference::PlainSimulator;
use parvo::cache::sim::{AddressSpace, CacheConfig, Policy, Simulator};

/// One input of the `cachesim` target: any outcome but a panic (or a failed
/// assertion below) is a pass.
pub fn run(data: &[u8]) {
    if data.len() < 12 {
        return;
    }
    // A small cache: 2^6 … 2^13 bytes, lines of 2^1 … 2^7 bytes.
    let line = 1u64 << (1 + data[0] % 7);
    let size = 1u64 << (6 + data[1] % 8);
    let ways = 1 + data[2] as u64 % 40;
    let mut c = CacheConfig::new(size, line, ways);
    c.policy = [Policy::Lru, Policy::Fifo, Policy::Random][data[3] as usize % 3];
    c.sector = match data[4] % 3 {
        0 => None,
        1 => Some(line / 2),
        _ => Some(line / 4),
    };
    c.seed = u64::from(data[5]);
    // A layout of arbitrary tile sizes (through its parser) and a chain
    // of arbitrary (small) sizes.
    let (tw, th) = (1 + u32::from(data[7] % 16), 1 + u32::from(data[8] % 16));
    let name = match data[6] % 5 {
        0 => "linear".to_string(),
        1 => format!("tiled:{tw}x{th}"),
        2 => "morton".to_string(),
        3 => format!("morton:{}x{}", 1 << (tw % 5), 1 << (th % 5)),
        _ => format!(
            "blocked:{tw}x{th}:{}x{}",
            tw * (1 + u32::from(data[9] % 4)),
            th * 2
        ),
    };
    let layout: Layout = name.parse().expect("a layout the parser accepts");
    let (w, h) = (1 + u32::from(data[10]) % 37, 1 + u32::from(data[11]) % 37);
    let sizes = parvo::mip::level_sizes(w, h, parvo::Rounding::Down, None);
    let texel = 1 + u64::from(data[9] % 16);
    let cl = ChainLayout::new(layout, &sizes, texel).with_sat(w, h, 16);
    let mut seen = HashSet::new();
    for (k, &(lw, lh)) in sizes.iter().enumerate() {
        for y in 0..lh {
            for x in 0..lw {
                let a = cl.address(k as u32, x, y);
                assert!(
                    a + texel <= cl.total_bytes(),
                    "{layout} {w}x{h}: ({k}, {x}, {y})"
                );
                // Non-overlapping texels differ by at least `texel` bytes.
                assert!(
                    seen.insert(a / texel),
                    "{layout} {w}x{h}: ({k}, {x}, {y}) overlaps"
                );
                assert_eq!(cl.level_of(a), Some(k as u32), "{layout}");
            }
        }
    }
    if c.validate().is_err() {
        return;
    }
    // The trace: 3 bytes per access (address in 16 bits, size code).
    let trace: Vec<(u64, u64)> = data[12..]
        .chunks_exact(3)
        .map(|b| {
            let a = u64::from(u16::from_le_bytes([b[0], b[1]]));
            (a, [1u64, 2, 4, 8, 16, 3, 5, 32][b[2] as usize % 8])
        })
        .take(4096)
        .collect();
    for space in [AddressSpace::Any, AddressSpace::Bounded((1 << 16) + 64)] {
        let Ok(mut fast) = Simulator::new(&c, None, space, true) else {
            return;
        };
        let mut plain = PlainSimulator::new(&c);
        for (i, &(a, b)) in trace.iter().enumerate() {
            let mut got = Vec::new();
            fast.access_with(a, b, 0, &mut |l, o| got.push((l, o)));
            let want = plain.access(a, b);
            assert_eq!(got, want, "{c} {space:?}: access {i} ({a}, {b})");
        }
        let s = fast.stats().total;
        assert_eq!(s.cold + s.capacity + s.conflict, s.misses, "{c}");
        assert_eq!(s.hits + s.misses, s.accesses, "{c}");
    }
}
