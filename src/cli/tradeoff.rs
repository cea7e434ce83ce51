//! `parvo tradeoff`: what each filter costs and how far it is from the
//! truth, on a texture and a scene — speed (ns per pixel, one thread, the
//! untraced fast path), memory traffic (texels read, bytes from memory
//! through a default cache), accuracy against the reference image (PSNR,
//! RMSE, maximum error) and flicker (two frames a quarter pixel apart).
//!
//! Outputs: a table on stdout, `DIR/report.json`, `DIR/tradeoff.svg`
//! (PSNR against ns per pixel, the Pareto front drawn) and PNGs (the
//! reference, each filter's render and error map, `--show-levels` images
//! of trilinear and aniso16). Only what the filters need is built (the
//! texture store): the report's `built` says what.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result, anyhow};
use indicatif::ProgressBar;

use parvo::compress::{BlockFormat, Quality};
use parvo::sample::SamplerOptions;
use parvo::scene::reference::{PixelFilter, Reference};
use parvo::scene::render::show_levels;
use parvo::scene::{Frame, Scene};
use parvo::store::TextureStore;
use parvo::tradeoff::{self, FLICKER_SHIFT, Progress, Rendered, Report, Row, Settings};

use super::images::{write_error_map, write_image, write_rgb, write_text};

/// The cache, layout and order the traffic figures use (stated in the
/// output).
const CACHE: &str = tradeoff::DEFAULT_CACHE;
const LAYOUT: &str = tradeoff::DEFAULT_LAYOUT;
const ORDER: &str = tradeoff::DEFAULT_ORDER;

/// Arguments of `parvo tradeoff`.
#[derive(clap::Args, Debug)]
#[command(
    about = "Measure each filter's speed, memory traffic, accuracy and flicker on a scene",
    long_about = "Measure what each sampling filter costs and how far it is from the truth on a \
    texture and a scene: ns per pixel (untraced fast path, one thread, median of runs), texels read \
    and bytes from memory per pixel (cache 16K:64:4, layout tiled:4x4, order tiled:8), PSNR, RMSE \
    and maximum error against the reference image (the scene's exact mapping integrated over the \
    pixel filter: gaussian, or box), and flicker (the RMS change between two frames a quarter pixel \
    apart, minus the reference's). Which filter is most accurate depends on the pixel filter: EWA's \
    weights assume the gaussian, footprint assembly the box.\n\n\
    Writes a table to stdout and DIR/report.json, DIR/tradeoff.svg (PSNR against ns per pixel, the \
    Pareto front drawn) and PNGs: reference.png, FILTER.png, FILTER-error.png, and the \
    --show-levels images of trilinear and aniso16. With no arguments: the plane, the zone plate, \
    gaussian, 320x240, into ./parvo-tradeoff."
)]
pub struct TradeoffArgs {
    /// Scene: plane, tunnel, zoom, rotate:DEG[:SCALE], sky or sphere (these two read --texture as a lat-long environment map).
    #[arg(long, default_value = "plane", value_name = "SCENE")]
    scene: Scene,
    /// Texture: a file or builtin:checker[:SIZE], builtin:zoneplate[:SIZE], builtin:bumps[:SIZE] (a normal map), builtin:photo[:SIZE], builtin:sky[:SIZE] (a lat-long sky, SIZE × SIZE/2, for the sky and sphere scenes).
    #[arg(long, default_value = "builtin:zoneplate:512", value_name = "TEXTURE")]
    texture: String,

