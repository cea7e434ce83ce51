//! Samplers: a texture coordinate and its screen-space derivatives in, a
//! filtered linear-light RGBA colour out.
//!
//! # Structure
//! - [`SamplerOptions`] (a hashable value type with presets) and
//!   [`Sampler`], built once from a [`MipChain`] prepared by
//!   [`LinearChain`]: texels stay as the chain stores them (1–4 channels
//!   of `u8`, `u16`, `f16` or `f32`) and are decoded at fetch, and a
//!   chain behind an `Arc` is read without a copy (see [`fetch`] for the
//!   decode rules and the memory cost).
//! - [`footprint`](mod@footprint): ρ, η, λ and the mip-level rules, exactly as SPEC.md
//!   (after Vulkan and EXT_texture_filter_anisotropic) states them, plus
//!   the per-sampler `Lod` that restates the nearest-mip rule without a
//!   logarithm.
//! - One file per filter: nearest and bilinear within a level
//!   (`bilinear`), magnification/minification/mip modes and trilinear
//!   (`trilinear`), footprint assembly (`aniso`), EWA ([`ewa`]), and the
//!   supersampled reference (`supersample`). Footprint assembly with
//!   `max_aniso = 1` is the isotropic lookup, and its probes are isotropic
//!   lookups sharing one λ and one pair of levels.
//! - [`crate::trace`]: every filter is generic over a [`TexelSink`] that sees each
//!   texel read; [`NoTrace`] compiles away.
//! - `simd`: on x86-64 CPUs with AVX-512 (F, BW, DQ, VL, VBMI), untraced
//!   bilinear, trilinear and footprint-assembly lookups run 8 queries (or
//!   8 probes) per step in vector registers, with results identical bit
//!   for bit to the portable code ([`Sampler::uses_simd`]; `PARVO_NO_AVX=1`
//!   turns it off).
//! - `batch`: slices of queries, serial or in parallel (rayon).
//!
//! # Speed
//! The choices that do not change per query — storage, filters, mip mode,
//! kernel — are made once per slice of queries ([`Sampler::sample_slice`],
//! [`Sampler::sample_batch`]; once per call for [`Sampler::sample`]): each
//! combination is its own monomorphised loop with no branch on them inside.
//! Within a loop, a lookup whose 2×2 block lies inside the level reads the
//! rows directly; NaN, huge and edge-crossing positions fall through to one
//! general path that wraps. No allocation, reference counting or dynamic
//! dispatch happens per query.
//!
//! # Alpha
//! Texels are filtered as stored, as GPU samplers do: a straight-alpha
//! texture's colour is not weighted by alpha here (the mip chain builder
//! does that when it builds the levels). Every result is a convex
//! combination of texels (and the border colour), up to `f32` rounding.
//!
//! # Extreme inputs (all tested)
//! - NaN `u` or `v` reads as 0.
//! - Under `repeat` and `mirror` every finite coordinate is first moved
//!   into its first period (exactly: `u − floor(u)` has no rounding in
//!   `f64`), so `u = 1e6` keeps its sub-texel position and `u = 1e30`
//!   samples where its period puts it. Under the other modes, and for
//!   ±Inf, positions are floored in `f64` to integer texel indices that
//!   saturate at ±2^62 (fraction 0) and are then wrapped.
//! - Zero derivatives: magnification (λ = −∞ before the clamp); EWA uses
//!   its unit reconstruction Gaussian on level 0.
//! - NaN or infinite derivatives: an unbounded isotropic footprint (see
//!   [`footprint::UNBOUNDED_TEXELS`]): the coarsest level allowed, one
//!   probe (the supersampled reference, always on level 0, spreads its
//!   lookups over that footprint).
//! - Huge finite derivatives select the coarsest level; the work per query
//!   is bounded for every filter: at most 16 probes × 8 texels for
//!   footprint assembly, `supersample²` bilinear lookups for the reference,
//!   and an ellipse of at most [`ewa::MAX_RADIUS`] texels for EWA.
//! - The output is never NaN when the texels and the border colour are
//!   finite.
//!
//! ```
//! use parvo::sample::{Query, Sampler, SamplerOptions};
//! let chain = parvo::mip::build(
//!     parvo::builtin::load("builtin:checker:64")?,
//!     &parvo::MipOptions::default(),
//! )?;
//! let sampler = Sampler::new(&chain, SamplerOptions::aniso(8))?;
//! let rgba = sampler.sample(&Query::new(0.3, 0.7, 0.01, 0.0, 0.0, 0.002));
//! assert!(rgba.iter().all(|c| c.is_finite()));
//! # Ok::<(), parvo::Error>(())
//! ```

mod aniso;
mod batch;
mod bilinear;
pub mod ewa;
#[cfg(target_arch = "x86_64")]
mod ewa_simd;
pub mod fetch;
pub mod footprint;
pub mod gl;
mod one;
mod query;
#[cfg(target_arch = "x86_64")]
pub(crate) mod simd;
mod supersample;
mod trilinear;

use std::fmt;
use std::hash::{Hash, Hasher};
use std::str::FromStr;
use std::sync::Arc;

use crate::error::{Error, Result};
use crate::mip::MipChain;
use crate::sat::SatSampler;
use crate::wrap::Wrap;

