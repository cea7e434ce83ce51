//! The builders that work band by band: level 0 cut into bands of rows,
//! each band reduced through several levels while it is in cache.
//!
//! - [`boxes`]: several 2×2 box levels at once, the whole-level build's
//!   fast tier (in memory, stored type out).
//! - `converted` (with the `io` feature): whole chains stored in another
//!   format than their source's, for the pipeline and the fused EXR
//!   write, without a full-resolution f32 copy of level 0.

pub mod boxes;
#[cfg(feature = "io")]
mod converted;

#[cfg(feature = "io")]
pub(crate) use converted::*;
