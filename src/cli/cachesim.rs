//! `parvo cachesim`: how many bytes reach memory for a memory layout, a
//! texel cache, a raster order and a filter, on a texture and a scene.
//!
//! Three modes:
//! - scene (default): the scene's pixels in raster order, each query
//!   filtered by the sampler, every texel read simulated (sampling and
//!   simulation overlap, see `parvo::cache::run`); a table or `--json`;
//! - `--trace FILE`: an address trace (SPEC.md's format, streamed) through
//!   the cache, to compare with other simulators; `--trace-out` writes the
//!   scene's reads in that format;
//! - `--sweep`: a grid of cache sizes, line sizes, associativities,
//!   layouts and filters, in parallel, to `DIR/sweep.csv` and an SVG plot.
//!
//! Scene runs and sweeps take `--quads` (a 2×2 quad's reads of one line
//! are one request); scene runs take `--prefetch` (the misses timed in a
//! prefetching texture unit, `parvo::cache::prefetch`).

use std::fs::File;
use std::io::{BufReader, IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result, anyhow, bail};
use indicatif::ProgressBar;

use std::sync::Arc;

use parvo::cache::layout::{ChainLayout, Layout};
use parvo::cache::prefetch::{PrefetchStats, Timing};
use parvo::cache::run::{Model, RunStats, SceneSetup, read_trace, unpack, write_trace_line};
use parvo::cache::shape::{self, CacheTexture};
use parvo::cache::sim::{AddressSpace, CacheConfig, Counters, Simulator, parse_size};
use parvo::cache::sweep::{SweepRow, SweepSettings, cache_grid, sweep_with};

use super::args::ColorArg;
use parvo::sample::{MipMode, Sampler, SamplerOptions};
use parvo::scene::{Frame, RasterOrder, Scene};

/// Arguments of `parvo cachesim`.
#[derive(clap::Args, Debug)]
#[command(
    about = "Simulate the texel cache: bytes from memory per layout, cache, raster order and filter",
    long_about = "Simulate the texel cache behind a filter: a scene's pixels are filtered in a \
    raster order, every texel read becomes a byte address of the chain's memory layout, and a \
    set-associative cache counts hits, misses (cold / capacity / conflict, Hill & Smith) and the \
    bytes that reach memory, in total and per mip level.\n\n\
    Modes: scene (default); --trace FILE (an address trace, one decimal or 0x-hex address per line, \
    `#` comments; - for stdin); --sweep (a grid of caches × layouts × filters to --out DIR as CSV \
    and SVG). --quads issues 2x2 quads whose reads of one line merge; --prefetch times the misses \
    in a prefetching texture unit.\n\n\
    Cache spec: SIZE:LINE:WAYS[:POLICY], SIZE as 16384, 16K, 16KiB or 4M, WAYS a number or `full`, \
    POLICY lru (default), fifo or random. Layouts: linear, tiled:WxH, morton, morton:WxH, \
    blocked:WxH:SWxSH. Orders: scanline, tiled:N, morton, hilbert. Scenes: plane, tunnel, zoom, \
    rotate:DEG[:SCALE], sky, sphere (a lat-long environment map looked up by direction: s \
    repeats, t clamps).\n\nExit codes: 0 success; 1 failure; 2 usage error."
)]
pub struct CachesimArgs {
    /// Scene: plane, tunnel, zoom, rotate:DEG[:SCALE], sky or sphere (these two read --texture as a lat-long environment map).
    #[arg(long, default_value = "plane", value_name = "SCENE")]
    scene: Scene,
    /// Frame size in pixels.
    #[arg(long, default_value = "512x384", value_name = "WxH")]
    size: Frame,
    /// Texture: a file or builtin:checker[:SIZE], builtin:zoneplate[:SIZE], builtin:bumps[:SIZE] (a normal map), builtin:photo[:SIZE], builtin:sky[:SIZE] (a lat-long sky, SIZE × SIZE/2, for the sky and sphere scenes).
    #[arg(long, default_value = "builtin:checker:1024", value_name = "TEXTURE")]
    texture: String,