use crate::trace::Erased;
pub use crate::trace::{NoTrace, TexelCounter, TexelRead, TexelRecorder, TexelSink};
pub use fetch::LinearChain;
pub use footprint::{Footprint, footprint, mip_linear, mip_nearest};
pub use gl::{CompareOp, quad_queries};
pub use query::Query;

use bilinear::{Filters, Lin, MagMin, Near};
use fetch::{Addressing, Chain, Pixel, with_chain};
use footprint::Lod;

/// Filter names used on the command line and in reports (SPEC.md "Names
/// used on the command line"). Each maps to a preset of
/// [`SamplerOptions`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Filter {
    /// Nearest texel, nearest mip level.
    Nearest,
    /// Bilinear within a level, nearest mip level (as games use the word).
    Bilinear,
    /// Bilinear in the two nearest levels, blended (8 texels).
    Trilinear,
    /// Footprint assembly: up to `max_aniso` trilinear probes.
    Aniso,
    /// Elliptical weighted average (Greene & Heckbert).
    Ewa,
    /// Box filter over the footprint's bounding box from a summed-area
    /// table (the summed-area-table issue provides it).
    Sat,
    /// The supersampled reference.
    Supersample,
}

impl Filter {
    /// Every filter, in a stable order.
    pub const ALL: [Filter; 7] = [
        Filter::Nearest,
        Filter::Bilinear,
        Filter::Trilinear,
        Filter::Aniso,
        Filter::Ewa,
        Filter::Sat,
        Filter::Supersample,
    ];

    /// The stable name.
    pub fn name(self) -> &'static str {
        match self {
            Filter::Nearest => "nearest",
            Filter::Bilinear => "bilinear",
            Filter::Trilinear => "trilinear",
            Filter::Aniso => "aniso",
            Filter::Ewa => "ewa",
            Filter::Sat => "sat",
            Filter::Supersample => "supersample",
        }
    }
}

impl fmt::Display for Filter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Filter {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        let t = s.trim();
        Filter::ALL
            .into_iter()
            .find(|f| f.name().eq_ignore_ascii_case(t))
            .ok_or_else(|| {
                Error::parse(
                    "filter",
                    s,
                    "expected nearest, bilinear, trilinear, aniso, ewa, sat or supersample",
                )
            })
    }
}

/// Filter within one mip level.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum TexelFilter {
    /// The texel containing the coordinate (1 texel).
    Nearest,
    /// Bilinear interpolation of the 2×2 nearest texel centres (4 texels).
    #[default]
    Linear,
}

impl fmt::Display for TexelFilter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            TexelFilter::Nearest => "nearest",
            TexelFilter::Linear => "linear",
        })
    }
}

impl FromStr for TexelFilter {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "nearest" => Ok(TexelFilter::Nearest),
            "linear" | "bilinear" => Ok(TexelFilter::Linear),
            _ => Err(Error::parse(
                "texel filter",
                s,
                "expected nearest or linear",
            )),
        }
    }
}

/// How mip levels are chosen when minifying.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum MipMode {
    /// No mipmapping: level 0 only.
    None,
    /// The nearest level (d = ceil(d' + 0.5) − 1).
    Nearest,
    /// Blend of the two nearest levels.
    #[default]
    Linear,
}

impl fmt::Display for MipMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            MipMode::None => "none",
            MipMode::Nearest => "nearest",
            MipMode::Linear => "linear",
        })
    }
}

impl FromStr for MipMode {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "none" => Ok(MipMode::None),
            "nearest" => Ok(MipMode::Nearest),
            "linear" => Ok(MipMode::Linear),
            _ => Err(Error::parse(
                "mip mode",
                s,
                "expected none, nearest or linear",
            )),
        }
    }
}

/// The algorithm behind a sampler.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Method {
    /// The GPU sampler: magnification/minification filter, mip mode, and
    /// footprint assembly when `max_aniso > 1` (nearest, bilinear,
    /// trilinear, aniso).
    #[default]
    Texel,
    /// Elliptical weighted average.
    Ewa,
    /// Summed-area table box filter (not built by this module yet:
    /// [`Sampler::new`] refuses it).
    Sat,
    /// n × n supersampled reference at level 0.
    Supersample,
}

/// Everything that decides how a lookup filters. `Copy`, `Eq` and `Hash`
/// (floats compare by bit pattern) so it can key caches.
///
/// The default is trilinear: linear/linear/linear, no anisotropy, no bias,
/// LOD clamp ±1000 (OpenGL's defaults), repeat, transparent black border.
#[derive(Clone, Copy, Debug)]
pub struct SamplerOptions {
    /// Algorithm. Default: [`Method::Texel`].
    pub method: Method,
    /// Filter when magnifying (λ ≤ 0). Default: linear.
    pub mag: TexelFilter,
    /// Filter when minifying (λ > 0). Default: linear.
    pub min: TexelFilter,
    /// Mip level selection when minifying. Default: linear.
    pub mip: MipMode,
    /// Maximum anisotropy, 1 to 16 (1 = isotropic). Default: 1. Used by
    /// footprint assembly (probe count) and EWA (minor-axis lengthening).
    pub max_aniso: u32,
    /// Added to λ before the clamp. Default: 0.
    pub lod_bias: f32,
    /// Lower LOD clamp. Default: −1000.
    pub lod_min: f32,
    /// Upper LOD clamp. Default: 1000.
    pub lod_max: f32,
    /// Wrap mode per axis. Default: repeat.
    pub wrap: Wrap,
    /// Colour read outside the level under `ClampToBorder`, linear RGBA.
    /// Default: transparent black.
    pub border: [f32; 4],
    /// Grid size n of the supersampled reference (n × n lookups), 1 to 64.
    /// Default: 8.
    pub supersample: u32,
}

