//! The cache model's fast paths, its quad and prefetch models, and the
//! trade-off report and cache sweep as library calls, modules of the
//! `core` test binary (see `tests/core/main.rs` for why one binary);
//! `cargo test --release --test core cache_report::MODULE::` runs one.

mod cache_fast_paths;
mod cache_quads_prefetch;
mod report_library;

use parvo::MipChain;
use parvo::cache::layout::ChainLayout;
use parvo::cache::run::SceneSetup;
use parvo::cache::sim::Outcome;
use parvo::sample::{Sampler, SamplerOptions};
use parvo::scene::{Frame, Scene};

/// Runs `f` on the scene run a test case names: the sampler preset
/// `filter` on `chain`, its layout, the scene and the raster order parsed,
/// on `frame`.
fn with_setup<R>(
    chain: &MipChain,
    (filter, scene, layout, order): (&str, &str, &str, &str),
    frame: Frame,
    f: impl FnOnce(&SceneSetup) -> R,
) -> R {
    let sampler = Sampler::new(chain, SamplerOptions::from_name(filter).unwrap()).unwrap();
    let cl = ChainLayout::for_sampler(chain, &sampler, layout.parse().unwrap());
    f(&SceneSetup {
        sampler: &sampler,
        layout: &cl,
        scene: scene.parse::<Scene>().unwrap(),
        frame,
        order: order.parse().unwrap(),
    })
}

/// Counts one access of the plain model into
/// `[accesses, hits, cold, capacity, conflict]`.
fn tally(c: &mut [u64; 5], o: Outcome) {
    c[0] += 1;
    c[match o {
        Outcome::Hit => 1,
        Outcome::Cold => 2,
        Outcome::Capacity => 3,
        _ => 4,
    }] += 1;
}
