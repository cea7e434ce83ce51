//! The batch mip pipeline behind `parvo mip`, for engines and asset
//! pipelines that embed parvo: a job list in, one [`Outcome`] (or error)
//! per job out, with the same planning, `--update` fingerprint rule and
//! conversions as the command line.
//!
//! Per job: load (with decoder limits) → interpret the input (colour
//! space, alpha) → resolve the output format for the container →
//! fingerprint (skip when the output already stores it and
//! [`Settings::update`] is set) → build the chain → convert each level to
//! the output type → write atomically. [`run`] runs a batch in parallel,
//! catches panics as per-job errors and refuses two jobs with one output.
//!
//! Type conversion: when the output type differs from the source (the
//! common 8-bit sRGB PNG → half EXR), level 0 is decoded once to linear
//! f32, the chain is built in f32 and each level is quantised once at the
//! end. Building in the source type would round every intermediate level
//! to 8 bits; decoding first costs memory (4 bytes per channel) but is the
//! most accurate, and the f32 box path is the fastest one.

use std::path::{Path, PathBuf};
use std::time::Instant;

use rayon::prelude::*;

use crate::compress::{BlockChain, BlockFormat, Quality};
use crate::error::{Error, Result};
use crate::io::exr::ExrCompression;
use crate::io::ktx2::Supercompression;
use crate::io::{self, FileFormat, Limits, LoadOptions, OutputKind, SaveOptions};
use crate::mip::roughness::{BaseRoughness, NormalChannels, Specular};
use crate::mip::{self, MipChain, MipFilter, MipOptions, NanPolicy, Rounding};
use crate::texel::{AlphaMode, ChannelType, ColorSpace, Format, Texels};
use crate::texture::Texture;
use crate::wrap::Wrap;

/// How to read the input's colour.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ColorChoice {
    /// What the file says (see [`crate::io::load`]); linear for normal maps.
    #[default]
    Auto,
    /// Linear, whatever the file says.
    Linear,
    /// sRGB-encoded, whatever the file says.
    Srgb,
}

/// How to read the input's alpha channel.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AlphaChoice {
    /// What the file says.
    #[default]
    Auto,
    /// Unassociated.
    Straight,
    /// Associated (premultiplied).
    Premultiplied,
    /// Not alpha: a data channel.
    None,
}

/// Everything a job needs besides its input and output.
#[derive(Clone, Debug)]
pub struct Settings {
    /// The mip filter.
    pub filter: MipFilter,
    /// Wrap modes; `None` takes the file's (repeat when it records none).
    pub wrap: Option<Wrap>,
    /// Level size rounding.
    pub rounding: Rounding,
    /// At most this many levels (including level 0); `None`: the full chain.
    pub levels: Option<u32>,
    /// Alpha coverage to preserve, in (0, 1).
    pub alpha_coverage: Option<f32>,
    /// The input is a normal map (see [`crate::mip::normal`]).
    pub normal_map: bool,
    /// What to do with NaN and infinite texels.
    pub nan_policy: NanPolicy,
    /// How to read the input's colour.
    pub color: ColorChoice,
    /// How to read the input's alpha.
    pub alpha: AlphaChoice,
    /// The output channel type; `None`: the container's default for the
    /// source.
    pub out_type: Option<ChannelType>,
    /// EXR tile size.
    pub tile: (u32, u32),
    /// EXR compression.
    pub compression: ExrCompression,
    /// Choices the loader cannot make from the file.
    pub load: LoadOptions,
    /// Decoder limits.
    pub limits: Limits,
    /// Skip a job whose output stores this run's fingerprint.
    pub update: bool,
    /// Plan only: nothing is built or written.
    pub dry_run: bool,
    /// Normal maps: a roughness (or Blinn-Phong exponent) chain from the
    /// spread of the normals (see [`crate::mip::roughness`]).
    pub roughness: Option<RoughnessSettings>,
    /// Block-compress every level (KTX2 and DDS; needs the `encode`
    /// feature).
    pub compress: Option<(BlockFormat, Quality)>,
    /// KTX2 supercompression of every level.
    pub supercompression: Option<Supercompression>,
    /// Resample level 0 first to a block-friendly size.
    pub resize_to: Option<ResizeTo>,
    /// Decode the blocks again and measure each level's PSNR (for
    /// `--stats` and `--json`).
    pub measure_blocks: bool,
}

/// Block-friendly level-0 sizes (`--resize-to`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ResizeTo {
    /// Each side up to the next multiple of 4 (whole blocks at level 0).
    MultipleOf4,
    /// Each side to the nearest power of two (ties up): every level of the
    /// chain stays block-aligned.
    Pow2,
}

impl ResizeTo {
    /// The size `(w, h)` becomes.
    pub fn apply(self, w: u32, h: u32) -> (u32, u32) {
        let f = |n: u32| match self {
            ResizeTo::MultipleOf4 => n.div_ceil(4).saturating_mul(4),
            ResizeTo::Pow2 => {
                let up = n.checked_next_power_of_two().unwrap_or(1 << 31);
                let down = if up == n { n } else { up / 2 };
                // Nearest in ratio: up when up/n <= n/down.
                if (up as u64) * (down as u64) <= (n as u64) * (n as u64) || down == 0 {
                    up
                } else {
                    down
                }
            }
        };
        (f(w), f(h))
    }
}

/// Per-level figures of a block-compressed output.
#[derive(Clone, Debug, PartialEq)]
pub struct BlockLevel {
    /// The level's size.
    pub width: u32,
    /// The level's size.
    pub height: u32,
    /// Bytes of its blocks.
    pub bytes: u64,
    /// Seconds encoding it (levels are encoded in parallel, so these
    /// overlap).
    pub encode_s: f64,
    /// PSNR of the decoded blocks against the uncompressed level (see
    /// [`crate::compress::psnr`]); `None` unless
    /// [`Settings::measure_blocks`].
    pub psnr_db: Option<f64>,
}

/// What block compression did to one job.
#[derive(Clone, Debug, PartialEq)]
pub struct BlockReport {
    /// The stored format, e.g. `BC7_SRGB`.
    pub stored: String,
    /// The encoder effort.
    pub quality: Quality,
    /// Per level, level 0 first.
    pub levels: Vec<BlockLevel>,
    /// Bytes the uncompressed levels would take.
    pub uncompressed_bytes: u64,
    /// Wall-clock seconds of the whole encode.
    pub encode_s: f64,
}

/// Where a normal map's roughness comes from and where it goes.
#[derive(Clone, Debug, PartialEq)]
pub struct RoughnessSettings {
    /// The base roughness: a number, or a roughness map (a file or a
    /// `builtin:` name) of the normal map's size.
    pub base: RoughnessSource,
    /// Which channels of the normal map hold the vector.
    pub channels: NormalChannels,
    /// Roughness α' or Blinn-Phong exponents s'.
    pub specular: Specular,
    /// A second output for the chain (one channel, linear), or `None`.
    pub output: Option<(PathBuf, OutputKind)>,
    /// Store the chain in the normal output's alpha channel instead.
    pub pack_alpha: bool,
}

/// The base roughness of a roughness chain.
#[derive(Clone, Debug, PartialEq)]
pub enum RoughnessSource {
    /// One roughness in [0, 1].
    Constant(f32),
    /// A roughness map, loaded with the job's limits.
    Map(String),
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            filter: MipFilter::Box,
            wrap: None,
            rounding: Rounding::Down,
            levels: None,
            alpha_coverage: None,
            normal_map: false,
            nan_policy: NanPolicy::Error,
            color: ColorChoice::Auto,
            alpha: AlphaChoice::Auto,
            out_type: None,
            tile: (64, 64),
            compression: ExrCompression::default(),
            load: LoadOptions::default(),
            limits: Limits::default(),
            update: false,
            dry_run: false,
            roughness: None,
            compress: None,
            supercompression: None,
            resize_to: None,
            measure_blocks: false,
        }
    }
}

/// One job: an input (a file or a `builtin:` name) and where it goes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Job {
    /// The input.
    pub input: String,
    /// The output path (a `{level}` template for PNG levels).
    pub output: PathBuf,
    /// The output container.
    pub kind: OutputKind,
}

impl Job {
    /// A job writing `output`, its container from the extension.
    pub fn new(input: &str, output: &Path) -> Result<Job> {
        Ok(Job {
            input: input.to_string(),
            output: output.to_path_buf(),
            kind: OutputKind::from_path(output)?,
        })
    }

    /// A batch into `dir`: each input's file stem (a `builtin:` name with
    /// `:` as `-`) with the extension's suffix.
    pub fn batch(inputs: &[String], dir: &Path, kind: OutputKind) -> Vec<Job> {
        inputs
            .iter()
            .map(|input| {
                let stem = if crate::builtin::is_builtin(input) {
                    input.replace(':', "-")
                } else {
                    Path::new(input)
                        .file_stem()
                        .map(|s| s.to_string_lossy().into_owned())
                        .unwrap_or_else(|| "output".into())
                };
                Job {
                    input: input.clone(),
                    output: kind.batch_path(dir, &stem),
                    kind,
                }
            })
            .collect()
    }
}

