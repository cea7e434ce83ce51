//! `parvo mip`: build renderer-ready mip-mapped textures (EXR, KTX2, DDS,
//! one PNG per level) from images, as maketx, nvtt_export and toktx do.
//!
//! Per input: load (with decoder limits) → resolve the output format →
//! fingerprint (for `--update`) → build the chain with
//! [`parvo::mip::build_with_progress`] → convert each level to the output
//! type → write atomically. Inputs of a batch run in parallel (rayon); a
//! failing input prints one line `parvo: INPUT: reason` and sets exit code
//! 1, the others are still written.
//!
//! Type conversion: when the output type differs from the source (the
//! common 8-bit sRGB PNG → half EXR), level 0 is decoded once to linear f32,
//! the chain is built in f32 and each level is quantised once at the end.
//! Building in the source type would round every intermediate level to 8
//! bits; decoding first costs memory (4 bytes per channel) but is the most
//! accurate, and the f32 box path is the fastest one.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Mutex;
use std::time::Instant;

use anyhow::{Context, anyhow};
use clap::ValueEnum;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;

use parvo::io::exr::ExrCompression;
use parvo::io::{self, FileFormat, Limits, OutputKind, SaveOptions};
use parvo::mip::{self, MipChain, MipFilter, MipOptions, NanPolicy, Rounding};
use parvo::texel::{AlphaMode, ChannelType, ColorSpace, Format, Texels};
use parvo::{Texture, Wrap};

/// How to interpret the colour channels of the input.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ColorArg {
    /// What the file says: PNG by its sRGB/cICP/gAMA chunks (sRGB when it has none), JPEG sRGB,
    /// KTX2 and DDS by their format, OpenEXR, TIFF and HDR linear.
    Auto,
    /// The input is linear light.
    Linear,
    /// The input is sRGB-encoded.
    Srgb,
}

/// Alpha convention of the input.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum AlphaArg {
    /// Premultiplied for OpenEXR, straight otherwise.
    Auto,
    /// Colour is independent of alpha (unassociated).
    Straight,
    /// Colour is already multiplied by alpha (associated).
    Premultiplied,
    /// No channel is alpha: a second or fourth channel is data.
    None,
}

/// Output container for `--out-dir` batches.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ExtArg {
    /// Tiled, mip-mapped OpenEXR.
    Exr,
    /// KTX 2.0.
    Ktx2,
    /// DDS.
    Dds,
    /// One PNG per level (`NAME_{level}.png`).
    Png,
}

/// Arguments of `parvo mip`.
#[derive(clap::Args, Debug)]
#[command(
    about = "Build mip-mapped textures (EXR, KTX2, DDS, PNG per level)",
    long_about = "Build mip-mapped textures from images, as maketx, nvtt_export or toktx do.\n\n\
    `parvo mip INPUT -o OUTPUT` writes one file; `parvo mip INPUT... --out-dir DIR` writes a batch \
    in parallel. The output container follows the extension: .exr (tiled, mip-mapped OpenEXR), \
    .ktx2, .dds, or a .png name containing {level} for one PNG per level (a re-run with a shorter \
    chain removes the higher levels parvo wrote before). Outputs are written \
    atomically (temporary file + rename): an error or an interrupt never leaves a truncated file.\n\n\
    Exit codes: 0 every input succeeded; 1 some input failed (the others were written); 2 usage error."
)]
pub struct MipArgs {
    /// Input images (PNG, JPEG, TIFF, HDR, EXR, KTX2, DDS) or builtin:NAME[:SIZE].
    #[arg(required = true, value_name = "INPUT")]
    inputs: Vec<String>,

    /// Output file for a single input (.exr, .ktx2, .dds, or NAME_{level}.png).
    #[arg(short, long, value_name = "OUTPUT", conflicts_with = "out_dir")]
    output: Option<PathBuf>,

    /// Output directory for a batch: DIR/STEM.EXT per input.
    #[arg(long, value_name = "DIR")]
    out_dir: Option<PathBuf>,

    /// Output container in --out-dir mode.
    #[arg(long, value_enum, default_value = "exr")]
    ext: ExtArg,

    /// Downsampling filter: box, triangle, kaiser, lanczos3, mitchell.
    #[arg(long, default_value = "box", value_name = "FILTER")]
    filter: MipFilter,

