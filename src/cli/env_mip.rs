//! `parvo mip --env latlong|cube` and cube maps or arrays given to `parvo
//! mip`: environment maps built as maketx's `--envlatl` / `--envcube`
//! build them (lat-long levels weighted by solid angle; cube faces
//! filtered each on its own, their edges made seamless), optionally
//! prefiltered for specular lighting, and textures of several faces or
//! layers kept as what they are.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result, anyhow, bail};
use parvo::env::cube::{CubeLayout, build_faces, faces_from_strip, fix_edges, layouts_sentence};
use parvo::env::prefilter::{self, Lobe};
use parvo::env::{Kind, convert, latlong};
use parvo::io::{self, Environment, LoadOptions, OutputKind, SaveOptions};
use parvo::mip::{self, MipChain, MipOptions, Rounding};
use parvo::pipeline::{ColorChoice, Settings};
use parvo::texel::{ChannelType, ColorSpace};
use parvo::texture::Texture;

use super::env::EnvArg;

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
        by filtered importance sampling (--prefilter-samples directions per texel, each read from \
        the level whose texels match the sample's solid angle). Levels are linear f32 RGBA \
        internally; written as --type, else f16 (f32 for f32 inputs) where the container stores \
        floats."
    )]
    pub prefilter: Option<LobeArg>,

    /// Lobe directions per texel for --prefilter.
    #[arg(long, default_value_t = 64, value_name = "N", requires = "prefilter")]
    pub prefilter_samples: u32,

    /// Also write the diffuse irradiance (cosine lobe) as a cube map of 32x32 faces to this file.
    #[arg(long, value_name = "OUTPUT")]
    pub irradiance: Option<PathBuf>,

    /// Keep each cube face's levels as filtered, without averaging the texels along the edges.
    #[arg(long)]
    pub no_edge_fixup: bool,
}

impl EnvMipArgs {
    /// True when an environment map is asked for.
    pub fn asked(&self) -> bool {
        self.env.is_some() || self.prefilter.is_some() || self.irradiance.is_some()
    }
}

/// True when `inputs` go through [`run`]: `--env` (or a flag of its own)
/// was given, or the one input is a cube map or an array.
pub fn wanted(args: &EnvMipArgs, inputs: &[String]) -> bool {
    if args.asked() || inputs.len() != 1 {
        return args.asked();
    }
    // A one-layer array is built as the one image it holds.
    let kind = io::peek_kind(Path::new(&inputs[0]));
    kind.images() > 1 || kind == Kind::LatLong
}

/// What the inputs hold, read as `--env` and the files say.
enum Source {
    /// Faces or layers of a KTX2/DDS file (level 0 of each).
    Images(Kind, Vec<Texture>),
    /// A lat-long image.
    LatLong(Texture),
}

/// Build the environment map, cube map or array of `inputs` into
/// `output` (see the module docs). Errors are the caller's to print.
pub fn run(
    inputs: &[String],
    output: Option<&Path>,
    args: &EnvMipArgs,
    settings: &Settings,
) -> Result<ExitCode> {
    let output = output.ok_or_else(|| {
        anyhow!("an environment map, cube map or array is written with -o OUTPUT (one output)")
    })?;
    let out_kind = OutputKind::from_path(output)?;
    let source = read(inputs, args.env, settings)?;
    let src_type = match &source {
        Source::Images(_, images) => images[0].channel_type(),
        Source::LatLong(base) => base.channel_type(),
    };
    let options = MipOptions {
        filter: settings.filter,
        rounding: Rounding::Down,
        nan_policy: settings.nan_policy,
        ..MipOptions::default()
    };
    let (kind, chains) = build(source, args, &options)?;
    let float_levels = args.prefilter.is_some();
    let out_type = settings.out_type.unwrap_or_else(|| {
        if float_levels && out_kind.stores().float {
            out_kind.default_type(if src_type == ChannelType::F32 {
                ChannelType::F32
            } else {
                ChannelType::F16
            })
        } else {
            out_kind.default_type(src_type)
        }
    });
    let save = SaveOptions {
        tile: settings.tile,
        compression: settings.compression,
        supercompression: settings.supercompression,
        attributes: vec![
            ("parvo:filter".into(), settings.filter.to_string()),
            ("parvo:source".into(), inputs.join(" ")),
        ],
        ..SaveOptions::default()
    };
    write(&chains, kind, out_type, output, out_kind, &save)?;
    eprintln!(
        "parvo: wrote {} ({}, {}x{} per image, {} levels, {out_type})",
        output.display(),
        kind.describe(),
        chains[0].levels()[0].width(),
        chains[0].levels()[0].height(),
        chains[0].len()
    );
    if let Some(path) = &args.irradiance {
        if !kind.is_cube() && kind != Kind::LatLong {
            bail!("--irradiance needs an environment map (--env cube or latlong)");
        }
        let faces = as_cube(kind, &chains, &options)?;
        let irr = prefilter::irradiance(&faces, 32)?;
        let k = OutputKind::from_path(path)?;
        let t = settings
            .out_type
            .unwrap_or(k.default_type(ChannelType::F16));
        write(&irr, Kind::Cube, t, path, k, &save)?;
        eprintln!("parvo: wrote {} (irradiance, 32x32 faces)", path.display());
    }
    Ok(ExitCode::SUCCESS)
}

