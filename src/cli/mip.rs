//! `parvo mip`: build renderer-ready mip-mapped textures (EXR, KTX2, DDS,
//! one PNG per level) from images, as maketx, nvtt_export and toktx do.
//!
//! The arguments become a job list and [`parvo::pipeline::Settings`]; the
//! library's [`parvo::pipeline`] plans, builds and writes (the same batch
//! and `--update` behaviour for programs that embed parvo). This layer
//! parses, draws the progress bar and prints one line per input; a failing
//! input prints `parvo: INPUT: reason` and sets exit code 1, the others
//! are still written.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Mutex;
use std::time::Instant;

use clap::ValueEnum;
use indicatif::ProgressBar;

use super::args::{ColorArg, QualityArg, parse_bytes};
use parvo::compress::{BlockFormat, Quality};
use parvo::io::exr::ExrCompression;
use parvo::io::ktx2::Supercompression;
use parvo::io::{self, Limits, OutputKind};
use parvo::mip::roughness::{NormalChannels, Specular};
use parvo::mip::{MipFilter, NanPolicy, Rounding};
use parvo::pipeline::{
    self, AlphaChoice, ColorChoice, Job, Note, Outcome, ResizeTo, RoughnessSettings,
    RoughnessSource, Settings, Stage, Status,
};
use parvo::texel::ChannelType;
use parvo::{ImageKind, Wrap};

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
pub enum NormalChannelsArg {
    Xyz,
    Xy,
}

fn parse_specular(s: &str) -> Result<Specular, String> {
    if s == "roughness" {
        return Ok(Specular::Roughness);
    }
    match s.split_once(':') {
        Some(("blinn-phong", e)) => match e.parse::<f32>() {
            Ok(x) if x > 0.0 && x.is_finite() => Ok(Specular::BlinnPhong(x)),
            _ => Err(format!("`{e}` is not a Blinn-Phong exponent above 0")),
        },
        _ => Err(format!(
            "`{s}`: expected roughness or blinn-phong:EXP (e.g. blinn-phong:64)"
        )),
    }
}

/// `--compress` formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum CompressArg {
    Bc1,
    Bc3,
    Bc4,
    Bc5,
    Bc7,
    Bc6h,
}

impl From<CompressArg> for BlockFormat {
    fn from(c: CompressArg) -> Self {
        match c {
            CompressArg::Bc1 => BlockFormat::Bc1,
            CompressArg::Bc3 => BlockFormat::Bc3,
            CompressArg::Bc4 => BlockFormat::Bc4 { signed: false },
            CompressArg::Bc5 => BlockFormat::Bc5 { signed: false },
            CompressArg::Bc7 => BlockFormat::Bc7,
            CompressArg::Bc6h => BlockFormat::Bc6h { signed: false },
        }
    }
}

/// `--resize-to` rules.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ResizeArg {
    #[value(name = "multiple-of-4")]
    MultipleOf4,
    Pow2,
}

/// The `--ext` choices: the output containers of the library's table.
fn ext_parser() -> impl clap::builder::TypedValueParser<Value = OutputKind> {
    use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
    PossibleValuesParser::new(
        io::container::outputs().map(|k| PossibleValue::new(k.id()).help(k.summary())),
    )
    .try_map(|id| OutputKind::from_id(&id).ok_or_else(|| format!("no output container `{id}`")))
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
    Each input is decoded within --max-width, --max-height and --max-alloc (checked from its header \
    before allocating); docs/limits.md in the repository lists every limit, its default and how to \
    raise it.\n\n\
    Memory, per level-0 texel of an input of B bytes per texel converted to an output type of O \
    bytes per texel (the chain adds a third): box filter with sides divisible by 2, and every other \
    filter or size, build band by band: at most B + 4/3·O, plus, for the other filters and odd \
    sizes, level 1 in f32 (a quarter of 4 bytes per channel). A chain to .exr never holds level 0 \
    in the output type (each row of tiles is built, compressed and written as it is made): \
    O/3 instead of 4/3·O. RGBA8 -> half EXR: 6.7 bytes (box), at most 10.7 (Kaiser, Lanczos, \
    Mitchell, triangle, odd sizes; 8.2 measured at 16384x16384: the source is freed before the \
    smaller levels are made); RGBA8 -> half .ktx2/.dds: 14.7 (box), 18.7 (the others). Alpha \
    coverage, normal maps, and float inputs holding NaN/Inf or written to 8/16-bit types build \
    whole: add level 0 in f32 (4 bytes per channel). An output of the input's own type keeps \
    the input as level 0 and reduces every later level from the unrounded one before it, in f32: \
    add level 1 in f32 (a quarter of 4 bytes per channel). --stats prints the peak and the time of each phase (for .exr, where building \
    and writing interleave, build is the time spent making levels and write the rest; read \
    includes mapping the pages of levels 1-4 on the core a one-thread decoder such as PNG's leaves \
    idle).\n\n\
    Exit codes: 0 every input succeeded; 1 some input failed (the others were written); 2 usage error."
)]
pub struct MipArgs {
    #[command(flatten)]
    env: super::env_mip::EnvMipArgs,