    /// Colour space of the input.
    #[arg(
        long,
        value_enum,
        default_value = "auto",
        long_help = "Colour space of the input. auto: what the file says (PNG by its sRGB, cICP or \
        gAMA chunk, sRGB when it has none, as OpenImageIO reads it; JPEG sRGB; KTX2 and DDS by their \
        format; OpenEXR, TIFF and HDR linear). sRGB is decoded and encoded with the exact IEC \
        61966-2-1 curve, which OpenImageIO's built-in transform departs from by up to about 0.004 \
        in linear light; filtering is in linear light."
    )]
    color: ColorArg,

    /// Alpha convention of the input: auto, straight, premultiplied or none.
    #[arg(
        long,
        value_enum,
        default_value = "auto",
        value_name = "MODE",
        long_help = "Alpha convention of the input. auto: premultiplied (associated) for OpenEXR, \
        as the format defines it, straight for everything else. Straight alpha is filtered with \
        alpha weighting; EXR outputs are always written premultiplied, as OpenEXR readers expect. \
        none: the second of two or fourth of four channels is data (a flow map, a packed mask), \
        filtered like the others and never written as alpha."
    )]
    alpha: AlphaArg,

    /// Preserve alpha-test coverage at this reference alpha (0 < REF < 1).
    #[arg(long, value_name = "REF")]
    alpha_coverage: Option<f32>,

    /// Treat RGB as unit normals: load as linear and renormalise each level.
    #[arg(long)]
    normal_map: bool,

    /// Wrap modes for the filter taps and the file: MODE or U,V (repeat, mirror, clamp, border, mirror-clamp).
    #[arg(
        long,
        value_name = "MODE[,MODE]",
        long_help = "Wrap modes used for filter taps outside the image and recorded in the output \
        (EXR `wrapmodes`, e.g. periodic,periodic). One mode for both axes or U,V. Default: the \
        input's own wrap modes if it records them, else repeat."
    )]
    wrap: Option<Wrap>,

    /// Output channel type: u8, u16, f16, f32.
    #[arg(
        long = "type",
        value_name = "TYPE",
        long_help = "Output channel type. Defaults: .exr f16 (f32 for f32 inputs); .ktx2/.dds the \
        input's type; PNG u8 for 8-bit inputs, else u16. EXR stores only f16/f32, PNG only u8/u16."
    )]
    out_type: Option<ChannelType>,

    /// EXR tile size: W or WxH.
    #[arg(long, default_value = "64", value_name = "W[xH]", value_parser = parse_tile)]
    tile: (u32, u32),

    /// Number of levels including level 0 (default: the full chain to 1x1).
    #[arg(long, value_name = "N")]
    levels: Option<u32>,

    /// Level size rounding: down (floor, the GPU rule) or up.
    #[arg(
        long,
        default_value = "down",
        value_name = "MODE",
        long_help = "Level size rounding: down (floor(size / 2^k), the GPU rule) or up (ceil; \
        OpenEXR's ROUND_UP). KTX2 and DDS define their level sizes by rounding down, so `up` is \
        refused for them before any work (exit 2)."
    )]
    rounding: Rounding,

    /// EXR compression: none, rle, zips, zip, piz, pxr24, b44, b44a, dwaa, dwab.
    #[arg(long, default_value = "zip", value_name = "NAME")]
    compression: ExrCompression,

    /// NaN/Inf in float input: error, black or neighbors.
    #[arg(long, default_value = "error", value_name = "POLICY")]
    fixnan: NanPolicy,

    /// Skip inputs whose output stores the same fingerprint (EXR, KTX2).
    #[arg(
        long,
        long_help = "Skip an input when its output exists and stores the fingerprint this run would \
        write: a hash of level 0's texels and of every option that changes the output. EXR and KTX2 \
        store it; DDS and PNG outputs are always rebuilt."
    )]
    update: bool,

    /// Load and check the inputs and print what would be written; write nothing.
    #[arg(long)]
    dry_run: bool,

    /// Print one JSON object per input on stdout instead of the summary line.
    #[arg(long)]
    json: bool,

    /// Print phase timings (read, build, write) and peak memory.
    #[arg(long)]
    stats: bool,

    /// Worker threads (default: all cores).
    #[arg(short = 'j', long, value_name = "N")]
    threads: Option<usize>,

    /// Largest accepted input width in texels.
    #[arg(long, default_value_t = Limits::default().max_width, value_name = "N")]
    max_width: u32,

    /// Largest accepted input height in texels.
    #[arg(long, default_value_t = Limits::default().max_height, value_name = "N")]
    max_height: u32,

    /// Largest decoded size of an input, e.g. 4G, 512M, 1000000.
    #[arg(long, default_value = "4G", value_name = "BYTES", value_parser = parse_bytes)]
    max_alloc: u64,

    /// EXR channels to load, in order: e.g. N.X,N.Y,N.Z or diffuse.R,diffuse.G,diffuse.B,diffuse.A.
    #[arg(
        long,
        value_name = "NAMES",
        value_delimiter = ',',
        long_help = "OpenEXR channels to load, by full name in the order wanted (1 to 4), e.g. \
        N.X,N.Y,N.Z or diffuse.R,diffuse.G,diffuse.B,diffuse.A. Default: OpenImageIO's conventions: \
        every channel when there are at most four (ordered by layer, then R, G, B, Y, A, ...; \
        X, Y, Z in a layer that has them), else the first layer's R,G,B[,A] or Y[,A]. A channel is \
        alpha only when it is named A (or Alpha) and is the last of two or four; other names are \
        data channels. The names are kept on EXR output."
    )]
    channels: Option<Vec<String>>,

    /// Which part of a multi-part EXR or page of a multi-page TIFF to read (0 = the first).
    #[arg(long, default_value_t = 0, value_name = "N")]
    subimage: usize,

    /// Keep JPEG/TIFF pixels in stored order instead of applying the EXIF orientation.
    #[arg(long)]
    no_auto_orient: bool,
}