    #[command(flatten)]
    read: super::texture::TextureArgs,
    /// Filters by report name.
    #[arg(
        long,
        value_delimiter = ',',
        default_values_t = SamplerOptions::REPORT_FILTERS.map(String::from)
    )]
    filters: Vec<String>,
    /// Pixel filter of the reference: gaussian or box.
    #[arg(long, default_value = "gaussian", value_name = "F")]
    pixel_filter: PixelFilter,
    /// Frame size.
    #[arg(long, default_value = "320x240", value_name = "WxH")]
    size: Frame,
    /// Output directory.
    #[arg(long, default_value = "parvo-tradeoff", value_name = "DIR")]
    out: PathBuf,
    /// Timing runs per filter (the median is reported).
    #[arg(long, default_value_t = 5, value_name = "N")]
    runs: usize,
    /// Reference samples per level-0 texel along each axis (default 1).
    #[arg(long, value_name = "N")]
    spp: Option<f64>,
    /// Also measure every filter on the chain block-compressed to this format (bc1, bc3, bc4, bc5, bc7, bc6h).
    #[arg(
        long,
        value_enum,
        value_name = "FORMAT",
        long_help = "Add a row per filter for the chain block-compressed to FORMAT (every level \
        encoded, then decoded again, as a GPU samples it): named FILTER+bc7 and so on. Their accuracy \
        is the compressed texture's against the same reference; their traffic counts whole 4x4 blocks \
        (a texel read fetches its block: 8 or 16 bytes), laid out with the same layout in units of \
        blocks; their speed is the decoded chain's on the CPU (a GPU decodes blocks in the texture unit)."
    )]
    compress: Option<super::mip::CompressArg>,
    /// Encoder effort for --compress.
    #[arg(
        long,
        value_enum,
        default_value = "normal",
        value_name = "Q",
        requires = "compress"
    )]
    quality: super::args::QualityArg,
}

fn machine() -> serde_json::Value {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into());
    let mem = std::fs::read_to_string("/proc/meminfo").ok().and_then(|s| {
        s.lines()
            .find(|l| l.starts_with("MemTotal:"))
            .and_then(|l| l.split_whitespace().nth(1))
            .and_then(|kb| kb.parse::<u64>().ok())
            .map(|kb| kb * 1024)
    });
    serde_json::json!({
        "cpu": cpu,
        "logical_cpus": std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1),
        "memory_bytes": mem,
        "os": std::env::consts::OS,
        "arch": std::env::consts::ARCH,
        "parvo": env!("CARGO_PKG_VERSION"),
    })
}

/// The report's settings from the arguments, or the usage error.
fn settings(args: &TradeoffArgs) -> std::result::Result<Settings, String> {
    let mut filters = Vec::new();
    for f in &args.filters {
        match SamplerOptions::from_name(f) {
            Ok(o) => filters.push(o),
            Err(e) => return Err(format!("--filters: {e}")),
        }
    }
    if filters.is_empty() {
        return Err("--filters: name at least one filter".into());
    }
    if args.runs == 0 {
        return Err("--runs must be at least 1".into());
    }
    let mut reference = Reference::new(args.pixel_filter);
    if let Some(s) = args.spp {
        if !(s > 0.0 && s <= 64.0) {
            return Err(format!("--spp {s}: must be above 0 and at most 64"));
        }
        reference.samples_per_texel = s;
    }
    if args.compress.is_some() && !cfg!(feature = "encode") {
        return Err("--compress: this parvo was built without the `encode` feature".into());
    }
    let mut settings = Settings::new(args.scene, args.size, filters).map_err(|e| e.to_string())?;
    settings.reference = reference;
    settings.runs = args.runs;
    settings.cache = CACHE.parse().map_err(|e: parvo::Error| e.to_string())?;
    settings.layout = LAYOUT.parse().map_err(|e: parvo::Error| e.to_string())?;
    settings.order = ORDER.parse().map_err(|e: parvo::Error| e.to_string())?;
    settings.flicker_shift = FLICKER_SHIFT;
    settings.compress = args.compress.map(|c| {
        let quality = match args.quality {
            super::args::QualityArg::Fast => Quality::Fast,
            super::args::QualityArg::Normal => Quality::Normal,
            super::args::QualityArg::Slow => Quality::Slow,
        };
        (BlockFormat::from(c), quality)
    });
    Ok(settings)
}