    /// Input images (PNG, JPEG, TIFF, HDR, EXR, KTX2, DDS), directories of them, or builtin:NAME[:SIZE].
    #[arg(required = true, value_name = "INPUT")]
    inputs: Vec<String>,

    /// Output file for a single input (.exr, .ktx2, .dds, or NAME_{level}.png).
    #[arg(short, long, value_name = "OUTPUT", conflicts_with = "out_dir")]
    output: Option<PathBuf>,

    /// Output directory for a batch: DIR/STEM.EXT per input.
    #[arg(long, value_name = "DIR")]
    out_dir: Option<PathBuf>,

    /// Output container in --out-dir mode.
    #[arg(long, default_value = "exr", value_parser = ext_parser())]
    ext: OutputKind,

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

    /// Normal maps: also build a roughness chain from the spread of the normals, from this base roughness.
    #[arg(
        long,
        value_name = "NUM|TEXTURE",
        requires = "normal_map",
        long_help = "Normal maps: build a roughness chain beside the normal chain, so that distant, \
        averaged bumps keep their specular look (SPEC.md: each texel's mean of the unit level-0 normals \
        of its footprint has length r; kappa = (3r - r^3) / (1 - r^2); roughness' = sqrt(roughness^2 + \
        2 / kappa), at most 1). The base roughness is a number from 0 to 1 (Beckmann m or GGX alpha) or \
        a roughness map of the normal map's size (its first channel, read as data). Write the chain \
        with --roughness-out or --pack-roughness A. With it the normal output has three channels (four \
        packed)."
    )]
    roughness: Option<String>,

    /// Where the roughness chain goes: any output parvo writes (one channel, linear).
    #[arg(
        long,
        value_name = "OUTPUT",
        requires = "roughness",
        long_help = "The roughness chain's output: .exr, .ktx2, .dds or NAME_{level}.png; one channel, \
        linear, in the main output's --type where the container stores it (else f16 for EXR, u8/u16 for \
        PNG and 8-bit for KTX2/DDS), with the same level sizes, wrap modes and fingerprint."
    )]
    roughness_out: Option<PathBuf>,

    /// Store the roughness chain in the normal output's alpha channel (A) instead of a second file.
    #[arg(
        long,
        value_name = "A",
        requires = "roughness",
        conflicts_with = "roughness_out"
    )]
    pack_roughness: Option<String>,

    /// Which channels of a normal map hold the vector: xyz, or xy (z rebuilt as sqrt(1 - x^2 - y^2)).
    #[arg(long, value_enum, default_value = "xyz", value_name = "CH")]
    normal_map_channels: NormalChannelsArg,

    /// With --roughness: roughness (default) or blinn-phong:EXP (Toksvig's exponent chain from base exponent EXP).
    #[arg(long, default_value = "roughness", value_name = "MODEL", value_parser = parse_specular, requires = "roughness")]
    specular: Specular,

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

    /// Block-compress every level (.ktx2 or .dds): bc1, bc3, bc4, bc5, bc7 or bc6h.
    #[arg(
        long,
        value_enum,
        value_name = "FORMAT",
        long_help = "Block-compress every level for the GPU (.ktx2 or .dds output). bc7: RGBA, the \
        quality choice for colour (16 bytes per 4x4 block); bc1: RGB with 1-bit alpha (8 bytes; texels \
        with alpha below 0.5 become transparent); bc3: RGB + interpolated alpha (16 bytes); bc4: one \
        channel (8 bytes); bc5: two channels, for normal maps (x, y; readers rebuild z) (16 bytes); \
        bc6h: HDR RGB, unsigned half floats (16 bytes; negative values become 0). sRGB input is \
        stored in the _SRGB variants of BC1/BC3/BC7. Levels smaller than a block are padded as the \
        formats define. The chain is built as for uncompressed output, then each level is encoded \
        (in parallel). With --stats or --json, each level's PSNR against the uncompressed level is \
        measured by decoding the blocks again with an independent decoder."
    )]
    compress: Option<CompressArg>,

    /// Encoder effort for --compress: fast, normal (default) or slow.
    #[arg(
        long,
        value_enum,
        default_value = "normal",
        value_name = "Q",
        requires = "compress",
        long_help = "Encoder effort for --compress. bc7 and bc6h: Intel ISPC's very-fast, basic or \
        slow profile; bc1 and bc3: ISPC's kernel at fast, refitted by least squares at normal (about \
        nvcompress -fast's time), searched from every start including libsquish's iterative cluster \
        fit at slow, each step at least as good as the one before (bc1 with alpha uses libsquish: \
        range fit, cluster fit, iterative cluster fit); bc4 and bc5 have one encoder."
    )]
    quality: QualityArg,

    /// KTX2 supercompression with Zstandard at LEVEL (1-22), per level (scheme 2).
    #[arg(long, value_name = "LEVEL", conflicts_with = "zlib")]
    zstd: Option<i32>,

    /// KTX2 supercompression with zlib at LEVEL (1-12), per level (scheme 3).
    #[arg(long, value_name = "LEVEL")]
    zlib: Option<i32>,

    /// Resample level 0 first: multiple-of-4 (whole blocks) or pow2 (nearest powers of two).
    #[arg(
        long,
        value_enum,
        value_name = "RULE",
        long_help = "Resample level 0 before building the chain, with the --filter kernel: \
        multiple-of-4 rounds each side up to whole 4x4 blocks, which is what WebGL requires of a \
        block-compressed texture (level 0's sides multiples of 4; each level k's sides times 2^k \
        multiples of 4, which levels rounded down from such a level 0 always are); pow2 takes each \
        side to the nearest power of two (ties up), so that every level is whole blocks too."
    )]
    resize_to: Option<ResizeArg>,

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

    /// Keep JPEG/PNG/TIFF pixels in stored order instead of applying the EXIF orientation.
    #[arg(
        long,
        long_help = "Keep JPEG, PNG and TIFF pixels in the order the file stores them instead of \
        applying their EXIF orientation (PNG: an eXIf chunk or ImageMagick's 'Raw profile type \
        exif' text), as image viewers and `oiiotool --autoorient` do by default. A KTX2 file's \
        KTXorientation is always applied: it states how the rows are stored, not how to display \
        them."
    )]
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