fn parse_tile(s: &str) -> Result<(u32, u32), String> {
    let parse = |p: &str| {
        p.trim()
            .parse::<u32>()
            .ok()
            .filter(|&n| (1..=65536).contains(&n))
            .ok_or_else(|| format!("`{p}` is not a tile size from 1 to 65536"))
    };
    match s.split_once(['x', 'X']) {
        Some((w, h)) => Ok((parse(w)?, parse(h)?)),
        None => parse(s).map(|n| (n, n)),
    }
}

pub(crate) fn parse_bytes(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let (num, mul) = match t.char_indices().last() {
        Some((i, c)) if c.is_ascii_alphabetic() => {
            let m: u64 = match c.to_ascii_uppercase() {
                'K' => 1 << 10,
                'M' => 1 << 20,
                'G' => 1 << 30,
                'T' => 1 << 40,
                _ => return Err(format!("`{s}`: unknown unit (use K, M, G or T)")),
            };
            (&t[..i], m)
        }
        _ => (t, 1),
    };
    num.parse::<u64>()
        .ok()
        .and_then(|n| n.checked_mul(mul))
        .ok_or_else(|| format!("`{s}` is not a byte count such as 4G or 512M"))
}

/// What happened to one input.
#[derive(Debug)]
enum Status {
    Written,
    UpToDate,
    DryRun,
}

impl Status {
    fn name(&self) -> &'static str {
        match self {
            Status::Written => "written",
            Status::UpToDate => "up to date",
            Status::DryRun => "dry run",
        }
    }
}

#[derive(Debug)]
struct Outcome {
    output: PathBuf,
    status: Status,
    width: u32,
    height: u32,
    format: Format,
    level_sizes: Vec<(u32, u32)>,
    read_s: f64,
    build_s: f64,
    write_s: f64,
    /// What the loader did that the user would not assume, for stderr.
    notes: Vec<String>,
}

/// One job: an input and where it goes.
struct Job {
    input: String,
    output: PathBuf,
    kind: OutputKind,
}

