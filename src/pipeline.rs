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
use crate::mip::{self, MipFilter, MipOptions, NanPolicy, Rounding};
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

/// The container of a batch's outputs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Extension {
    /// Tiled, mip-mapped OpenEXR.
    #[default]
    Exr,
    /// KTX2.
    Ktx2,
    /// DDS.
    Dds,
    /// One PNG per level (`NAME_{level}.png`).
    Png,
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
    pub fn batch(inputs: &[String], dir: &Path, ext: Extension) -> Vec<Job> {
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
                let (output, kind) = match ext {
                    Extension::Exr => (dir.join(format!("{stem}.exr")), OutputKind::Exr),
                    Extension::Ktx2 => (dir.join(format!("{stem}.ktx2")), OutputKind::Ktx2),
                    Extension::Dds => (dir.join(format!("{stem}.dds")), OutputKind::Dds),
                    Extension::Png => (
                        dir.join(format!("{stem}_{{level}}.png")),
                        OutputKind::PngLevels,
                    ),
                };
                Job {
                    input: input.clone(),
                    output,
                    kind,
                }
            })
            .collect()
    }
}

/// File extensions [`expand_inputs`] takes from a directory: the
/// containers parvo reads (case does not matter).
pub const IMAGE_EXTENSIONS: &[&str] = &[
    "png", "jpg", "jpeg", "tif", "tiff", "tx", "hdr", "exr", "ktx2", "dds",
];

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
                IMAGE_EXTENSIONS
                    .iter()
                    .any(|x| e.to_string_lossy().eq_ignore_ascii_case(x))
            });
            if image && p.is_file() && !name.is_some_and(|n| n.starts_with('.')) {
                found.push(p.to_string_lossy().into_owned());
            }
        }
        if found.is_empty() {
            return Err(Error::InvalidOption(format!(
                "directory {input} holds no image parvo reads (.{})",
                IMAGE_EXTENSIONS.join(", .")
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
                None => kind == OutputKind::Exr,
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
        if let Some(j) = jobs
            .iter()
            .find(|j| !matches!(j.kind, OutputKind::Ktx2 | OutputKind::Dds))
        {
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
        if let Some(j) = jobs.iter().find(|j| j.kind != OutputKind::Ktx2) {
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
            .find(|j| matches!(j.kind, OutputKind::Ktx2 | OutputKind::Dds))
    {
        return bad(format!(
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
        None => match kind {
            OutputKind::Exr if src.channel_type == ChannelType::F32 => ChannelType::F32,
            OutputKind::Exr => ChannelType::F16,
            OutputKind::PngLevels if src.channel_type == ChannelType::U8 => ChannelType::U8,
            OutputKind::PngLevels => ChannelType::U16,
            OutputKind::Ktx2 | OutputKind::Dds => src.channel_type,
        },
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
    if job.kind == OutputKind::Exr {
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
    let base = if job.kind == OutputKind::Exr
        && s.compress.is_none()
        && s.roughness.is_none()
        && !s.normal_map
        && !same
    {
        match mip::band::Stream::new(base, &options, src, out_format, association, prepared)? {
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
        let (levels, clipped) = mip::band::build_converted(
            base,
            &options,
            src,
            out_format,
            association,
            same,
            &mut on_progress,
        )?;
        notes.extend(clipped.map(|c| {
            format!(
                "{} of {} texels (all levels) hold values outside 0..1 and are clipped \
                 to the {} range; keep a float output (.exr, or --type f16) to keep them",
                c.clipped, c.texels, out_format.channel_type
            )
        }));
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
            channel_names: (*kind == OutputKind::Exr).then(|| vec!["Y".to_string()]),
            ..save.clone()
        };
        io::save(&levels, s.rounding, path, *kind, &rs)?;
    }
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
                _ => match kind {
                    OutputKind::Exr => ChannelType::F16,
                    OutputKind::PngLevels if out.channel_type == ChannelType::U16 => {
                        ChannelType::U16
                    }
                    OutputKind::PngLevels => ChannelType::U8,
                    OutputKind::Ktx2 | OutputKind::Dds if kind.supports(out.channel_type) => {
                        out.channel_type
                    }
                    _ => ChannelType::U8,
                },
            };
            let f = Format::new(1, ty, ColorSpace::Linear).with_alpha(AlphaMode::None);
            let f = match kind {
                OutputKind::Ktx2 => io::ktx2::storable(f),
                OutputKind::Dds => io::dds::storable(f),
                _ => f,
            };
            Some(
                chain
                    .specular
                    .into_iter()
                    .map(|l| mip::band::convert_level(l, f))
                    .collect::<Result<Vec<_>>>()?,
            )
        }
    };
    Ok((normals, rough))
}

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

/// The buffers of levels 1..=m of a fused box write to EXR (the box
/// shortcut of [`mip::band::Stream`] under [`Fused`]) for a `w`×`h` source of `ch` channels of `ty`,
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
    let fused = job.kind == OutputKind::Exr
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
    let band = mip::band::box_band_rows(w, h, &options)?;
    // A source already in the output type is built without bands.
    if !fused || out.channel_type == ty || fused_group(band, s.tile.1 as usize).is_none() {
        return None;
    }
    mip::band::prefault(w, h, &options, out)
}

/// A band-by-band builder as the level-0 source of a streamed EXR write,
/// timing the build and reporting progress.
struct Fused<'a, 'p> {
    st: Option<mip::band::Stream<'a>>,
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
        let texels_done = st.rows(y0, dst)?;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mip::band::Stream;

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
        let out = output_format(src, OutputKind::Exr, &s).unwrap();
        let assoc = Some(AlphaMode::Premultiplied);
        let base = rgba8(w, h).reinterpret(src).unwrap();
        let Ok(mut st) = Stream::new(base, &options, src, out, assoc, Some(bufs)).unwrap() else {
            panic!("the box shortcut applies to 256x96");
        };
        let got: Vec<*const u8> = st.level_buffers().iter_mut().map(first_ptr).collect();
        assert_eq!(got, ptrs);
        // Buffers of another shape are not taken.
        let mut wrong = prefault_streamed(&exr, &s, 128, 96, 4, ChannelType::U8).unwrap();
        let wrong_ptr = first_ptr(&mut wrong[0]);
        let base = rgba8(w, h).reinterpret(src).unwrap();
        let Ok(mut st) = Stream::new(base, &options, src, out, assoc, Some(wrong)).unwrap() else {
            panic!("the box shortcut applies to 256x96");
        };
        assert_ne!(first_ptr(&mut st.level_buffers()[0]), wrong_ptr);
        assert_eq!(st.level_buffers()[0].len(), 128 * 48 * 4);

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
