//! The settings of a batch: everything a job needs besides its input and
//! output.

use std::path::PathBuf;

use crate::compress::{BlockFormat, Quality};
use crate::env::prefilter::{Integration, Lobe};
use crate::io::exr::ExrOptions;
use crate::io::ktx2::Ktx2Options;
use crate::io::{Environment, Limits, LoadOptions, OutputKind};
use crate::mip::roughness::{NormalChannels, Specular};
use crate::mip::{MipFilter, NanPolicy, Rounding};
use crate::texel::ChannelType;
use crate::wrap::Wrap;

/// How to read the input's colour.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ColorChoice {
    /// What the file says (see [`crate::io::load`]); linear for normal maps.
    #[default]
    Auto,
    /// Linear, whatever the file says.
    Linear,
    /// sRGB-encoded, whatever the file says.
    Srgb,
}

/// How to read the input's alpha channel.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AlphaChoice {
    /// What the file says.
    #[default]
    Auto,
    /// Unassociated.
    Straight,
    /// Associated (premultiplied).
    Premultiplied,
    /// Not alpha: a data channel.
    None,
}

/// Everything a job needs besides its input and output.
#[derive(Clone, Debug)]
pub struct Settings {
    /// The mip filter.
    pub filter: MipFilter,
    /// Wrap modes; `None` takes the file's (repeat when it records none).
    pub wrap: Option<Wrap>,
    /// Level size rounding.
    pub rounding: Rounding,
    /// At most this many levels (including level 0); `None`: the full chain.
    pub levels: Option<u32>,
    /// Alpha coverage to preserve, in (0, 1).
    pub alpha_coverage: Option<f32>,
    /// The input is a normal map (see [`crate::mip::normal`]).
    pub normal_map: bool,
    /// What to do with NaN and infinite texels.
    pub nan_policy: NanPolicy,
    /// How to read the input's colour.
    pub color: ColorChoice,
    /// How to read the input's alpha.
    pub alpha: AlphaChoice,
    /// The output channel type; `None`: the container's default for the
    /// source.
    pub out_type: Option<ChannelType>,
    /// OpenEXR's options (tile size, compression).
    pub exr: ExrOptions,
    /// Choices the loader cannot make from the file.
    pub load: LoadOptions,
    /// Decoder limits.
    pub limits: Limits,
    /// Skip a job whose output stores this run's fingerprint.
    pub update: bool,
    /// Plan only: nothing is built or written.
    pub dry_run: bool,
    /// Normal maps: a roughness (or Blinn-Phong exponent) chain from the
    /// spread of the normals (see [`crate::mip::roughness`]).
    pub roughness: Option<RoughnessSettings>,
    /// Block-compress every level (KTX2 and DDS; needs the `encode`
    /// feature).
    pub compress: Option<(BlockFormat, Quality)>,
    /// KTX2's options (supercompression of every level).
    pub ktx2: Ktx2Options,
    /// Resample level 0 first to a block-friendly size.
    pub resize_to: Option<ResizeTo>,
    /// Decode the blocks again and measure each level's PSNR
    /// ([`super::BlockLevel::psnr_db`]).
    pub measure_blocks: bool,
    /// Environment maps: what to build and how (see [`EnvSettings`]).
    pub env: EnvSettings,
}