impl From<ColorArg> for ColorChoice {
    fn from(c: ColorArg) -> Self {
        match c {
            ColorArg::Auto => ColorChoice::Auto,
            ColorArg::Linear => ColorChoice::Linear,
            ColorArg::Srgb => ColorChoice::Srgb,
        }
    }
}

impl From<AlphaArg> for AlphaChoice {
    fn from(a: AlphaArg) -> Self {
        match a {
            AlphaArg::Auto => AlphaChoice::Auto,
            AlphaArg::Straight => AlphaChoice::Straight,
            AlphaArg::Premultiplied => AlphaChoice::Premultiplied,
            AlphaArg::None => AlphaChoice::None,
        }
    }
}

/// The library settings of these arguments.
fn settings(args: &MipArgs) -> Settings {
    Settings {
        filter: args.filter,
        wrap: args.wrap,
        rounding: args.rounding,
        levels: args.levels,
        alpha_coverage: args.alpha_coverage,
        normal_map: args.normal_map,
        nan_policy: args.fixnan,
        color: args.color.into(),
        alpha: args.alpha.into(),
        out_type: args.out_type,
        exr: io::exr::ExrOptions {
            tile: args.tile,
            compression: args.compression,
        },
        load: io::LoadOptions {
            channels: args.channels.clone(),
            subimage: args.subimage,
            auto_orient: !args.no_auto_orient,
            // The colour choice and the NaN policy are the build's
            // (Settings::color, Settings::nan_policy).
            ..io::LoadOptions::default()
        },
        limits: Limits {
            max_width: args.max_width,
            max_height: args.max_height,
            max_alloc: args.max_alloc,
        },
        update: args.update,
        dry_run: args.dry_run,
        roughness: None,
        compress: args.compress.map(|c| {
            (
                c.into(),
                match args.quality {
                    QualityArg::Fast => Quality::Fast,
                    QualityArg::Normal => Quality::Normal,
                    QualityArg::Slow => Quality::Slow,
                },
            )
        }),
        ktx2: io::ktx2::Ktx2Options {
            supercompression: match (args.zstd, args.zlib) {
                (Some(l), _) => Some(Supercompression::Zstd(l)),
                (None, Some(l)) => Some(Supercompression::Zlib(l)),
                (None, None) => None,
            },
        },
        resize_to: args.resize_to.map(|r| match r {
            ResizeArg::MultipleOf4 => ResizeTo::MultipleOf4,
            ResizeArg::Pow2 => ResizeTo::Pow2,
        }),
        measure_blocks: args.stats || args.json,
        env: Default::default(),
    }
}