/// The inputs of a batch with every directory replaced by the image files
/// in it (not its subdirectories; hidden files skipped; by name, so the
/// order does not depend on the file system), files and `builtin:` names
/// kept as given. A directory holding no image is an error, as is one
/// that cannot be listed.
pub fn expand_inputs(inputs: &[String]) -> Result<Vec<String>> {
    let mut out = Vec::with_capacity(inputs.len());
    for input in inputs {
        let path = Path::new(input);
        if crate::builtin::is_builtin(input) || !path.is_dir() {
            out.push(input.clone());
            continue;
        }
        let io_err = |e| Error::Io {
            path: path.to_path_buf(),
            action: "cannot list the directory".into(),
            error: e,
        };
        let mut found = Vec::new();
        for entry in std::fs::read_dir(path).map_err(io_err)? {
            let p = entry.map_err(io_err)?.path();
            let name = p.file_name().map(|n| n.to_string_lossy().into_owned());
            let image = p.extension().is_some_and(|e| {
                io::container::read_extensions()
                    .any(|x| e.to_string_lossy().eq_ignore_ascii_case(x))
            });
            if image && p.is_file() && !name.is_some_and(|n| n.starts_with('.')) {
                found.push(p.to_string_lossy().into_owned());
            }
        }
        if found.is_empty() {
            return Err(Error::InvalidOption(format!(
                "directory {input} holds no image parvo reads (.{})",
                io::container::read_extensions()
                    .collect::<Vec<_>>()
                    .join(", .")
            )));
        }
        found.sort();
        out.extend(found);
    }
    Ok(out)
}

/// The checks that need no input read: option ranges, a channel type the
/// container cannot store, round-up sizes where the container fixes them.
/// The command line reports these as usage errors.
pub fn check(jobs: &[Job], s: &Settings) -> Result<()> {
    let bad = |m: String| Err(Error::InvalidOption(m));
    if s.levels == Some(0) {
        return bad("--levels must be at least 1".into());
    }
    if let Some(r) = s.alpha_coverage
        && !(r > 0.0 && r < 1.0)
    {
        return bad(format!("--alpha-coverage {r}: must be between 0 and 1"));
    }
    if let Some(t) = s.out_type
        && let Some(j) = jobs.iter().find(|j| !j.kind.supports(t))
    {
        return bad(format!(
            "--type {t}: {} cannot store {t} texels (EXR: f16, f32; PNG: u8, u16; KTX2 and DDS: all)",
            j.kind.name()
        ));
    }
    if let Some(r) = &s.roughness {
        if !s.normal_map {
            return bad("a roughness chain is made from a normal map: add --normal-map".into());
        }
        if jobs.len() > 1 && r.output.is_some() {
            return bad("--roughness-out names one file: use it with -o (one input)".into());
        }
        if r.pack_alpha && r.output.is_some() {
            return bad(
                "--pack-roughness stores the roughness in the normal output: drop --roughness-out"
                    .into(),
            );
        }
        if !r.pack_alpha && r.output.is_none() {
            return bad("give --roughness-out FILE or --pack-roughness A for the roughness".into());
        }
        if let RoughnessSource::Constant(a) = r.base
            && !(0.0..=1.0).contains(&a)
        {
            return bad(format!("--roughness {a}: must be from 0 to 1"));
        }
        if s.alpha_coverage.is_some() {
            return bad("--alpha-coverage does not apply to normal maps".into());
        }
        // Exponents are not unorm values.
        if let Specular::BlinnPhong(_) = r.specular {
            let float = |kind: OutputKind| match s.out_type {
                Some(t) => t.is_float() && kind.supports(t),
                // A container whose own default is float, even for an
                // 8-bit source.
                None => kind.default_type(ChannelType::U8).is_float(),
            };
            let kinds: Vec<OutputKind> = match &r.output {
                Some((_, k)) => vec![*k],
                None => jobs.iter().map(|j| j.kind).collect(),
            };
            if kinds.iter().any(|&k| !float(k)) {
                return bad(
                    "--specular blinn-phong writes exponents above 1: the chain needs a float \
                     output (.exr, or --type f16/f32 with .ktx2/.dds)"
                        .into(),
                );
            }
        }
    }
    if let Some((bf, _)) = s.compress {
        if !cfg!(feature = "encode") {
            return bad(format!(
                "--compress {}: this parvo was built without the `encode` feature (the block encoders)",
                bf.name().to_ascii_lowercase()
            ));
        }
        if !crate::compress::can_encode(bf) {
            return bad(format!("parvo does not encode {bf}"));
        }
        if let Some(j) = jobs.iter().find(|j| !j.kind.stores().blocks) {
            return bad(format!(
                "--compress: {} cannot store block-compressed texels; use .ktx2 or .dds (output {})",
                j.kind.name(),
                j.output.display()
            ));
        }
        if let Some(t) = s.out_type {
            return bad(format!(
                "--type {t} with --compress: the block format fixes what is stored"
            ));
        }
        if s.roughness.is_some() {
            return bad(
                "--compress with --roughness is not supported yet: compress the normal and \
                 roughness chains in two runs"
                    .into(),
            );
        }
    }
    if let Some(sc) = s.supercompression {
        let (lo, hi) = match sc {
            Supercompression::Zstd(_) => (1, 22),
            Supercompression::Zlib(_) => (1, 12),
        };
        let (Supercompression::Zstd(l) | Supercompression::Zlib(l)) = sc;
        if !(lo..=hi).contains(&l) {
            return bad(format!(
                "--{} {l}: the level must be from {lo} to {hi}",
                sc.name()
            ));
        }
        if let Some(j) = jobs.iter().find(|j| !j.kind.stores().supercompression) {
            return bad(format!(
                "--{}: supercompression is a KTX2 feature; output {} is {}",
                sc.name(),
                j.output.display(),
                j.kind.name()
            ));
        }
    }
    if s.resize_to.is_some() && s.normal_map {
        return bad(
            "--resize-to with --normal-map is not supported: resize the normal map first".into(),
        );
    }
    let rough_out = s
        .roughness
        .as_ref()
        .and_then(|r| r.output.clone())
        .map(|(output, kind)| Job {
            input: String::new(),
            output,
            kind,
        });
    if s.rounding == Rounding::Up
        && let Some(j) = jobs
            .iter()
            .chain(&rough_out)
            .find(|j| !j.kind.stores().round_up)
    {
        return bad(format!(
            "--rounding up: {} defines its level sizes as floor(size / 2^k); \
             use .exr or PNG levels for rounded-up chains (output {})",
            j.kind.name(),
            j.output.display()
        ));
    }
    Ok(())
}

/// What happened to one job.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    /// The output was written.
    Written,
    /// The output already stores this run's fingerprint.
    UpToDate,
    /// A dry run: nothing was built or written.
    DryRun,
}

impl Status {
    /// The name reports use (`written`, `up to date`, `dry run`).
    pub fn name(&self) -> &'static str {
        match self {
            Status::Written => "written",
            Status::UpToDate => "up to date",
            Status::DryRun => "dry run",
        }
    }
}

/// The result of one job.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// Where it went.
    pub output: PathBuf,
    /// What happened.
    pub status: Status,
    /// Level 0's size.
    pub width: u32,
    /// Level 0's size.
    pub height: u32,
    /// The output texel format.
    pub format: Format,
    /// Every level's size.
    pub level_sizes: Vec<(u32, u32)>,
    /// Seconds reading the input.
    pub read_s: f64,
    /// Seconds building the chain.
    pub build_s: f64,
    /// Seconds writing the output.
    pub write_s: f64,
    /// What the loader or the build did that the user would not assume.
    pub notes: Vec<String>,
    /// Block compression figures, when this run encoded blocks.
    pub blocks: Option<BlockReport>,
    /// The block format the output holds (`BC7_SRGB`, ...) when it is
    /// block-compressed, also when this run encoded nothing (`--update`,
    /// a dry run).
    pub block_format: Option<String>,
}

/// Progress of one job.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// The build starts: this many texels of levels above 0 to make.
    Building {
        /// Texels of all levels above 0.
        total_texels: u64,
    },
    /// Texels made so far.
    Built {
        /// Texels of levels above 0 made so far.
        texels_done: u64,
    },
    /// Block compression starts: this many texels (all levels) to encode.
    Encoding {
        /// Texels of all levels.
        total_texels: u64,
    },
    /// Texels encoded so far.
    Encoded {
        /// Texels encoded so far.
        texels_done: u64,
    },
    /// The output is being written.
    Writing,
}

/// The output texel format for a source format, container and settings.
pub fn output_format(src: Format, kind: OutputKind, s: &Settings) -> Result<Format> {
    let ty = match s.out_type {
        Some(t) => t,
        None => kind.default_type(src.channel_type),
    };
    if !kind.supports(ty) {
        return Err(Error::InvalidOption(format!(
            "{} cannot store {ty} texels (EXR: f16, f32; PNG: u8, u16)",
            kind.name()
        )));
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
    let alpha = match kind.stores().alpha {
        Some(a) if src.has_alpha() => a,
        _ => src.alpha,
    };
    Ok(kind.storable(Format::new(src.channels, ty, cs).with_alpha(alpha)))
}

/// The text the fingerprint hashes beside level 0: every setting that
/// changes the output's bytes.
pub fn fingerprint_text(s: &Settings, opts: &MipOptions, out: &Format, kind: OutputKind) -> String {
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
        s.tile.0,
        s.tile.1,
        s.compression,
    ) + &format!(
        " compress={:?} supercompression={:?} resize={:?}",
        s.compress, s.supercompression, s.resize_to
    ) + &match &s.roughness {
        Some(r) => format!(
            " roughness={:?} channels={:?} specular={:?} pack={} rough_out={:?}",
            r.base, r.channels, r.specular, r.pack_alpha, r.output
        ),
        None => String::new(),
    }
}