pub fn run(args: MipArgs) -> anyhow::Result<ExitCode> {
    let usage = |msg: String| {
        eprintln!("parvo: {msg}");
        Ok(ExitCode::from(2))
    };
    if let Some(n) = args.threads {
        if n == 0 {
            return usage("--threads must be at least 1".into());
        }
        // Ignore the error if a pool exists already (only in tests).
        let _ = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global();
    }
    if args.levels == Some(0) {
        return usage("--levels must be at least 1".into());
    }
    if let Some(r) = args.alpha_coverage
        && !(r > 0.0 && r < 1.0)
    {
        return usage(format!("--alpha-coverage {r}: must be between 0 and 1"));
    }
    let jobs = match (&args.output, &args.out_dir) {
        (Some(out), None) => {
            if args.inputs.len() != 1 {
                return usage(format!(
                    "-o takes one input, got {}; use --out-dir DIR for a batch",
                    args.inputs.len()
                ));
            }
            let kind = match OutputKind::from_path(out) {
                Ok(k) => k,
                Err(e) => return usage(e.to_string()),
            };
            vec![Job {
                input: args.inputs[0].clone(),
                output: out.clone(),
                kind,
            }]
        }
        (None, Some(dir)) => {
            let mut jobs: Vec<Job> = Vec::new();
            for input in &args.inputs {
                let (output, kind) = batch_output(dir, input, args.ext);
                jobs.push(Job {
                    input: input.clone(),
                    output,
                    kind,
                });
            }
            jobs
        }
        _ => return usage("give -o OUTPUT (one input) or --out-dir DIR (a batch)".into()),
    };
    // A channel type the container cannot store is a usage error, found
    // before any input is read.
    if let Some(t) = args.out_type
        && let Some(j) = jobs.iter().find(|j| !j.kind.supports(t))
    {
        return usage(format!(
            "--type {t}: {} cannot store {t} texels (EXR: f16, f32; PNG: u8, u16; KTX2 and DDS: all)",
            j.kind.name()
        ));
    }
    // Containers whose level sizes are fixed by their specification.
    if args.rounding == Rounding::Up
        && let Some(j) = jobs
            .iter()
            .find(|j| matches!(j.kind, OutputKind::Ktx2 | OutputKind::Dds))
    {
        return usage(format!(
            "--rounding up: {} defines its level sizes as floor(size / 2^k); \
             use .exr or PNG levels for rounded-up chains (output {})",
            if j.kind == OutputKind::Ktx2 {
                "KTX2"
            } else {
                "DDS"
            },
            j.output.display()
        ));
    }
    // Report panics (bugs in parvo or a dependency) as per-file errors, not
    // as the default multi-line message.
    std::panic::set_hook(Box::new(|_| {}));
    // Ctrl-C: delete the temporary files being written (destinations are
    // only ever replaced by a complete file) and exit like a shell does.
    let _ = ctrlc::set_handler(|| {
        io::atomic::remove_temporary_files();
        eprintln!("parvo: interrupted; no output was left half-written");
        std::process::exit(130);
    });
    let limits = Limits {
        max_width: args.max_width,
        max_height: args.max_height,
        max_alloc: args.max_alloc,
    };
    let tty = std::io::stderr().is_terminal() && !args.json;
    let batch = jobs.len() > 1;
    let bar = if tty {
        let b = if batch {
            ProgressBar::new(jobs.len() as u64).with_style(
                ProgressStyle::with_template("{bar:40} {pos}/{len} files {elapsed_precise} {msg}")
                    .expect("valid template"),
            )
        } else {
            ProgressBar::new(0).with_style(
                ProgressStyle::with_template("{bar:40} {percent:>3}% {elapsed_precise} {msg}")
                    .expect("valid template"),
            )
        };
        Some(b)
    } else {
        None
    };
    // Two inputs with the same output name would overwrite each other.
    let mut seen = std::collections::HashMap::new();
    let dup: Vec<Option<String>> = jobs
        .iter()
        .map(|j| seen.insert(j.output.clone(), j.input.clone()))
        .collect();
    let failed = Mutex::new(0usize);
    let print = Mutex::new(());
    let work = |(job, dup): (&Job, &Option<String>)| {
        let t0 = Instant::now();
        let result = match dup {
            Some(first) => Err(anyhow!(
                "output {} is also the output of {first}",
                job.output.display()
            )),
            None => std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                process(job, &args, &limits, if batch { None } else { bar.as_ref() })
            }))
            .unwrap_or_else(|p| {
                Err(anyhow!(
                    "internal error: {}",
                    io::atomic::panic_message(&*p)
                ))
            }),
        };
        let _guard = print.lock().unwrap_or_else(|e| e.into_inner());
        let line = |s: String| match &bar {
            Some(b) => b.suspend(|| println!("{s}")),
            None => println!("{s}"),
        };
        match result {
            Ok(o) => {
                for n in &o.notes {
                    match &bar {
                        Some(b) => b.suspend(|| eprintln!("parvo: {}: {n}", job.input)),
                        None => eprintln!("parvo: {}: {n}", job.input),
                    }
                }
                if args.json {
                    line(json_line(job, &o, t0.elapsed().as_secs_f64()));
                } else {
                    line(summary_line(job, &o, &args, t0.elapsed().as_secs_f64()));
                    if args.stats {
                        line(stats_line(&o));
                    }
                }
            }
            Err(e) => {
                *failed.lock().unwrap_or_else(|e| e.into_inner()) += 1;
                let msg = format!("{e:#}").replace('\n', " ");
                match &bar {
                    Some(b) => b.suspend(|| eprintln!("parvo: {}: {msg}", job.input)),
                    None => eprintln!("parvo: {}: {msg}", job.input),
                }
                if args.json {
                    line(
                        serde_json::json!({
                            "input": job.input,
                            "output": job.output,
                            "status": "failed",
                            "error": msg,
                        })
                        .to_string(),
                    );
                }
            }
        }
        if batch && let Some(b) = &bar {
            b.inc(1);
        }
    };
    if batch {
        jobs.par_iter().zip(dup.par_iter()).for_each(work);
    } else {
        jobs.iter().zip(dup.iter()).for_each(work);
    }
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let failed = *failed.lock().unwrap_or_else(|e| e.into_inner());
    Ok(if failed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

fn batch_output(dir: &Path, input: &str, ext: ExtArg) -> (PathBuf, OutputKind) {
    let stem = if parvo::builtin::is_builtin(input) {
        input.replace(':', "-")
    } else {
        Path::new(input)
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "output".into())
    };
    match ext {
        ExtArg::Exr => (dir.join(format!("{stem}.exr")), OutputKind::Exr),
        ExtArg::Ktx2 => (dir.join(format!("{stem}.ktx2")), OutputKind::Ktx2),
        ExtArg::Dds => (dir.join(format!("{stem}.dds")), OutputKind::Dds),
        ExtArg::Png => (
            dir.join(format!("{stem}_{{level}}.png")),
            OutputKind::PngLevels,
        ),
    }
}