    #[command(flatten)]
    read: super::texture::TextureArgs,
    /// Filter: nearest, bilinear, bilinear-nomip, trilinear, aniso, anisoN, ewa, sat, supersample.
    #[arg(long, default_value = "trilinear", value_name = "F")]
    filter: String,
    /// Maximum anisotropy for aniso and ewa (1 to 16).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=16))]
    max_aniso: Option<u32>,
    /// Mip mode override: none (level 0 only), nearest or linear.
    #[arg(long, value_name = "MODE")]
    mip: Option<MipMode>,
    /// Memory layout of the chain.
    #[arg(long, default_value = "tiled:4x4", value_name = "LAYOUT")]
    layout: Layout,
    /// First-level cache: SIZE:LINE:WAYS[:POLICY].
    #[arg(long, default_value = "16K:64:4", value_name = "SPEC")]
    cache: String,
    /// Sector size in bytes (a miss fetches only the missing sectors of a line).
    #[arg(long, value_name = "BYTES", value_parser = parse_size_arg)]
    sector: Option<u64>,
    /// Seed of the random replacement policy.
    #[arg(long, default_value_t = 0x5eed, value_name = "N")]
    seed: u64,
    /// Second-level cache: SIZE:LINE:WAYS[:POLICY] (sees the first level's misses).
    #[arg(long, value_name = "SPEC")]
    l2: Option<String>,
    /// Raster order.
    #[arg(long, default_value = "scanline", value_name = "ORDER")]
    order: RasterOrder,
    /// Write the scene's reads as an address trace (one per line).
    #[arg(long, value_name = "FILE")]
    trace_out: Option<PathBuf>,
    /// Simulate an address trace instead of a scene (- for stdin).
    #[arg(long, value_name = "FILE", conflicts_with_all = ["trace_out", "sweep"])]
    trace: Option<PathBuf>,
    /// Bytes per access of --trace (default 4).
    #[arg(long, value_name = "N", default_value_t = 4)]
    access_bytes: u64,
    /// Print one JSON object instead of the table.
    #[arg(long)]
    json: bool,
    /// Run a grid of caches, layouts and filters (see --cache-sizes …).
    #[arg(long)]
    sweep: bool,
    /// Sweep: cache sizes.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "1K,2K,4K,8K,16K,32K,64K,128K,256K"
    )]
    cache_sizes: Vec<String>,
    /// Sweep: line sizes in bytes.
    #[arg(long, value_delimiter = ',', default_value = "32,64,128")]
    lines: Vec<u64>,
    /// Sweep: associativities.
    #[arg(long, value_delimiter = ',', default_value = "1,2,4,8")]
    ways: Vec<u64>,
    /// Sweep: layouts.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "linear,tiled:4x4,morton,blocked:4x4:32x32"
    )]
    layouts: Vec<Layout>,
    /// Sweep: filters.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "bilinear,trilinear,aniso16"
    )]
    filters: Vec<String>,
    /// Sweep: output directory for sweep.csv and sweep.svg.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Issue the frame by 2x2 quads: a quad's texel reads of one cache line are one request.
    #[arg(
        long,
        long_help = "Issue the frame by 2x2 quads, as GPUs shade: the four pixels of a quad are \
        filtered together and their texel reads of one cache line merge into one request. The \
        raster order runs over the grid of quads (tiled:N in tiles of N pixels rounded up to whole \
        quads). The report adds the quads, the line requests and the line fetches beside the \
        per-texel reads."
    )]
    quads: bool,
    /// Prefetching texture unit: FIFO depths in fragments, e.g. 0,16,64,256 (0: a blocking cache).
    #[arg(
        long,
        value_delimiter = ',',
        value_name = "DEPTHS",
        value_parser = clap::value_parser!(u32).range(0..=1 << 20),
        conflicts_with = "sweep",
        long_help = "Time the cache's misses in a prefetching texture unit after Igehy, Eldridge \
        and Proudfoot (1998): tags are looked up when a fragment (a pixel, or a quad with --quads) \
        enters, its missing lines are requested at once, and it waits in a FIFO of DEPTH fragments \
        until they are back; the unit filters one fragment per cycle. One row per depth: cycles, \
        cycles lost to memory, stall-free hit rate, and the share of a blocking cache's lost cycles \
        the FIFO recovers. See --latency and --request-cycles."
    )]
    prefetch: Vec<u32>,
    /// Prefetching: memory latency in cycles (up to a million).
    #[arg(
        long,
        value_name = "CYCLES",
        default_value_t = 200,
        requires = "prefetch",
        value_parser = clap::value_parser!(u32).range(0..=1_000_000)
    )]
    latency: u32,
    /// Prefetching: cycles per line request (the memory's bandwidth), at least 1.
    #[arg(
        long,
        value_name = "CYCLES",
        default_value_t = 1,
        requires = "prefetch",
        value_parser = clap::value_parser!(u32).range(1..)
    )]
    request_cycles: u32,
}

