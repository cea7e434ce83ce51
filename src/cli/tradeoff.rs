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
use std::time::Instant;

use anyhow::{Context, Result, anyhow};
use indicatif::ProgressBar;

use parvo::cache::layout::{ChainLayout, Layout};
use parvo::cache::run::SceneSetup;
use parvo::cache::sim::CacheConfig;
use parvo::compress::{BlockFormat, Quality};
use parvo::sample::{Query, Sampler, SamplerOptions, TexelSink};
use parvo::scene::metrics::{flicker, scores};
use parvo::scene::reference::{PixelFilter, Reference};
use parvo::scene::render::{ns_per_query, queries, render, show_levels};
use parvo::scene::{Frame, RasterOrder, Scene};
use parvo::store::TextureStore;

use super::images::{error_scale, write_error_map, write_image, write_rgb, write_text};

/// The cache the traffic figures use (stated in the output).
const CACHE: &str = "16K:64:4";
const LAYOUT: &str = "tiled:4x4";
const ORDER: &str = "tiled:8";
/// The camera move between the flicker frames, pixels.
const FLICKER_SHIFT: (f64, f64) = (0.25, 0.0);

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
    /// Scene: plane, tunnel, zoom, rotate:DEG[:SCALE].
    #[arg(long, default_value = "plane", value_name = "SCENE")]
    scene: Scene,
    /// Texture: a file or builtin:checker[:SIZE], builtin:zoneplate[:SIZE], builtin:bumps[:SIZE] (a normal map).
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
    quality: super::mip::QualityArg,
}

/// One filter's row of the report.
struct Row {
    name: String,
    /// What the chain stores: its texel format, or the block format.
    stored: String,
    ns_per_pixel: f64,
    texels_per_pixel: f64,
    bytes_per_pixel: f64,
    psnr_db: f64,
    rmse: f64,
    max_error: f64,
    flicker: f64,
    error_scale: f64,
    working_set: Vec<serde_json::Value>,
}

/// Marks the 64×64 tiles of each level a run reads.
struct TileSink {
    sizes: Vec<(u32, u32)>,
    tiles: Vec<Vec<bool>>,
}

impl TileSink {
    fn new(sampler: &Sampler) -> Self {
        let n = sampler.chain().len();
        let sizes: Vec<(u32, u32)> = (0..n)
            .map(|k| sampler.chain().level_size(k).unwrap_or((1, 1)))
            .collect();
        let tiles = sizes
            .iter()
            .map(|&(w, h)| vec![false; (w.div_ceil(64) * h.div_ceil(64)) as usize])
            .collect();
        TileSink { sizes, tiles }
    }
}

impl TexelSink for TileSink {
    #[inline]
    fn texel(&mut self, level: u32, x: u32, y: u32) {
        let k = level as usize;
        let w = self.sizes[k].0.div_ceil(64);
        self.tiles[k][((y / 64) * w + x / 64) as usize] = true;
    }
}

/// What every row's measurement shares.
struct RowEnv<'a> {
    scene: Scene,
    frame: Frame,
    out: &'a Path,
    ref0: &'a parvo::scene::metrics::Pixels,
    ref1: &'a parvo::scene::metrics::Pixels,
    q0: &'a [Option<Query>],
    q1: &'a [Option<Query>],
    dense: &'a [Query],
    cache: &'a CacheConfig,
    order: RasterOrder,
}

impl RowEnv<'_> {
    /// Render, score, simulate and write the images of one filter.
    fn row(
        &self,
        name: String,
        stored: String,
        sampler: &Sampler,
        cl: &ChainLayout,
        ns: f64,
    ) -> Result<Row> {
        let img0 = render(sampler, self.q0);
        let img1 = render(sampler, self.q1);
        let sc = scores(self.ref0, &img0);
        let fl = flicker((&img0, &img1), (self.ref0, self.ref1));
        let setup = SceneSetup {
            sampler,
            layout: cl,
            scene: self.scene,
            frame: self.frame,
            order: self.order,
        };
        let run = setup.simulate(self.cache, None, &mut |_| Ok(()), &|_, _| {})?;
        let mut tiles = TileSink::new(sampler);
        let mut out = vec![[0f32; 4]; self.dense.len()];
        sampler.sample_slice_traced(self.dense, &mut out, &mut tiles)?;
        let working_set = tiles
            .tiles
            .iter()
            .enumerate()
            .map(|(k, t)| {
                let touched = t.iter().filter(|&&b| b).count();
                serde_json::json!({
                    "level": k,
                    "touched": touched > 0,
                    "tiles_touched": touched,
                    "tiles": t.len(),
                    "fraction": touched as f64 / t.len().max(1) as f64,
                })
            })
            .collect();
        let scale = error_scale(&img0, self.ref0);
        let frame = self.frame;
        write_image(&self.out.join(format!("{name}.png")), frame, &img0)?;
        write_error_map(
            &self.out.join(format!("{name}-error.png")),
            frame,
            &img0,
            self.ref0,
            scale,
        )?;
        if name == "trilinear" || name == "aniso16" {
            let tint = show_levels(sampler, self.q0, &img0);
            write_rgb(&self.out.join(format!("{name}-levels.png")), frame, &tint)?;
        }
        Ok(Row {
            name,
            stored,
            ns_per_pixel: ns,
            texels_per_pixel: run.reads as f64 / run.pixels.max(1) as f64,
            bytes_per_pixel: run.stats.bytes_from_memory() as f64 / run.pixels.max(1) as f64,
            psnr_db: sc.psnr_db,
            rmse: sc.rmse,
            max_error: sc.max_error,
            flicker: fl,
            error_scale: scale,
            working_set,
        })
    }
}