/// A loader's options for `settings`, every face and layer accepted.
fn load_options(settings: &Settings) -> LoadOptions {
    LoadOptions {
        color: match settings.color {
            ColorChoice::Auto => None,
            ColorChoice::Linear => Some(ColorSpace::Linear),
            ColorChoice::Srgb => Some(ColorSpace::Srgb),
        },
        nan_policy: Some(settings.nan_policy),
        environment: io::EnvironmentMaps::Accept,
        ..settings.load.clone()
    }
}

fn load(spec: &str, settings: &Settings) -> Result<io::Loaded> {
    let loaded = io::load_with(spec, &settings.limits, &load_options(settings))
        .map_err(super::with_hint)
        .with_context(|| format!("cannot read texture `{spec}`"))?;
    for n in &loaded.info.notes {
        eprintln!("parvo: {spec}: {}", super::words(n));
    }
    Ok(loaded)
}

/// Read the inputs: six face files, or one file holding faces, layers, a
/// strip or a lat-long map.
fn read(inputs: &[String], env: Option<EnvArg>, settings: &Settings) -> Result<Source> {
    if inputs.len() == 6 {
        if env == Some(EnvArg::Latlong) {
            bail!("six face files make a cube map: use --env cube (a lat-long map is one image)");
        }
        let faces = inputs
            .iter()
            .map(|f| Ok(load(f, settings)?.into_base()))
            .collect::<Result<Vec<_>>>()?;
        return Ok(Source::Images(Kind::Cube, faces));
    }
    if inputs.len() != 1 {
        bail!(
            "an environment map is built from one file or six face files (+x -x +y -y +z -z), got {} inputs",
            inputs.len()
        );
    }
    let spec = &inputs[0];
    let loaded = load(spec, settings)?;
    let kind = loaded.info.kind;
    if kind != Kind::Plain {
        let images = loaded
            .into_images()
            .into_iter()
            .filter_map(|levels| levels.into_iter().next())
            .collect();
        return Ok(Source::Images(kind, images));
    }
    let recorded = loaded.info.environment;
    let base = loaded.into_base();
    let (w, h) = (base.width(), base.height());
    // A strip or a cross, told by the aspect (an OpenEXR cube map is
    // always the vertical strip).
    let layout = CubeLayout::detect(w, h).map(|(l, _)| l);
    match (env, recorded, layout) {
        (_, Some(Environment::Cube), _) => {
            let faces = faces_from_strip(&base)
                .with_context(|| format!("cannot read `{spec}` as a cube map"))?;
            Ok(Source::Images(Kind::Cube, faces))
        }
        (Some(EnvArg::Cube), None, Some(layout)) => {
            let faces = parvo::env::cube::faces_in_layout(&base, layout)
                .with_context(|| format!("cannot read `{spec}` as a cube map ({layout})"))?;
            Ok(Source::Images(Kind::Cube, faces))
        }
        (_, Some(Environment::LatLong), _) | (Some(EnvArg::Latlong), None, _) => {
            Ok(Source::LatLong(base))
        }
        (Some(EnvArg::Cube), None, _) if w == 2 * h => Ok(Source::LatLong(base)),
        (Some(EnvArg::Cube), ..) => bail!(
            "`{spec}` is {w}x{h}: a cube map comes from six faces in one image ({}), a lat-long \
             map (2:1), a KTX2 or DDS cube map, or six face files",
            layouts_sentence()
        ),
        _ => bail!("`{spec}` is one 2-D image: say what it holds with --env latlong or --env cube"),
    }
}