fn parse_size_arg(s: &str) -> Result<u64, String> {
    parse_size(s).map_err(|e| e.to_string())
}

fn cache_config(spec: &str, sector: Option<u64>, seed: u64) -> Result<CacheConfig> {
    let mut c: CacheConfig = spec.parse()?;
    c.sector = sector;
    c.seed = seed;
    c.validate()?;
    Ok(c)
}

pub fn run(args: CachesimArgs) -> Result<ExitCode> {
    let usage = |msg: String| {
        eprintln!("parvo: {msg}");
        Ok(ExitCode::from(2))
    };
    let l1 = match cache_config(&args.cache, args.sector, args.seed) {
        Ok(c) => c,
        Err(e) => return usage(format!("--cache: {e:#}")),
    };
    let l2 = match args
        .l2
        .as_deref()
        .map(|s| cache_config(s, None, args.seed ^ 1))
    {
        Some(Err(e)) => return usage(format!("--l2: {e:#}")),
        Some(Ok(c)) => Some(c),
        None => None,
    };
    if let Some(t) = &args.trace {
        return trace_mode(&args, t, &l1, l2.as_ref());
    }
    if args.sweep {
        return sweep_mode(&args);
    }
    if args.out.is_some() {
        return usage("--out belongs to --sweep".into());
    }
    let options = match sampler_options(&args, &args.filter) {
        Ok(o) => o,
        Err(e) => return usage(format!("{e:#}")),
    };
    let model = match model(&args) {
        Ok(m) => m,
        Err(m) => return usage(m),
    };
    let texture = texture_for(&args, &[options])?;
    let sampler = Sampler::shared(texture.chain.clone(), options)?;
    let layout = texture.layout(&sampler, args.layout);
    let setup = SceneSetup {
        sampler: &sampler,
        layout: &layout,
        scene: args.scene,
        frame: args.size,
        order: args.order,
    };
    let bar = progress_bar(&args)?;
    let progress = |done: u64, total: u64| {
        if let Some(b) = &bar {
            b.set_length(total);
            b.set_position(done);
        }
    };
    let stats = match &args.trace_out {
        // The trace is written while the frame is simulated, into a
        // temporary file renamed over the destination once complete.
        Some(p) => {
            super::progress::remove_temporary_files_on_interrupt();
            let header = format!(
                "# parvo cachesim trace: scene {} {}, texture {}, filter {}, layout {}, order {}, access bytes {}",
                args.scene,
                args.size,
                args.texture,
                sampler.options().name(),
                args.layout,
                args.order,
                if sampler.sat().is_some() {
                    layout.sat_entry().unwrap_or(layout.texel())
                } else {
                    layout.texel()
                }
            );
            let io_err = |e: std::io::Error| parvo::Error::Io {
                path: p.clone(),
                action: "cannot write the trace".into(),
                error: e,
            };
            parvo::io::atomic::write(p, |w| {
                writeln!(w, "{header}").map_err(io_err)?;
                setup.run(
                    &l1,
                    l2.as_ref(),
                    &model,
                    Some(&mut |a| write_trace_line(w, unpack(a).0).map_err(io_err)),
                    &progress,
                )
            })?
        }
        None => setup.run(&l1, l2.as_ref(), &model, None, &progress)?,
    };
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let report = Report {
        what: scene_what(&args, &texture, &sampler, &layout),
        l1,
        l2,
        run: stats,
        levels: texture.chain.len(),
    };
    if args.json {
        println!("{}", report.json());
    } else {
        print!("{}", report.table());
    }
    Ok(ExitCode::SUCCESS)
}

/// What a scene run measured, the report's first line.
fn scene_what(
    args: &CachesimArgs,
    texture: &CacheTexture,
    sampler: &Sampler,
    layout: &ChainLayout,
) -> String {
    format!(
        "scene {} {}, texture {} ({}, {} levels), filter {}, layout {}, order {}",
        args.scene,
        args.size,
        args.texture,
        match texture.blocks {
            Some(b) => format!(
                "{b} blocks, {} bytes per 4x4 block (a texel read fetches its block; the \
                 layout counts blocks)",
                layout.texel()
            ),
            None => format!("{}, {} bytes per texel", texture.format(), layout.texel()),
        },
        texture.chain.len(),
        sampler.options().name(),
        args.layout,
        args.order
    )
}