impl Default for SamplerOptions {
    fn default() -> Self {
        SamplerOptions {
            method: Method::Texel,
            mag: TexelFilter::Linear,
            min: TexelFilter::Linear,
            mip: MipMode::Linear,
            max_aniso: 1,
            lod_bias: 0.0,
            lod_min: -1000.0,
            lod_max: 1000.0,
            wrap: Wrap::default(),
            border: [0.0; 4],
            supersample: 8,
        }
    }
}

impl SamplerOptions {
    /// Nearest texel, nearest mip level.
    pub fn nearest() -> Self {
        SamplerOptions {
            mag: TexelFilter::Nearest,
            min: TexelFilter::Nearest,
            mip: MipMode::Nearest,
            ..Default::default()
        }
    }

    /// Bilinear, nearest mip level.
    pub fn bilinear() -> Self {
        SamplerOptions {
            mip: MipMode::Nearest,
            ..Default::default()
        }
    }

    /// Trilinear (the default).
    pub fn trilinear() -> Self {
        Self::default()
    }

    /// Trilinear footprint assembly with up to `max_aniso` probes (1–16).
    pub fn aniso(max_aniso: u32) -> Self {
        SamplerOptions {
            max_aniso,
            ..Default::default()
        }
    }

    /// EWA with maximum anisotropy 16.
    pub fn ewa() -> Self {
        SamplerOptions {
            method: Method::Ewa,
            max_aniso: 16,
            ..Default::default()
        }
    }

    /// The summed-area-table box filter (see [`Method::Sat`]).
    pub fn sat() -> Self {
        SamplerOptions {
            method: Method::Sat,
            ..Default::default()
        }
    }

    /// The supersampled reference with `n × n` lookups.
    pub fn supersample(n: u32) -> Self {
        SamplerOptions {
            method: Method::Supersample,
            supersample: n,
            ..Default::default()
        }
    }

    /// The preset behind a filter name; `max_aniso` is used by `aniso`
    /// (and `ewa`), `supersample` by `supersample`.
    pub fn preset(filter: Filter, max_aniso: u32) -> Self {
        match filter {
            Filter::Nearest => Self::nearest(),
            Filter::Bilinear => Self::bilinear(),
            Filter::Trilinear => Self::trilinear(),
            Filter::Aniso => Self::aniso(max_aniso),
            Filter::Ewa => SamplerOptions {
                max_aniso,
                ..Self::ewa()
            },
            Filter::Sat => Self::sat(),
            Filter::Supersample => Self::supersample(8),
        }
    }

    /// The name used in reports: `nearest`, `bilinear`, `trilinear`,
    /// `aniso2`…`aniso16`, `ewa`, `sat`, `supersample`, or a description
    /// of a non-preset combination (`mag-linear-min-nearest-mip-none`).
    pub fn name(&self) -> String {
        match self.method {
            Method::Ewa => return "ewa".into(),
            Method::Sat => return "sat".into(),
            Method::Supersample => return "supersample".into(),
            Method::Texel => {}
        }
        use TexelFilter::{Linear, Nearest};
        match (self.mag, self.min, self.mip, self.max_aniso) {
            (Linear, Linear, MipMode::Linear, n) if n > 1 => format!("aniso{n}"),
            (Nearest, Nearest, MipMode::Nearest, 1) => "nearest".into(),
            (Linear, Linear, MipMode::Nearest, 1) => "bilinear".into(),
            (Linear, Linear, MipMode::None, 1) => "bilinear-nomip".into(),
            (Linear, Linear, MipMode::Linear, 1) => "trilinear".into(),
            (mag, min, mip, n) => {
                let mut s = format!("mag-{mag}-min-{min}-mip-{mip}");
                if n > 1 {
                    s += &format!("-aniso{n}");
                }
                s
            }
        }
    }

    /// The report names of the filters `parvo tradeoff` compares by
    /// default, cheapest first (SPEC.md report names).
    pub const REPORT_FILTERS: [&'static str; 9] = [
        "nearest",
        "bilinear",
        "trilinear",
        "aniso2",
        "aniso4",
        "aniso8",
        "aniso16",
        "ewa",
        "sat",
    ];

    /// The preset a report name names: a filter name (`aniso` meaning
    /// aniso16), `aniso2` … `aniso16`, or `bilinear-nomip` (bilinear with
    /// mip mode none: level 0 only).
    pub fn from_name(name: &str) -> Result<Self> {
        let t = name.trim().to_ascii_lowercase();
        if let Some(n) = t.strip_prefix("aniso").filter(|n| !n.is_empty()) {
            let n: u32 = n
                .parse()
                .ok()
                .filter(|n| (1..=16).contains(n))
                .ok_or_else(|| Error::parse("filter", name, "anisoN needs N from 1 to 16"))?;
            return Ok(SamplerOptions::aniso(n));
        }
        if t == "bilinear-nomip" {
            return Ok(SamplerOptions {
                mip: MipMode::None,
                ..SamplerOptions::bilinear()
            });
        }
        let f: Filter = t.parse()?;
        Ok(SamplerOptions::preset(f, 16))
    }

