//! The reductions of one level: the filter kernels ([`kernel`]) and their
//! per-axis weights ([`weights`]), the general separable path
//! ([`separable`], every filter, size and wrap mode: the reference) and
//! the fast paths tested against it ([`fast`]: exact 2×2 boxes on stored
//! integers; `sep_fast`, `sep_simd`, `srgb_simd`: linear-light and SIMD
//! rows). [`crate::mip::reduce`] is the one public entry that picks among
//! them.

pub mod fast;
pub mod kernel;
pub(crate) mod sep_fast;
pub(crate) mod sep_simd;
pub mod separable;
pub(crate) mod srgb_simd;
pub mod weights;