/// Save one image of the report into `out`: the reference, or a row's
/// frame, its error map and (trilinear, aniso16) its level tint.
fn save(out: &Path, frame: Frame, image: Rendered<'_>) -> Result<()> {
    match image {
        Rendered::Reference(img) => write_image(&out.join("reference.png"), frame, img),
        Rendered::Filter {
            row,
            image,
            reference,
            sampler,
            queries,
        } => {
            let name = &row.name;
            write_image(&out.join(format!("{name}.png")), frame, image)?;
            write_error_map(
                &out.join(format!("{name}-error.png")),
                frame,
                image,
                reference,
                row.error_scale,
            )?;
            if name == "trilinear" || name == "aniso16" {
                let tint = show_levels(sampler, queries, image);
                write_rgb(&out.join(format!("{name}-levels.png")), frame, &tint)?;
            }
            Ok(())
        }
    }
}

pub fn run(args: TradeoffArgs) -> Result<ExitCode> {
    let settings = match settings(&args) {
        Ok(s) => s,
        Err(m) => {
            eprintln!("parvo: {m}");
            return Ok(ExitCode::from(2));
        }
    };
    let store = TextureStore::from_loaded(args.read.load_for_scene(&args.texture, &args.scene)?);
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let bar = if std::io::stderr().is_terminal() {
        let b = ProgressBar::new(tradeoff::progress_total(&settings));
        b.set_style(super::progress::bar_style(super::progress::BAR_COUNT)?);
        Some(b)
    } else {
        None
    };
    let progress = |p: Progress<'_>| {
        if let Some(b) = &bar {
            match p {
                Progress::Step(msg) => b.set_message(msg.to_string()),
                Progress::Advance => b.inc(1),
            }
        }
    };
    let report = tradeoff::run(&store, &settings, &progress, &mut |image| {
        save(&args.out, args.size, image)
    })?;
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let json_path = args.out.join("report.json");
    let text = serde_json::to_string_pretty(&report_json(&args, &settings, &report))
        .context("cannot format report.json")?;
    write_text(&json_path, "JSON", &text)?;
    let svg = args.out.join("tradeoff.svg");
    plot(&svg, &report.rows, &args)?;
    print_table(&args, &report);
    println!(
        "wrote {}, {} and the images in {}",
        json_path.display(),
        svg.display(),
        args.out.display()
    );
    Ok(ExitCode::SUCCESS)
}

/// `report.json`.
fn report_json(args: &TradeoffArgs, settings: &Settings, report: &Report) -> serde_json::Value {
    let reference = &settings.reference;
    let built = &report.built;
    let tex = report.texture_size;
    serde_json::json!({
        "scene": args.scene.to_string(),
        "frame": args.size.to_string(),
        "pixels": report.pixels,
        "texture": args.texture,
        "texture_size": [tex.0, tex.1],
        "pixel_filter": args.pixel_filter.to_string(),
        "reference": {
            "samples_per_texel": reference.samples_per_texel,
            "min_samples": reference.min_samples,
            "max_samples": reference.max_samples,
            "seconds": report.reference_seconds,
        },
        "cache": {"cache": CACHE, "layout": LAYOUT, "order": ORDER},
        "flicker_shift_pixels": [FLICKER_SHIFT.0, FLICKER_SHIFT.1],
        "machine": machine(),
        "built": {
            "mip_levels": built.mip_levels,
            "mip_bytes": built.mip_bytes,
            "sat": built.sat,
            "sat_bytes": built.sat_bytes,
        },
        "filters": report.rows.iter().map(|r| serde_json::json!({
            "name": r.name,
            "stored": r.stored,
            "ns_per_pixel": r.ns_per_pixel,
            "texels_per_pixel": r.texels_per_pixel,
            "bytes_per_pixel": r.bytes_per_pixel,
            "psnr_db": r.psnr_db,
            "rmse": r.rmse,
            "max_error": r.max_error,
            "flicker": r.flicker,
            "error_map_scale": r.error_scale,
            "working_set": r.working_set.iter().map(|t| serde_json::json!({
                "level": t.level,
                "touched": t.touched > 0,
                "tiles_touched": t.touched,
                "tiles": t.tiles,
                "fraction": t.fraction(),
            })).collect::<Vec<_>>(),
        })).collect::<Vec<_>>(),
    })
}