    /// Check every field; [`Sampler::new`] calls this.
    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(Error::InvalidOption(m));
        if !(1..=16).contains(&self.max_aniso) {
            return bad(format!("max anisotropy {} must be 1 to 16", self.max_aniso));
        }
        for (name, x) in [
            ("LOD bias", self.lod_bias),
            ("LOD min", self.lod_min),
            ("LOD max", self.lod_max),
        ] {
            if !x.is_finite() {
                return bad(format!("{name} {x} must be finite"));
            }
        }
        if self.lod_min > self.lod_max {
            return bad(format!(
                "LOD min {} is above LOD max {}",
                self.lod_min, self.lod_max
            ));
        }
        if !self.border.iter().all(|c| c.is_finite()) {
            return bad(format!("border colour {:?} must be finite", self.border));
        }
        if !(1..=64).contains(&self.supersample) {
            return bad(format!(
                "supersample grid {} must be 1 to 64",
                self.supersample
            ));
        }
        Ok(())
    }

    fn key(&self) -> impl PartialEq + Hash {
        (
            self.method,
            self.mag,
            self.min,
            self.mip,
            self.max_aniso,
            [
                self.lod_bias.to_bits(),
                self.lod_min.to_bits(),
                self.lod_max.to_bits(),
            ],
            self.wrap,
            self.border.map(f32::to_bits),
            self.supersample,
        )
    }
}

impl PartialEq for SamplerOptions {
    fn eq(&self, other: &Self) -> bool {
        self.key() == other.key()
    }
}

impl Eq for SamplerOptions {}

impl Hash for SamplerOptions {
    fn hash<H: Hasher>(&self, state: &mut H) {
        self.key().hash(state);
    }
}

impl fmt::Display for SamplerOptions {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.name())
    }
}

/// What [`Sampler`] runs.
#[derive(Clone, Copy, Debug)]
enum Kernel {
    /// `Texel` with `max_aniso == 1`: η = 1, one probe, λ without roots.
    Isotropic,
    /// `Texel` with `max_aniso > 1`: footprint assembly.
    Texel,
    Ewa,
    Supersample,
    /// Summed-area table over level 0 (`sat`).
    Sat,
}

/// A texture ready to be sampled with one set of options.
///
/// Building it prepares the chain once ([`LinearChain`]: the texels as
/// stored, decoded at fetch); [`Sampler::shared`] reads an `Arc`'d chain
/// without copying it, and [`Sampler::from_linear`] shares a prepared
/// chain between samplers (the `sat` filter's too). Lookups take `&self` and are
/// safe to run from many threads.
///
/// Every lookup goes through one dispatch on the storage, the filter and
/// the mip mode, made once per slice of queries (once per call for
/// [`Sampler::sample`]); the loop inside is compiled for that combination
/// alone.
#[derive(Clone, Debug)]
pub struct Sampler {
    chain: Arc<LinearChain>,
    options: SamplerOptions,
    kernel: Kernel,
    addr: Addressing,
    lod: Lod,
    sat: Option<Arc<SatSampler>>,
    /// What [`Sampler::sample`] and [`Sampler::sample_quad`] run (see
    /// `one.rs`).
    paths: one::Paths,
    /// The chain's level table for the AVX-512 path, when it can run.
    #[cfg(target_arch = "x86_64")]
    simd: Option<simd::LevelTable>,
}

impl Sampler {
    /// Prepare a copy of `chain` ([`LinearChain::new`]) and check
    /// `options` (an [`Error::InvalidOption`] for out-of-range values).
    /// [`Sampler::shared`] reads the caller's chain without the copy.
    ///
    /// For `sat` the summed-area table of level 0 is built here (the
    /// narrowest exact accumulator, see [`crate::sat::choose`]).
    pub fn new(chain: &MipChain, options: SamplerOptions) -> Result<Self> {
        options.validate()?;
        Self::from_linear(Arc::new(LinearChain::new(chain)), options)
    }

    /// A sampler that reads `chain`'s texel buffers where they are
    /// ([`LinearChain::shared`]): no copy of the texels, whatever the
    /// storage type (sRGB `f32` chains excepted, see [`fetch`]).
    pub fn shared(chain: Arc<MipChain>, options: SamplerOptions) -> Result<Self> {
        options.validate()?;
        Self::from_linear(Arc::new(LinearChain::shared(chain)), options)
    }

    /// A `sat` sampler over `chain` with an already built table (the
    /// texture store builds it once for every run that needs it).
    pub fn with_sat(
        chain: &MipChain,
        options: SamplerOptions,
        sat: Arc<SatSampler>,
    ) -> Result<Self> {
        Self::from_linear_with_sat(Arc::new(LinearChain::new(chain)), options, sat)
    }

    /// The summed-area-table sampler of the `sat` filter.
    pub fn sat(&self) -> Option<&SatSampler> {
        self.sat.as_deref()
    }

