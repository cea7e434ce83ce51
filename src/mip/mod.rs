//! Mip pyramids: level sizes, downsampling filters, and the chain builder.
//!
//! [`build`] turns a level-0 [`Texture`] into a [`MipChain`]. Every level
//! is reduced in linear light from the *unrounded* level before it and
//! rounded to the source's format once, as it is stored: a chain that
//! reduced each level from the previous level's 8-bit codes (as some
//! drivers and tools do) drifts by a code or more within a few levels
//! (`tests/files/regression/eight_bit_chains_drift.rs`, `scripts/drift-table.py`).
//!
//! 1. Level 0 is checked for NaN/Inf under [`NanPolicy`] (float types).
//! 2. For each next level, [`level_size`] gives the size; the reduction runs
//!    on rayon. Tiers:
//!    - the 2×2 box of levels that halve exactly: levels 1..=m are made
//!      band by band ([`band::boxes`]): bands of level 0 decoded to f32, reduced
//!      through m levels in per-thread scratch, each level's rows encoded
//!      while in cache; only level m is kept in f32;
//!    - the general separable path ([`separable`]) for every filter, type,
//!      size and wrap mode, from linear f32 working levels. It is the
//!      reference the fast paths are tested against
//!      (`tests/core/mip_fast_paths_match_plain.rs`).
//!    - [`reduce`] (one level, stored type in and out) keeps the integer
//!      fast paths ([`fast`]): exact for a single reduction.
//! 3. Optional per-level post-processing: alpha-test coverage preservation
//!    ([`alpha`]) on the working level, measured after the stored type's
//!    rounding. Normal maps take their own path ([`normal`]): decoded to
//!    unit vectors, averaged in f32, renormalised and encoded once per
//!    level.
//!
//! Layout, one folder per layer: [`kernels`] (the reduction of one level:
//! filter kernels, weights, the separable path and the fast paths),
//! [`chain`] (the builder above and its per-level passes) and [`band`]
//! (the builders that work band by band). One entry point per job:
//! [`build`] / [`build_with_progress`] for a chain, [`reduce`] for one
//! level; the pipeline's chains in another stored format go through
//! `band::build_converted`, on the path its plan chose.
//!
//! Memory: the source, the stored chain, and the working level in f32
//! (level m of the band build, 1/4^m of level 0; level 1, a quarter of
//! level 0 in f32, on the separable path).

// The layers, one folder each: the reductions of one level (`kernels`),
// the chain builder and its per-level passes (`chain`), and the builders
// that work band by band (`band`). The modules keep their public paths.
pub mod band;
pub mod chain;
pub mod kernels;

pub use chain::{
    alpha, build, build_reduced_levels, build_with_progress, nan, normal, reduce, roughness,
};
pub use kernels::{fast, kernel, separable, weights};
pub(crate) use kernels::{sep_fast, sep_simd, srgb_simd};

use std::fmt;
use std::str::FromStr;

use crate::error::{Error, Result};
use crate::texture::Texture;
use crate::wrap::Wrap;

pub use nan::NanPolicy;

/// Downsampling filter (SPEC.md "Mip levels").
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum MipFilter {
    /// Area-weighted box: 2×2 average, polyphase 3-tap box on odd sizes.
    #[default]
    Box,
    /// Tent, radius 1 (scaled by the reduction).
    Triangle,
    /// Kaiser-windowed sinc, width 3, alpha 4 (NVIDIA texture tools).
    Kaiser,
    /// Lanczos, three lobes.
    Lanczos3,
    /// Mitchell–Netravali, B = C = 1/3.
    Mitchell,
}

impl MipFilter {
    /// Every filter, in a stable order.
    pub const ALL: [MipFilter; 5] = [
        MipFilter::Box,
        MipFilter::Triangle,
        MipFilter::Kaiser,
        MipFilter::Lanczos3,
        MipFilter::Mitchell,
    ];