/// The roughness settings of these arguments (a usage error as text).
fn roughness_settings(args: &MipArgs) -> Result<Option<RoughnessSettings>, String> {
    let channels = match args.normal_map_channels {
        NormalChannelsArg::Xyz => NormalChannels::Xyz,
        NormalChannelsArg::Xy => NormalChannels::Xy,
    };
    let Some(r) = &args.roughness else {
        if channels == NormalChannels::Xy {
            return Err(
                "--normal-map-channels xy needs --roughness (the roughness path rebuilds z)".into(),
            );
        }
        return Ok(None);
    };
    let base = match r.trim().parse::<f32>() {
        Ok(a) => RoughnessSource::Constant(a),
        Err(_) if parvo::builtin::is_builtin(r) || std::path::Path::new(r).is_file() => {
            RoughnessSource::Map(r.clone())
        }
        Err(_) => {
            return Err(format!(
                "--roughness {r}: neither a number from 0 to 1 nor a texture file"
            ));
        }
    };
    if let Some(p) = &args.pack_roughness
        && !p.eq_ignore_ascii_case("a")
    {
        return Err(format!(
            "--pack-roughness {p}: only A (the alpha channel) is supported"
        ));
    }
    let output = match &args.roughness_out {
        Some(p) => Some((
            p.clone(),
            OutputKind::from_path(p).map_err(|e| e.to_string())?,
        )),
        None => None,
    };
    Ok(Some(RoughnessSettings {
        base,
        channels,
        specular: args.specular,
        output,
        pack_alpha: args.pack_roughness.is_some(),
    }))
}