/// The texture unit the arguments ask for, or the usage error.
fn model(args: &CachesimArgs) -> std::result::Result<Model, String> {
    if args.quads && args.trace_out.is_some() {
        return Err(
            "--trace-out writes every texel read; with --quads the cache sees merged requests, \
             which a replay of that trace would not"
                .into(),
        );
    }
    let prefetch: Vec<Timing> = args
        .prefetch
        .iter()
        .map(|&depth| Timing {
            depth,
            latency: args.latency,
            request_cycles: args.request_cycles,
        })
        .collect();
    // The arguments' ranges are the model's: this only guards them.
    for t in &prefetch {
        t.validate()
            .map_err(|e| super::words::words(e).to_string())?;
    }
    Ok(Model {
        quads: args.quads,
        prefetch,
    })
}

/// The texture the runs read: for a built-in texture whose values none
/// of `filters` reads (and no --color override), its sizes and format
/// alone ([`CacheTexture::builtin`]: no texel generated or mip-mapped);
/// otherwise the texture as loaded.
fn texture_for(args: &CachesimArgs, filters: &[SamplerOptions]) -> Result<CacheTexture> {
    let spec = &args.texture;
    let values = filters.iter().any(shape::reads_depend_on_values);
    if !values && parvo::builtin::is_builtin(spec) && args.read.color == ColorArg::Auto {
        return parvo::builtin::parse(spec)
            .and_then(|(kind, size)| {
                let (w, h) = parvo::builtin::dimensions(kind, size);
                let (w, h) = (w as u64, h as u64);
                parvo::io::Limits::default().check(w, h, w * h * 4)
            })
            .and_then(|()| CacheTexture::builtin(spec))
            .map_err(super::words::with_hint)
            .with_context(|| format!("cannot read texture `{spec}`"));
    }
    let (chain, blocks) = args
        .read
        .load_for_scene(spec, &args.scene)?
        .into_chain()
        .with_context(|| format!("cannot read texture `{spec}`"))?;
    Ok(CacheTexture::loaded(Arc::new(chain), blocks))
}

fn sampler_options(args: &CachesimArgs, name: &str) -> Result<SamplerOptions> {
    let mut o = SamplerOptions::from_name(name)?;
    if let Some(w) = args.scene.wrap() {
        o.wrap = w;
    }
    if let Some(n) = args.max_aniso {
        o.max_aniso = n;
    }
    if let Some(m) = args.mip {
        o.mip = m;
    }
    o.validate()?;
    Ok(o)
}

fn progress_bar(args: &CachesimArgs) -> Result<Option<ProgressBar>> {
    if !std::io::stderr().is_terminal() || args.json {
        return Ok(None);
    }
    Ok(Some(ProgressBar::new(0).with_style(
        super::progress::bar_style(super::progress::BAR_COUNT)?,
    )))
}

fn trace_mode(
    args: &CachesimArgs,
    path: &PathBuf,
    l1: &CacheConfig,
    l2: Option<&CacheConfig>,
) -> Result<ExitCode> {
    if args.access_bytes == 0 {
        eprintln!("parvo: --access-bytes must be at least 1");
        return Ok(ExitCode::from(2));
    }
    if args.quads || !args.prefetch.is_empty() {
        eprintln!("parvo: --quads and --prefetch need a scene's pixels; an address trace has none");
        return Ok(ExitCode::from(2));
    }
    let mut sim = Simulator::new(l1, l2, AddressSpace::Any, true)?;
    let n = if path.as_os_str() == "-" {
        read_trace(std::io::stdin().lock(), &mut |a| {
            sim.access(a, args.access_bytes, 0)
        })?
    } else {
        let f = File::open(path).with_context(|| format!("cannot open {}", path.display()))?;
        read_trace(BufReader::with_capacity(1 << 20, f), &mut |a| {
            sim.access(a, args.access_bytes, 0)
        })
        .with_context(|| format!("reading {}", path.display()))?
    };
    let report = Report {
        what: format!(
            "trace {} ({n} accesses of {} bytes)",
            path.display(),
            args.access_bytes
        ),
        l1: *l1,
        l2: l2.copied(),
        run: RunStats::plain(sim.into_stats(), 0, n),
        levels: 0,
    };
    if args.json {
        println!("{}", report.json());
    } else {
        print!("{}", report.table());
    }
    Ok(ExitCode::SUCCESS)
}