    /// A sampler over an already prepared chain, shared with the other
    /// samplers built from it. For the `sat` filter the summed-area table
    /// is built here from the chain's source level 0
    /// ([`LinearChain::source`]); [`Sampler::from_linear_with_sat`] shares
    /// a built one.
    pub fn from_linear(chain: Arc<LinearChain>, options: SamplerOptions) -> Result<Self> {
        if options.method != Method::Sat {
            return Self::build(chain, options, false);
        }
        options.validate()?;
        let base = chain
            .source()
            .level(0)
            .ok_or_else(|| Error::InvalidOption("empty mip chain".into()))?;
        let sat = Arc::new(SatSampler::new(base, options.wrap, options.border)?);
        Self::from_linear_with_sat(chain, options, sat)
    }

    /// A sampler over an already prepared chain with an already built
    /// summed-area table (used when `options` is the `sat` filter, ignored
    /// otherwise): a `sat` sampler and the mip samplers of one texture
    /// then share one prepared chain and one table.
    pub fn from_linear_with_sat(
        chain: Arc<LinearChain>,
        options: SamplerOptions,
        sat: Arc<SatSampler>,
    ) -> Result<Self> {
        if options.method != Method::Sat {
            return Self::build(chain, options, false);
        }
        let mut s = Self::build(chain, options, true)?;
        s.sat = Some(sat);
        Ok(s)
    }

    fn build(chain: Arc<LinearChain>, options: SamplerOptions, have_sat: bool) -> Result<Self> {
        options.validate()?;
        let kernel = match options.method {
            Method::Texel if options.max_aniso == 1 => Kernel::Isotropic,
            Method::Texel => Kernel::Texel,
            Method::Ewa => Kernel::Ewa,
            Method::Supersample => Kernel::Supersample,
            Method::Sat if have_sat => Kernel::Sat,
            Method::Sat => return Err(sat_unavailable()),
        };
        let (wf, hf) = chain.size0();
        let lod = Lod::new(&options, wf, hf, chain.len());
        #[cfg(target_arch = "x86_64")]
        let simd = simd_table(&chain);
        let paths = one::pick(kernel, &options, &chain.store);
        Ok(Sampler {
            chain,
            options,
            kernel,
            addr: Addressing {
                wrap: options.wrap,
                border: options.border,
            },
            lod,
            sat: None,
            paths,
            #[cfg(target_arch = "x86_64")]
            simd,
        })
    }

    /// Whether lookups without a tracing sink take the AVX-512 path: the
    /// bilinear, trilinear and footprint-assembly lookups (linear
    /// magnification and minification, mip mode nearest or linear) and
    /// the isotropic nearest ones (nearest magnification and
    /// minification, mip mode nearest or linear) on a
    /// CPU with AVX-512 F, BW, DQ, VL and VBMI, unless `PARVO_NO_AVX` is
    /// set. The results are the same either way, bit for bit; traced
    /// lookups always take the portable path.
    pub fn uses_simd(&self) -> bool {
        #[cfg(target_arch = "x86_64")]
        {
            use TexelFilter::{Linear, Nearest};
            let o = &self.options;
            let filters = match self.kernel {
                Kernel::Isotropic => {
                    (o.mag, o.min) == (Linear, Linear) || (o.mag, o.min) == (Nearest, Nearest)
                }
                Kernel::Texel => (o.mag, o.min) == (Linear, Linear),
                _ => false,
            };
            filters && o.mip != MipMode::None && self.simd.is_some()
        }
        #[cfg(not(target_arch = "x86_64"))]
        false
    }

