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
//!      band by band ([`stream`]): bands of level 0 decoded to f32, reduced
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
//! Memory: the source, the stored chain, and the working level in f32
//! (level m of the band build, 1/4^m of level 0; level 1, a quarter of
//! level 0 in f32, on the separable path).

pub mod alpha;
#[cfg(feature = "io")]
pub(crate) mod band;
pub mod fast;
pub mod kernel;
pub mod nan;
pub mod normal;
pub mod roughness;
mod sep_fast;
mod sep_simd;
pub mod separable;
mod srgb_simd;
pub mod stream;
pub mod weights;

use std::fmt;
use std::str::FromStr;

use crate::error::{Error, Result};
use crate::texel::{ChannelType, ColorSpace, Format, Texels};
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

/// Levels 1.. of `base`'s chain without taking or copying level 0 (for
/// callers that keep the source elsewhere). NaN policies other than
/// [`NanPolicy::Error`] need to modify level 0 and are refused here.
pub fn build_reduced_levels(base: &Texture, options: &MipOptions) -> Result<Vec<Texture>> {
    validate(base, options)?;
    if options.normal_map {
        let vectors = normal::build_levels(base, options, &mut |_| {})?;
        return vectors[1..]
            .iter()
            .map(|v| normal::encode(v, base.format()))
            .collect();
    }
    if options.nan_policy != NanPolicy::Error {
        return Err(Error::InvalidOption(
            "build_reduced_levels cannot repair level 0: use build with this NaN policy".into(),
        ));
    }
    let deferred = defer_nan_check(base, options)?;
    let sizes = level_sizes(
        base.width(),
        base.height(),
        options.rounding,
        options.max_levels,
    );
    reduced_levels(base, &sizes, options, deferred, &mut |_, _| {})
}

/// The form every level is reduced from: linear f32 with the source's
/// channels and alpha mode, never rounded to the stored type.
fn working_format(f: Format) -> Format {
    Format::new(f.channels, ChannelType::F32, ColorSpace::Linear).with_alpha(f.alpha)
}

/// Levels 1.. of `base`'s chain of `sizes`, each reduced from the
/// unrounded level before it (level 0 as stored, then linear f32) and
/// rounded to `base`'s format once, as it is stored; `done(k, texels)`
/// after level `k`. A chain of linear f32 keeps no second copy: its stored
/// levels are the working ones.
fn reduced_levels(
    base: &Texture,
    sizes: &[(u32, u32)],
    options: &MipOptions,
    deferred: bool,
    done: &mut dyn FnMut(usize, u64),
) -> Result<Vec<Texture>> {
    let stored = base.format();
    let separate = stored != working_format(stored);
    let coverage0 = coverage_target(base, options);
    let mut levels: Vec<Texture> = Vec::with_capacity(sizes.len().saturating_sub(1));
    // The unrounded last level, when it is not the stored one.
    let mut work: Option<Texture> = None;
    // Box levels made band by band first, where they apply (stream).
    let m = stream::levels(sizes, options);
    if m >= 1 {
        let made = stream::box_levels(base, m, stored);
        for (k, t) in made.stored.into_iter().enumerate() {
            let (w, h) = sizes[k + 1];
            levels.push(Texture::from_texels(w, h, stored, t)?);
            if k == 0 && deferred && !made.finite {
                nan::check_via_reduced(base, &levels[0])?;
            }
            done(k + 1, w as u64 * h as u64);
        }
        let (wm, hm) = sizes[m];
        work = Some(Texture::from_f32(
            wm,
            hm,
            working_format(stored),
            made.last,
        )?);
    }
    // Levels 1 and 2 at once from 8- and 16-bit level 0 (the separable
    // filters), level 1 never whole in f32 (sep_fast::try_reduce_two).
    let fuse = m == 0
        && sizes.len() > 2
        && separate
        && options.fast_paths
        && options.filter != MipFilter::Box
        && options.alpha_coverage.is_none();
    let two = fuse
        .then(|| sep_fast::try_reduce_two(base, sizes[1], sizes[2], options, stored))
        .flatten();
    let mut from = m + 1;
    if let Some(two) = two {
        for (k, t) in [(1, two.stored1), (2, two.stored2)] {
            let (w, h) = sizes[k];
            levels.push(Texture::from_texels(w, h, stored, t)?);
            done(k, w as u64 * h as u64);
        }
        let (w2, h2) = sizes[2];
        work = Some(Texture::from_f32(
            w2,
            h2,
            working_format(stored),
            two.linear2,
        )?);
        from = 3;
    }
    for (k, &(w, h)) in sizes.iter().enumerate().skip(from) {
        let prev = match (&work, levels.last()) {
            (Some(t), _) => t,
            (None, Some(t)) => t,
            (None, None) => base,
        };
        // The stored level comes with the reduction (8-bit box) unless
        // alpha coverage must change the level first.
        let encode = (separate && options.alpha_coverage.is_none()).then_some(stored);
        let (mut next, coded, finite) = reduce_working(prev, w, h, options, encode)?;
        if let (Some(r), Some(c0)) = (options.alpha_coverage, coverage0) {
            let store = options.alpha_store.unwrap_or(stored.channel_type);
            alpha::preserve_coverage(&mut next, r, c0, store);
        }
        if deferred && k == 1 && !finite {
            nan::check_via_reduced(base, &next)?;
        }
        if separate {
            let out = match coded {
                Some(t) => Texture::from_texels(w, h, stored, t)?,
                None => {
                    let mut out = Texture::new(w, h, stored)?;
                    let Texels::F32(lin) = next.texels() else {
                        return Err(Error::InvalidOption("working levels are f32".into()));
                    };
                    crate::texel::encode_from_linear(&stored, lin, out.texels_mut());
                    out
                }
            };
            levels.push(out);
            work = Some(next);
        } else {
            // The stored level is the working one.
            levels.push(next);
            work = None;
        }
        done(k, w as u64 * h as u64);
    }
    Ok(levels)
}