/// What one run reports, as a table or JSON.
struct Report {
    what: String,
    l1: CacheConfig,
    l2: Option<CacheConfig>,
    run: RunStats,
    levels: usize,
}

fn counters_json(c: &Counters, line: u64, pixels: u64) -> serde_json::Value {
    serde_json::json!({
        "accesses": c.accesses,
        "hits": c.hits,
        "misses": c.misses,
        "hit_rate": c.hit_rate(),
        "cold_misses": c.cold,
        "capacity_misses": c.capacity,
        "conflict_misses": c.conflict,
        "bytes_from_memory": c.bytes_fetched,
        "bytes_per_pixel": if pixels > 0 { c.bytes_fetched as f64 / pixels as f64 } else { 0.0 },
        "working_set_bytes": c.lines_touched * line,
    })
}

impl Report {
    fn level_name(&self, k: usize) -> String {
        if k == self.levels && self.levels > 0 {
            "sat".to_string()
        } else {
            k.to_string()
        }
    }

    fn json(&self) -> serde_json::Value {
        let s = &self.run.stats;
        let pixels = self.run.pixels;
        let mut v = counters_json(&s.total, self.l1.line, pixels);
        let bytes = s.bytes_from_memory();
        v["bytes_from_memory"] = bytes.into();
        v["bytes_per_pixel"] = if pixels > 0 {
            (bytes as f64 / pixels as f64).into()
        } else {
            0.0.into()
        };
        v["pixels"] = pixels.into();
        v["texel_reads"] = self.run.reads.into();
        v["texels_per_pixel"] = if pixels > 0 {
            (self.run.reads as f64 / pixels as f64).into()
        } else {
            0.0.into()
        };
        v["run"] = self.what.clone().into();
        v["cache"] = self.l1.to_string().into();
        v["per_level"] = s
            .per_level
            .iter()
            .enumerate()
            .filter(|(_, c)| c.accesses > 0)
            .map(|(k, c)| {
                let mut o = counters_json(c, self.l1.line, pixels);
                o["level"] = self.level_name(k).into();
                o
            })
            .collect::<Vec<_>>()
            .into();
        if let (Some(c), Some(cfg)) = (&s.l2, &self.l2) {
            let mut o = counters_json(c, cfg.line, pixels);
            o["cache"] = cfg.to_string().into();
            v["l2"] = o;
        }
        if let Some(q) = self.run.quads {
            let per_pixel = |n: u64| n as f64 / pixels.max(1) as f64;
            v["quads"] = q.into();
            v["line_requests"] = s.total.accesses.into();
            v["line_requests_per_pixel"] = per_pixel(s.total.accesses).into();
            v["line_fetches"] = s.total.misses.into();
            v["line_fetches_per_pixel"] = per_pixel(s.total.misses).into();
        }
        if !self.run.prefetch.is_empty() {
            v["prefetch"] = self
                .run
                .prefetch
                .iter()
                .map(prefetch_json)
                .collect::<Vec<_>>()
                .into();
        }
        v
    }

    /// The quads' lines and the prefetch table, when the run has them.
    fn model_table(&self, t: &mut String) {
        use std::fmt::Write as _;
        let s = &self.run.stats.total;
        let px = self.run.pixels.max(1) as f64;
        if let Some(q) = self.run.quads {
            let _ = writeln!(
                t,
                "quads {q}: line requests {} ({:.2} per pixel; a quad's reads of one line are one \
                 request), line fetches {} ({:.2} per pixel)",
                s.accesses,
                s.accesses as f64 / px,
                s.misses,
                s.misses as f64 / px
            );
        }
        let Some(first) = self.run.prefetch.first() else {
            return;
        };
        let _ = writeln!(
            t,
            "prefetching unit: {} {}, memory latency {} cycles, a line request every {} cycle(s), \
             one fragment filtered per cycle; blocking cache (FIFO 0) {} cycles",
            first.fragments,
            if self.run.quads.is_some() {
                "quads"
            } else {
                "pixels"
            },
            first.timing.latency,
            first.timing.request_cycles,
            first.blocking_cycles
        );
        let _ = writeln!(
            t,
            "{:>6} {:>12} {:>12} {:>10} {:>17} {:>15} {:>11}",
            "fifo",
            "cycles",
            "stall cycles",
            "stalled",
            "stall-free hits",
            "latency hidden",
            "efficiency"
        );
        for p in &self.run.prefetch {
            let _ = writeln!(
                t,
                "{:>6} {:>12} {:>12} {:>10} {:>16.2}% {:>14.1}% {:>10.1}%",
                p.timing.depth,
                p.cycles,
                p.stall_cycles(),
                p.stalled_fragments,
                p.stall_free_hit_rate() * 100.0,
                p.latency_hidden() * 100.0,
                p.efficiency() * 100.0
            );
        }
    }