    /// The stable name (`box`, `triangle`, `kaiser`, `lanczos3`, `mitchell`).
    pub fn name(self) -> &'static str {
        match self {
            MipFilter::Box => "box",
            MipFilter::Triangle => "triangle",
            MipFilter::Kaiser => "kaiser",
            MipFilter::Lanczos3 => "lanczos3",
            MipFilter::Mitchell => "mitchell",
        }
    }

    /// The kernel behind the filter.
    pub fn kernel(self) -> Box<dyn kernel::Kernel + Send + Sync> {
        match self {
            MipFilter::Box => Box::new(kernel::BoxKernel),
            MipFilter::Triangle => Box::new(kernel::Triangle),
            MipFilter::Kaiser => Box::new(kernel::Kaiser::default()),
            MipFilter::Lanczos3 => Box::new(kernel::Lanczos3),
            MipFilter::Mitchell => Box::new(kernel::Mitchell::default()),
        }
    }
}

impl fmt::Display for MipFilter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for MipFilter {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        MipFilter::ALL
            .into_iter()
            .find(|f| f.name().eq_ignore_ascii_case(s))
            .ok_or_else(|| {
                Error::parse(
                    "mip filter",
                    s,
                    "expected box, triangle, kaiser, lanczos3 or mitchell",
                )
            })
    }
}

/// How odd level sizes round (OpenEXR's `RoundingMode`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Rounding {
    /// `floor(size / 2)` (the GPU rule).
    #[default]
    Down,
    /// `ceil(size / 2)`.
    Up,
}

impl fmt::Display for Rounding {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Rounding::Down => "down",
            Rounding::Up => "up",
        })
    }
}

impl FromStr for Rounding {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s.to_ascii_lowercase().as_str() {
            "down" => Ok(Rounding::Down),
            "up" => Ok(Rounding::Up),
            _ => Err(Error::parse("rounding mode", s, "expected down or up")),
        }
    }
}

/// Everything that decides how a chain is built. Comparable and hashable so
/// it can key caches and fingerprints.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MipOptions {
    /// Downsampling filter. Default: box.
    pub filter: MipFilter,
    /// Wrap modes used to resolve taps outside a level. Default: repeat.
    pub wrap: Wrap,
    /// Level size rounding. Default: down.
    pub rounding: Rounding,
    /// Maximum number of levels including level 0; `None` (default) builds
    /// the full chain down to 1×1.
    pub max_levels: Option<u32>,
    /// Alpha-test coverage preservation with this reference alpha
    /// (Castaño); `None` (default) leaves alpha as filtered.
    pub alpha_coverage: Option<f32>,
    /// Treat RGB as a unit normal (unorm codes `c` hold `2c − 1`, floats
    /// the components) and build the chain from unit vectors, renormalising
    /// each level once in full precision ([`normal`]). Default: false.
    pub normal_map: bool,
    /// The channel type the levels' alpha will be stored in, when it is
    /// not the type they are built in (a chain built in f32 for 8-bit
    /// output): alpha coverage is measured after that rounding. `None`
    /// (default): the build type.
    pub alpha_store: Option<crate::texel::ChannelType>,
    /// What to do with NaN/Inf in float input. Default: error.
    pub nan_policy: NanPolicy,
    /// Use the fast paths where they apply. Default: true. Turning it off
    /// forces the plain separable path (used by tests as the reference).
    pub fast_paths: bool,
}

impl Default for MipOptions {
    fn default() -> Self {
        MipOptions {
            filter: MipFilter::Box,
            wrap: Wrap::default(),
            rounding: Rounding::Down,
            max_levels: None,
            alpha_coverage: None,
            alpha_store: None,
            normal_map: false,
            nan_policy: NanPolicy::Error,
            fast_paths: true,
        }
    }
}

impl MipOptions {
    /// Options with the given filter and defaults otherwise.
    pub fn with_filter(filter: MipFilter) -> Self {
        MipOptions {
            filter,
            ..Default::default()
        }
    }
}