/// The output texel format for a source format, container and options.
fn output_format(src: Format, kind: OutputKind, args: &MipArgs) -> anyhow::Result<Format> {
    let ty = match args.out_type {
        Some(t) => t,
        None => match kind {
            OutputKind::Exr if src.channel_type == ChannelType::F32 => ChannelType::F32,
            OutputKind::Exr => ChannelType::F16,
            OutputKind::PngLevels if src.channel_type == ChannelType::U8 => ChannelType::U8,
            OutputKind::PngLevels => ChannelType::U16,
            OutputKind::Ktx2 | OutputKind::Dds => src.channel_type,
        },
    };
    if !kind.supports(ty) {
        anyhow::bail!(
            "{} cannot store {ty} texels (EXR: f16, f32; PNG: u8, u16)",
            kind.name()
        );
    }
    // Floats are linear light; integer outputs keep the source's encoding
    // (a float source gives linear integers).
    let cs = if ty.is_float() || src.channel_type.is_float() {
        ColorSpace::Linear
    } else {
        src.color_space
    };
    // Each container's alpha convention: OpenEXR defines colour as
    // associated with alpha, PNG as unassociated; KTX2 and DDS say which in
    // their headers, so they keep the source's.
    let alpha = match kind {
        OutputKind::Exr if src.has_alpha() => AlphaMode::Premultiplied,
        OutputKind::PngLevels if src.has_alpha() => AlphaMode::Straight,
        _ => src.alpha,
    };
    let f = Format::new(src.channels, ty, cs).with_alpha(alpha);
    Ok(match kind {
        OutputKind::Ktx2 => io::ktx2::storable(f),
        OutputKind::Dds => io::dds::storable(f),
        _ => f,
    })
}

fn options_string(args: &MipArgs, opts: &MipOptions, out: &Format, kind: OutputKind) -> String {
    format!(
        "parvo {} filter={} wrap={},{} rounding={} levels={} coverage={:?} normal={} fixnan={} out={out} kind={kind:?} tile={}x{} compression={}",
        env!("CARGO_PKG_VERSION"),
        opts.filter,
        opts.wrap.u,
        opts.wrap.v,
        opts.rounding,
        opts.max_levels
            .map_or("full".to_string(), |n| n.to_string()),
        opts.alpha_coverage,
        opts.normal_map,
        opts.nan_policy,
        args.tile.0,
        args.tile.1,
        args.compression,
    )
}