/// How environment maps are built. A file that records an environment
/// (an OpenEXR `envmap`, a maketx `textureformat`) or holds a cube map
/// is built as what it holds without any of these.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvSettings {
    /// Build this environment: a plain image is read as one (six faces in
    /// a strip or cross, or a lat-long map), and a lat-long source
    /// becomes a cube map or a cube map a lat-long map when the other is
    /// asked for ([`crate::io::source::interpret`]).
    pub target: Option<Environment>,
    /// Cube faces' size when a lat-long map becomes a cube map (default:
    /// a quarter of its width).
    pub face_size: Option<u32>,
    /// Prefiltered specular levels instead of a plain chain (cube maps):
    /// the lobe and how it is integrated
    /// ([`crate::env::prefilter::specular`]).
    pub prefilter: Option<(Lobe, Integration)>,
    /// Also write the diffuse irradiance (a cube map of 32×32 faces) here.
    pub irradiance: Option<(PathBuf, OutputKind)>,
    /// Also write GGX's split-sum BRDF table, `size × size`, here
    /// ([`crate::env::prefilter::dfg::table`]).
    pub brdf_lut: Option<(PathBuf, OutputKind, u32)>,
    /// Average the texels along cube faces' edges from level 1 on
    /// ([`crate::env::cube::fix_edges`]).
    pub edge_fixup: bool,
}

impl EnvSettings {
    /// True when any environment setting is given.
    pub fn asked(&self) -> bool {
        self.target.is_some()
            || self.face_size.is_some()
            || self.prefilter.is_some()
            || self.irradiance.is_some()
            || self.brdf_lut.is_some()
            || !self.edge_fixup
    }
}

impl Default for EnvSettings {
    fn default() -> Self {
        EnvSettings {
            target: None,
            face_size: None,
            prefilter: None,
            irradiance: None,
            brdf_lut: None,
            edge_fixup: true,
        }
    }
}

/// Block-friendly level-0 sizes ([`Settings::resize_to`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ResizeTo {
    /// Each side up to the next multiple of 4 (whole blocks at level 0).
    MultipleOf4,
    /// Each side to the nearest power of two (ties up): every level of the
    /// chain stays block-aligned.
    Pow2,
}

impl ResizeTo {
    /// The size `(w, h)` becomes.
    pub fn apply(self, w: u32, h: u32) -> (u32, u32) {
        let f = |n: u32| match self {
            ResizeTo::MultipleOf4 => n.div_ceil(4).saturating_mul(4),
            ResizeTo::Pow2 => {
                let up = n.checked_next_power_of_two().unwrap_or(1 << 31);
                let down = if up == n { n } else { up / 2 };
                // Nearest in ratio: up when up/n <= n/down.
                if (up as u64) * (down as u64) <= (n as u64) * (n as u64) || down == 0 {
                    up
                } else {
                    down
                }
            }
        };
        (f(w), f(h))
    }
}

/// Where a normal map's roughness comes from and where it goes.
#[derive(Clone, Debug, PartialEq)]
pub struct RoughnessSettings {
    /// The base roughness: a number, or a roughness map (a file or a
    /// `builtin:` name) of the normal map's size.
    pub base: RoughnessSource,
    /// Which channels of the normal map hold the vector.
    pub channels: NormalChannels,
    /// Roughness α' or Blinn-Phong exponents s'.
    pub specular: Specular,
    /// A second output for the chain (one channel, linear), or `None`.
    pub output: Option<(PathBuf, OutputKind)>,
    /// Store the chain in the normal output's alpha channel instead.
    pub pack_alpha: bool,
}

/// The base roughness of a roughness chain.
#[derive(Clone, Debug, PartialEq)]
pub enum RoughnessSource {
    /// One roughness in [0, 1].
    Constant(f32),
    /// A roughness map, loaded with the job's limits.
    Map(String),
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            filter: MipFilter::Box,
            wrap: None,
            rounding: Rounding::Down,
            levels: None,
            alpha_coverage: None,
            normal_map: false,
            nan_policy: NanPolicy::Error,
            color: ColorChoice::Auto,
            alpha: AlphaChoice::Auto,
            out_type: None,
            exr: ExrOptions::default(),
            load: LoadOptions::default(),
            limits: Limits::default(),
            update: false,
            dry_run: false,
            roughness: None,
            compress: None,
            ktx2: Ktx2Options::default(),
            resize_to: None,
            measure_blocks: false,
            env: EnvSettings::default(),
        }
    }
}
