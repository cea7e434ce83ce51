//! `parvo render`: a scene rendered with a filter (or the reference) to a
//! PNG, optionally tinted by the mip levels each pixel read.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Result;

use parvo::sample::SamplerOptions;
use parvo::scene::reference::{PixelFilter, Reference};
use parvo::scene::render::{queries, render, show_levels};
use parvo::scene::{Frame, Scene};
use parvo::store::TextureStore;

use super::images::{write_image, write_rgb};

/// Arguments of `parvo render`.
#[derive(clap::Args, Debug)]
#[command(
    about = "Render a scene with a filter (or the reference image) to a PNG",
    long_about = "Render a scene with a sampling filter, or the reference image (--filter reference: \
    the scene's exact mapping at stratified positions over the pixel filter's support, bilinear on \
    level 0), to an sRGB PNG. --show-levels tints each pixel by the mip level(s) it read (level 0 \
    red, 1 orange, 2 yellow, 3 green, 4 cyan, 5 blue, 6 purple, 7 magenta, ...), blended by the \
    filter's level weights, shaded by the image's luminance."
)]
pub struct RenderArgs {
    /// Scene: plane, tunnel, zoom, rotate:DEG[:SCALE], sky or sphere (these two read --texture as a lat-long environment map).
    #[arg(long, default_value = "plane", value_name = "SCENE")]
    scene: Scene,
    /// Texture: a file or builtin:checker[:SIZE], builtin:zoneplate[:SIZE], builtin:bumps[:SIZE] (a normal map), builtin:photo[:SIZE], builtin:sky[:SIZE] (a lat-long sky, SIZE × SIZE/2, for the sky and sphere scenes).
    #[arg(long, default_value = "builtin:zoneplate:512", value_name = "TEXTURE")]
    texture: String,

    #[command(flatten)]
    read: super::texture::TextureArgs,
    /// Filter (nearest, bilinear, bilinear-nomip, trilinear, anisoN, ewa, sat, supersample) or reference.
    #[arg(long, default_value = "trilinear", value_name = "F")]
    filter: String,
    /// Pixel filter of the reference: gaussian or box.
    #[arg(long, default_value = "gaussian", value_name = "F")]
    pixel_filter: PixelFilter,
    /// Reference samples per level-0 texel along each axis (default 1; see parvo::scene::reference).
    #[arg(long, value_name = "N")]
    spp: Option<f64>,
    /// Frame size.
    #[arg(long, default_value = "320x240", value_name = "WxH")]
    size: Frame,
    /// Tint each pixel by the mip level(s) it read.
    #[arg(long)]
    show_levels: bool,
    /// Shade the texture as a normal map with this BRDF: blinn-phong or cook-torrance.
    #[arg(
        long,
        value_name = "BRDF",
        long_help = "Read --texture as a normal map and shade it with the lecture's BRDF \
        (blinn-phong: normalised, exponent 2/roughness^2 - 2; cook-torrance: Beckmann D, V-groove G, \
        Schlick F, F0 0.04), lit from --light, seen from the plane's camera (other scenes: from \
        straight above), drawn --shading truth (every level-0 normal under the pixel shaded and \
        averaged), renormalised (the trilinear normal chain with the base roughness) or adjusted \
        (with the roughness chain of parvo::mip::roughness). --filter does not apply."
    )]
    shade: Option<ShadeBrdf>,
    /// Light direction in the texture's tangent space (x along u, y along v, z up).
    #[arg(
        long,
        default_value = "0,1,0.25",
        value_name = "X,Y,Z",
        requires = "shade"
    )]
    light: String,
    /// Base roughness for --shade (0 < m <= 1).
    #[arg(long, default_value_t = 0.2, value_name = "M", requires = "shade")]
    roughness: f32,
    /// What --shade draws: truth, renormalised or adjusted.
    #[arg(long, default_value = "adjusted", value_name = "S", requires = "shade")]
    shading: parvo::shade::Shading,
    /// Radiance scale before the sRGB encode of --shade images.
    #[arg(long, default_value_t = 0.5, value_name = "E", requires = "shade")]
    exposure: f32,
    /// Output PNG.
    #[arg(short, long, value_name = "PNG")]
    output: PathBuf,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ShadeBrdf {
    BlinnPhong,
    CookTorrance,
}