fn process(
    job: &Job,
    args: &MipArgs,
    limits: &Limits,
    bar: Option<&ProgressBar>,
) -> anyhow::Result<Outcome> {
    let t_read = Instant::now();
    let load_options = io::LoadOptions {
        channels: args.channels.clone(),
        subimage: args.subimage,
        auto_orient: !args.no_auto_orient,
    };
    let loaded = io::load_with(&job.input, limits, &load_options)?;
    let src_kind = loaded.info.format;
    let file_wrap = loaded.info.wrap;
    let mut notes = loaded.info.notes.clone();
    let channel_names = loaded.info.channel_names.clone();
    let mut base = loaded.into_base();
    // Interpretation of the input.
    let mut src = base.format();
    src.color_space = match (args.color, args.normal_map) {
        (ColorArg::Linear, _) | (ColorArg::Auto, true) => ColorSpace::Linear,
        (ColorArg::Srgb, _) => ColorSpace::Srgb,
        // The loader's reading of the file (see io::load).
        (ColorArg::Auto, false) => src.color_space,
    };
    src.alpha = match args.alpha {
        // A normal map's fourth channel is data, not alpha.
        _ if args.normal_map => AlphaMode::None,
        AlphaArg::Auto => src.alpha,
        AlphaArg::Straight => AlphaMode::Straight,
        AlphaArg::Premultiplied => AlphaMode::Premultiplied,
        AlphaArg::None => AlphaMode::None,
    };
    base = base.reinterpret(src)?;
    let read_s = t_read.elapsed().as_secs_f64();

    let out_format = output_format(src, job.kind, args)?;
    let options = MipOptions {
        filter: args.filter,
        wrap: args.wrap.or(file_wrap).unwrap_or_default(),
        rounding: args.rounding,
        max_levels: args.levels,
        alpha_coverage: args.alpha_coverage,
        alpha_store: Some(out_format.channel_type),
        normal_map: args.normal_map,
        nan_policy: args.fixnan,
        fast_paths: true,
    };
    if job.kind == OutputKind::Exr {
        let full = mip::level_count(base.width(), base.height(), args.rounding, None);
        if args.levels.is_some_and(|n| n < full) {
            anyhow::bail!(
                "a mip-mapped OpenEXR file holds the full chain ({full} levels); --levels applies to .ktx2, .dds and PNG"
            );
        }
    }
    let level_sizes = mip::level_sizes(base.width(), base.height(), args.rounding, args.levels);
    let (width, height) = (base.width(), base.height());
    let fingerprint = io::fingerprint(
        &base,
        &options_string(args, &options, &out_format, job.kind),
    );
    if args.dry_run {
        return Ok(Outcome {
            output: job.output.clone(),
            status: Status::DryRun,
            width,
            height,
            format: out_format,
            level_sizes,
            read_s,
            build_s: 0.0,
            write_s: 0.0,
            notes: notes.clone(),
        });
    }
    if args.update
        && io::stored_fingerprint(&job.output, job.kind).as_deref() == Some(fingerprint.as_str())
    {
        return Ok(Outcome {
            output: job.output.clone(),
            status: Status::UpToDate,
            width,
            height,
            format: out_format,
            level_sizes,
            read_s,
            build_s: 0.0,
            write_s: 0.0,
            notes: notes.clone(),
        });
    }

    let t_build = Instant::now();
    if let Some(b) = bar {
        let total: u64 = level_sizes[1..]
            .iter()
            .map(|&(w, h)| w as u64 * h as u64)
            .sum();
        b.set_length(total.max(1));
        b.set_message(job.input.clone());
    }
    let mut on_progress = |p: mip::Progress| {
        if let Some(b) = bar {
            b.set_position(p.texels_done);
        }
    };
    let association =
        (out_format.has_alpha() && src.alpha != out_format.alpha).then_some(out_format.alpha);
    // Alpha coverage is matched on the unrounded filtered alpha (rounding
    // each level to 8 bits first would tie texels the test must separate),
    // so it always builds in f32.
    let same = src.channel_type == out_format.channel_type
        && src.color_space == out_format.color_space
        && association.is_none()
        && args.alpha_coverage.is_none();
    let levels = if args.normal_map {
        // Decoded to vectors, averaged in f32, encoded once per level into
        // the output type (parvo::mip::normal).
        mip::normal::build(base, &options, out_format, &mut on_progress)?
    } else {
        let (levels, clip_note) = build_colour(
            base,
            &options,
            src,
            out_format,
            association,
            same,
            &mut on_progress,
        )?;
        notes.extend(clip_note);
        levels
    };
    let build_s = t_build.elapsed().as_secs_f64();
    if let Some(b) = bar {
        b.set_message(format!("{}: writing {}", job.input, job.output.display()));
    }

    let t_write = Instant::now();
    let save = SaveOptions {
        // An EXR source's channel names carry to EXR output (N.X stays
        // N.X, a lone Z stays Z); other sources get the layout's names.
        channel_names: (src_kind == FileFormat::Exr
            && channel_names.len() == out_format.channels as usize)
            .then_some(channel_names),
        wrap: options.wrap,
        tile: args.tile,
        compression: args.compression,
        fingerprint: Some(fingerprint),
        attributes: vec![
            ("parvo:filter".into(), args.filter.to_string()),
            ("parvo:source".into(), src.to_string()),
            ("parvo:rounding".into(), args.rounding.to_string()),
        ],
    };
    io::save(&levels, args.rounding, &job.output, job.kind, &save)
        .with_context(|| format!("writing {}", job.output.display()))?;
    if job.kind == OutputKind::PngLevels {
        // Levels an earlier, longer chain left behind under this template.
        let stale = io::png_levels::remove_stale(&job.output, levels.len())?;
        let list = |v: &[PathBuf]| {
            v.iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        };
        if !stale.removed.is_empty() {
            notes.push(format!(
                "removed {} stale level file(s) of an earlier run: {}",
                stale.removed.len(),
                list(&stale.removed)
            ));
        }
        if !stale.foreign.is_empty() {
            notes.push(format!(
                "left alone (not written by parvo): {}",
                list(&stale.foreign)
            ));
        }
    }
    let write_s = t_write.elapsed().as_secs_f64();
    Ok(Outcome {
        output: job.output.clone(),
        status: Status::Written,
        width,
        height,
        format: out_format,
        level_sizes,
        read_s,
        build_s,
        write_s,
        notes,
    })
}