    fn table(&self) -> String {
        use std::fmt::Write as _;
        let s = &self.run.stats;
        let px = self.run.pixels;
        let mut t = String::new();
        let _ = writeln!(t, "{}", self.what);
        let _ = writeln!(t, "cache {}", self.l1);
        if px > 0 {
            let _ = writeln!(
                t,
                "pixels {px}, texel reads {} ({:.2} per pixel)",
                self.run.reads,
                self.run.reads as f64 / px as f64
            );
        }
        let _ = writeln!(
            t,
            "{:>7} {:>12} {:>8} {:>11} {:>11} {:>11} {:>11} {:>14} {:>11} {:>12}",
            "level",
            "accesses",
            "hit rate",
            "misses",
            "cold",
            "capacity",
            "conflict",
            "bytes fetched",
            "bytes/pixel",
            "working set"
        );
        let row = |t: &mut String, name: &str, c: &Counters, line: u64| {
            let bpp = if px > 0 {
                format!("{:.2}", c.bytes_fetched as f64 / px as f64)
            } else {
                "-".into()
            };
            let _ = writeln!(
                t,
                "{name:>7} {:>12} {:>7.2}% {:>11} {:>11} {:>11} {:>11} {:>14} {bpp:>11} {:>12}",
                c.accesses,
                c.hit_rate() * 100.0,
                c.misses,
                c.cold,
                c.capacity,
                c.conflict,
                c.bytes_fetched,
                human(c.lines_touched * line)
            );
        };
        row(&mut t, "total", &s.total, self.l1.line);
        for (k, c) in s.per_level.iter().enumerate() {
            if c.accesses > 0 && (self.levels > 0) {
                row(&mut t, &self.level_name(k), c, self.l1.line);
            }
        }
        if let (Some(c), Some(cfg)) = (&s.l2, &self.l2) {
            let _ = writeln!(t, "second level {cfg}:");
            row(&mut t, "l2", c, cfg.line);
        }
        let _ = writeln!(
            t,
            "bytes from memory {} ({} per pixel)",
            s.bytes_from_memory(),
            if px > 0 {
                format!("{:.2}", s.bytes_from_memory() as f64 / px as f64)
            } else {
                "-".into()
            }
        );
        self.model_table(&mut t);
        t
    }
}

fn prefetch_json(p: &PrefetchStats) -> serde_json::Value {
    serde_json::json!({
        "fifo_depth": p.timing.depth,
        "latency_cycles": p.timing.latency,
        "request_cycles": p.timing.request_cycles,
        "fragments": p.fragments,
        "line_requests": p.requests,
        "line_fetches": p.misses,
        "cycles": p.cycles,
        "stall_cycles": p.stall_cycles(),
        "stalled_fragments": p.stalled_fragments,
        "stall_free_hit_rate": p.stall_free_hit_rate(),
        "latency_hidden": p.latency_hidden(),
        "efficiency": p.efficiency(),
        "blocking_cycles": p.blocking_cycles,
    })
}

fn human(b: u64) -> String {
    if b >= 1 << 20 {
        format!("{:.1} MiB", b as f64 / (1 << 20) as f64)
    } else if b >= 1 << 10 {
        format!("{:.1} KiB", b as f64 / 1024.0)
    } else {
        format!("{b} B")
    }
}

/// The sweep's settings from the arguments, or the usage error.
fn sweep_settings(args: &CachesimArgs) -> std::result::Result<SweepSettings, String> {
    let mut sizes = Vec::new();
    for size in &args.cache_sizes {
        sizes.push(parse_size(size).map_err(|e| format!("--cache-sizes: {e}"))?);
    }
    let caches = cache_grid(&sizes, &args.lines, &args.ways, args.seed, args.sector);
    if caches.is_empty() {
        return Err(
            "no valid cache in the sweep (each size must be a multiple of line × ways)".into(),
        );
    }
    let mut filters = Vec::new();
    for f in &args.filters {
        let o = sampler_options(args, f).map_err(|e| format!("--filters: {e:#}"))?;
        filters.push((f.clone(), o));
    }
    Ok(SweepSettings {
        scene: args.scene,
        frame: args.size,
        order: args.order,
        filters,
        layouts: args.layouts.clone(),
        caches,
    })
}