pub fn run(args: MipArgs) -> anyhow::Result<ExitCode> {
    let (jobs, settings) = match jobs_and_settings(&args) {
        Ok(js) => js,
        Err(code) => return Ok(code),
    };
    // Report panics (bugs in parvo or a dependency) as per-file errors, not
    // as the default multi-line message.
    std::panic::set_hook(Box::new(|_| {}));
    super::progress::remove_temporary_files_on_interrupt();
    let tty = std::io::stderr().is_terminal() && !args.json;
    let batch = jobs.len() > 1;
    let bar = if tty {
        let template = if batch {
            super::progress::BAR_FILES
        } else {
            super::progress::BAR_PERCENT
        };
        Some(
            ProgressBar::new(if batch { jobs.len() as u64 } else { 0 })
                .with_style(super::progress::bar_style(template)?),
        )
    } else {
        None
    };
    let out = Printer {
        args: &args,
        bar: bar.as_ref(),
        batch,
        started: Instant::now(),
        failed: Mutex::new(0),
        print: Mutex::new(()),
        seen: Mutex::new(Vec::new()),
    };
    let single = jobs.first().map(|j| (j.input.clone(), j.output.clone()));
    let mut progress = |stage: Stage| {
        if let (Some(b), Some((input, output))) = (&bar, &single) {
            show_stage(b, input, output, stage);
        }
    };
    pipeline::run(&jobs, &settings, &mut progress, &|job, result| {
        out.done(job, result)
    });
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    out.repeats();
    let failed = *out.failed.lock().unwrap_or_else(|e| e.into_inner());
    Ok(if failed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

/// The jobs and settings of `args`, or the exit code of a usage problem
/// (said on stderr), found before any input is read.
fn jobs_and_settings(args: &MipArgs) -> Result<(Vec<Job>, Settings), ExitCode> {
    let usage = |msg: String| {
        eprintln!("parvo: {}", super::words::words(msg));
        Err(ExitCode::from(2))
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
    // A directory among the inputs stands for the images in it.
    let inputs = match pipeline::expand_inputs(&args.inputs) {
        Ok(i) => i,
        Err(e) => return usage(e.to_string()),
    };
    let jobs = match (&args.output, &args.out_dir) {
        (Some(out), None) => {
            // Six face files make one cube map.
            let faces = inputs.len() == 6 && args.env.env.is_some();
            if inputs.len() != 1 && !faces {
                return usage(format!(
                    "-o takes one input (or six face files +x -x +y -y +z -z with --env), \
                     got {}; use --out-dir DIR for a batch",
                    inputs.len()
                ));
            }
            let job = if faces {
                Job::faces(&inputs, out)
            } else {
                Job::new(&inputs[0], out)
            };
            match job {
                Ok(j) => vec![j],
                Err(e) => return usage(e.to_string()),
            }
        }
        (None, Some(dir)) => {
            // Made when missing (not by a dry run, which writes nothing).
            if !args.dry_run
                && !dir.is_dir()
                && let Err(e) = std::fs::create_dir_all(dir)
            {
                eprintln!(
                    "parvo: cannot create the output directory {}: {e}",
                    dir.display()
                );
                return Err(ExitCode::from(1));
            }
            Job::batch(&inputs, dir, args.ext)
        }
        _ => return usage("give -o OUTPUT (one input) or --out-dir DIR (a batch)".into()),
    };
    let mut settings = settings(args);
    match roughness_settings(args) {
        Ok(r) => settings.roughness = r,
        Err(e) => return usage(e),
    }
    match args.env.settings() {
        Ok(e) => settings.env = e,
        Err(e) => return usage(e),
    }
    if let Err(e) = pipeline::check(&jobs, &settings) {
        return usage(super::words::error_text(&e));
    }
    Ok((jobs, settings))
}

/// A single job's progress on its bar.
fn show_stage(b: &ProgressBar, input: &str, output: &std::path::Path, stage: Stage) {
    match stage {
        Stage::Building { total_texels } => {
            b.set_length(total_texels.max(1));
            b.set_message(input.to_string());
        }
        Stage::Built { texels_done } => b.set_position(texels_done),
        Stage::Encoding { total_texels } => {
            b.set_length(total_texels.max(1));
            b.set_position(0);
            b.set_message(format!("{input}: block-compressing"));
        }
        Stage::Encoded { texels_done } => b.set_position(texels_done),
        Stage::Writing => b.set_message(format!("{input}: writing {}", output.display())),
    }
}

/// How `run` reports finished jobs: one line each (text or JSON) on
/// stdout, notes and errors on stderr, around the progress bar.
struct Printer<'a> {
    args: &'a MipArgs,
    bar: Option<&'a ProgressBar>,
    batch: bool,
    started: Instant,
    failed: Mutex<usize>,
    print: Mutex<()>,
    /// A batch's notes said so far: each distinct text, the input it was
    /// said for, and how many inputs it concerns.
    seen: Mutex<Vec<(String, String, usize)>>,
}

impl Printer<'_> {
    /// A note for `input`: said at once, except in a batch, where a note
    /// already said for another input is only counted
    /// ([`Printer::repeats`] says the counts at the end).
    fn note(&self, input: &str, text: String) {
        if self.batch {
            let mut seen = self.seen.lock().unwrap_or_else(|e| e.into_inner());
            if let Some(s) = seen.iter_mut().find(|s| s.0 == text) {
                s.2 += 1;
                return;
            }
            seen.push((text.clone(), input.to_string(), 1));
        }
        self.warn(format!("parvo: {input}: {text}"));
    }

    /// After a batch: how many inputs each repeated note concerned.
    fn repeats(&self) {
        let seen = self.seen.lock().unwrap_or_else(|e| e.into_inner());
        for (text, first, n) in seen.iter().filter(|s| s.2 > 1) {
            let short: String = text.chars().take(60).collect();
            let more = if short.len() < text.len() { "…" } else { "" };
            self.warn(format!(
                "parvo: the note for {first} (\"{short}{more}\") concerns {n} inputs in all \
                 (--json lists each input's notes)"
            ));
        }
    }

    fn line(&self, s: String) {
        match self.bar {
            Some(b) => b.suspend(|| println!("{s}")),
            None => println!("{s}"),
        }
    }

    fn warn(&self, s: String) {
        match self.bar {
            Some(b) => b.suspend(|| eprintln!("{}", super::words::words(&s))),
            None => eprintln!("{}", super::words::words(&s)),
        }
    }

    fn done(&self, job: &Job, result: parvo::Result<Outcome>) {
        // A single job's time is the run's; a batch's jobs overlap, so
        // each reports the sum of its own phases.
        let secs = self.started.elapsed().as_secs_f64();
        let _guard = self.print.lock().unwrap_or_else(|e| e.into_inner());
        let args = self.args;
        match result {
            Ok(o) => {
                let secs = if self.batch {
                    o.read_s + o.build_s + o.write_s
                } else {
                    secs
                };
                for n in &o.notes {
                    self.note(&job.input, note_text(n));
                }
                if args.json {
                    self.line(json_line(job, &o, secs));
                } else {
                    self.line(summary_line(job, &o, args, secs));
                    if args.stats {
                        self.line(stats_line(&o));
                    }
                }
            }
            Err(e) => {
                *self.failed.lock().unwrap_or_else(|e| e.into_inner()) += 1;
                let msg = super::words::error_text(&e).replace('\n', " ");
                self.warn(format!("parvo: {}: {msg}", job.input));
                if args.json {
                    self.line(
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
        if self.batch
            && let Some(b) = self.bar
        {
            b.inc(1);
        }
    }
}

fn summary_line(job: &Job, o: &Outcome, args: &MipArgs, secs: f64) -> String {
    let out = if job.kind.stores().file_per_level {
        format!("{} (x{})", o.output.display(), o.level_sizes.len())
    } else {
        o.output.display().to_string()
    };
    let what = match o.status {
        Status::Written => "",
        Status::UpToDate => " (up to date)",
        Status::DryRun => " (dry run: nothing written)",
    };
    let rough = match (&args.roughness_out, &args.pack_roughness) {
        (Some(p), _) => format!(", roughness -> {}", p.display()),
        (None, Some(_)) => ", roughness in A".to_string(),
        _ => String::new(),
    };
    let stored = match &o.blocks {
        Some(b) => {
            let bytes: u64 = b.levels.iter().map(|l| l.bytes).sum();
            format!(
                "{} ({} quality, {:.1} MiB of blocks, {:.1}x smaller than {})",
                b.stored,
                b.quality,
                bytes as f64 / (1 << 20) as f64,
                b.uncompressed_bytes as f64 / bytes.max(1) as f64,
                o.format
            )
        }
        // Not encoded by this run (up to date, dry run): what the output
        // holds, not the texels the encoder would read.
        None => match (&o.block_format, &args.compress) {
            (Some(bf), Some(_)) => format!(
                "{bf} ({} quality)",
                args.quality
                    .to_possible_value()
                    .map_or(String::new(), |v| v.get_name().to_string())
            ),
            _ => o.format.to_string(),
        },
    };
    let sc = match (args.zstd, args.zlib) {
        (Some(l), _) => format!(", zstd {l}"),
        (None, Some(l)) => format!(", zlib {l}"),
        _ => String::new(),
    };
    let kind = match o.image_kind {
        ImageKind::Plain => String::new(),
        k => format!("{} of ", k.describe()),
    };
    format!(
        "{} -> {out}: {kind}{}x{} {}{sc}, {} levels, {}{rough}{what}, {:.2} s",
        job.input,
        o.width,
        o.height,
        stored,
        o.level_sizes.len(),
        args.filter,
        secs
    )
}

fn stats_line(o: &Outcome) -> String {
    let peak = peak_rss_bytes()
        .map(|b| format!("{:.1} MiB", b as f64 / (1 << 20) as f64))
        .unwrap_or_else(|| "n/a".into());
    let mut text = format!(
        "  stats: read {:.3} s, build {:.3} s, {}write {:.3} s, peak memory {peak}",
        o.read_s,
        o.build_s,
        o.blocks
            .as_ref()
            .map_or(String::new(), |b| format!("encode {:.3} s, ", b.encode_s)),
        o.write_s
    );
    if let Some(b) = &o.blocks {
        text.push_str(&format!(
            "\n  level        size       bytes  bytes/texel   PSNR dB  encode s ({})",
            b.stored
        ));
        for (k, l) in b.levels.iter().enumerate() {
            // Bytes are summed over every face and layer.
            let texels = l.width as f64 * l.height as f64 * o.image_kind.images() as f64;
            text.push_str(&format!(
                "\n  {k:>5} {:>11} {:>11} {:>12.3} {:>9} {:>9.3}",
                format!("{}x{}", l.width, l.height),
                l.bytes,
                l.bytes as f64 / texels,
                l.psnr_db.map_or("-".into(), |p| if p.is_finite() {
                    format!("{p:.2}")
                } else {
                    "inf".into()
                }),
                l.encode_s
            ));
        }
    }
    text
}

fn json_line(job: &Job, o: &Outcome, secs: f64) -> String {
    serde_json::json!({
        "input": job.input,
        "output": o.output,
        "status": o.status.name(),
        "kind": o.image_kind.id(),
        "images": o.image_kind.images(),
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
        "block_format": o.block_format,
        "compression": o.blocks.as_ref().map(|b| serde_json::json!({
            "format": b.stored,
            "quality": b.quality.name(),
            "encode_seconds": b.encode_s,
            "uncompressed_bytes": b.uncompressed_bytes,
            "bytes": b.levels.iter().map(|l| l.bytes).sum::<u64>(),
            "levels": b.levels.iter().map(|l| serde_json::json!({
                "width": l.width,
                "height": l.height,
                "bytes": l.bytes,
                "bytes_per_texel": l.bytes as f64
                    / (l.width as f64 * l.height as f64 * o.image_kind.images() as f64),
                // JSON has no infinity: identical levels report null.
                "psnr_db": l.psnr_db.filter(|p| p.is_finite()),
                "encode_seconds": l.encode_s,
            })).collect::<Vec<_>>(),
        })),
        "notes": o.notes.iter().map(note_text).collect::<Vec<_>>(),
        "lighting": o.lighting.as_ref().map(|l| serde_json::json!({
            "prefilter": l.roughness.as_ref().map(|(lobe, _)| lobe.name()),
            "roughness": l.roughness.as_ref().map(|(_, a)| a),
            "sh9": l.sh9,
        })),
        "plan": {
            "path": format!("{:?}", o.plan.path),
            "memory_estimate_bytes": o.plan.memory_bytes,
        },
    })
    .to_string()
}

/// A pipeline note in this command's option names.
fn note_text(n: &Note) -> String {
    match n {
        Note::Resized { from, to, filter } => format!(
            "resized {}x{} to {}x{} ({filter} filter) for --resize-to",
            from.0, from.1, to.0, to.1
        ),
        Note::WebGlMisfit { level, size } => format!(
            "level {level} is {}x{}: WebGL refuses block-compressed levels unless level 0's sides \
             are multiples of 4 (and level k's sides times 2^k are); --resize-to multiple-of-4 \
             makes them so",
            size.0, size.1
        ),
        Note::Clipped {
            clipped,
            texels,
            to,
        } => format!(
            "{clipped} of {texels} texels (all levels) hold values outside 0..1 and are clipped to \
             the {to} range; keep a float output (.exr, or --type f16) to keep them"
        ),
        // The loader's notes, which may name settings.
        _ => super::words::words(n),
    }
}

/// Peak resident set size of this process (Linux `VmHWM`), if available.
pub fn peak_rss_bytes() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}
