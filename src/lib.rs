//! parvo: texture filtering and mipmap processing.
//!
//! # Structure and data flow
//!
//! ```text
//! file / builtin ──▶ Texture (level 0, its storage format)
//!                      │ mip::build(MipOptions)
//!                      ▼
//!                   MipChain (levels in the source format)
//!                      │ sample::Sampler::new(SamplerOptions): 8-bit kept packed, others to linear RGBA f32
//!                      ▼
//! Query{uv, derivatives} ──▶ Footprint (λ, η) ──▶ filter ──▶ [f32; 4]
//!                                                   └──▶ TexelSink (every texel read)
//!
//! Texture ──sat::build(accumulator)──▶ SummedAreaTable ──▶ SatSampler
//!
//! scene::Scene + RasterOrder ──▶ queries ──▶ Sampler ──TexelSink──▶
//!     cache::run::AddressSink (cache::layout) ──▶ cache::sim::Simulator ──▶ Stats
//! ```
//!
//! - [`texel`]: formats (1–4 channels; u8, u16, f16, f32; linear or sRGB;
//!   straight or premultiplied alpha) and the conversions to and from
//!   linear-light f32 that every filter works in.
//! - [`texture`]: [`Texture`], an owned level with checked dimensions.
//! - [`wrap`]: [`WrapMode`] and the wrap rule: the one function mapping
//!   integer texel indices into a level, a mode's period.
//! - [`builtin`]: procedural textures (`builtin:checker`,
//!   `builtin:zoneplate`).
//! - [`mip`]: level sizes, kernels, polyphase weights, the separable
//!   reference path and the fast box paths, alpha coverage and normal
//!   renormalisation, the chain builder.
//! - [`sample`]: [`SamplerOptions`], [`Query`], the footprint (LOD,
//!   anisotropy) and the filters from nearest to EWA, generic over a
//!   [`TexelSink`] that sees every texel read; batch sampling on rayon.
//! - [`sat`]: summed-area tables with exact integer or bounded-error float
//!   accumulators, O(1) box sums under every wrap mode, the SAT sampler.
//! - [`scene`]: scenes (plane, tunnel, zoom, rotate) as exact mappings
//!   from screen to texture, their per-pixel queries, raster orders,
//!   accuracy metrics.
//! - [`cache`]: memory layouts of a chain, the texel cache simulator with
//!   3C miss classes and its plain reference model, scene runs, sweeps of
//!   caches × layouts × filters.
//! - [`tradeoff`]: the trade-off report (each filter's speed, traffic,
//!   accuracy and flicker on a scene) as data.
//! - [`compress`]: GPU block formats (BC1–BC7) and their decoding.
//! - `io` (feature `io`): file formats: loading PNG, JPEG, TIFF, HDR,
//!   OpenEXR, KTX2, DDS and built-ins with decoder limits, and atomic
//!   saving of mip chains as tiled mip-mapped EXR, KTX2, DDS or one PNG per
//!   level; `pipeline` (feature `io`): the file-to-files mip and compress
//!   batch the command line runs.
//!
//! Without default features the crate is the sampling core above (every
//! module but `io` and `pipeline`): pure Rust, no C code and no image
//! codec. The features are `io` (files), `encode` (BC encoders) and `cli`
//! (the command-line tool); the README's "Features" table lists what each
//! brings.
//!
//! Level buffers of 4 MiB and more are advised for transparent huge pages
//! on Linux (one page fault per 2 MiB instead of 512; see `mem.rs`).
//!
//! The library never prints and never panics on bad input: errors are
//! [`Error`] values, long builds report through a progress callback.
//!
//! ```
//! use parvo::{builtin, mip};
//! let tex = builtin::load("builtin:checker:64")?;
//! let chain = mip::build(tex, &mip::MipOptions::with_filter(mip::MipFilter::Kaiser))?;
//! assert_eq!(chain.len(), 7); // 64, 32, ..., 1
//! # Ok::<(), parvo::Error>(())
//! ```

#![deny(unsafe_code)]
#![warn(missing_docs)]
// No panic reachable from input: errors are values. Tests may unwrap.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used))]

pub mod builtin;
pub mod cache;
pub mod compress;
mod cpu;
pub mod env;
pub mod error;
#[cfg(feature = "io")]
pub mod io;
mod mem;
pub mod mip;
mod par;
#[cfg(feature = "io")]
pub mod pipeline;
pub mod sample;
pub mod sat;
pub mod scene;
pub mod setting;
pub mod shade;
mod simd;
pub mod store;
pub mod texel;
pub mod texture;
pub mod trace;
pub mod tradeoff;
pub mod wrap;

pub use error::{Error, Result};
pub use mip::{MipChain, MipFilter, MipOptions, NanPolicy, Rounding};
pub use sample::{
    CompareOp, Filter, Method, MipMode, Query, Sampler, SamplerOptions, TexelFilter, TexelSink,
};
pub use sat::{AccumulatorKind, SatSampler, SummedAreaTable};
pub use texel::{AlphaMode, ChannelType, ColorSpace, Format, Texels};
pub use texture::{ImageKind, Texture};
pub use wrap::{Wrap, WrapMode};