/// The store's full chain block-compressed and decoded again, and the
/// stored format's name.
fn compressed_chain(
    store: &TextureStore,
    bf: BlockFormat,
    quality: Quality,
) -> Result<(Vec<parvo::texture::Texture>, String)> {
    #[cfg(feature = "encode")]
    {
        let levels = store.chain()?.levels();
        let (decoded, _) = parvo::compress::round_trip(levels, bf, quality)?;
        let srgb = decoded[0].format().color_space == parvo::texel::ColorSpace::Srgb;
        Ok((decoded, format!("{bf}{}", if srgb { "_SRGB" } else { "" })))
    }
    #[cfg(not(feature = "encode"))]
    {
        let _ = (store, quality);
        Err(anyhow!(
            "{bf}: this parvo was built without the `encode` feature"
        ))
    }
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

pub fn run(args: TradeoffArgs) -> Result<ExitCode> {
    let usage = |m: String| {
        eprintln!("parvo: {m}");
        Ok(ExitCode::from(2))
    };
    let mut filters = Vec::new();
    for f in &args.filters {
        match SamplerOptions::from_name(f) {
            Ok(o) => filters.push((o.name(), o)),
            Err(e) => return usage(format!("--filters: {e}")),
        }
    }
    if filters.is_empty() {
        return usage("--filters: name at least one filter".into());
    }
    if args.runs == 0 {
        return usage("--runs must be at least 1".into());
    }
    let mut reference = Reference::new(args.pixel_filter);
    if let Some(s) = args.spp {
        if !(s > 0.0 && s <= 64.0) {
            return usage(format!("--spp {s}: must be above 0 and at most 64"));
        }
        reference.samples_per_texel = s;
    }
    let store = TextureStore::from_loaded(args.read.load(&args.texture)?);
    let wrap = store.options().wrap;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let base = store.base();
    let tex = (base.width(), base.height());
    let frame = args.size;
    let tty = std::io::stderr().is_terminal();
    let bar = if tty {
        let b = ProgressBar::new(frame.height as u64 * 2 + filters.len() as u64);
        b.set_style(super::bar_style(super::BAR_COUNT)?);
        Some(b)
    } else {
        None
    };
    let step = |msg: &str| {
        if let Some(b) = &bar {
            b.set_message(msg.to_string());
        }
    };

    // The reference, twice (the flicker frames).
    step("reference");
    let ref_sampler = store.reference_sampler(wrap)?;
    let t0 = Instant::now();
    let tick = |_| {
        if let Some(b) = &bar {
            b.inc(1);
        }
    };
    let ref0 = reference.render(&args.scene, frame, (0.0, 0.0), &ref_sampler, &tick);
    let ref_secs = t0.elapsed().as_secs_f64();
    let ref1 = reference.render(&args.scene, frame, FLICKER_SHIFT, &ref_sampler, &tick);
    write_image(&args.out.join("reference.png"), frame, &ref0)?;
    let q0 = queries(&args.scene, frame, tex, (0.0, 0.0));
    let q1 = queries(&args.scene, frame, tex, FLICKER_SHIFT);
    let dense: Vec<Query> = q0.iter().flatten().copied().collect();
    if dense.is_empty() {
        anyhow::bail!("scene {} shows no texture in a {frame} frame", args.scene);
    }
    let cache: CacheConfig = CACHE.parse()?;
    let layout: Layout = LAYOUT.parse()?;
    let order: RasterOrder = ORDER.parse()?;

    if args.compress.is_some() && !cfg!(feature = "encode") {
        return usage("--compress: this parvo was built without the `encode` feature".into());
    }
    let mut samplers = Vec::new();
    for (_, options) in &mut filters {
        options.wrap = wrap;
        samplers.push(store.sampler(*options)?);
    }
    step("timing");
    let timings = ns_per_query(&samplers.iter().collect::<Vec<_>>(), &dense, args.runs);
    let mut rows = Vec::new();
    let env = RowEnv {
        scene: args.scene,
        frame,
        out: &args.out,
        ref0: &ref0,
        ref1: &ref1,
        q0: &q0,
        q1: &q1,
        dense: &dense,
        cache: &cache,
        order,
    };
    let stored = match store.stored_blocks() {
        Some(b) => b.name().to_string(),
        None => base.format().to_string(),
    };
    for ((name, options), (sampler, ns)) in filters.iter().zip(samplers.iter().zip(&timings)) {
        step(name);
        let chain = store.chain_for(options)?;
        let cl = ChainLayout::for_sampler_stored(chain, sampler, layout, store.stored_blocks());
        rows.push(env.row(name.clone(), stored.clone(), sampler, &cl, *ns)?);
        if let Some(b) = &bar {
            b.inc(1);
        }
    }
    if let Some(c) = args.compress {
        let bf: BlockFormat = c.into();
        let quality = match args.quality {
            super::mip::QualityArg::Fast => Quality::Fast,
            super::mip::QualityArg::Normal => Quality::Normal,
            super::mip::QualityArg::Slow => Quality::Slow,
        };
        step(&format!("{} encode", bf));
        let (decoded, stored) = compressed_chain(&store, bf, quality)?;
        let cstore = TextureStore::from_levels(decoded, *store.options());
        let tag = bf.name().to_ascii_lowercase().replace("_uf16", "");
        let mut csamplers = Vec::new();
        for (_, options) in &filters {
            csamplers.push(cstore.sampler(*options)?);
        }
        let ctimings = ns_per_query(&csamplers.iter().collect::<Vec<_>>(), &dense, args.runs);
        for ((name, options), (sampler, ns)) in filters.iter().zip(csamplers.iter().zip(&ctimings))
        {
            let name = format!("{name}+{tag}");
            step(&name);
            let chain = cstore.chain_for(options)?;
            let cl = ChainLayout::for_sampler_stored(chain, sampler, layout, Some(bf));
            rows.push(env.row(name, stored.clone(), sampler, &cl, *ns)?);
        }
    }
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let built = store.built();
    let report = serde_json::json!({
        "scene": args.scene.to_string(),
        "frame": frame.to_string(),
        "pixels": dense.len(),
        "texture": args.texture,
        "texture_size": [tex.0, tex.1],
        "pixel_filter": args.pixel_filter.to_string(),
        "reference": {
            "samples_per_texel": reference.samples_per_texel,
            "min_samples": reference.min_samples,
            "max_samples": reference.max_samples,
            "seconds": ref_secs,
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
        "filters": rows.iter().map(|r| serde_json::json!({
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
            "working_set": r.working_set,
        })).collect::<Vec<_>>(),
    });
    let json_path = args.out.join("report.json");
    let text = serde_json::to_string_pretty(&report).context("cannot format report.json")?;
    write_text(&json_path, "JSON", &text)?;
    let svg = args.out.join("tradeoff.svg");
    plot(&svg, &rows, &args)?;

    println!(
        "scene {} {frame} ({} pixels), texture {} {}x{}, reference: {} pixel filter ({:.1} s per frame)",
        args.scene,
        dense.len(),
        args.texture,
        tex.0,
        tex.1,
        args.pixel_filter,
        ref_secs
    );
    println!(
        "speed: one thread, untraced, median of {}; traffic: cache {CACHE}, layout {LAYOUT}, order {ORDER}; flicker: camera moved 1/4 pixel",
        args.runs
    );
    println!(
        "{:<12} {:>9} {:>9} {:>9} {:>8} {:>8} {:>8} {:>9}",
        "filter", "ns/pixel", "texels/px", "bytes/px", "PSNR dB", "RMSE", "max err", "flicker"
    );
    for r in &rows {
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
    println!(
        "wrote {}, {} and the images in {}",
        json_path.display(),
        svg.display(),
        args.out.display()
    );
    Ok(ExitCode::SUCCESS)
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
        chart
            .draw_series(LineSeries::new(
                front.iter().map(|r| (r.ns_per_pixel, r.psnr_db)),
                RED.stroke_width(2),
            ))
            .map_err(|e| anyhow!("{e}"))?
            .label("Pareto front")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], RED));
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
                placed.iter().any(|&(a, b, c, d)| {
                    px + x < c && a < px + x + w && py + y < d && b < py + y + 14
                })
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
