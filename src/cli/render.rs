//! `parvo render`: a scene rendered with a filter (or the reference) to a
//! PNG, optionally tinted by the mip levels each pixel read.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};

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
    /// Scene: plane, tunnel, zoom, rotate:DEG[:SCALE].
    #[arg(long, default_value = "plane", value_name = "SCENE")]
    scene: Scene,
    /// Texture: a file or builtin:checker[:SIZE], builtin:zoneplate[:SIZE].
    #[arg(long, default_value = "builtin:zoneplate:512", value_name = "TEXTURE")]
    texture: String,
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
    /// Output PNG.
    #[arg(short, long, value_name = "PNG")]
    output: PathBuf,
}

pub fn run(args: RenderArgs) -> Result<ExitCode> {
    let store = TextureStore::load(&args.texture, &parvo::io::Limits::default())
        .with_context(|| format!("cannot read texture `{}`", args.texture))?;
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