/// The table on stdout.
fn print_table(args: &TradeoffArgs, report: &Report) {
    let tex = report.texture_size;
    println!(
        "scene {} {} ({} pixels), texture {} {}x{}, reference: {} pixel filter ({:.1} s per frame)",
        args.scene,
        args.size,
        report.pixels,
        args.texture,
        tex.0,
        tex.1,
        args.pixel_filter,
        report.reference_seconds
    );
    println!(
        "speed: one thread, untraced, median of {}; traffic: cache {CACHE}, layout {LAYOUT}, order {ORDER}; flicker: camera moved 1/4 pixel",
        args.runs
    );
    println!(
        "{:<12} {:>9} {:>9} {:>9} {:>8} {:>8} {:>8} {:>9}",
        "filter", "ns/pixel", "texels/px", "bytes/px", "PSNR dB", "RMSE", "max err", "flicker"
    );
    for r in &report.rows {
        println!(
            "{:<12} {:>9.1} {:>9.2} {:>9.2} {:>8.2} {:>8.4} {:>8.4} {:>9.4}",
            r.name,
            r.ns_per_pixel,
            r.texels_per_pixel,
            r.bytes_per_pixel,
            r.psnr_db,
            r.rmse,
            r.max_error,
            r.flicker
        );
    }
    let built = &report.built;
    println!(
        "built: {} mip levels ({} bytes){}; error maps scaled to the 99th-percentile error (in report.json)",
        built.mip_levels,
        built.mip_bytes,
        if built.sat {
            format!(", a summed-area table ({} bytes)", built.sat_bytes)
        } else {
            String::new()
        }
    );
}

/// PSNR against ns per pixel, one labelled point per filter, the Pareto
/// front (no other filter both faster and more accurate) joined.
fn plot(path: &Path, rows: &[Row], args: &TradeoffArgs) -> Result<()> {
    use plotters::prelude::*;
    let mut svg = String::new();
    {
        let (xmin, xmax) = rows.iter().fold((f64::MAX, 0f64), |(a, b), r| {
            (a.min(r.ns_per_pixel), b.max(r.ns_per_pixel))
        });
        let finite: Vec<f64> = rows
            .iter()
            .map(|r| r.psnr_db)
            .filter(|p| p.is_finite())
            .collect();
        let (ymin, ymax) = finite
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), &p| (a.min(p), b.max(p)));
        let root = SVGBackend::with_string(&mut svg, (760, 520)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(
                format!(
                    "parvo tradeoff: {} {}, {}, {} pixel filter",
                    args.scene, args.size, args.texture, args.pixel_filter
                ),
                ("sans-serif", 16),
            )
            .margin(15)
            .x_label_area_size(40)
            .y_label_area_size(55)
            .build_cartesian_2d(
                ((xmin * 0.7).max(0.1)..xmax * 1.5).log_scale(),
                (ymin - 1.0).floor()..(ymax + 1.0).ceil(),
            )
            .map_err(|e| anyhow!("{e}"))?;
        chart
            .configure_mesh()
            .light_line_style(WHITE)
            // The x labels are drawn below: 1, 2 and 5 of each decade.
            .disable_x_mesh()
            .x_label_formatter(&|_| String::new())
            .x_desc("ns per pixel (one thread)")
            .y_desc("PSNR against the reference (dB)")
            .draw()
            .map_err(|e| anyhow!("{e}"))?;
        let (x0, x1) = ((xmin * 0.7).max(0.1), xmax * 1.5);
        let (y0, y1) = ((ymin - 1.0).floor(), (ymax + 1.0).ceil());
        for d in (x0.log10().floor() as i32)..=(x1.log10().ceil() as i32) {
            for m in [1.0, 2.0, 5.0] {
                let v = m * 10f64.powi(d);
                if v < x0 || v > x1 {
                    continue;
                }
                chart
                    .draw_series(LineSeries::new([(v, y0), (v, y1)], BLACK.mix(0.12)))
                    .map_err(|e| anyhow!("{e}"))?;
                let (px, py) = chart.backend_coord(&(v, y0));
                let label = if v >= 1.0 {
                    format!("{v:.0}")
                } else {
                    format!("{v}")
                };
                root.draw(&Text::new(
                    label.clone(),
                    (px - 3 * label.len() as i32, py + 6),
                    ("sans-serif", 12).into_font(),
                ))
                .map_err(|e| anyhow!("{e}"))?;
            }
        }
        chart
            .draw_series(LineSeries::new(
                pareto_front(rows)
                    .iter()
                    .map(|r| (r.ns_per_pixel, r.psnr_db)),
                RED.stroke_width(2),
            ))
            .map_err(|e| anyhow!("{e}"))?
            .label("Pareto front")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], RED));
        draw_points(&mut chart, rows)?;
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .position(SeriesLabelPosition::LowerRight)
            .draw()
            .map_err(|e| anyhow!("{e}"))?;
        root.present().map_err(|e| anyhow!("{e}"))?;
    }
    super::images::write_text(path, "SVG", &svg)
}