    /// Allows (`true`, the default) or forbids the AVX-512 path of
    /// [`uses_simd`](Self::uses_simd) for this sampler. The results are
    /// the same bit for bit; forbidding it times the portable code, or
    /// rules the SIMD code out while debugging. It also governs the
    /// AVX-512 sums of EWA on packed RGBA8 chains (untraced), whose
    /// results differ from the AVX2 build's in the last bits (both are
    /// within 1e-3 of [`sample_ewa_exact`](Self::sample_ewa_exact)). Allowing it does nothing
    /// where the CPU, `PARVO_NO_AVX` or the texture format rule it out.
    pub fn set_simd(&mut self, allowed: bool) {
        #[cfg(target_arch = "x86_64")]
        {
            self.simd = if allowed {
                simd_table(&self.chain)
            } else {
                None
            };
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = allowed;
    }

    /// The options.
    pub fn options(&self) -> &SamplerOptions {
        &self.options
    }

    /// The prepared chain.
    pub fn chain(&self) -> &Arc<LinearChain> {
        &self.chain
    }

    /// LOD and anisotropy of `q` under these options.
    pub fn footprint(&self, q: &Query) -> Footprint {
        footprint::footprint_f64(q, self.lod.wf, self.lod.hf, &self.options)
    }

    /// Filtered linear RGBA colour at `q`.
    #[inline]
    pub fn sample(&self, q: &Query) -> [f32; 4] {
        bilinear::unpack((self.paths.one)(self, &self.lod, &self.options, q))
    }

    /// [`Sampler::sample`] encoded to 8 bits in the texture's own colour
    /// space (sRGB colour channels for an sRGB texture, alpha always
    /// linear), rounded to nearest, clamped to [0, 1] (NaN reads 0): what a
    /// renderer writes to an RGBA8 framebuffer. The filtering itself stays
    /// in linear light.
    pub fn sample_rgba8(&self, q: &Query) -> [u8; 4] {
        self.encode_rgba8(self.sample(q))
    }

    /// A linear RGBA colour encoded as [`Sampler::sample_rgba8`] encodes it.
    pub fn encode_rgba8(&self, c: [f32; 4]) -> [u8; 4] {
        let srgb = self.chain.format().color_space == crate::texel::ColorSpace::Srgb;
        let lin = |x: f32| {
            #[allow(clippy::manual_clamp)]
            let x = x.max(0.0).min(1.0);
            (x * 255.0 + 0.5) as u8
        };
        std::array::from_fn(|k| {
            if srgb && k < 3 {
                crate::texel::srgb::encode_u8(c[k])
            } else {
                lin(c[k])
            }
        })
    }

    /// Filtered colour at `(u, v)` on the explicit level `level` (GLSL
    /// `textureLod`, WGSL `textureSampleLevel`): the sampler's bias and LOD
    /// clamps apply, its mag/min/mip filters choose the texels, there is no
    /// anisotropy (see [`gl`]).
    pub fn sample_level(&self, u: f32, v: f32, level: f32) -> [f32; 4] {
        let plan = gl::level_plan(&self.lod, &self.options, level);
        self.probe_plan(&plan, u, v)
    }

    /// [`Sampler::sample`] with `bias` added to the sampler's LOD bias
    /// (GLSL `texture(s, p, bias)`, WGSL `textureSampleBias`). Every method
    /// takes it: the isotropic and anisotropic lookups in λ, EWA, the
    /// summed-area table and the reference by scaling the footprint by
    /// 2^bias, which moves their λ by `bias` too.
    pub fn sample_bias(&self, q: &Query, bias: f32) -> [f32; 4] {
        // The LOD rules need a finite bias (`validate`): ±∞ saturates λ at
        // the clamp as ±4096 does; NaN reads as 0, as a NaN coordinate does.
        let bias = if bias.is_nan() {
            0.0
        } else {
            bias.clamp(-4096.0, 4096.0)
        };
        if bias == 0.0 {
            return self.sample(q);
        }
        match self.kernel {
            Kernel::Isotropic | Kernel::Texel => {
                let mut o = self.options;
                o.lod_bias += bias;
                let lod = Lod::new(&o, self.lod.wf, self.lod.hf, self.chain.len());
                bilinear::unpack((self.paths.one)(self, &lod, &o, q))
            }
            _ => {
                let k = (bias as f64).exp2() as f32;
                let scaled = Query::new(q.u, q.v, q.dudx * k, q.dvdx * k, q.dudy * k, q.dvdy * k);
                self.sample(&scaled)
            }
        }
    }

    /// Component `component` (0–3; higher reads 3) of the four texels a
    /// bilinear lookup of level 0 at `(u, v)` reads, in GL's order
    /// (T_i0j1, T_i1j1, T_i1j0, T_i0j0) (GLSL `textureGather`, WGSL
    /// `textureGather`; see [`gl`]).
    pub fn gather(&self, u: f32, v: f32, component: usize) -> [f32; 4] {
        with_chain!(&self.chain.store, c => gl::gather(c, &self.addr, u, v, component))
    }

    /// Depth comparison at `q`: channel 0 of each texel read is compared
    /// with `reference` by `op` and the 0/1 results are filtered with the
    /// sampler's mag/min/mip filters, isotropically (GLSL `textureGrad` on
    /// a `sampler2DShadow`, WGSL `textureSampleCompare`; see [`gl`]).
    pub fn sample_compare(&self, q: &Query, reference: f32, op: CompareOp) -> f32 {
        self.sample_compare_bias(q, reference, op, 0.0)
    }

    /// [`Sampler::sample_compare`] with a shader LOD bias added to the
    /// sampler's (GLSL `texture(sampler2DShadow, p, bias)`; WGSL has no
    /// biased compare).
    pub fn sample_compare_bias(&self, q: &Query, reference: f32, op: CompareOp, bias: f32) -> f32 {
        let plan = gl::gradient_plan(&self.lod, &self.options, q, bias);
        self.compare_plan(&plan, q.u, q.v, reference, op)
    }

    /// [`Sampler::sample_compare`] on an explicit level (GLSL `textureLod`
    /// on a shadow sampler, WGSL `textureSampleCompareLevel`).
    pub fn sample_compare_level(
        &self,
        u: f32,
        v: f32,
        level: f32,
        reference: f32,
        op: CompareOp,
    ) -> f32 {
        let plan = gl::level_plan(&self.lod, &self.options, level);
        self.compare_plan(&plan, u, v, reference, op)
    }

    /// The decoded texel `(x, y)` of `level`, without filtering or wrapping
    /// (GLSL `texelFetch`, WGSL `textureLoad`); `None` outside the level.
    pub fn load(&self, x: i64, y: i64, level: u32) -> Option<[f32; 4]> {
        let (x, y) = (u32::try_from(x).ok()?, u32::try_from(y).ok()?);
        self.chain.texel(level as usize, x, y)
    }

    /// The four pixels of a 2×2 quad (top-left, top-right, bottom-left,
    /// bottom-right), their derivatives taken inside the quad as a GPU
    /// does ([`quad_queries`]).
    pub fn sample_quad(&self, uv: &[[f32; 2]; 4]) -> [[f32; 4]; 4] {
        (self.paths.quad)(self, &quad_queries(uv))
    }

    fn probe_plan(&self, plan: &footprint::Plan, u: f32, v: f32) -> [f32; 4] {
        let f = MagMin {
            mag: self.options.mag,
            min: self.options.min,
        };
        let q = Query::point(u, v);
        let (u, v) = self.lod.reduce(&q);
        with_chain!(&self.chain.store, c => trilinear::probe(c, f, plan, u, v, &self.addr, &mut NoTrace))
    }

    fn compare_plan(
        &self,
        plan: &footprint::Plan,
        u: f32,
        v: f32,
        reference: f32,
        op: CompareOp,
    ) -> f32 {
        let normalised = !self.chain.format().channel_type.is_float();
        let (a, o) = (&self.addr, &self.options);
        with_chain!(&self.chain.store, c => gl::compare(c, a, o, plan, u, v, reference, op, normalised))
    }

    /// EWA with exactly computed weights (`exp` per texel, every fetch
    /// wrapped, `f64` sums): the reference the fast EWA of
    /// [`Sampler::sample`] is tested against (they agree within 1e-3).
    /// Uses this sampler's options as the `ewa` preset would.
    pub fn sample_ewa_exact(&self, q: &Query) -> [f32; 4] {
        let (a, lod, o) = (&self.addr, &self.lod, &self.options);
        with_chain!(&self.chain.store, c => ewa::ewa_exact(c, a, lod, o, q, &mut NoTrace))
    }

    /// [`Sampler::sample`], reporting every texel read to `sink`.
    #[inline]
    pub fn sample_traced<S: TexelSink>(&self, q: &Query, sink: &mut S) -> [f32; 4] {
        let mut out = [[0.0; 4]];
        self.run(std::slice::from_ref(q), &mut out, sink);
        out[0]
    }

    /// Sample `queries` into `out` (same length) in order, reporting to
    /// `sink`: the one dispatch point of every lookup.
    pub(crate) fn run<S: TexelSink>(&self, queries: &[Query], out: &mut [[f32; 4]], sink: &mut S) {
        // Two sink types reach the kernels (see `trace::Erased`); `S::TRACES`
        // is a constant, so each `S` compiles one of the two calls.
        if S::TRACES {
            self.run_sink(queries, out, &mut Erased(sink));
        } else {
            self.run_sink(queries, out, &mut NoTrace);
        }
    }

    fn run_sink<S: TexelSink>(&self, queries: &[Query], out: &mut [[f32; 4]], sink: &mut S) {
        with_chain!(&self.chain.store, c => self.run_on(c, queries, out, sink))
    }

    fn run_on<P: Pixel, S: TexelSink>(
        &self,
        c: &Chain<P>,
        queries: &[Query],
        out: &mut [[f32; 4]],
        sink: &mut S,
    ) {
        let (a, lod, o) = (&self.addr, &self.lod, &self.options);
        match self.kernel {
            Kernel::Isotropic => self.run_filters::<P, S, false>(c, queries, out, sink),
            Kernel::Texel => self.run_filters::<P, S, true>(c, queries, out, sink),
            Kernel::Ewa => {
                #[cfg(target_arch = "x86_64")]
                let avx512 = self.simd.is_some();
                #[cfg(not(target_arch = "x86_64"))]
                let avx512 = false;
                ewa::ewa_slice(c, a, lod, o, queries, out, sink, avx512)
            }
            Kernel::Supersample => each(queries, out, |q| {
                supersample::supersample(c, a, lod, o, q, sink)
            }),
            // The table answers from corner entries per rectangle, not
            // from texels: the sink sees those entries.
            Kernel::Sat => each(queries, out, |q| match &self.sat {
                Some(t) => t.sample_traced(q.u, q.v, q.dudx, q.dvdx, q.dudy, q.dvdy, &mut *sink),
                None => [0.0; 4],
            }),
        }
    }

    fn run_filters<P: Pixel, S: TexelSink, const ANISO: bool>(
        &self,
        c: &Chain<P>,
        queries: &[Query],
        out: &mut [[f32; 4]],
        sink: &mut S,
    ) {
        use TexelFilter::{Linear, Nearest};
        // A traced lookup (the cache simulator's) takes the run-time pair:
        // the same texels and values, one copy of the kernels instead of
        // three (a constant test, so untraced code keeps its three).
        if S::TRACES {
            let f = MagMin {
                mag: self.options.mag,
                min: self.options.min,
            };
            return self.run_mip::<P, S, MagMin, ANISO>(c, f, queries, out, sink);
        }
        match (self.options.mag, self.options.min) {
            (Nearest, Nearest) => self.run_mip::<P, S, Near, ANISO>(c, Near, queries, out, sink),
            (Linear, Linear) => self.run_mip::<P, S, Lin, ANISO>(c, Lin, queries, out, sink),
            (mag, min) => {
                let f = MagMin { mag, min };
                self.run_mip::<P, S, MagMin, ANISO>(c, f, queries, out, sink)
            }
        }
    }

    fn run_mip<P: Pixel, S: TexelSink, F: Filters, const ANISO: bool>(
        &self,
        c: &Chain<P>,
        f: F,
        queries: &[Query],
        out: &mut [[f32; 4]],
        sink: &mut S,
    ) {
        use trilinear::{MIP_LINEAR, MIP_NEAREST, MIP_NONE};
        match self.options.mip {
            MipMode::None => self.run_texel::<P, S, F, MIP_NONE, ANISO>(c, f, queries, out, sink),
            MipMode::Nearest => {
                self.run_texel::<P, S, F, MIP_NEAREST, ANISO>(c, f, queries, out, sink)
            }
            MipMode::Linear => {
                self.run_texel::<P, S, F, MIP_LINEAR, ANISO>(c, f, queries, out, sink)
            }
        }
    }

    fn run_texel<P: Pixel, S: TexelSink, F: Filters, const MIP: u8, const ANISO: bool>(
        &self,
        c: &Chain<P>,
        f: F,
        queries: &[Query],
        out: &mut [[f32; 4]],
        sink: &mut S,
    ) {
        let (a, lod, o) = (&self.addr, &self.lod, &self.options);
        // Isotropic lookups go 8 at a time: fewer take the portable path
        // directly.
        #[cfg(target_arch = "x86_64")]
        if let Some(table) = &self.simd
            && !S::TRACES
            && F::LINEAR
            && MIP != trilinear::MIP_NONE
            && (ANISO || queries.len() >= 8)
        {
            // SAFETY: `self.simd` is `LevelTable::new` of this sampler's
            // chain, `c` (see `Sampler::build`).
            #[allow(unsafe_code)]
            unsafe {
                if ANISO {
                    simd::anisotropic::<P, MIP>(c, table, a, lod, o, queries, out);
                } else {
                    simd::isotropic::<P, MIP>(c, table, a, lod, o, queries, out);
                }
            }
            return;
        }
        // Nearest lookups go 16 at a time (see `simd::nearest`).
        #[cfg(target_arch = "x86_64")]
        if let Some(table) = &self.simd
            && !S::TRACES
            && F::NEAREST
            && !ANISO
            && MIP != trilinear::MIP_NONE
            && queries.len() >= 16
        {
            // SAFETY: as above.
            #[allow(unsafe_code)]
            unsafe {
                simd::nearest::<P, MIP>(c, table, a, lod, o, queries, out);
            }
            return;
        }
        // Two passes per block of queries: first every footprint (LOD,
        // levels, probe count), then every texel read. A lookup is one long
        // chain of dependent steps (derivatives → λ → level → position →
        // texel → decode); splitting it lets the processor overlap the
        // arithmetic of one pass's independent queries instead of waiting
        // on each chain in turn.
        for (qs, os) in queries.chunks(BLOCK).zip(out.chunks_mut(BLOCK)) {
            if ANISO {
                let mut st = [aniso::Setup::EMPTY; BLOCK];
                for (s, q) in st.iter_mut().zip(qs) {
                    *s = aniso::setup::<F, MIP>(lod, o, q);
                }
                for (s, o) in st.iter().zip(os.iter_mut()) {
                    *o = aniso::anisotropic(c, f, s, a, sink);
                }
            } else {
                let mut plans = [footprint::Plan::MAGNIFY; BLOCK];
                for (p, q) in plans.iter_mut().zip(qs) {
                    *p = trilinear::plan::<F, MIP>(lod, o, q);
                }
                for ((p, q), o) in plans.iter().zip(qs).zip(os.iter_mut()) {
                    // Into the first wrap period, so that a rasterizer's
                    // tiled UVs (−30…30) take the inside-the-level path.
                    let (u, v) = lod.reduce(q);
                    *o = trilinear::probe(c, f, p, u, v, a, sink);
                }
            }
        }
    }
}

/// The AVX-512 level table of `chain`, if that path can run on it.
#[cfg(target_arch = "x86_64")]
fn simd_table(chain: &LinearChain) -> Option<simd::LevelTable> {
    with_chain!(&chain.store, c => simd::LevelTable::new(c))
}

/// Queries per block of the two-pass loop (see `Sampler::run_texel`).
const BLOCK: usize = 16;

/// `a.map(f)` for four elements, written out: the standard library's
/// `map` brings six helper functions per call site, and a generic caller
/// is copied per storage, filter and level mode (hundreds of copies).
#[inline(always)]
pub(crate) fn map4<T: Copy, U>(a: [T; 4], mut f: impl FnMut(T) -> U) -> [U; 4] {
    [f(a[0]), f(a[1]), f(a[2]), f(a[3])]
}

/// `out[i] = f(&queries[i])`.
#[inline(always)]
fn each(queries: &[Query], out: &mut [[f32; 4]], mut f: impl FnMut(&Query) -> [f32; 4]) {
    for (q, o) in queries.iter().zip(out.iter_mut()) {
        *o = f(q);
    }
}

fn sat_unavailable() -> Error {
    Error::InvalidOption(
        "the sat filter needs a summed-area table, built from the chain's level 0".into(),
    )
}