/// Runs one job (see the module docs), reporting progress to `progress`
/// on the calling thread.
pub fn process(job: &Job, s: &Settings, progress: &mut dyn FnMut(Stage)) -> Result<Outcome> {
    let t_read = Instant::now();
    // Levels 1.. of a fused box write, faulted in on the core the decoder
    // leaves idle (`prefault_streamed`).
    let mut prepared = None;
    let loaded = io::load_overlapped(
        &job.input,
        &s.limits,
        &s.load,
        Some(&mut |w, h, ch, ty| prepared = prefault_streamed(job, s, w, h, ch, ty)),
    )?;
    let src_kind = loaded.info.format;
    let file_wrap = loaded.info.wrap;
    let mut notes = loaded.info.notes.clone();
    // Said once per file, whatever the output (a 16-bit grey height map
    // read as sRGB changes every value of a linear output).
    if s.color == ColorChoice::Auto && !s.normal_map {
        notes.extend(io::assumed_color_note(
            &loaded.info,
            &loaded.base().format(),
        ));
    }
    let channel_names = loaded.info.channel_names.clone();
    let mut base = loaded.into_base();
    // Interpretation of the input.
    let mut src = base.format();
    src.color_space = match (s.color, s.normal_map) {
        (ColorChoice::Linear, _) | (ColorChoice::Auto, true) => ColorSpace::Linear,
        (ColorChoice::Srgb, _) => ColorSpace::Srgb,
        // The loader's reading of the file (see io::load).
        (ColorChoice::Auto, false) => src.color_space,
    };
    src.alpha = match s.alpha {
        // A normal map's fourth channel is data, not alpha.
        _ if s.normal_map => AlphaMode::None,
        AlphaChoice::Auto => src.alpha,
        AlphaChoice::Straight => AlphaMode::Straight,
        AlphaChoice::Premultiplied => AlphaMode::Premultiplied,
        AlphaChoice::None => AlphaMode::None,
    };
    base = base.reinterpret(src)?;
    let read_s = t_read.elapsed().as_secs_f64();
    if let Some(r) = s.resize_to {
        let (w, h) = (base.width(), base.height());
        let (nw, nh) = r.apply(w, h);
        if (nw, nh) != (w, h) {
            s.limits.check(nw as u64, nh as u64, 0)?;
            let opts = MipOptions {
                filter: s.filter,
                wrap: s.wrap.or(file_wrap).unwrap_or_default(),
                ..MipOptions::default()
            };
            base = mip::separable::reduce(&base, nw, nh, &opts)?.0;
            notes.push(format!(
                "resized {w}x{h} to {nw}x{nh} ({} filter) for --resize-to",
                s.filter
            ));
        }
    }

    let out_format = match &s.roughness {
        // The normal output holds the vectors (and, packed, the roughness
        // in alpha): three or four channels whatever the source has.
        Some(r) => {
            if r.pack_alpha && src.channels == 4 {
                return Err(Error::InvalidOption(
                    "the normal map has a fourth channel; --pack-roughness would overwrite it \
                     (write the roughness with --roughness-out instead)"
                        .into(),
                ));
            }
            let n = if r.pack_alpha { 4 } else { 3 };
            let f =
                Format::new(n, src.channel_type, ColorSpace::Linear).with_alpha(AlphaMode::None);
            output_format(f, job.kind, s)?
        }
        None => match s.compress {
            // Built in the type the encoder reads (u8, or f16 for BC6H),
            // then shaped into its input format per level.
            Some((bf, _)) => {
                let ty = crate::compress::input_format(bf, src.color_space, None).channel_type;
                let typed = Settings {
                    out_type: Some(ty),
                    ..s.clone()
                };
                output_format(src, job.kind, &typed)?
            }
            None => output_format(src, job.kind, s)?,
        },
    };
    let options = MipOptions {
        filter: s.filter,
        wrap: s.wrap.or(file_wrap).unwrap_or_default(),
        rounding: s.rounding,
        max_levels: s.levels,
        alpha_coverage: s.alpha_coverage,
        alpha_store: Some(out_format.channel_type),
        normal_map: s.normal_map,
        nan_policy: s.nan_policy,
        fast_paths: true,
    };
    if job.kind.stores().whole_chain {
        let full = mip::level_count(base.width(), base.height(), s.rounding, None);
        if s.levels.is_some_and(|n| n < full) {
            return Err(Error::InvalidOption(format!(
                "a mip-mapped OpenEXR file holds the full chain ({full} levels); --levels applies to .ktx2, .dds and PNG"
            )));
        }
    }
    let level_sizes = mip::level_sizes(base.width(), base.height(), s.rounding, s.levels);
    let (width, height) = (base.width(), base.height());
    let fingerprint = io::fingerprint(&base, &fingerprint_text(s, &options, &out_format, job.kind));
    let block_format = s.compress.map(|(bf, _)| block_label(bf, out_format));
    let skipped = |status| Outcome {
        output: job.output.clone(),
        status,
        width,
        height,
        format: out_format,
        level_sizes: level_sizes.clone(),
        read_s,
        build_s: 0.0,
        write_s: 0.0,
        notes: notes.clone(),
        blocks: None,
        block_format: block_format.clone(),
    };
    if s.dry_run {
        return Ok(skipped(Status::DryRun));
    }
    let stored =
        |p: &Path, k| io::stored_fingerprint(p, k).as_deref() == Some(fingerprint.as_str());
    if s.update
        && stored(&job.output, job.kind)
        && s.roughness
            .as_ref()
            .and_then(|r| r.output.as_ref())
            .is_none_or(|(p, k)| stored(p, *k))
    {
        return Ok(skipped(Status::UpToDate));
    }

    let save = SaveOptions {
        // An EXR source's channel names carry to EXR output (N.X stays
        // N.X, a lone Z stays Z); other sources get the layout's names.
        channel_names: (src_kind == FileFormat::Exr
            && channel_names.len() == out_format.channels as usize)
            .then_some(channel_names),
        wrap: options.wrap,
        tile: s.tile,
        compression: s.compression,
        fingerprint: Some(fingerprint),
        supercompression: s.supercompression,
        attributes: vec![
            ("parvo:filter".into(), s.filter.to_string()),
            ("parvo:source".into(), src.to_string()),
            ("parvo:rounding".into(), s.rounding.to_string()),
        ],
    };

    let t_build = Instant::now();
    let total_texels: u64 = level_sizes[1..]
        .iter()
        .map(|&(w, h)| w as u64 * h as u64)
        .sum();
    progress(Stage::Building { total_texels });
    let mut on_progress = |p: mip::Progress| {
        progress(Stage::Built {
            texels_done: p.texels_done,
        })
    };
    let association =
        (out_format.has_alpha() && src.alpha != out_format.alpha).then_some(out_format.alpha);
    // Alpha coverage is matched on the unrounded filtered alpha (rounding
    // each level to 8 bits first would tie texels the test must separate),
    // so it always builds in f32.
    let same = src.channel_type == out_format.channel_type
        && src.color_space == out_format.color_space
        && association.is_none()
        && s.alpha_coverage.is_none();
    // A band-by-band colour chain to EXR never holds level 0 in the
    // output type: each group of its rows is built, compressed and written
    // (`io::exr::save_streamed`), so level 0's output buffer is neither
    // allocated nor faulted in.
    let base = if job.kind.stores().streamed_level0
        && s.compress.is_none()
        && s.roughness.is_none()
        && !s.normal_map
        && !same
    {
        match Builder::new(base, &options, src, out_format, association, prepared)? {
            Ok(st) => match fused_group(st.band(), s.tile.1 as usize) {
                Some(group) => {
                    let mut source = Fused {
                        st: Some(st),
                        group,
                        build: std::time::Duration::ZERO,
                        progress,
                    };
                    io::exr::save_streamed(
                        width,
                        height,
                        out_format,
                        s.rounding,
                        &job.output,
                        &save,
                        &mut source,
                    )?;
                    let build_s = source.build.as_secs_f64();
                    return Ok(Outcome {
                        output: job.output.clone(),
                        status: Status::Written,
                        width,
                        height,
                        format: out_format,
                        level_sizes,
                        read_s,
                        build_s,
                        write_s: (t_build.elapsed().as_secs_f64() - build_s).max(0.0),
                        notes,
                        blocks: None,
                        block_format: None,
                    });
                }
                None => st.into_base(),
            },
            Err(base) => base,
        }
    } else {
        base
    };
    let mut rough_levels = None;
    let levels = if let Some(r) = &s.roughness {
        let (normals, chain) =
            build_roughness(&base, r, s, &options, out_format, &mut on_progress)?;
        rough_levels = chain;
        normals
    } else if s.normal_map {
        // Decoded to vectors, averaged in f32, encoded once per level into
        // the output type (crate::mip::normal).
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
    let blocks = match s.compress {
        Some((bf, quality)) => {
            notes.extend(compress_notes(bf, src, &level_sizes));
            Some(encode_chain(
                &levels,
                bf,
                quality,
                s.measure_blocks,
                progress,
            )?)
        }
        None => None,
    };
    progress(Stage::Writing);

    let t_write = Instant::now();
    match &blocks {
        Some((chain, _)) => io::save_blocks(chain, &job.output, job.kind, &save)?,
        None => io::save(&levels, s.rounding, &job.output, job.kind, &save)?,
    }
    if let (Some(levels), Some(r)) = (rough_levels, &s.roughness)
        && let Some((path, kind)) = &r.output
    {
        let rs = SaveOptions {
            channel_names: kind.stores().channel_names.then(|| vec!["Y".to_string()]),
            ..save.clone()
        };
        io::save(&levels, s.rounding, path, *kind, &rs)?;
    }
    if job.kind.stores().file_per_level {
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
        blocks: blocks.map(|(_, r)| r),
        block_format,
    })
}