fn sweep_mode(args: &CachesimArgs) -> Result<ExitCode> {
    let Some(out) = &args.out else {
        eprintln!("parvo: --sweep needs --out DIR");
        return Ok(ExitCode::from(2));
    };
    let settings = match sweep_settings(args) {
        Ok(s) => s,
        Err(m) => {
            eprintln!("parvo: {m}");
            return Ok(ExitCode::from(2));
        }
    };
    let model = match model(args) {
        Ok(m) => m,
        Err(m) => {
            eprintln!("parvo: {m}");
            return Ok(ExitCode::from(2));
        }
    };
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let options: Vec<SamplerOptions> = settings.filters.iter().map(|f| f.1).collect();
    let texture = texture_for(args, &options)?;
    let bar = progress_bar(args)?;
    if let Some(b) = &bar {
        b.set_length(settings.configurations() as u64);
        b.set_message("configurations");
    }
    let rows = sweep_with(&texture, &settings, &model, &|| {
        if let Some(b) = &bar {
            b.inc(1);
        }
    })?;
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let csv = out.join("sweep.csv");
    write_csv(&csv, &rows).with_context(|| format!("writing {}", csv.display()))?;
    let svg = out.join("sweep.svg");
    plot(&svg, &rows, args).with_context(|| format!("writing {}", svg.display()))?;
    println!(
        "{} configurations ({} filters × {} layouts × {} caches) of scene {} {} on {}: {} and {}",
        rows.len(),
        settings.filters.len(),
        settings.layouts.len(),
        settings.caches.len(),
        args.scene,
        args.size,
        args.texture,
        csv.display(),
        svg.display()
    );
    Ok(ExitCode::SUCCESS)
}

fn write_csv(path: &Path, rows: &[SweepRow]) -> Result<()> {
    parvo::io::atomic::write(path, |w| {
        let io = |e: std::io::Error| parvo::Error::Encode {
            format: "CSV",
            reason: e.to_string(),
        };
        writeln!(
            w,
            "filter,layout,cache,size,line,ways,policy,accesses,hits,misses,hit_rate,cold_misses,capacity_misses,conflict_misses,bytes_from_memory,bytes_per_pixel,pixels,texels_per_pixel,working_set_bytes"
        )
        .map_err(io)?;
        for r in rows {
            let c = &r.run.stats.total;
            let px = r.run.pixels.max(1) as f64;
            writeln!(
                w,
                "{},{},{},{},{},{},{},{},{},{},{:.6},{},{},{},{},{:.4},{},{:.4},{}",
                r.filter,
                r.layout,
                r.cache.to_string().split(' ').next().unwrap_or(""),
                r.cache.size,
                r.cache.line,
                r.cache.ways,
                r.cache.policy,
                c.accesses,
                c.hits,
                c.misses,
                c.hit_rate(),
                c.cold,
                c.capacity,
                c.conflict,
                c.bytes_fetched,
                c.bytes_fetched as f64 / px,
                r.run.pixels,
                r.run.reads as f64 / px,
                c.lines_touched * r.cache.line
            )
            .map_err(io)?;
        }
        Ok(())
    })?;
    Ok(())
}