/// One reduction to `w × h` in the working form (see [`working_format`]),
/// with the fast box where it applies; with `encode`, the level in that
/// format too when the fast path made it on the way. The flag says every
/// value came out finite.
fn reduce_working(
    src: &Texture,
    w: u32,
    h: u32,
    options: &MipOptions,
    encode: Option<Format>,
) -> Result<(Texture, Option<Texels>, bool)> {
    let fast = options
        .fast_paths
        .then(|| {
            fast::try_reduce_linear(src, w, h, options, encode)
                .or_else(|| sep_fast::try_reduce_linear(src, w, h, options, encode))
        })
        .flatten();
    let (v, coded, finite) = match fast {
        Some(r) => (r.linear, r.stored, r.finite),
        None => {
            let (v, finite) = separable::reduce_linear_checked(src, w, h, options);
            (v, None, finite)
        }
    };
    Ok((
        Texture::from_f32(w, h, working_format(src.format()), v)?,
        coded,
        finite,
    ))
}

fn coverage_target(base: &Texture, options: &MipOptions) -> Option<f32> {
    match (options.alpha_coverage, base.format().alpha_channel()) {
        (Some(r), Some(_)) => Some(alpha::coverage(base, r)),
        _ => None,
    }
}

/// Build the full chain of `base` (see the module docs).
pub fn build(base: Texture, options: &MipOptions) -> Result<MipChain> {
    build_with_progress(base, options, &mut |_| {})
}

/// [`build`] with a callback after each level (called on the caller's
/// thread; the library never prints).
pub fn build_with_progress(
    mut base: Texture,
    options: &MipOptions,
    progress: &mut dyn FnMut(Progress),
) -> Result<MipChain> {
    validate(&base, options)?;
    if options.normal_map {
        let f = base.format();
        let levels = normal::build(base, options, f, progress)?;
        return Ok(MipChain {
            levels,
            options: *options,
        });
    }
    let deferred = defer_nan_check(&base, options)?;
    if !deferred {
        nan::apply(&mut base, options.nan_policy)?;
    }
    let sizes = level_sizes(
        base.width(),
        base.height(),
        options.rounding,
        options.max_levels,
    );
    let texels_total: u64 = sizes[1..].iter().map(|&(w, h)| w as u64 * h as u64).sum();
    let mut p = Progress {
        levels_done: 1,
        levels_total: sizes.len() as u32,
        texels_done: 0,
        texels_total,
    };
    progress(p);
    let rest = reduced_levels(&base, &sizes, options, deferred, &mut |_, texels| {
        p.levels_done += 1;
        p.texels_done += texels;
        progress(p);
    })?;
    let mut levels = Vec::with_capacity(sizes.len());
    levels.push(base);
    levels.extend(rest);
    Ok(MipChain {
        levels,
        options: *options,
    })
}

/// Under [`NanPolicy::Error`] the full scan of level 0 is deferred when a
/// reduction follows: every texel of level 0 has a non-zero weight in
/// level 1 and NaN/Inf propagate through the filters, so a clean level 1
/// proves a clean level 0 and the scan (a whole extra pass over the
/// largest level) is only run to name the bad texel. Returns whether the
/// check was deferred; a single-level chain is checked here.
/// Post-processing that could hide a NaN (normal renormalisation, alpha
/// scaling) also turns the deferral off.
fn defer_nan_check(base: &Texture, options: &MipOptions) -> Result<bool> {
    if options.nan_policy != NanPolicy::Error || !base.channel_type().is_float() {
        return Ok(false);
    }
    let levels = level_count(
        base.width(),
        base.height(),
        options.rounding,
        options.max_levels,
    );
    if levels < 2 || options.normal_map || options.alpha_coverage.is_some() {
        nan::check(base)?;
        return Ok(false);
    }
    Ok(true)
}

fn validate(base: &Texture, options: &MipOptions) -> Result<()> {
    if let Some(r) = options.alpha_coverage {
        if !(r > 0.0 && r < 1.0) {
            return Err(Error::InvalidOption(format!(
                "alpha coverage reference {r} must be between 0 and 1 (exclusive)"
            )));
        }
        if !base.format().has_alpha() && !options.normal_map {
            return Err(Error::InvalidOption(
                "alpha coverage needs a texture with an alpha channel".into(),
            ));
        }
    }

    if options.max_levels == Some(0) {
        return Err(Error::InvalidOption(
            "the chain needs at least one level".into(),
        ));
    }
    Ok(())
}

/// Reduce one level to `w × h` with the chosen filter (fast path if one
/// applies, otherwise the separable path).
pub fn reduce(src: &Texture, w: u32, h: u32, options: &MipOptions) -> Result<Texture> {
    reduce_tracked(src, w, h, options).map(|(t, _)| t)
}

/// [`reduce`], and whether the kernel already proved every output value
/// finite (then the deferred NaN check need not scan the result).
fn reduce_tracked(src: &Texture, w: u32, h: u32, options: &MipOptions) -> Result<(Texture, bool)> {
    if options.fast_paths
        && let Some(t) = fast::try_reduce(src, w, h, options)?
    {
        return Ok(t);
    }
    separable::reduce(src, w, h, options)
}