/// The name of the block format `bf` stores levels of format `f` in
/// (`BC7_SRGB` for sRGB colour, as the KTX2 and DDS formats name it).
pub fn block_label(bf: BlockFormat, f: Format) -> String {
    let alpha = f.has_alpha().then_some(f.alpha);
    let want = crate::compress::input_format(bf, f.color_space, alpha);
    let srgb = want.color_space == ColorSpace::Srgb;
    format!("{bf}{}", if srgb { "_SRGB" } else { "" })
}

/// The first level WebGL refuses to take as a block-compressed level:
/// WEBGL_compressed_texture_s3tc (revision 6, as its RGTC and BPTC
/// siblings) requires `width << level` and `height << level` to be
/// multiples of 4 — level 0's sides multiples of 4, level 1's even, any
/// later level (earlier revisions asked every level for 1, 2 or a multiple
/// of 4, which rejected the level 1 of a 1004-texel level 0).
fn webgl_misfit(sizes: &[(u32, u32)]) -> Option<(usize, (u32, u32))> {
    let ok = |n: u32, k: usize| k >= 2 || (n << k).is_multiple_of(4);
    sizes
        .iter()
        .enumerate()
        .find(|&(k, &(w, h))| !ok(w, k) || !ok(h, k))
        .map(|(k, &s)| (k, s))
}

/// What a block format does to this source that the user should hear of:
/// channels it drops or changes, and levels WebGL refuses ([`webgl_misfit`]).
fn compress_notes(bf: BlockFormat, src: Format, sizes: &[(u32, u32)]) -> Vec<String> {
    let mut notes = Vec::new();
    let ch = src.channels;
    match bf {
        BlockFormat::Bc4 { .. } if ch > 1 => notes.push(format!(
            "BC4 stores one channel: the first of the input's {ch} is kept"
        )),
        BlockFormat::Bc5 { .. } if ch > 2 => notes.push(format!(
            "BC5 stores two channels: the first two of the input's {ch} are kept (normal maps: \
             readers rebuild z as sqrt(1 - x^2 - y^2))"
        )),
        BlockFormat::Bc6h { .. } if src.has_alpha() => {
            notes.push("BC6H stores RGB: the alpha channel is dropped".into())
        }
        _ => {}
    }
    if matches!(bf, BlockFormat::Bc4 { .. } | BlockFormat::Bc5 { .. })
        && src.color_space == ColorSpace::Srgb
    {
        notes.push(format!(
            "{bf} has no sRGB variant: the sRGB values are stored decoded to linear"
        ));
    }
    if matches!(bf, BlockFormat::Bc6h { .. }) && !src.channel_type.is_float() {
        notes.push("BC6H is an HDR format; this input is not float (bc7 stores 8-bit colour in the same size)".into());
    }
    if let Some((k, (w, h))) = webgl_misfit(sizes) {
        notes.push(format!(
            "level {k} is {w}x{h}: WebGL refuses block-compressed levels unless level 0's sides are \
             multiples of 4 (and level k's sides times 2^k are); --resize-to multiple-of-4 makes \
             them so"
        ));
    }
    notes
}

/// Encode every level as `bf` blocks: levels (and bands of large levels)
/// on all threads, progress reported from the calling thread; with
/// `measure`, each level decoded again (by `bcdec_rs`, independent of the
/// encoders) and scored against the uncompressed level.
fn encode_chain(
    levels: &[Texture],
    bf: BlockFormat,
    quality: Quality,
    measure: bool,
    progress: &mut dyn FnMut(Stage),
) -> Result<(BlockChain, BlockReport)> {
    #[cfg(not(feature = "encode"))]
    {
        let _ = (levels, quality, measure, progress);
        Err(Error::InvalidOption(format!(
            "{bf}: this parvo was built without the `encode` feature"
        )))
    }
    #[cfg(feature = "encode")]
    {
        use std::sync::atomic::{AtomicU64, Ordering};
        let first = levels
            .first()
            .ok_or_else(|| Error::InvalidOption("nothing to encode: no levels".into()))?;
        let f0 = first.format();
        let alpha = f0.has_alpha().then_some(f0.alpha);
        let want = crate::compress::input_format(bf, f0.color_space, alpha);
        let total: u64 = levels.iter().map(|l| l.texel_count() as u64).sum();
        progress(Stage::Encoding {
            total_texels: total,
        });
        let done = AtomicU64::new(0);
        let t0 = Instant::now();
        // Progress is polled from this thread while the pool encodes; a
        // job of a batch (on a pool thread) encodes in place instead
        // (crate::par: a pool thread that slept here hung the batch).
        let result = crate::par::polled(
            || {
                levels
                    .par_iter()
                    .map(|l| -> Result<(Vec<u8>, BlockLevel)> {
                        let t = Instant::now();
                        let input = crate::compress::prepare(l, bf, want)?;
                        let data = crate::compress::encode::encode(bf, quality, &input)?;
                        let encode_s = t.elapsed().as_secs_f64();
                        done.fetch_add(l.texel_count() as u64, Ordering::Relaxed);
                        Ok((
                            data,
                            BlockLevel {
                                width: l.width(),
                                height: l.height(),
                                bytes: 0,
                                encode_s,
                                psnr_db: None,
                            },
                        ))
                    })
                    .collect::<Result<Vec<_>>>()
            },
            std::time::Duration::from_millis(50),
            || {
                progress(Stage::Encoded {
                    texels_done: done.load(Ordering::Relaxed),
                })
            },
        )?;
        progress(Stage::Encoded { texels_done: total });
        let encode_s = t0.elapsed().as_secs_f64();
        let mut data = Vec::with_capacity(result.len());
        let mut report_levels = Vec::with_capacity(result.len());
        for (d, mut lv) in result {
            lv.bytes = d.len() as u64;
            data.push(d);
            report_levels.push(lv);
        }
        if measure {
            // After the encode, so the encode times do not include it.
            let ch = match bf {
                BlockFormat::Bc4 { .. } => 1,
                BlockFormat::Bc5 { .. } => 2,
                BlockFormat::Bc6h { .. } => 3,
                _ if want.alpha == AlphaMode::None => 3,
                _ => 4,
            };
            let scores = levels
                .par_iter()
                .zip(&data)
                .map(|(l, d)| {
                    let input = crate::compress::prepare(l, bf, want)?;
                    let dec = crate::compress::decode(
                        bf,
                        want.color_space == ColorSpace::Srgb,
                        want.alpha,
                        l.width(),
                        l.height(),
                        d,
                    )?;
                    crate::compress::psnr(&input, &dec, ch)
                })
                .collect::<Result<Vec<_>>>()?;
            for (lv, p) in report_levels.iter_mut().zip(scores) {
                lv.psnr_db = Some(p);
            }
        }
        let srgb = want.color_space == ColorSpace::Srgb;
        let chain = BlockChain {
            format: bf,
            srgb,
            alpha: want.alpha,
            width: first.width(),
            height: first.height(),
            levels: data,
        };
        let stored = block_label(bf, f0);
        Ok((
            chain,
            BlockReport {
                stored,
                quality,
                levels: report_levels,
                uncompressed_bytes: levels.iter().map(|l| l.byte_len() as u64).sum(),
                encode_s,
            },
        ))
    }
}

/// Runs `jobs`: in parallel when there is more than one, each job's result
/// handed to `done` as it finishes (from any thread). A panic in a job is
/// its error (`internal error: …`); a job whose output is another job's is
/// refused. A single job reports its progress to `progress`.
pub fn run(
    jobs: &[Job],
    s: &Settings,
    progress: &mut (dyn FnMut(Stage) + Send),
    done: &(dyn Fn(&Job, Result<Outcome>) + Sync),
) {
    // Two inputs with the same output name would overwrite each other.
    let mut seen = std::collections::HashMap::new();
    let dup: Vec<Option<String>> = jobs
        .iter()
        .map(|j| seen.insert(j.output.clone(), j.input.clone()))
        .collect();
    let one = |job: &Job, dup: &Option<String>, progress: &mut dyn FnMut(Stage)| {
        let r = match dup {
            Some(first) => Err(Error::InvalidOption(format!(
                "output {} is also the output of {first}",
                job.output.display()
            ))),
            None => {
                std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| process(job, s, progress)))
                    .unwrap_or_else(|p| {
                        Err(Error::InvalidOption(format!(
                            "internal error: {}",
                            io::atomic::panic_message(&*p)
                        )))
                    })
            }
        };
        done(job, r);
    };
    if jobs.len() > 1 {
        jobs.par_iter()
            .zip(dup.par_iter())
            .for_each(|(j, d)| one(j, d, &mut |_| {}));
    } else {
        for (j, d) in jobs.iter().zip(&dup) {
            one(j, d, progress);
        }
    }
}