/// The colour chain: built in the source format when it is the output
/// format, else in linear f32 from a single decode of level 0 (see the
/// module docs), each level converted to the output format.
fn build_colour(
    base: Texture,
    options: &MipOptions,
    src: Format,
    out_format: Format,
    association: Option<AlphaMode>,
    same: bool,
    progress: &mut dyn FnMut(mip::Progress),
) -> anyhow::Result<(Vec<Texture>, Option<String>)> {
    let work_base = if same {
        base
    } else {
        // Decode straight into the f32 buffer (`Texture::convert` would
        // hold a second full-size f32 copy while encoding).
        let f =
            Format::new(src.channels, ChannelType::F32, ColorSpace::Linear).with_alpha(src.alpha);
        let mut linear = vec![0f32; base.texels().len()];
        parvo::texel::decode_to_linear(&base.format(), base.texels(), &mut linear);
        let (w, h) = (base.width(), base.height());
        drop(base);
        Texture::from_f32(w, h, f, linear)?
    };
    let chain: MipChain = mip::build_with_progress(work_base, options, progress)?;
    // Float data (HDR) written to a normalised type is clipped to [0, 1]:
    // count the texels that lose something, to say so once.
    let count_clipped = src.channel_type.is_float() && !out_format.channel_type.is_float();
    let mut clipped = 0u64;
    let mut texels = 0u64;
    // Smallest level first, so level 0's f32 and converted copies never
    // coexist with the unconverted rest of the chain.
    let mut levels: Vec<Texture> = Vec::with_capacity(chain.len());
    for l in chain.into_levels().into_iter().rev() {
        let l = associate(l, association)?;
        if count_clipped {
            clipped += outside_unit_range(&l);
            texels += l.texel_count() as u64;
        }
        levels.push(convert_level(l, out_format)?);
    }
    levels.reverse();
    let note = (clipped > 0).then(|| {
        format!(
            "{clipped} of {texels} texels (all levels) hold values outside 0..1 and are clipped \
             to the {} range; keep a float output (.exr, or --type f16) to keep them",
            out_format.channel_type
        )
    });
    Ok((levels, note))
}

/// Texels with a channel outside [0, 1] (or NaN).
fn outside_unit_range(l: &Texture) -> u64 {
    let ch = l.channels();
    let count = |v: &[f32]| {
        v.par_chunks(ch * 4096)
            .map(|rows| {
                rows.chunks_exact(ch)
                    .filter(|p| p.iter().any(|x| !(0.0..=1.0).contains(x)))
                    .count() as u64
            })
            .sum::<u64>()
    };
    match l.texels() {
        Texels::F32(v) => count(v),
        Texels::F16(v) => {
            let f: Vec<f32> = v.iter().map(|x| x.to_f32()).collect();
            count(&f)
        }
        _ => 0,
    }
}