fn shade(args: &RenderArgs, brdf: ShadeBrdf) -> Result<ExitCode> {
    let light: Vec<f64> = args
        .light
        .split(',')
        .map(|c| c.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .unwrap_or_default();
    let [x, y, z] = light[..] else {
        eprintln!(
            "parvo: --light {}: expected X,Y,Z (three numbers)",
            args.light
        );
        return Ok(ExitCode::from(2));
    };
    let loaded = args.read.load(&args.texture)?;
    let mut n = loaded.into_base();
    // A normal map holds vectors: read its codes as they are stored.
    let mut f = n.format();
    f.color_space = parvo::ColorSpace::Linear;
    n = n.reinterpret(f)?;
    let brdf = match brdf {
        ShadeBrdf::BlinnPhong => parvo::shade::Brdf::BlinnPhong,
        ShadeBrdf::CookTorrance => parvo::shade::Brdf::CookTorrance,
    };
    let img = match parvo::shade::render(
        &n,
        args.roughness,
        brdf,
        [x, y, z],
        &args.scene,
        args.size,
        args.shading,
    ) {
        Ok(i) => i,
        Err(e @ parvo::Error::InvalidOption(_)) => {
            eprintln!("parvo: {}", super::words::words(&e));
            return Ok(ExitCode::from(2));
        }
        Err(e) => return Err(e.into()),
    };
    let e = args.exposure;
    let grey: Vec<Option<[f32; 4]>> = img.iter().map(|v| v.map(|v| [(v as f32 * e); 4])).collect();
    write_image(&args.output, args.size, &grey)?;
    Ok(ExitCode::SUCCESS)
}

pub fn run(args: RenderArgs) -> Result<ExitCode> {
    if let Some(b) = args.shade {
        return shade(&args, b);
    }
    let store = TextureStore::from_loaded(args.read.load_for_scene(&args.texture, &args.scene)?);
    let wrap = store.options().wrap;
    let base = store.base();
    let tex = (base.width(), base.height());
    if args.filter.eq_ignore_ascii_case("reference") {
        if args.show_levels {
            eprintln!("parvo: --show-levels: the reference reads level 0 only");
            return Ok(ExitCode::from(2));
        }
        let mut r = Reference::new(args.pixel_filter);
        if let Some(s) = args.spp {
            if !(s > 0.0 && s <= 64.0) {
                eprintln!("parvo: --spp {s}: must be above 0 and at most 64");
                return Ok(ExitCode::from(2));
            }
            r.samples_per_texel = s;
        }
        let s = store.reference_sampler(wrap)?;
        let img = r.render(&args.scene, args.size, (0.0, 0.0), &s, &|_| {});
        write_image(&args.output, args.size, &img)?;
        return Ok(ExitCode::SUCCESS);
    }
    let mut options = match SamplerOptions::from_name(&args.filter) {
        Ok(o) => o,
        Err(e) => {
            eprintln!("parvo: --filter: {e}");
            return Ok(ExitCode::from(2));
        }
    };
    options.wrap = wrap;
    let sampler = store.sampler(options)?;
    let qs = queries(&args.scene, args.size, tex, (0.0, 0.0));
    let img = render(&sampler, &qs);
    if args.show_levels {
        let tint = show_levels(&sampler, &qs, &img);
        write_rgb(&args.output, args.size, &tint)?;
    } else {
        write_image(&args.output, args.size, &img)?;
    }
    Ok(ExitCode::SUCCESS)
}