/// The normal chain (encoded as `out`) and, unless packed into its
/// alpha, the roughness chain encoded for its own output.
fn build_roughness(
    base: &Texture,
    r: &RoughnessSettings,
    s: &Settings,
    options: &MipOptions,
    out: Format,
    progress: &mut dyn FnMut(mip::Progress),
) -> Result<(Vec<Texture>, Option<Vec<Texture>>)> {
    let map;
    let base_rough = match &r.base {
        RoughnessSource::Constant(a) => BaseRoughness::Constant(*a),
        RoughnessSource::Map(name) => {
            map = io::load_with(name, &s.limits, &s.load)?.into_base();
            BaseRoughness::Map(&map)
        }
    };
    let opts = MipOptions {
        normal_map: false,
        alpha_store: None,
        ..*options
    };
    let chain = mip::roughness::build(base, r.channels, base_rough, r.specular, &opts, progress)?;
    let narrow = |f: Format, ch: u8| Format {
        channels: ch,
        alpha: AlphaMode::None,
        ..f
    };
    let mut normals = Vec::with_capacity(chain.normals.len());
    for (n, sp) in chain.normals.iter().zip(&chain.specular) {
        let v = if r.pack_alpha {
            let (Texels::F32(nv), Texels::F32(sv)) = (n.texels(), sp.texels()) else {
                return Err(Error::InvalidOption("roughness chains are f32".into()));
            };
            let packed: Vec<f32> = nv
                .chunks_exact(3)
                .zip(sv)
                .flat_map(|(n, a)| [n[0], n[1], n[2], *a])
                .collect();
            let f =
                Format::new(4, ChannelType::F32, ColorSpace::Linear).with_alpha(AlphaMode::None);
            Texture::from_f32(n.width(), n.height(), f, packed)?
        } else {
            n.clone()
        };
        let ch = v.format().channels;
        let enc = mip::normal::encode(&v, narrow(out, ch))?;
        normals.push(if out.channels != ch {
            enc.expand_channels(out.channels)?
        } else {
            enc
        });
    }
    let rough = match &r.output {
        None => None,
        Some((_, kind)) => {
            let ty = match s.out_type {
                Some(t) if kind.supports(t) => t,
                _ => kind.data_type(out.channel_type),
            };
            let f =
                kind.storable(Format::new(1, ty, ColorSpace::Linear).with_alpha(AlphaMode::None));
            Some(
                chain
                    .specular
                    .into_iter()
                    .map(|l| convert_level(l, f))
                    .collect::<Result<Vec<_>>>()?,
            )
        }
    };
    Ok((normals, rough))
}