/// The chains of every face or layer and the kind they make.
fn build(source: Source, args: &EnvMipArgs, options: &MipOptions) -> Result<(Kind, Vec<MipChain>)> {
    let want = args.env;
    let (kind, chains) = match (source, want) {
        (Source::LatLong(base), Some(EnvArg::Latlong) | None) => {
            (Kind::LatLong, vec![latlong::build_chain(base)?])
        }
        (Source::LatLong(base), Some(EnvArg::Cube)) => {
            let n = args.face_size.unwrap_or((base.width() / 4).max(1));
            let faces = convert::latlong_to_cube(&latlong::build_chain(base)?, n)?;
            (Kind::Cube, cube_chains(faces, args, options)?)
        }
        (Source::Images(Kind::Cube, faces), Some(EnvArg::Latlong)) => {
            let n = faces[0].width();
            let chains = build_faces(faces, options)?;
            let base = convert::cube_to_latlong(&chains, 4 * n, 2 * n)?;
            (Kind::LatLong, vec![latlong::build_chain(base)?])
        }
        (Source::Images(k, _), Some(EnvArg::Latlong)) => {
            bail!(
                "a {} cannot become a lat-long map (one cube map can)",
                k.describe()
            )
        }
        (Source::Images(Kind::Cube, faces), _) => (Kind::Cube, cube_chains(faces, args, options)?),
        (Source::Images(Kind::CubeArray { cubes }, faces), None) => {
            let mut chains = Vec::new();
            for cube in faces.chunks(6) {
                chains.extend(cube_chains(cube.to_vec(), args, options)?);
            }
            (Kind::CubeArray { cubes }, chains)
        }
        (Source::Images(k, images), None) => {
            let chains = images
                .into_iter()
                .map(|t| mip::build(t, options))
                .collect::<parvo::error::Result<Vec<_>>>()?;
            (k, chains)
        }
        (Source::Images(k, _), Some(EnvArg::Cube)) => {
            bail!("a {} is not one cube map", k.describe())
        }
    };
    if args.prefilter.is_some() && kind != Kind::Cube {
        bail!("--prefilter builds a cube map: add --env cube");
    }
    Ok((kind, chains))
}

/// Six faces' chains: filtered per face, prefiltered when asked, edges
/// fixed up unless told not to.
fn cube_chains(
    faces: Vec<Texture>,
    args: &EnvMipArgs,
    options: &MipOptions,
) -> Result<Vec<MipChain>> {
    let mut chains = build_faces(faces, options)?;
    if let Some(lobe) = args.prefilter {
        chains = prefilter::specular(&chains, lobe.into(), args.prefilter_samples)?;
    }
    if !args.no_edge_fixup {
        chains = fix_edges(chains, 1)?;
    }
    Ok(chains)
}

/// A cube map of `kind`'s chains (a lat-long map converted).
fn as_cube(kind: Kind, chains: &[MipChain], options: &MipOptions) -> Result<Vec<MipChain>> {
    if kind == Kind::LatLong {
        let n = (chains[0].levels()[0].width() / 4).max(1);
        let faces = convert::latlong_to_cube(&chains[0], n)?;
        return Ok(build_faces(faces, options)?);
    }
    Ok(chains[..6].to_vec())
}

/// Convert every level to `ty` (as the container can store it) and save.
fn write(
    chains: &[MipChain],
    kind: Kind,
    ty: ChannelType,
    path: &Path,
    out: OutputKind,
    save: &SaveOptions,
) -> Result<()> {
    if !out.supports(ty) {
        bail!("{} cannot store {ty} texels (--type)", out.name());
    }
    let images: Vec<Vec<Texture>> = chains
        .iter()
        .map(|c| {
            c.levels()
                .iter()
                .map(|l| {
                    let f = out.storable(parvo::texel::Format {
                        channel_type: ty,
                        ..l.format()
                    });
                    l.convert(f)
                })
                .collect::<parvo::error::Result<Vec<_>>>()
        })
        .collect::<parvo::error::Result<_>>()?;
    let refs: Vec<&[Texture]> = images.iter().map(|v| v.as_slice()).collect();
    io::save_images(&refs, kind, Rounding::Down, path, out, save)
        .map_err(super::with_hint)
        .with_context(|| format!("cannot write `{}`", path.display()))?;
    Ok(())
}
