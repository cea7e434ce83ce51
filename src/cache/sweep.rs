//! Cache sweeps: one scene's texel reads under a grid of caches, memory
//! layouts and filters.
//!
//! Each filter's frame is sampled once; every texel read is addressed in
//! every layout of the grid, and the reads flow in raster order to one
//! simulator per (layout, cache) pair, all run in parallel while the next
//! pixels are sampled ([`SceneSetup::run_jobs`]): no trace is stored. [`sweep`] returns one
//! [`SweepRow`] per configuration, filters outermost, then layouts, then
//! caches in the order given; it writes nothing.
//!
//! ```
//! use parvo::cache::layout::Layout;
//! use parvo::cache::sweep::{SweepSettings, cache_grid, sweep};
//! use parvo::{MipOptions, SamplerOptions, builtin, mip};
//!
//! let chain = mip::build(builtin::load("builtin:checker:64")?, &MipOptions::default())?;
//! let settings = SweepSettings {
//!     scene: "plane".parse()?,
//!     frame: parvo::scene::Frame::new(32, 24),
//!     order: "scanline".parse()?,
//!     filters: vec![("trilinear".into(), SamplerOptions::from_name("trilinear")?)],
//!     layouts: vec!["linear".parse::<Layout>()?],
//!     caches: cache_grid(&[1024, 4096], &[64], &[1, 4], 0x5eed, None),
//! };
//! let rows = sweep(&chain, None, &settings, &|| {})?;
//! assert_eq!(rows.len(), 4);
//! # Ok::<(), parvo::Error>(())
//! ```

use std::sync::Arc;

use super::layout::{ChainLayout, Layout};
use super::run::{Job, Model, RunStats, SceneSetup};
use super::shape::CacheTexture;
use super::sim::CacheConfig;
use crate::compress::BlockFormat;
use crate::error::Result;
use crate::mip::MipChain;
use crate::sample::{Sampler, SamplerOptions};
use crate::scene::{Frame, RasterOrder, Scene};

/// What a sweep runs.
#[derive(Clone, Debug)]
pub struct SweepSettings {
    /// The scene.
    pub scene: Scene,
    /// The frame.
    pub frame: Frame,
    /// The raster order.
    pub order: RasterOrder,
    /// The filters, each with the label its rows carry.
    pub filters: Vec<(String, SamplerOptions)>,
    /// The memory layouts of the chain.
    pub layouts: Vec<Layout>,
    /// The caches (see [`cache_grid`]).
    pub caches: Vec<CacheConfig>,
}

impl SweepSettings {
    /// Configurations the sweep runs: filters × layouts × caches.
    pub fn configurations(&self) -> usize {
        self.filters.len() * self.layouts.len() * self.caches.len()
    }
}

/// One configuration's result.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SweepRow {
    /// The filter's label.
    pub filter: String,
    /// The chain's layout.
    pub layout: Layout,
    /// The cache.
    pub cache: CacheConfig,
    /// The run's counters.
    pub run: RunStats,
}

/// Every cache of `sizes × lines × ways` (LRU, that replacement seed and
/// sector size) that can exist, in that nesting order: the combinations a
/// cache of a size cannot have (more ways than lines, or no whole sets)
/// are left out.
pub fn cache_grid(
    sizes: &[u64],
    lines: &[u64],
    ways: &[u64],
    seed: u64,
    sector: Option<u64>,
) -> Vec<CacheConfig> {
    let mut caches = Vec::new();
    for &size in sizes {
        for &line in lines {
            for &w in ways {
                let mut c = CacheConfig::new(size, line, w);
                c.seed = seed;
                c.sector = sector;
                if c.validate().is_ok() {
                    caches.push(c);
                }
            }
        }
    }
    caches
}

/// Run every configuration of `settings` on `chain` (`blocks`: the block
/// format its levels were stored in, whose reads fetch whole blocks);
/// `progress` is called once per configuration done, from any thread.
/// (The chain is copied once; [`sweep_with`] reads a shared one, or a
/// stand-in.)
pub fn sweep(
    chain: &MipChain,
    blocks: Option<BlockFormat>,
    settings: &SweepSettings,
    progress: &(dyn Fn() + Sync),
) -> Result<Vec<SweepRow>> {
    let texture = CacheTexture::loaded(Arc::new(chain.clone()), blocks);
    sweep_with(&texture, settings, &Model::default(), progress)
}

/// [`sweep`] of `texture` under `model` (quads, prefetching): each
/// filter's frame is sampled once, its reads addressed in every layout,
/// and every (layout, cache) pair simulated from them in parallel.
pub fn sweep_with(
    texture: &CacheTexture,
    settings: &SweepSettings,
    model: &Model,
    progress: &(dyn Fn() + Sync),
) -> Result<Vec<SweepRow>> {
    let mut rows = Vec::with_capacity(settings.configurations());
    let mut jobs = Vec::new();
    for layout in 0..settings.layouts.len() {
        for c in &settings.caches {
            jobs.push(Job {
                layout,
                l1: *c,
                l2: None,
            });
        }
    }
    for (name, options) in &settings.filters {
        let sampler = Sampler::shared(texture.chain.clone(), *options)?;
        let layouts: Vec<ChainLayout> = settings
            .layouts
            .iter()
            .map(|&l| texture.layout(&sampler, l))
            .collect();
        let refs: Vec<&ChainLayout> = layouts.iter().collect();
        let Some(&first) = refs.first() else {
            continue;
        };
        let setup = SceneSetup {
            sampler: &sampler,
            layout: first,
            scene: settings.scene,
            frame: settings.frame,
            order: settings.order,
        };
        let runs = setup.run_jobs(&refs, &jobs, model, &|_, _| {})?;
        for (job, run) in jobs.iter().zip(runs) {
            progress();
            rows.push(SweepRow {
                filter: name.clone(),
                layout: settings.layouts[job.layout],
                cache: job.l1,
                run,
            });
        }
    }
    Ok(rows)
}