/// The colour chain: built in the source format when it is the output
/// format, else in linear f32 from a single decode of level 0 (see the
/// module docs), each level converted to the output format; with a note
/// when float values were clipped to a normalised output.
fn build_colour(
    base: Texture,
    options: &MipOptions,
    src: Format,
    out_format: Format,
    association: Option<AlphaMode>,
    same: bool,
    progress: &mut dyn FnMut(mip::Progress),
) -> Result<(Vec<Texture>, Option<String>)> {
    let base = if same {
        base
    } else {
        match Builder::new(base, options, src, out_format, association, None)? {
            Ok(b) => return Ok((b.build_all(progress)?, None)),
            Err(base) => base,
        }
    };
    let work_base = if same {
        base
    } else {
        // Decode straight into the f32 buffer (`Texture::convert` would
        // hold a second full-size f32 copy while encoding).
        let f =
            Format::new(src.channels, ChannelType::F32, ColorSpace::Linear).with_alpha(src.alpha);
        let mut linear = vec![0f32; base.texels().len()];
        crate::texel::decode_to_linear(&base.format(), base.texels(), &mut linear);
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

/// Most levels [`Streamer`] makes band by band (bands of up to
/// 2^4 = 16 level-0 rows: a band of 16384-wide RGBA f32 is 4 MiB).
const STREAM_LEVELS: u32 = 4;

/// Level-0 rows per group of a fused EXR write: a multiple of both the
/// band height and the tile height, and at least 4 bands so that the
/// threads share each group (`None` past 256 rows: odd tile heights).
fn fused_group(band: usize, tile_h: usize) -> Option<usize> {
    if band == 0 || tile_h == 0 {
        return None;
    }
    let gcd = |mut a: usize, mut b: usize| {
        while b != 0 {
            (a, b) = (b, a % b);
        }
        a
    };
    let mut group = band / gcd(band, tile_h) * tile_h;
    while group < 4 * band {
        group *= 2;
    }
    (group <= 256).then_some(group)
}

/// The buffers of levels 1..=m of a fused box write to EXR ([`Streamer`]
/// under [`Fused`]) for a `w`×`h` source of `ch` channels of `ty`,
/// allocated and faulted in: called from [`io::load_overlapped`] on the
/// core a single-threaded decoder leaves idle, it takes the OS's clearing
/// of fresh pages off the build (0.67 GiB of half at 16384² RGBA, about
/// 1.3 s of first touches on the project's VM, some 0.7 s of the build's
/// wall time on two threads). `None` where that path will not run; the
/// buffers are checked again before use.
fn prefault_streamed(
    job: &Job,
    s: &Settings,
    w: u32,
    h: u32,
    ch: u8,
    ty: ChannelType,
) -> Option<Vec<Texels>> {
    // (A dry run builds nothing: no buffers to make.)
    let fused = job.kind.stores().streamed_level0
        && !s.dry_run
        && s.compress.is_none()
        && s.roughness.is_none()
        && !s.normal_map
        && s.resize_to.is_none();
    let out = output_format(Format::new(ch, ty, ColorSpace::Linear), job.kind, s).ok()?;
    let options = MipOptions {
        filter: s.filter,
        rounding: s.rounding,
        max_levels: s.levels,
        alpha_coverage: s.alpha_coverage,
        normal_map: s.normal_map,
        ..MipOptions::default()
    };
    let (sizes, m) = Streamer::plan(w, h, &options)?;
    // A source already in the output type is built without bands.
    if !fused || out.channel_type == ty || fused_group(1 << m, s.tile.1 as usize).is_none() {
        return None;
    }
    let mut bufs = Streamer::level_buffers(&sizes, m, out);
    for b in &mut bufs {
        let bytes = b.bytes_mut();
        crate::mem::populate(bytes.as_ptr(), bytes.len());
    }
    Some(bufs)
}

/// Progress through a chain of `sizes`, counting the texels of levels
/// above 0.
fn chain_progress(sizes: &[(u32, u32)], levels_done: u32, texels_done: u64) -> mip::Progress {
    mip::Progress {
        levels_done,
        levels_total: sizes.len() as u32,
        texels_done,
        texels_total: sizes[1..].iter().map(|&(w, h)| w as u64 * h as u64).sum(),
    }
}

/// The chain from `level` (level `first` of a chain of `sizes`, in linear
/// f32) down, built as the whole-level build does, `level` first;
/// progress counts on from `done` texels of levels 1..=`first`.
fn rest_of_chain(
    level: Texture,
    first: usize,
    sizes: &[(u32, u32)],
    options: &MipOptions,
    done: u64,
    progress: &mut dyn FnMut(mip::Progress),
) -> Result<Vec<Texture>> {
    progress(chain_progress(sizes, first as u32 + 1, done));
    let rest_options = MipOptions {
        max_levels: Some((sizes.len() - first) as u32),
        ..*options
    };
    let chain = mip::build_with_progress(level, &rest_options, &mut |q| {
        progress(chain_progress(
            sizes,
            q.levels_done + first as u32,
            done + q.texels_done,
        ))
    })?;
    Ok(chain.into_levels())
}

/// A band-by-band builder: the box shortcut or the general one.
enum Builder<'a> {
    Stream(Streamer<'a>),
    Band(Banded<'a>),
}

impl<'a> Builder<'a> {
    /// The box shortcut where it applies, else the general build;
    /// `Err(base)` when neither does.
    /// `prepared`: the box shortcut's levels 1..=m, if made beforehand
    /// ([`prefault_streamed`]).
    fn new(
        base: Texture,
        options: &'a MipOptions,
        src: Format,
        out_format: Format,
        association: Option<AlphaMode>,
        prepared: Option<Vec<Texels>>,
    ) -> Result<std::result::Result<Self, Texture>> {
        Ok(
            match Streamer::new(base, options, src, out_format, association, prepared)? {
                Ok(st) => Ok(Builder::Stream(st)),
                Err(base) => {
                    Banded::new(base, options, src, out_format, association).map(Builder::Band)
                }
            },
        )
    }

    /// The whole chain, level 0 into one buffer.
    fn build_all(mut self, progress: &mut dyn FnMut(mip::Progress)) -> Result<Vec<Texture>> {
        let (base, out_format, sizes) = match &self {
            Builder::Stream(st) => (&st.base, st.out_format, &st.sizes),
            Builder::Band(bd) => (&bd.base, bd.out_format, &bd.sizes),
        };
        progress(chain_progress(sizes, 1, 0));
        let (w, h) = (base.width(), base.height());
        // Level 0 as little-endian bytes written in place by the bands on
        // all threads (zero pages from the OS: no zeroing pass).
        let n = w as usize * h as usize * out_format.channels as usize;
        let mut out0 = Texels::zeroed(out_format.channel_type, n);
        match &mut self {
            Builder::Stream(st) => st.rows(0, out0.bytes_mut())?,
            Builder::Band(bd) => bd.rows(0, out0.bytes_mut())?,
        }
        let mut levels = vec![Texture::from_texels(w, h, out_format, out0)?];
        levels.extend(self.finish(progress)?);
        Ok(levels)
    }

    /// Level-0 rows a call of `rows` must start and end on.
    fn band(&self) -> usize {
        match self {
            Builder::Stream(st) => st.band,
            Builder::Band(_) => 1,
        }
    }

    fn into_base(self) -> Texture {
        match self {
            Builder::Stream(st) => st.base,
            Builder::Band(bd) => bd.base,
        }
    }

    fn finish(self, progress: &mut dyn FnMut(mip::Progress)) -> Result<Vec<Texture>> {
        match self {
            Builder::Stream(st) => st.finish(progress),
            Builder::Band(bd) => bd.finish(progress),
        }
    }
}

/// A band-by-band builder as the level-0 source of a streamed EXR write,
/// timing the build and reporting progress.
struct Fused<'a, 'p> {
    st: Option<Builder<'a>>,
    group: usize,
    build: std::time::Duration,
    progress: &'p mut dyn FnMut(Stage),
}

impl io::exr::Level0Source for Fused<'_, '_> {
    fn group_rows(&self) -> usize {
        self.group
    }

    fn rows(&mut self, y0: usize, dst: &mut [u8]) -> Result<()> {
        let t = Instant::now();
        let st = self
            .st
            .as_mut()
            .ok_or_else(|| Error::InvalidOption("level 0 asked for after the rest".into()))?;
        let texels_done = match st {
            Builder::Stream(st) => {
                st.rows(y0, dst)?;
                let w = st.base.width() as usize;
                let y1 = (y0 + dst.len() / (w * st.out_format.texel_bytes())) as u64;
                (1..=st.m).map(|k| (w as u64 >> k) * (y1 >> k)).sum()
            }
            // Level 0 only: levels 1.. are made at the end.
            Builder::Band(bd) => {
                bd.rows(y0, dst)?;
                0
            }
        };
        self.build += t.elapsed();
        (self.progress)(Stage::Built { texels_done });
        Ok(())
    }

    fn rest(&mut self) -> Result<Vec<Texture>> {
        let t = Instant::now();
        let st = self
            .st
            .take()
            .ok_or_else(|| Error::InvalidOption("the rest of the chain asked for twice".into()))?;
        let progress = &mut *self.progress;
        let levels = st.finish(&mut |p: mip::Progress| {
            progress(Stage::Built {
                texels_done: p.texels_done,
            })
        })?;
        self.build += t.elapsed();
        (self.progress)(Stage::Writing);
        Ok(levels)
    }
}

/// A band-by-band box build ([`Builder`]): the colour chain of a source (u8, u16, or f16/f32 without NaN or
/// infinities) converted to another type, box filter, even-sized levels, without a full-resolution f32 copy
/// of any level: level 0 is cut into bands of 2^m rows (m ≤ 6 levels that
/// halve exactly: both sides divisible by 2^m, m ≤ 4), and each band, on its own
/// thread, is decoded to linear f32, reduced through levels 1..m with the
/// box row kernel of the whole-level path ([`mip::fast`]), and every
/// level's rows are alpha-associated and encoded into the output type as
/// soon as they exist. Level m's f32 rows are kept (1/4^m of level 0) and
/// the rest of the chain is built from them as before. Decoding, the row
/// kernel, association and encoding are row-local, so the chain is bit for
/// bit the whole-image one (`tests/mip_streamed.rs`).
///
/// [`Streamer::new`] hands the source back when the shortcut does not
/// apply (other filters, odd sizes, alpha coverage, float sources holding
/// NaN or infinities): [`Builder::new`] then tries [`Banded`].
/// Memory: the source, the output chain and two threads' bands (about
/// 1.4 × 16 level-0 rows of f32 each): for RGBA8 → half EXR
/// 4 + 8 × 4/3 bytes per level-0 texel (4 + 8/3 to EXR, which never holds
/// level 0: [`io::exr::save_streamed`]), where decoding level 0 whole held
/// 4 + 16 + 8 × 4/3 at the end of the build. The struct holds the source,
/// levels 1..=m in the output type (filled band by band) and level m's f32
/// rows, kept to build the rest of the chain from.
struct Streamer<'a> {
    base: Texture,
    options: &'a MipOptions,
    sizes: Vec<(u32, u32)>,
    /// Levels made band by band after level 0.
    m: usize,
    /// Level-0 rows per band (2^m).
    band: usize,
    f32fmt: Format,
    out_format: Format,
    association: Option<AlphaMode>,
    /// Levels 1..=m in the output type.
    outs: Vec<Texels>,
    /// Level m in linear f32.
    keep: Vec<f32>,
}

impl<'a> Streamer<'a> {
    /// The chain's level sizes and the levels made band by band (m), when
    /// the shortcut applies to a `w`×`h` level 0 built with `options`
    /// (whatever its texels).
    fn plan(w: u32, h: u32, options: &MipOptions) -> Option<(Vec<(u32, u32)>, usize)> {
        let sizes = mip::level_sizes(w, h, options.rounding, options.max_levels);
        let m = w
            .trailing_zeros()
            .min(h.trailing_zeros())
            .min(STREAM_LEVELS)
            .min(sizes.len() as u32 - 1) as usize;
        let applies = options.filter == MipFilter::Box
            && options.fast_paths
            && options.alpha_coverage.is_none()
            && !options.normal_map
            && m >= 1
            && (0..=m).all(|k| sizes[k] == (w >> k, h >> k));
        applies.then_some((sizes, m))
    }

    /// Zeroed buffers for levels 1..=m in `out`.
    fn level_buffers(sizes: &[(u32, u32)], m: usize, out: Format) -> Vec<Texels> {
        (1..=m)
            .map(|k| {
                let n = sizes[k].0 as usize * sizes[k].1 as usize * out.channels as usize;
                Texels::zeroed(out.channel_type, n)
            })
            .collect()
    }

    /// `Err(base)` when the shortcut does not apply. `prepared`: levels
    /// 1..=m's buffers made beforehand, used when they are what
    /// [`Self::level_buffers`] would make.
    fn new(
        base: Texture,
        options: &'a MipOptions,
        src: Format,
        out_format: Format,
        association: Option<AlphaMode>,
        prepared: Option<Vec<Texels>>,
    ) -> Result<std::result::Result<Self, Texture>> {
        let Some((sizes, m)) = Self::plan(base.width(), base.height(), options)
            .filter(|_| bandable_source(&base, out_format))
        else {
            return Ok(Err(base));
        };
        let ch = src.channels as usize;
        let outs = match prepared {
            Some(p)
                if p.len() == m
                    && p.iter().zip(1..=m).all(|(t, k)| {
                        t.channel_type() == out_format.channel_type
                            && t.len()
                                == sizes[k].0 as usize
                                    * sizes[k].1 as usize
                                    * out_format.channels as usize
                    }) =>
            {
                p
            }
            _ => Self::level_buffers(&sizes, m, out_format),
        };
        let keep = crate::mem::zeroed(sizes[m].0 as usize * sizes[m].1 as usize * ch);
        Ok(Ok(Streamer {
            base,
            options,
            sizes,
            m,
            band: 1 << m,
            f32fmt: Format::new(src.channels, ChannelType::F32, ColorSpace::Linear)
                .with_alpha(src.alpha),
            out_format,
            association,
            outs,
            keep,
        }))
    }

    /// Level-0 rows `y0 ..` (as many as `dst0` holds, a multiple of the
    /// band height from a multiple of it) encoded into `dst0` as
    /// little-endian bytes of the output type, and the rows of levels
    /// 1..=m that come from them, in parallel over bands.
    fn rows(&mut self, y0: usize, dst0: &mut [u8]) -> Result<()> {
        let Streamer {
            base,
            m,
            band: rows,
            f32fmt,
            out_format,
            association,
            outs,
            keep,
            ..
        } = self;
        let (m, rows, f32fmt, out_format, association) =
            (*m, *rows, *f32fmt, *out_format, *association);
        let w = base.width() as usize;
        let ch = f32fmt.channels as usize;
        let tb = out_format.texel_bytes();
        let per0 = rows * w * tb;
        if !y0.is_multiple_of(rows) || !dst0.len().is_multiple_of(per0) {
            return Err(Error::InvalidOption(format!(
                "level-0 rows from {y0} in {} bytes are not whole bands of {rows} rows",
                dst0.len()
            )));
        }
        let (b0, nb) = (y0 / rows, dst0.len() / per0);
        let mut lists: Vec<Vec<&mut [u8]>> = dst0.chunks_mut(per0).map(|c| vec![c]).collect();
        for (k, o) in outs.iter_mut().enumerate() {
            let per = (w >> (k + 1)) * (rows >> (k + 1)) * tb;
            let bytes = o.bytes_mut();
            for (l, c) in lists
                .iter_mut()
                .zip(bytes[b0 * per..(b0 + nb) * per].chunks_mut(per))
            {
                l.push(c);
            }
        }
        let per_keep = (w >> m) * (rows >> m) * ch;
        let kept = &mut keep[b0 * per_keep..(b0 + nb) * per_keep];
        let straight = f32fmt
            .alpha_channel()
            .filter(|_| f32fmt.alpha == AlphaMode::Straight);
        let stored = base.format();
        let texels = base.texels();
        // Per-thread scratch: level k's band rows in f32 and level k + 1's,
        // reused from band to band (fresh buffers per band cost a page
        // fault per 4 KiB each time the allocator hands memory back).
        let band_len = rows * w * ch;
        let scratch = || {
            (
                Vec::<f32>::with_capacity(band_len),
                Vec::<f32>::with_capacity(band_len / 4),
            )
        };
        let band = |(cur, next): &mut (Vec<f32>, Vec<f32>),
                    b: usize,
                    dst: &mut [&mut [u8]],
                    kept: &mut [f32]|
         -> Result<()> {
            cur.resize(band_len, 0.0);
            crate::texel::decode_range_to_linear(&stored, texels, b * band_len, cur);
            let (mut lw, mut lr) = (w, rows);
            for (k, d) in dst.iter_mut().enumerate() {
                encode_band(cur, lw, lr, f32fmt, association, out_format, d)?;
                if k == m {
                    kept.copy_from_slice(cur);
                    break;
                }
                let (nw, nr) = (lw / 2, lr / 2);
                next.resize(nw * nr * ch, 0.0);
                for (r, o) in next.chunks_exact_mut(nw * ch).enumerate() {
                    let r0 = &cur[2 * r * lw * ch..(2 * r + 1) * lw * ch];
                    let r1 = &cur[(2 * r + 1) * lw * ch..(2 * r + 2) * lw * ch];
                    mip::fast::box_row_f32(r0, r1, o, ch, straight);
                }
                std::mem::swap(cur, next);
                (lw, lr) = (nw, nr);
            }
            Ok(())
        };
        lists
            .into_par_iter()
            .zip(kept.par_chunks_mut(per_keep))
            .enumerate()
            .try_for_each_init(scratch, |sc, (i, (mut l, kp))| band(sc, b0 + i, &mut l, kp))
    }

    /// Levels 1.. once every row of level 0 went through [`Self::rows`]:
    /// levels 1..=m from the bands, the rest built from level m in f32,
    /// as the whole-level build does.
    fn finish(self, progress: &mut dyn FnMut(mip::Progress)) -> Result<Vec<Texture>> {
        let Streamer {
            base,
            options,
            sizes,
            m,
            f32fmt,
            out_format,
            association,
            outs,
            keep,
            ..
        } = self;
        drop(base);
        let done: u64 = sizes[1..=m].iter().map(|&(w, h)| w as u64 * h as u64).sum();
        let mut levels: Vec<Texture> = Vec::with_capacity(sizes.len() - 1);
        for (k, t) in outs.into_iter().enumerate() {
            levels.push(Texture::from_texels(
                sizes[k + 1].0,
                sizes[k + 1].1,
                out_format,
                t,
            )?);
        }
        // Level m is in `outs` already: the chain's first level is skipped.
        let level_m = Texture::from_f32(sizes[m].0, sizes[m].1, f32fmt, keep)?;
        let rest = rest_of_chain(level_m, m, &sizes, options, done, progress)?;
        for l in rest.into_iter().skip(1) {
            levels.push(convert_level(associate(l, association)?, out_format)?);
        }
        Ok(levels)
    }
}

/// One band of a level (`lw`×`lr` texels of linear f32 in `fmt`) with
/// its alpha association changed and encoded into `out` as little-endian
/// bytes in `dst`: the same values as [`associate`] then [`convert_level`]
/// give for the whole level. Linear float outputs of the same channels
/// (the EXR path) are encoded a few texels at a time with no allocation;
/// other outputs go through the whole-level functions.
fn encode_band(
    lin: &[f32],
    lw: usize,
    lr: usize,
    fmt: Format,
    association: Option<AlphaMode>,
    out: Format,
    dst: &mut [u8],
) -> Result<()> {
    let ch = fmt.channels as usize;
    let direct = out.channels == fmt.channels
        && out.color_space == ColorSpace::Linear
        && fmt.color_space == ColorSpace::Linear
        && matches!(out.channel_type, ChannelType::F16 | ChannelType::F32)
        && cfg!(target_endian = "little");
    if !direct {
        let t = Texture::from_f32(lw as u32, lr as u32, fmt, lin.to_vec())?;
        let t = convert_level(associate(t, association)?, out)?;
        dst.copy_from_slice(&crate::io::le_bytes(t.texels()));
        return Ok(());
    }
    const STEP: usize = 256;
    let mut tmp = [0f32; STEP * 4];
    let bytes = out.channel_type.bytes();
    for (i, o) in lin.chunks(STEP * ch).zip(dst.chunks_mut(STEP * ch * bytes)) {
        let t = &mut tmp[..i.len()];
        t.copy_from_slice(i);
        match association {
            Some(AlphaMode::Premultiplied) => {
                for px in t.chunks_exact_mut(ch) {
                    let a = px[ch - 1];
                    px[..ch - 1].iter_mut().for_each(|c| *c *= a);
                }
            }
            Some(_) => {
                for px in t.chunks_exact_mut(ch) {
                    let a = px[ch - 1];
                    if a != 0.0 {
                        px[..ch - 1].iter_mut().for_each(|c| *c /= a);
                    }
                }
            }
            None => {}
        }
        match out.channel_type {
            ChannelType::F16 => {
                use half::slice::{HalfBitsSliceExt, HalfFloatSliceExt};
                let o: &mut [half::f16] =
                    bytemuck::cast_slice_mut::<u8, u16>(o).reinterpret_cast_mut();
                o.convert_from_f32_slice(t);
                saturate_f16(t, o);
            }
            _ => o.copy_from_slice(bytemuck::cast_slice(t)),
        }
    }
    Ok(())
}

/// Finite values that became infinite in f16 saturate to ±65504, as
/// [`crate::texel::encode_from_linear`] does.
fn saturate_f16(from: &[f32], to: &mut [half::f16]) {
    for (o, &i) in to.iter_mut().zip(from) {
        if i.is_finite() && o.is_infinite() {
            *o = if i > 0.0 {
                half::f16::MAX
            } else {
                half::f16::MIN
            };
        }
    }
}

/// True for the sources the band-by-band builders take: integer texels,
/// or float texels that are all finite and go to a float output (NaN and
/// infinities go through the whole-image build, which applies the NaN
/// policy to level 0 as a whole; float values written to a normalised
/// type are counted for the clipping note there).
fn bandable_source(base: &Texture, out: Format) -> bool {
    cfg!(target_endian = "little")
        && match base.channel_type() {
            ChannelType::U8 | ChannelType::U16 => true,
            ChannelType::F16 | ChannelType::F32 => {
                out.channel_type.is_float() && mip::nan::check(base).is_ok()
            }
        }
}

/// Rows per band of [`Banded`].
const BAND_ROWS: usize = 16;

/// The general band-by-band build ([`Builder`]): the colour chain of a
/// source converted to another type, for the filters and sizes
/// [`Streamer`] does not take (Kaiser, Lanczos,
/// Mitchell, triangle; the polyphase box of odd sizes; every wrap mode),
/// without a full-resolution f32 copy of level 0:
/// - level 0 is decoded, alpha-associated and encoded into the output type
///   band by band ([`BAND_ROWS`] rows per band, in parallel);
/// - level 1 is filtered band by band ([`mip::separable::Reducer::band`]):
///   each band decodes the level-0 rows its taps name (wrapped rows from
///   the far edge included), so bands meet exactly;
/// - the rest of the chain is built from level 1 in f32 as before.
///
/// Decoding, the filter's rows, association and encoding are the
/// whole-image build's own, row by row, so the chain is bit for bit the
/// whole-image one (`tests/mip_streamed.rs`). Memory: the source, the
/// output chain and level 1 in f32 (a quarter of level 0 in f32), where
/// the whole-image build holds level 0 in f32 too.
///
/// [`Banded::new`] hands the source back when it does not apply (alpha
/// coverage, normal maps, a single level, a box filter the whole-image
/// build reduces with its fast 2×2 kernel, float sources holding NaN or
/// infinities).
struct Banded<'a> {
    base: Texture,
    options: &'a MipOptions,
    sizes: Vec<(u32, u32)>,
    f32fmt: Format,
    out_format: Format,
    association: Option<AlphaMode>,
}

impl<'a> Banded<'a> {
    /// `Err(base)` when the band-by-band build does not apply.
    fn new(
        base: Texture,
        options: &'a MipOptions,
        src: Format,
        out_format: Format,
        association: Option<AlphaMode>,
    ) -> std::result::Result<Self, Texture> {
        let (w, h) = (base.width() as usize, base.height() as usize);
        let sizes = mip::level_sizes(
            base.width(),
            base.height(),
            options.rounding,
            options.max_levels,
        );
        let fast_box = options.filter == MipFilter::Box
            && options.fast_paths
            && sizes
                .get(1)
                .is_some_and(|&(w1, h1)| 2 * w1 as usize == w && 2 * h1 as usize == h);
        let applies = sizes.len() >= 2
            && !fast_box
            && options.alpha_coverage.is_none()
            && !options.normal_map
            && bandable_source(&base, out_format);
        if !applies {
            return Err(base);
        }
        Ok(Banded {
            base,
            options,
            sizes,
            f32fmt: Format::new(src.channels, ChannelType::F32, ColorSpace::Linear)
                .with_alpha(src.alpha),
            out_format,
            association,
        })
    }

    /// Level-0 rows `y0 ..` (as many as `dst` holds) decoded, associated
    /// and encoded into `dst` as little-endian bytes of the output type,
    /// [`BAND_ROWS`] rows per task.
    fn rows(&self, y0: usize, dst: &mut [u8]) -> Result<()> {
        let w = self.base.width() as usize;
        let ch = self.f32fmt.channels as usize;
        let row_bytes = w * self.out_format.texel_bytes();
        let stored = self.base.format();
        dst.par_chunks_mut(BAND_ROWS * row_bytes)
            .enumerate()
            .try_for_each_init(Vec::<f32>::new, |lin, (b, dst)| -> Result<()> {
                let rows = dst.len() / row_bytes;
                lin.resize(rows * w * ch, 0.0);
                let start = (y0 + b * BAND_ROWS) * w * ch;
                crate::texel::decode_range_to_linear(&stored, self.base.texels(), start, lin);
                encode_band(
                    lin,
                    w,
                    rows,
                    self.f32fmt,
                    self.association,
                    self.out_format,
                    dst,
                )
            })
    }

    /// Levels 1..: level 1 filtered band by band in f32 from the level-0
    /// rows each band's taps name, the rest built from it as the
    /// whole-level build does.
    fn finish(self, progress: &mut dyn FnMut(mip::Progress)) -> Result<Vec<Texture>> {
        let Banded {
            base,
            options,
            sizes,
            f32fmt,
            out_format,
            association,
        } = self;
        let (w, h) = (base.width() as usize, base.height() as usize);
        let ch = f32fmt.channels as usize;
        let stored = base.format();
        let decode = |j: u32, row: &mut [f32]| {
            crate::texel::decode_range_to_linear(&stored, base.texels(), j as usize * w * ch, row)
        };
        let (w1, h1) = (sizes[1].0 as usize, sizes[1].1 as usize);
        let reducer =
            mip::separable::Reducer::new(f32fmt, w as u32, h as u32, w1 as u32, h1 as u32, options);
        let mut lvl1: Vec<f32> = crate::mem::zeroed(w1 * h1 * ch);
        lvl1.par_chunks_mut(BAND_ROWS * w1 * ch)
            .enumerate()
            .for_each(|(b, dst)| {
                let y0 = b * BAND_ROWS;
                let y1 = y0 + dst.len() / (w1 * ch);
                reducer.band(y0, y1, decode, dst);
            });
        drop(base);
        let level1 = Texture::from_f32(w1 as u32, h1 as u32, f32fmt, lvl1)?;
        let rest = rest_of_chain(level1, 1, &sizes, options, (w1 * h1) as u64, progress)?;
        let mut levels = Vec::with_capacity(sizes.len() - 1);
        for l in rest {
            levels.push(convert_level(associate(l, association)?, out_format)?);
        }
        Ok(levels)
    }
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

/// Change the alpha association of a level built in linear f32:
/// premultiply, or divide colour by alpha (where alpha is 0 the colour is
/// kept, as oiiotool's --unpremult does).
fn associate(mut l: Texture, association: Option<AlphaMode>) -> Result<Texture> {
    let Some(to) = association else {
        return Ok(l);
    };
    let ch = l.channels();
    let Texels::F32(v) = l.texels_mut() else {
        return Err(Error::InvalidOption(
            "changing the alpha association needs f32 levels".into(),
        ));
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
    l.reinterpret(f)
}

/// Convert a built level to the output format (type, colour space, and
/// channel widening for containers that need it).
fn convert_level(l: Texture, out: Format) -> Result<Texture> {
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
    if conv.format().channels != out.channels {
        conv.expand_channels(out.channels)
    } else {
        Ok(conv)
    }
}

/// Linear f32 → linear f16 without the general path's extra copy; finite
/// values beyond the half range saturate (as `encode_from_linear` does).
fn f32_to_f16(l: &Texture, f: Format) -> Result<Texture> {
    use half::slice::HalfFloatSliceExt;
    let Texels::F32(v) = l.texels() else {
        return Err(Error::InvalidOption("expected f32 texels".into()));
    };
    let mut out = vec![half::f16::ZERO; v.len()];
    out.par_chunks_mut(1 << 16)
        .zip(v.par_chunks(1 << 16))
        .for_each(|(o, i)| {
            o.convert_from_f32_slice(i);
            saturate_f16(i, o);
        });
    Texture::from_f16(l.width(), l.height(), f, out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn webgl_takes_levels_whose_sides_shifted_by_the_level_are_multiples_of_4() {
        let sizes = |w, h| mip::level_sizes(w, h, Rounding::Down, None);
        // Level 0 a multiple of 4: every level is fine (1004 -> 502 -> 251 ...).
        assert_eq!(webgl_misfit(&sizes(1004, 1000)), None);
        assert_eq!(webgl_misfit(&sizes(4, 4)), None);
        // Level 0 not whole blocks.
        assert_eq!(webgl_misfit(&sizes(1001, 1000)), Some((0, (1001, 1000))));
        assert_eq!(webgl_misfit(&sizes(2, 2)), Some((0, (2, 2))));
        // Level 1 odd (rounded up from a multiple of 4 it never is; an
        // explicit list can hold one).
        assert_eq!(webgl_misfit(&[(12, 12), (7, 6)]), Some((1, (7, 6))));
        assert_eq!(webgl_misfit(&[(12, 12), (6, 6), (3, 3), (1, 1)]), None);
    }

    fn rgba8(w: u32, h: u32) -> Texture {
        let v = (0..w as usize * h as usize * 4)
            .map(|i| (i * 7 % 251) as u8)
            .collect();
        Texture::from_u8(w, h, Format::new(4, ChannelType::U8, ColorSpace::Srgb), v).unwrap()
    }

    fn first_ptr(t: &mut Texels) -> *const u8 {
        t.bytes_mut().as_ptr()
    }

    /// The buffers faulted in during the decode are the ones the fused box
    /// build fills (not dropped for fresh ones), and none are made where
    /// that path does not run.
    #[test]
    fn prefaulted_levels_are_the_ones_the_fused_build_fills() {
        let exr = Job::new("in.png", Path::new("out.exr")).unwrap();
        let s = Settings::default();
        let (w, h) = (256, 96);
        let mut bufs = prefault_streamed(&exr, &s, w, h, 4, ChannelType::U8).unwrap();
        // Levels 1..=m, m = 5 trailing zeros of 96, at most 4.
        let lens: Vec<usize> = bufs.iter().map(Texels::len).collect();
        assert_eq!(lens, [128 * 48 * 4, 64 * 24 * 4, 32 * 12 * 4, 16 * 6 * 4]);
        assert!(bufs.iter().all(|b| b.channel_type() == ChannelType::F16));
        let ptrs: Vec<*const u8> = bufs.iter_mut().map(first_ptr).collect();
        let options = MipOptions::default();
        let src = Format::new(4, ChannelType::U8, ColorSpace::Srgb).with_alpha(AlphaMode::Straight);
        let out = output_format(src, OutputKind::EXR, &s).unwrap();
        let assoc = Some(AlphaMode::Premultiplied);
        let base = rgba8(w, h).reinterpret(src).unwrap();
        let Ok(mut st) = Streamer::new(base, &options, src, out, assoc, Some(bufs)).unwrap() else {
            panic!("the box shortcut applies to 256x96");
        };
        let got: Vec<*const u8> = st.outs.iter_mut().map(first_ptr).collect();
        assert_eq!(got, ptrs);
        // Buffers of another shape are not taken.
        let mut wrong = prefault_streamed(&exr, &s, 128, 96, 4, ChannelType::U8).unwrap();
        let wrong_ptr = first_ptr(&mut wrong[0]);
        let base = rgba8(w, h).reinterpret(src).unwrap();
        let Ok(mut st) = Streamer::new(base, &options, src, out, assoc, Some(wrong)).unwrap()
        else {
            panic!("the box shortcut applies to 256x96");
        };
        assert_ne!(first_ptr(&mut st.outs[0]), wrong_ptr);
        assert_eq!(st.outs[0].len(), 128 * 48 * 4);

        // Paths that do not stream levels 1..=m to EXR get nothing.
        let none =
            |job: &Job, s: &Settings, w, h, ty| prefault_streamed(job, s, w, h, 4, ty).is_none();
        let kaiser = Settings {
            filter: MipFilter::Kaiser,
            ..Settings::default()
        };
        assert!(none(&exr, &kaiser, w, h, ChannelType::U8));
        assert!(none(&exr, &s, 255, 96, ChannelType::U8)); // odd: no band levels
        let ktx2 = Job::new("in.png", Path::new("out.ktx2")).unwrap();
        assert!(none(&ktx2, &s, w, h, ChannelType::U8));
        let f16_in = Settings::default(); // half source to half EXR: not converted
        assert!(none(&exr, &f16_in, w, h, ChannelType::F16));
        let tall_tiles = Settings {
            tile: (64, 63),
            ..Settings::default()
        };
        assert!(none(&exr, &tall_tiles, w, h, ChannelType::U8));
    }
}