/// Change the alpha association of a level built in linear f32 (see
/// `process`): premultiply, or divide colour by alpha (where alpha is 0
/// the colour is kept, as oiiotool's --unpremult does).
fn associate(mut l: Texture, association: Option<AlphaMode>) -> anyhow::Result<Texture> {
    let Some(to) = association else {
        return Ok(l);
    };
    let ch = l.channels();
    let Texels::F32(v) = l.texels_mut() else {
        anyhow::bail!("changing the alpha association needs f32 levels");
    };
    let premultiply = to == AlphaMode::Premultiplied;
    v.par_chunks_mut(ch * 4096).for_each(|rows| {
        for px in rows.chunks_exact_mut(ch) {
            let a = px[ch - 1];
            if premultiply {
                px[..ch - 1].iter_mut().for_each(|c| *c *= a);
            } else if a != 0.0 {
                px[..ch - 1].iter_mut().for_each(|c| *c /= a);
            }
        }
    });
    let f = l.format().with_alpha(to);
    Ok(l.reinterpret(f)?)
}

/// Convert a built level to the output format (type, colour space, and
/// channel widening for containers that need it).
fn convert_level(l: Texture, out: Format) -> anyhow::Result<Texture> {
    let narrow = Format {
        channels: l.format().channels,
        ..out
    };
    let conv = if l.format() == narrow {
        l
    } else if l.channel_type() == ChannelType::F32
        && l.format().color_space == ColorSpace::Linear
        && narrow.channel_type == ChannelType::F16
        && narrow.color_space == ColorSpace::Linear
    {
        f32_to_f16(&l, narrow)?
    } else {
        l.convert(narrow)?
    };
    Ok(if conv.format().channels != out.channels {
        io::expand_channels(&conv, out.channels)?
    } else {
        conv
    })
}

/// Linear f32 → linear f16 without the general path's extra copy; finite
/// values beyond the half range saturate (as `encode_from_linear` does).
fn f32_to_f16(l: &Texture, f: Format) -> anyhow::Result<Texture> {
    use half::slice::HalfFloatSliceExt;
    let Texels::F32(v) = l.texels() else {
        anyhow::bail!("expected f32 texels");
    };
    let mut out = vec![half::f16::ZERO; v.len()];
    out.par_chunks_mut(1 << 16)
        .zip(v.par_chunks(1 << 16))
        .for_each(|(o, i)| {
            o.convert_from_f32_slice(i);
            for (o, &i) in o.iter_mut().zip(i) {
                if i.is_finite() && o.is_infinite() {
                    *o = if i > 0.0 {
                        half::f16::MAX
                    } else {
                        half::f16::MIN
                    };
                }
            }
        });
    Ok(Texture::from_f16(l.width(), l.height(), f, out)?)
}

fn summary_line(job: &Job, o: &Outcome, args: &MipArgs, secs: f64) -> String {
    let out = if job.kind == OutputKind::PngLevels {
        format!("{} (x{})", o.output.display(), o.level_sizes.len())
    } else {
        o.output.display().to_string()
    };
    let what = match o.status {
        Status::Written => "",
        Status::UpToDate => " (up to date)",
        Status::DryRun => " (dry run: nothing written)",
    };
    format!(
        "{} -> {out}: {}x{} {}, {} levels, {}{what}, {:.2} s",
        job.input,
        o.width,
        o.height,
        o.format,
        o.level_sizes.len(),
        args.filter,
        secs
    )
}

fn stats_line(o: &Outcome) -> String {
    let peak = peak_rss_bytes()
        .map(|b| format!("{:.1} MiB", b as f64 / (1 << 20) as f64))
        .unwrap_or_else(|| "n/a".into());
    format!(
        "  stats: read {:.3} s, build {:.3} s, write {:.3} s, peak memory {peak}",
        o.read_s, o.build_s, o.write_s
    )
}

fn json_line(job: &Job, o: &Outcome, secs: f64) -> String {
    serde_json::json!({
        "input": job.input,
        "output": o.output,
        "status": o.status.name(),
        "width": o.width,
        "height": o.height,
        "channels": o.format.channels,
        "type": o.format.channel_type.name(),
        "color": o.format.color_space.to_string(),
        "levels": o.level_sizes.iter().map(|&(w, h)| [w, h]).collect::<Vec<_>>(),
        "seconds": {
            "total": secs,
            "read": o.read_s,
            "build": o.build_s,
            "write": o.write_s,
        },
        "peak_rss_bytes": peak_rss_bytes(),
        "notes": o.notes,
    })
    .to_string()
}

/// Peak resident set size of this process (Linux `VmHWM`), if available.
pub fn peak_rss_bytes() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}