/// The rows no other row beats on both speed and accuracy (no other
/// filter both faster and more accurate), fastest first.
fn pareto_front(rows: &[Row]) -> Vec<&Row> {
    let mut front: Vec<&Row> = rows
        .iter()
        .filter(|r| {
            !rows.iter().any(|o| {
                (o.ns_per_pixel <= r.ns_per_pixel && o.psnr_db > r.psnr_db)
                    || (o.ns_per_pixel < r.ns_per_pixel && o.psnr_db >= r.psnr_db)
            })
        })
        .collect();
    front.sort_by(|a, b| a.ns_per_pixel.total_cmp(&b.ns_per_pixel));
    front
}

/// The plot's chart: ns per pixel (log) against PSNR.
type Chart<'a, 'b> = plotters::chart::ChartContext<
    'a,
    plotters::backend::SVGBackend<'b>,
    plotters::coord::cartesian::Cartesian2d<
        plotters::coord::combinators::LogCoord<f64>,
        plotters::coord::types::RangedCoordf64,
    >,
>;

/// One labelled point per row with a finite PSNR.
fn draw_points(chart: &mut Chart<'_, '_>, rows: &[Row]) -> Result<()> {
    use plotters::prelude::*;
    // Labels placed greedily where they overlap no label placed
    // before (points close together, such as aniso4..16, would
    // otherwise print over each other).
    let mut placed: Vec<(i32, i32, i32, i32)> = Vec::new();
    let mut order: Vec<&Row> = rows.iter().filter(|r| r.psnr_db.is_finite()).collect();
    order.sort_by(|a, b| a.ns_per_pixel.total_cmp(&b.ns_per_pixel));
    for r in order {
        let p = (r.ns_per_pixel, r.psnr_db);
        let (px, py) = chart.backend_coord(&p);
        let w = 7 * r.name.len() as i32 + 4;
        let candidates = [(6, 3), (6, -17), (6, 19), (6, -33), (6, 35), (6, -49)];
        let overlaps = |(x, y): (i32, i32)| {
            placed
                .iter()
                .any(|&(a, b, c, d)| px + x < c && a < px + x + w && py + y < d && b < py + y + 14)
        };
        let (dx, dy) = candidates
            .iter()
            .copied()
            .find(|&o| !overlaps(o))
            .unwrap_or(candidates[0]);
        placed.push((px + dx, py + dy, px + dx + w, py + dy + 14));
        chart
            .draw_series(std::iter::once(
                EmptyElement::at(p)
                    + Circle::new((0, 0), 4, BLUE.filled())
                    // A leader line where the label had to move away.
                    + PathElement::new(
                        if dy == 3 { vec![] } else { vec![(0, 0), (dx, dy + 7)] },
                        BLACK.mix(0.5),
                    )
                    + Text::new(r.name.clone(), (dx + 2, dy), ("sans-serif", 13).into_font()),
            ))
            .map_err(|e| anyhow!("{e}"))?;
    }
    Ok(())
}