/// Hit rate (top) and bytes per pixel (bottom) against cache size, one
/// line per layout, one column per filter, for the sweep's middle line
/// size and associativity.
fn plot(path: &Path, rows: &[SweepRow], args: &CachesimArgs) -> Result<()> {
    use plotters::prelude::*;
    let pick = |v: &[u64], want: u64| {
        if v.contains(&want) {
            want
        } else {
            v[v.len() / 2]
        }
    };
    let line = pick(&args.lines, 64);
    let ways = pick(&args.ways, 4);
    let filters: Vec<String> = {
        let mut f: Vec<String> = Vec::new();
        for r in rows {
            if !f.contains(&r.filter) {
                f.push(r.filter.clone());
            }
        }
        f
    };
    let sel: Vec<&SweepRow> = rows
        .iter()
        .filter(|r| r.cache.line == line && r.cache.ways == ways)
        .collect();
    if sel.is_empty() {
        bail!("no configuration with line {line} and {ways} ways to plot");
    }
    let (smin, smax) = sel.iter().fold((u64::MAX, 0), |(a, b), r| {
        (a.min(r.cache.size), b.max(r.cache.size))
    });
    // Each panel gets its own range, so small differences stay visible.
    let range = |f: &str, top: bool| {
        let ys = sel
            .iter()
            .filter(|r| r.filter == f)
            .map(|r| y_value(r, top));
        if top {
            let lo = ys.fold(1.0, f64::min);
            ((lo * 20.0).floor() / 20.0).min(0.95)..1.0
        } else {
            0.0..(ys.fold(0.0, f64::max) * 1.05).max(1.0)
        }
    };
    let w = 420 * filters.len() as u32;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (w.max(420), 720)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
        let root = root
            .titled(
                &format!(
                    "parvo cachesim: scene {} {}, {}, order {}, lines of {line} bytes, {ways}-way LRU",
                    args.scene, args.size, args.texture, args.order
                ),
                ("sans-serif", 16),
            )
            .map_err(|e| anyhow!("{e}"))?;
        let cols = root.split_evenly((2, filters.len()));
        let kib = |b: u64| b as f64 / 1024.0;
        for (fi, f) in filters.iter().enumerate() {
            for (panel, top) in [(fi, true), (filters.len() + fi, false)] {
                let area = &cols[panel];
                let ylabel = if top { "hit rate" } else { "bytes per pixel" };
                let yrange = range(f, top);
                let mut chart = ChartBuilder::on(area)
                    .caption(format!("{f}: {ylabel}"), ("sans-serif", 14))
                    .margin(10)
                    .x_label_area_size(35)
                    .y_label_area_size(50)
                    .build_cartesian_2d((kib(smin)..kib(smax)).log_scale(), yrange)
                    .map_err(|e| anyhow!("{e}"))?;
                chart
                    .configure_mesh()
                    .x_desc("cache size (KiB)")
                    .y_desc(ylabel)
                    .draw()
                    .map_err(|e| anyhow!("{e}"))?;
                draw_layouts(&mut chart, &sel, f, top, &args.layouts)?;
                chart
                    .configure_series_labels()
                    .background_style(WHITE.mix(0.8))
                    .border_style(BLACK)
                    .position(if top {
                        SeriesLabelPosition::LowerRight
                    } else {
                        SeriesLabelPosition::UpperRight
                    })
                    .draw()
                    .map_err(|e| anyhow!("{e}"))?;
            }
        }
        root.present().map_err(|e| anyhow!("{e}"))?;
    }
    super::images::write_text(path, "SVG", &svg)
}

/// A sweep row's value in the plot: the hit rate (top panels) or the
/// bytes from memory per pixel (bottom).
fn y_value(r: &SweepRow, top: bool) -> f64 {
    let c = &r.run.stats.total;
    if top {
        c.hit_rate()
    } else {
        c.bytes_fetched as f64 / r.run.pixels.max(1) as f64
    }
}

/// A panel's chart: cache size in KiB (log) against the value.
type Chart<'a, 'b> = plotters::chart::ChartContext<
    'a,
    plotters::backend::SVGBackend<'b>,
    plotters::coord::cartesian::Cartesian2d<
        plotters::coord::combinators::LogCoord<f64>,
        plotters::coord::types::RangedCoordf64,
    >,
>;

/// One line per layout of filter `f`'s rows in `sel`, against cache size.
fn draw_layouts(
    chart: &mut Chart<'_, '_>,
    sel: &[&SweepRow],
    f: &str,
    top: bool,
    layouts: &[Layout],
) -> Result<()> {
    use plotters::prelude::*;
    let colours = [&BLUE, &RED, &GREEN, &MAGENTA, &BLACK, &CYAN];
    let kib = |b: u64| b as f64 / 1024.0;
    for (li, layout) in layouts.iter().enumerate() {
        let mut pts: Vec<(f64, f64)> = sel
            .iter()
            .filter(|r| r.filter == f && &r.layout == layout)
            .map(|r| (kib(r.cache.size), y_value(r, top)))
            .collect();
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        let colour = colours[li % colours.len()];
        chart
            .draw_series(LineSeries::new(pts.clone(), colour))
            .map_err(|e| anyhow!("{e}"))?
            .label(layout.to_string())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], colour));
        chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, 2, colour.filled())))
            .map_err(|e| anyhow!("{e}"))?;
    }
    Ok(())
}