/// Size of level `k` of a `w × h` texture: `max(1, floor(w / 2^k))` (or
/// `ceil` when rounding up), per axis.
pub fn level_size(width: u32, height: u32, level: u32, rounding: Rounding) -> (u32, u32) {
    let f = |n: u32| -> u32 {
        if level >= 32 {
            return 1;
        }
        let r = match rounding {
            Rounding::Down => n >> level,
            Rounding::Up => ((n as u64 + (1u64 << level) - 1) >> level) as u32,
        };
        r.max(1)
    };
    (f(width), f(height))
}

/// Number of levels of a full chain: `floor(log2(max(w, h))) + 1` when
/// rounding down (`ceil` when rounding up), capped by `max_levels`.
pub fn level_count(width: u32, height: u32, rounding: Rounding, max_levels: Option<u32>) -> u32 {
    let m = width.max(height).max(1);
    let full = match rounding {
        Rounding::Down => 32 - m.leading_zeros(),
        Rounding::Up => 32 - (m - 1).leading_zeros() + 1,
    };
    match max_levels {
        Some(n) => full.min(n.max(1)),
        None => full,
    }
}

/// Sizes of every level of the chain.
pub fn level_sizes(
    width: u32,
    height: u32,
    rounding: Rounding,
    max_levels: Option<u32>,
) -> Vec<(u32, u32)> {
    (0..level_count(width, height, rounding, max_levels))
        .map(|k| level_size(width, height, k, rounding))
        .collect()
}

/// Progress of a chain build, reported after each level.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Progress {
    /// Levels finished (level 0 counts as finished once validated).
    pub levels_done: u32,
    /// Levels in the chain.
    pub levels_total: u32,
    /// Destination texels written so far.
    pub texels_done: u64,
    /// Destination texels of all levels after level 0.
    pub texels_total: u64,
}

/// A texture and its reduced levels, level 0 first.
#[derive(Clone, Debug, PartialEq)]
pub struct MipChain {
    levels: Vec<Texture>,
    options: MipOptions,
}

impl MipChain {
    /// Assemble a chain from existing levels (e.g. read from a file). The
    /// sizes must follow [`level_size`] for `rounding`.
    pub fn from_levels(levels: Vec<Texture>, options: MipOptions) -> Result<Self> {
        let first = levels
            .first()
            .ok_or_else(|| Error::InvalidOption("a mip chain needs at least one level".into()))?;
        let (w, h, fmt) = (first.width(), first.height(), first.format());
        for (k, l) in levels.iter().enumerate() {
            let want = level_size(w, h, k as u32, options.rounding);
            if (l.width(), l.height()) != want || l.format() != fmt {
                return Err(Error::InvalidOption(format!(
                    "level {k} is {}x{} {}, expected {}x{} {}",
                    l.width(),
                    l.height(),
                    l.format(),
                    want.0,
                    want.1,
                    fmt
                )));
            }
        }
        if levels.len() as u32 > level_count(w, h, options.rounding, None) {
            return Err(Error::InvalidOption(
                "more levels than the chain can have".into(),
            ));
        }
        Ok(MipChain { levels, options })
    }

    /// All levels, level 0 first.
    pub fn levels(&self) -> &[Texture] {
        &self.levels
    }
    /// Level `k`.
    pub fn level(&self, k: usize) -> Option<&Texture> {
        self.levels.get(k)
    }
    /// Number of levels.
    pub fn len(&self) -> usize {
        self.levels.len()
    }
    /// Always false: a chain has level 0.
    pub fn is_empty(&self) -> bool {
        self.levels.is_empty()
    }
    /// The options the chain was built with.
    pub fn options(&self) -> &MipOptions {
        &self.options
    }
    /// Consume into the levels.
    pub fn into_levels(self) -> Vec<Texture> {
        self.levels
    }
}
