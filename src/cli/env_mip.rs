//! The environment-map arguments of `parvo mip` (`--env`, `--prefilter`,
//! ...), as the library's [`EnvSettings`]: environment maps are built as
//! maketx's `--envlatl` / `--envcube` build them (lat-long levels weighted
//! by solid angle; cube faces filtered each on its own, their edges made
//! seamless), optionally prefiltered for specular lighting, by the same
//! pipeline as every other image ([`parvo::pipeline`]).

use std::path::PathBuf;

use parvo::env::prefilter::{Integration, Lobe};
use parvo::io::{Environment, OutputKind};
use parvo::pipeline::EnvSettings;

use super::args::EnvArg;

/// `--prefilter` lobes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum LobeArg {
    /// GGX (Trowbridge-Reitz), what engines use.
    Ggx,
    /// Beckmann, the Cook-Torrance distribution.
    Beckmann,
    /// Phong around the reflection direction.
    Phong,
}

impl From<LobeArg> for Lobe {
    fn from(l: LobeArg) -> Lobe {
        match l {
            LobeArg::Ggx => Lobe::Ggx,
            LobeArg::Beckmann => Lobe::Beckmann,
            LobeArg::Phong => Lobe::Phong,
        }
    }
}

/// The environment-map arguments of `parvo mip`.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct EnvMipArgs {
    /// Build an environment map: latlong or cube.
    #[arg(
        long,
        value_enum,
        value_name = "KIND",
        long_help = "Build an environment map, as maketx --envlatl / --envcube do. latlong: a \
        lat-long (equirectangular, 2:1, y up) map whose levels weight each row by the solid angle \
        it covers; write it to .exr (marked `envmap` latlong). cube: six square faces (+x -x +y -y \
        +z -z), each filtered on its own with --filter, then every edge and corner texel of levels \
        1 and up averaged with the texels across the edge (seamless for samplers without seamless \
        cube filtering; --no-edge-fixup keeps the per-face levels); write it to .ktx2 (a cube map) \
        or .exr (OpenEXR's strip of six faces, power-of-two faces). The input is a lat-long image, \
        six faces in one image told by its aspect (a vertical strip w x 6w as OpenEXR stores cube \
        maps, a horizontal strip 6w x w, a horizontal cross 4w x 3w: -x +z +x -z across, +y above \
        and -y below +z, or a vertical cross 3w x 4w: -z below -y turned 180 degrees), a KTX2 or \
        DDS cube map, or six face files in the order +x -x +y -y +z -z; a lat-long input becomes a \
        cube map and a cube map a lat-long map when the other kind is asked for (each new texel an \
        EWA lookup over its own footprint)."
    )]
    pub env: Option<EnvArg>,

    /// Cube faces' size when a lat-long input becomes a cube map (default: a quarter of its width).
    #[arg(long, value_name = "N", requires = "env")]
    pub face_size: Option<u32>,

    /// Prefiltered specular levels: level k convolved with the lobe of roughness alpha_k = (k/(L-1))^2.
    #[arg(
        long,
        value_enum,
        value_name = "LOBE",
        long_help = "Write prefiltered specular levels instead of a plain chain (cube maps): level k \
        holds the environment convolved with the lobe (ggx, beckmann or phong) of roughness alpha_k \
        = (k / (L - 1))^2 over the L levels, with the split-sum convention N = V = R (Karis 2013), \
        integrated over level 0's texels by a deterministic quadrature (each texel's exact solid \
        angle; blocks of texels summed whole where the lobe is flat across them), or by filtered \
        importance sampling with --prefilter-samples. Levels are linear f32 RGBA \
        internally; written as --type, else f16 (f32 for f32 inputs) where the container stores \
        floats."
    )]
    pub prefilter: Option<LobeArg>,

    /// Prefilter by filtered importance sampling with N lobe directions per texel (as cmgen does)
    /// instead of the quadrature.
    #[arg(long, value_name = "N", requires = "prefilter")]
    pub prefilter_samples: Option<u32>,

    /// Also write the diffuse irradiance (cosine lobe) as a cube map of 32x32 faces to this file.
    #[arg(long, value_name = "OUTPUT")]
    pub irradiance: Option<PathBuf>,

    /// Also write GGX's split-sum BRDF table (R scale, G bias of F0; n.v across, roughness down)
    /// to this file (with --prefilter ggx).
    #[arg(long, value_name = "OUTPUT")]
    pub brdf_lut: Option<PathBuf>,

    /// The BRDF table's size.
    #[arg(long, value_name = "N", default_value_t = 128, requires = "brdf_lut")]
    pub brdf_lut_size: u32,

    /// Keep each cube face's levels as filtered, without averaging the texels along the edges.
    #[arg(long)]
    pub no_edge_fixup: bool,
}

impl EnvMipArgs {
    /// How `--prefilter` integrates its lobe.
    fn integration(&self) -> Integration {
        match self.prefilter_samples {
            Some(n) => Integration::Sampled(n),
            None => Integration::Quadrature,
        }
    }

    /// The library's environment settings of these arguments (a bad
    /// irradiance output name as text).
    pub fn settings(&self) -> Result<EnvSettings, String> {
        let kind = |p: &PathBuf| OutputKind::from_path(p).map_err(|e| e.to_string());
        let irradiance = match &self.irradiance {
            Some(p) => Some((p.clone(), kind(p)?)),
            None => None,
        };
        let brdf_lut = match &self.brdf_lut {
            Some(p) => Some((
                p.clone(),
                OutputKind::for_one_level(p).map_err(|e| e.to_string())?,
                self.brdf_lut_size,
            )),
            None => None,
        };
        Ok(EnvSettings {
            target: self.env.map(|e| match e {
                EnvArg::Latlong => Environment::LatLong,
                EnvArg::Cube => Environment::Cube,
            }),
            face_size: self.face_size,
            prefilter: self.prefilter.map(|l| (Lobe::from(l), self.integration())),
            irradiance,
            brdf_lut,
            edge_fixup: !self.no_edge_fixup,
        })
    }
}
