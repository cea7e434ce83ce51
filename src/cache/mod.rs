//! The texel cache: memory layouts of a chain ([`layout`]), the cache
//! simulator with its 3C miss classification ([`sim`]) and the plain model
//! it is tested against ([`mod@reference`]), and the sink that turns a
//! sampler's texel reads into memory accesses ([`run::AddressSink`]).
//!
//! Data flow: a [`crate::scene::Scene`] emits queries in a
//! [`crate::scene::RasterOrder`]; a sampler filters each and reports every
//! texel it reads to a [`crate::sample::TexelSink`]; [`run::AddressSink`] maps
//! (level, x, y) to a byte address with a [`layout::ChainLayout`] and feeds
//! the [`sim::Simulator`] (or records the addresses as a trace); [`run`]
//! drives a whole frame (pixel by pixel, or by 2×2 quads whose requests to
//! one line merge), [`sweep`] one frame under a grid of caches, layouts and
//! filters, [`prefetch`] times the cache's misses in a prefetching texture
//! unit. [`shape`] stands in for a texture whose values no filter reads:
//! sizes and format only, no texel generated; [`isotropic`] reports what
//! an isotropic lookup reads without reading it (8 at a time
//! with AVX-512).

pub mod isotropic;
#[cfg(target_arch = "x86_64")]
mod lanes;
pub mod layout;
pub mod prefetch;
pub mod reference;
pub mod run;
pub mod shape;
pub mod sim;
pub mod sweep;

pub use layout::{ChainLayout, Layout};
pub use sim::{AddressSpace, CacheConfig, Counters, Outcome, Policy, Simulator, Stats};
