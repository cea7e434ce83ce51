//! The texture a sampling command reads (`sample`, `render`, `tradeoff`,
//! `cachesim`): `--color` and `--fixnan` as `parvo mip` has them, so that a
//! file is read the same way by every command, and what the loader
//! assumed or chose said on stderr once, as `parvo mip` says it.

use anyhow::{Context, Result};

use parvo::MipChain;
use parvo::compress::BlockFormat;
use parvo::io::{self, Limits, LoadOptions, Loaded};
use parvo::mip::NanPolicy;
use parvo::scene::Scene;
use parvo::texel::ColorSpace;

use super::args::ColorArg;

/// How to read the texture file.
#[derive(clap::Args, Debug, Clone)]
pub struct TextureArgs {
    /// How the file's colour values are encoded: auto, linear or srgb.
    #[arg(
        long,
        default_value = "auto",
        value_name = "SPACE",
        long_help = "How the texture's colour values are encoded. auto: what the file says (PNG \
        by its sRGB/cICP/gAMA chunks, sRGB when it has none, as OpenImageIO reads it; JPEG sRGB; \
        KTX2 and DDS by their format; OpenEXR, TIFF and HDR linear). linear: the values are data or \
        linear light, used as stored (a height map, a 16-bit data PNG that OpenImageIO wrote with \
        an sRGB chunk). srgb: decode them as sRGB."
    )]
    pub color: ColorArg,

    /// NaN/Inf in float texels: error, black or neighbors.
    #[arg(
        long,
        default_value = "error",
        value_name = "POLICY",
        long_help = "Non-finite values (NaN, +Inf, -Inf) in a float texture, in any of its levels: \
        error refuses the file naming the first one (as parvo mip does); black replaces each by 0; \
        neighbors by the average of its finite neighbours."
    )]
    pub fixnan: NanPolicy,
}

impl TextureArgs {
    /// The loader's options these arguments ask for.
    pub fn options(&self) -> LoadOptions {
        LoadOptions {
            color: match self.color {
                ColorArg::Auto => None,
                ColorArg::Linear => Some(ColorSpace::Linear),
                ColorArg::Srgb => Some(ColorSpace::Srgb),
            },
            nan_policy: Some(self.fixnan),
            ..LoadOptions::default()
        }
    }

    /// Load `spec`, printing the loader's notes (and its colour assumption
    /// under `--color auto`) on stderr.
    pub fn load(&self, spec: &str) -> Result<Loaded> {
        self.load_as(spec, self.options())
    }

    /// [`Self::load`] for a direction lookup: an environment map (a
    /// maketx or OpenEXR lat-long or cube-face file) is loaded as one,
    /// marked in [`io::SourceInfo::environment`], not refused.
    pub fn load_environment(&self, spec: &str) -> Result<Loaded> {
        let options = LoadOptions {
            environment: io::EnvironmentMaps::Accept,
            ..self.options()
        };
        self.load_as(spec, options)
    }

    /// [`Self::load`] for `scene`: an environment scene (`sky`, `sphere`)
    /// reads the texture as a lat-long map (a lat-long OpenEXR or maketx
    /// file as one, any 2-D image taken as one) with the scene's
    /// addressing, s repeating and t clamped, which the chain is built
    /// and sampled with; a cube map or an array is refused, saying how to
    /// convert it.
    pub fn load_for_scene(&self, spec: &str, scene: &Scene) -> Result<Loaded> {
        let Some(wrap) = scene.wrap() else {
            return self.load(spec);
        };
        let mut loaded = self.load_environment(spec)?;
        let kind = loaded.info.kind;
        let cube = loaded.info.environment == Some(io::Environment::Cube);
        if kind.images() > 1 || cube {
            let what = if cube {
                "a cube map".to_string()
            } else {
                format!("a {}", kind.describe())
            };
            anyhow::bail!(
                "the {scene} scene looks up a lat-long environment map, and `{spec}` is {what}: \
                 convert it first with `parvo mip --env latlong {spec} -o latlong.exr`"
            );
        }
        loaded.info.wrap = Some(wrap);
        Ok(loaded)
    }

    fn load_as(&self, spec: &str, options: LoadOptions) -> Result<Loaded> {
        let loaded = io::load_with(spec, &Limits::default(), &options)
            .map_err(super::words::with_hint)
            .with_context(|| format!("cannot read texture `{spec}`"))?;
        let assumed = (self.color == ColorArg::Auto)
            .then(|| io::assumed_color_note(&loaded.info, &loaded.base().format()))
            .flatten();
        for n in loaded.info.notes.iter().chain(&assumed) {
            eprintln!("parvo: {spec}: {}", super::words::words(n));
        }
        Ok(loaded)
    }

    /// [`Self::load`] as a mip chain: the file's own levels, or box mips
    /// built on load; and the block format the file stores, if any.
    pub fn load_chain(&self, spec: &str) -> Result<(MipChain, Option<BlockFormat>)> {
        self.load(spec)?
            .into_chain()
            .with_context(|| format!("cannot read texture `{spec}`"))
    }
}
