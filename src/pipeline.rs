//! The batch mip pipeline behind `parvo mip`, for engines and asset
//! pipelines that embed parvo: a job list in, one [`Outcome`] (or error)
//! per job out, with the same planning, fingerprint rule ([`Settings::update`]) and
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

use std::fmt;
use std::path::{Path, PathBuf};
use std::time::Instant;

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::io::{self, FileFormat, OutputKind, SaveOptions};
use crate::mip::{self, MipFilter, MipOptions};
use crate::texel::{AlphaMode, ChannelType, ColorSpace, Format, Texels};
use crate::texture::{ImageKind, Texture};
use crate::wrap::Wrap;

mod blocks;
mod check;
mod images;
mod plan;

pub use blocks::{BlockLevel, BlockReport, block_label};
use blocks::{compress_notes, encode_chain};
pub use check::{Usage, check};
pub use plan::{BuildPath, Plan};
pub use settings::{
    AlphaChoice, ColorChoice, EnvSettings, ResizeTo, RoughnessSettings, RoughnessSource, Settings,
};

mod roughness;
mod settings;

/// One job: an input (a file or a `builtin:` name) and where it goes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Job {
    /// The input.
    pub input: String,
    /// The output path (a `{level}` template for PNG levels).
    pub output: PathBuf,
    /// The output container.
    pub kind: OutputKind,
    /// Six face files (+X, −X, +Y, −Y, +Z, −Z) making one cube map
    /// ([`Job::faces`]); empty for a job of one input.
    pub faces: Vec<String>,
}

impl Job {
    /// A job writing `output`, its container from the extension.
    pub fn new(input: &str, output: &Path) -> Result<Job> {
        Ok(Job {
            input: input.to_string(),
            output: output.to_path_buf(),
            kind: OutputKind::from_path(output)?,
            faces: Vec::new(),
        })
    }

    /// A job building one cube map from six face files (+X, −X, +Y, −Y,
    /// +Z, −Z) into `output`; its [`Job::input`] names them all.
    pub fn faces(files: &[String], output: &Path) -> Result<Job> {
        if files.len() != 6 {
            return Err(Error::InvalidOption(format!(
                "a cube map is built from six face files (+x -x +y -y +z -z), got {}",
                files.len()
            )));
        }
        Ok(Job {
            input: files.join(" "),
            faces: files.to_vec(),
            ..Job::new(&files[0], output)?
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
                    faces: Vec::new(),
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
    pub notes: Vec<Note>,
    /// Block compression figures, when this run encoded blocks.
    pub blocks: Option<BlockReport>,
    /// The block format the output holds (`BC7_SRGB`, ...) when it is
    /// block-compressed, also when this run encoded nothing ([`Settings::update`],
    /// a dry run).
    pub block_format: Option<String>,
    /// What the output holds: one 2-D image, an array, a cube map, an
    /// array of them or a lat-long map.
    pub image_kind: ImageKind,
    /// How the job was (or, in a dry run, would be) built and written.
    pub plan: Plan,
    /// What the lighting options of an environment job computed
    /// (`--prefilter`, `--irradiance`), else `None`.
    pub lighting: Option<Lighting>,
}

/// What the lighting options of an environment job computed.
#[derive(Clone, Debug, PartialEq)]
pub struct Lighting {
    /// The prefilter's lobe and each level's roughness α, level 0 first
    /// ([`crate::env::prefilter::alpha`]), when levels are prefiltered.
    pub roughness: Option<(crate::env::prefilter::Lobe, Vec<f64>)>,
    /// The environment's 9 spherical-harmonic coefficients per RGB
    /// channel ([`crate::env::prefilter::sh9`]), from its level 0; `None`
    /// in a dry run and for an up-to-date output.
    pub sh9: Option<[[f64; 3]; 9]>,
}

/// The [`Lighting`] a job of settings `s` and `plan` reports before its
/// levels are built (the roughness of prefiltered levels; no SH9 yet), or
/// `None` when it asks for no lighting.
fn lighting(s: &Settings, plan: &Plan) -> Option<Lighting> {
    if s.env.prefilter.is_none() && s.env.irradiance.is_none() {
        return None;
    }
    let levels = plan.level_sizes.len();
    Some(Lighting {
        roughness: s.env.prefilter.map(|(lobe, _)| {
            let a = (0..levels)
                .map(|k| crate::env::prefilter::alpha(k, levels))
                .collect();
            (lobe, a)
        }),
        sh9: None,
    })
}

impl Lighting {
    /// The roughness list as the output's `parvo:roughness` attribute
    /// (KTX2 key/value, OpenEXR attribute) holds it: α per level, level 0
    /// first, separated by spaces.
    pub fn roughness_text(&self) -> Option<String> {
        self.roughness.as_ref().map(|(_, a)| {
            a.iter()
                .map(|a| (*a as f32).to_string())
                .collect::<Vec<_>>()
                .join(" ")
        })
    }
}

/// Something the loader or the build did that the user would not assume.
/// Its `Display` names no option; a front end may say the typed ones in
/// its own option names.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum Note {
    /// Said in words that name no option (the loader's notes among them).
    Text(String),
    /// Level 0 was resized for [`Settings::resize_to`].
    Resized {
        /// The source's size.
        from: (u32, u32),
        /// The size it was resized to.
        to: (u32, u32),
        /// The filter it was resized with.
        filter: MipFilter,
    },
    /// A level WebGL refuses to take as a block-compressed level (its
    /// sides shifted by the level are not multiples of 4).
    WebGlMisfit {
        /// The first such level.
        level: usize,
        /// Its size.
        size: (u32, u32),
    },
    /// Float values (HDR) written to a normalised type were clipped to
    /// its range.
    Clipped {
        /// Texels with a channel outside 0..1 (all levels).
        clipped: u64,
        /// Texels of all levels.
        texels: u64,
        /// The normalised type.
        to: ChannelType,
    },
}

impl fmt::Display for Note {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Note::Text(t) => f.write_str(t),
            Note::Resized { from, to, filter } => write!(
                f,
                "resized {}x{} to {}x{} ({filter} filter) to block-friendly sizes",
                from.0, from.1, to.0, to.1
            ),
            Note::WebGlMisfit { level, size } => write!(
                f,
                "level {level} is {}x{}: WebGL refuses block-compressed levels unless level 0's \
                 sides are multiples of 4 (and level k's sides times 2^k are)",
                size.0, size.1
            ),
            Note::Clipped {
                clipped,
                texels,
                to,
            } => write!(
                f,
                "{clipped} of {texels} texels (all levels) hold values outside 0..1 and are \
                 clipped to the {to} range; keep a float output to keep them"
            ),
        }
    }
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
            "{} cannot store {ty} texels ({})",
            kind.name(),
            io::container::types_stored()
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
        s.exr.tile.0,
        s.exr.tile.1,
        s.exr.compression,
    ) + &format!(
        " compress={:?} supercompression={:?} resize={:?}",
        s.compress, s.ktx2.supercompression, s.resize_to
    ) + &match &s.roughness {
        Some(r) => format!(
            " roughness={:?} channels={:?} specular={:?} pack={} rough_out={:?}",
            r.base, r.channels, r.specular, r.pack_alpha, r.output
        ),
        None => String::new(),
    }
}

/// A job's level 0, read and interpreted.
struct Input {
    base: Texture,
    /// `base`'s format as the build reads it (colour space and alpha as
    /// the settings say).
    src: Format,
    src_kind: FileFormat,
    file_wrap: Option<Wrap>,
    channel_names: Vec<String>,
    notes: Vec<Note>,
    read_s: f64,
    /// The source is a 1-D texture (see [`io::SourceInfo::one_d`]).
    one_d: bool,
}

/// The plan of one job: its input read and interpreted, nothing built or
/// written (a dry run of [`process`]).
pub fn plan(job: &Job, s: &Settings) -> Result<Plan> {
    let dry = Settings {
        dry_run: true,
        ..s.clone()
    };
    process(job, &dry, &mut |_| {}).map(|o| o.plan)
}

/// Runs one job (see the module docs), reporting progress to `progress`
/// on the calling thread.
pub fn process(job: &Job, s: &Settings, progress: &mut dyn FnMut(Stage)) -> Result<Outcome> {
    let t_read = Instant::now();
    if !job.faces.is_empty() {
        return images::process(job, s, None, t_read, progress);
    }
    let (loaded, prepared) = load(job, s)?;
    if images::holds_images(&loaded, s) {
        return images::process(job, s, Some(loaded), t_read, progress);
    }
    let input = read(loaded, s, job.kind, t_read)?;
    let out_format = output_format_of(job, s, input.src)?;
    let plan = Plan::new(
        job,
        s,
        &input.base,
        input.src,
        out_format,
        plan::mip_options(s, input.file_wrap, out_format),
    );
    if job.kind.stores().whole_chain {
        let (w, h) = (input.base.width(), input.base.height());
        let full = mip::level_count(w, h, s.rounding, None);
        if s.levels.is_some_and(|n| n < full) {
            return Err(Error::from(Usage::ExrLevels { full }));
        }
    }
    let fingerprint = io::fingerprint(
        &input.base,
        &fingerprint_text(s, &plan.options, &out_format, job.kind),
    );
    let outcome = |status, input: &Input| Outcome {
        output: job.output.clone(),
        status,
        width: input.base.width(),
        height: input.base.height(),
        format: out_format,
        level_sizes: plan.level_sizes.clone(),
        read_s: input.read_s,
        build_s: 0.0,
        write_s: 0.0,
        notes: (input.notes.iter().cloned())
            .chain(codes_decoded_note(input.src, out_format))
            .collect(),
        blocks: None,
        block_format: s.compress.map(|(bf, _)| block_label(bf, out_format)),
        image_kind: ImageKind::Plain,
        plan: plan.clone(),
        lighting: None,
    };
    if s.dry_run {
        return Ok(outcome(Status::DryRun, &input));
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
        return Ok(outcome(Status::UpToDate, &input));
    }
    // An EXR source's channel names carry to EXR output (N.X stays N.X, a
    // lone Z stays Z); other sources get the layout's names.
    let names = (input.src_kind == FileFormat::Exr
        && input.channel_names.len() == out_format.channels as usize)
        .then(|| input.channel_names.clone());
    let mut save = save_options(s, &plan, input.src, fingerprint, names);
    save.one_d = input.one_d && input.base.height() == 1;
    let mut done = outcome(Status::Written, &input);
    build_and_write(job, s, &plan, input, prepared, &save, &mut done, progress)?;
    Ok(done)
}

/// What a job of `plan` writes besides the levels: its wrap modes, the
/// containers' settings, the fingerprint and parvo's attributes.
fn save_options(
    s: &Settings,
    plan: &Plan,
    src: Format,
    fingerprint: String,
    channel_names: Option<Vec<String>>,
) -> SaveOptions {
    let mut attributes = vec![
        ("parvo:filter".into(), s.filter.to_string()),
        ("parvo:source".into(), src.to_string()),
        ("parvo:rounding".into(), s.rounding.to_string()),
    ];
    if let Some((lobe, how)) = s.env.prefilter {
        let text = lighting(s, plan).and_then(|l| l.roughness_text());
        attributes.push((
            "parvo:prefilter".into(),
            format!("{} {}", lobe.name(), how.describe()),
        ));
        attributes.extend(text.map(|t| ("parvo:roughness".into(), t)));
    }
    SaveOptions {
        channel_names,
        wrap: plan.options.wrap,
        exr: s.exr,
        fingerprint: Some(fingerprint),
        ktx2: s.ktx2,
        attributes,
        placement: crate::env::Placement::Centred,
        one_d: false,
    }
}

/// Load `job`'s input (faulting in the fused write's buffers meanwhile,
/// [`plan::prefault_streamed`]), every face and layer and a recorded
/// environment accepted: what the file holds decides the path.
fn load(job: &Job, s: &Settings) -> Result<(io::Loaded, Option<Vec<Texels>>)> {
    // Levels 1.. of a fused box write, faulted in on the core the decoder
    // leaves idle.
    let mut prepared = None;
    let loaded = io::load_overlapped(
        &job.input,
        &s.limits,
        &images::load_options(s),
        Some(&mut |w, h, ch, ty| prepared = plan::prefault_streamed(job, s, w, h, ch, ty)),
    )?;
    Ok((loaded, prepared))
}

/// The format the build reads a source of format `f` as: its colour space
/// and alpha as the settings say (a normal map is linear, its fourth
/// channel data).
fn read_as(f: Format, s: &Settings, data: bool) -> Format {
    let mut src = f;
    src.color_space = match (s.color, s.normal_map) {
        (ColorChoice::Linear, _) | (ColorChoice::Auto, true) => ColorSpace::Linear,
        // An output that holds data keeps the stored codes.
        (ColorChoice::Auto, false) if data => ColorSpace::Linear,
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
    src
}

/// The loader's notes, and the colour assumption said once per file
/// (a 16-bit grey height map read as sRGB changes every value of a
/// linear output); and whether the output holds data, read as the
/// stored codes (see [`data_output`]).
fn load_notes(loaded: &io::Loaded, s: &Settings, kind: OutputKind) -> (Vec<Note>, bool) {
    let mut notes: Vec<Note> = loaded.info.notes.iter().cloned().map(Note::Text).collect();
    let f = loaded.base().format();
    if s.color != ColorChoice::Auto || s.normal_map {
        return (notes, false);
    }
    let data = data_output(s, &f, loaded.info.color_stated, kind);
    match &data {
        Some(why) => {
            if f.color_space == ColorSpace::Srgb && !f.channel_type.is_float() {
                notes.push(Note::Text(format!(
                    "{why}: the file's stored codes are kept as they are, not decoded from sRGB \
                     ({} srgb decodes them to linear first)",
                    crate::setting::Setting::Color
                )));
            }
        }
        None => notes.extend(io::assumed_color_note(&loaded.info, &f).map(Note::Text)),
    }
    (notes, data.is_some())
}

/// Why the output holds data rather than colour, when it does and
/// neither `--color` nor `--normal-map` says otherwise: BC4 and BC5 (no
/// sRGB forms; roughness, height, masks, normals), or, for a file that
/// does not say how its values encode colour (`stated` false), an output
/// of one channel, or two without alpha (R, G), as `kind` stores it. Such
/// an output keeps the input's stored codes, as every peer does.
fn data_output(s: &Settings, f: &Format, stated: bool, kind: OutputKind) -> Option<String> {
    if s.color != ColorChoice::Auto || s.normal_map {
        return None;
    }
    match s.compress {
        Some((bf, _)) if bf.holds_data() => return Some(format!("{bf} holds data")),
        Some(_) => return None,
        None if stated || f.channel_type.is_float() => return None,
        None => {}
    }
    let kept = output_format(*f, kind, s).is_ok_and(|o| o.channels == f.channels);
    match f.channels {
        1 if kept => Some("a one-channel output holds data".into()),
        2 if kept && !f.has_alpha() => Some("a two-channel output (R, G) holds data".into()),
        _ => None,
    }
}

/// `base` resized as [`Settings::resize_to`] asks (with the wrap modes
/// `wrap`), and the note that says so; `base` itself when it is the
/// size already.
fn resize(base: Texture, s: &Settings, wrap: Wrap) -> Result<(Texture, Option<Note>)> {
    let Some(r) = s.resize_to else {
        return Ok((base, None));
    };
    let (w, h) = (base.width(), base.height());
    let to = r.apply(w, h);
    if to == (w, h) {
        return Ok((base, None));
    }
    s.limits.check(to.0 as u64, to.1 as u64, 0)?;
    let opts = MipOptions {
        filter: s.filter,
        wrap,
        ..MipOptions::default()
    };
    let resized = mip::separable::reduce(&base, to.0, to.1, &opts)?.0;
    let note = Note::Resized {
        from: (w, h),
        to,
        filter: s.filter,
    };
    Ok((resized, Some(note)))
}

/// `loaded`, one 2-D image, interpreted under `s` and resized.
fn read(loaded: io::Loaded, s: &Settings, kind: OutputKind, t_read: Instant) -> Result<Input> {
    let src_kind = loaded.info.format;
    let file_wrap = loaded.info.wrap;
    let (mut notes, data) = load_notes(&loaded, s, kind);
    let channel_names = loaded.info.channel_names.clone();
    let one_d = loaded.info.one_d;
    let mut base = loaded.into_base();
    let src = read_as(base.format(), s, data);
    base = base.reinterpret(src)?;
    let read_s = t_read.elapsed().as_secs_f64();
    let (base, resized) = resize(base, s, s.wrap.or(file_wrap).unwrap_or_default())?;
    notes.extend(resized);
    Ok(Input {
        base,
        src,
        src_kind,
        file_wrap,
        channel_names,
        notes,
        read_s,
        one_d,
    })
}

/// The output texel format of `job` for a source read as `src`.
fn output_format_of(job: &Job, s: &Settings, src: Format) -> Result<Format> {
    match &s.roughness {
        // The normal output holds the vectors (and, packed, the roughness
        // in alpha): three or four channels whatever the source has.
        Some(r) => {
            if r.pack_alpha && src.channels == 4 {
                return Err(Error::from(Usage::PackOverwritesAlpha));
            }
            let n = if r.pack_alpha { 4 } else { 3 };
            let f =
                Format::new(n, src.channel_type, ColorSpace::Linear).with_alpha(AlphaMode::None);
            output_format(f, job.kind, s)
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
                output_format(src, job.kind, &typed)
            }
            None => output_format(src, job.kind, s),
        },
    }
}

/// Build `input`'s chain as `plan` says, encode it to blocks if asked,
/// and write it, filling in `out`'s times, notes and block figures.
#[allow(clippy::too_many_arguments)]
fn build_and_write(
    job: &Job,
    s: &Settings,
    plan: &Plan,
    input: Input,
    prepared: Option<Vec<Texels>>,
    save: &SaveOptions,
    out: &mut Outcome,
    progress: &mut dyn FnMut(Stage),
) -> Result<()> {
    let t_build = Instant::now();
    let total_texels: u64 = plan.level_sizes[1..]
        .iter()
        .map(|&(w, h)| w as u64 * h as u64)
        .sum();
    progress(Stage::Building { total_texels });
    let src = input.src;
    // A band-by-band colour chain to EXR never holds level 0 in the
    // output type: each group of its rows is built, compressed and written
    // (`io::exr::save_streamed`), so level 0's output buffer is neither
    // allocated nor faulted in.
    let base = if plan.path == BuildPath::FusedExr {
        match write_fused(job, s, plan, input.base, src, prepared, save, progress)? {
            Ok(build_s) => {
                out.build_s = build_s;
                out.write_s = (t_build.elapsed().as_secs_f64() - build_s).max(0.0);
                out.block_format = None;
                return Ok(());
            }
            Err(base) => base,
        }
    } else {
        input.base
    };
    let mut on_progress = |p: mip::Progress| {
        progress(Stage::Built {
            texels_done: p.texels_done,
        })
    };
    let out_format = plan.out_format;
    let options = &plan.options;
    let mut rough_levels = None;
    // The plan's path decides; the roughness settings are there when it is
    // BuildPath::Roughness.
    let levels = if let (BuildPath::Roughness, Some(r)) = (plan.path, &s.roughness) {
        let (normals, chain) =
            roughness::build_roughness(&base, r, s, options, out_format, &mut on_progress)?;
        rough_levels = chain;
        normals
    } else if plan.path == BuildPath::Normal {
        // Decoded to vectors, averaged in f32, encoded once per level into
        // the output type (crate::mip::normal).
        mip::normal::build(base, options, out_format, &mut on_progress)?
    } else {
        let (levels, clipped) = mip::band::build_converted(
            base,
            options,
            src,
            out_format,
            plan.association,
            plan.route,
            &mut on_progress,
        )?;
        out.notes.extend(clipped.map(|c| Note::Clipped {
            clipped: c.clipped,
            texels: c.texels,
            to: out_format.channel_type,
        }));
        levels
    };
    out.build_s = t_build.elapsed().as_secs_f64();
    let blocks = match s.compress {
        Some((bf, quality)) => {
            out.notes.extend(compress_notes(bf, src, &plan.level_sizes));
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
        Some((chain, _)) => io::save_blocks(
            std::slice::from_ref(chain),
            ImageKind::Plain,
            &job.output,
            job.kind,
            save,
        )?,
        None => io::save(&levels, s.rounding, &job.output, job.kind, save)?,
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
        out.notes
            .extend(stale_level_notes(&job.output, levels.len())?);
    }
    out.write_s = t_write.elapsed().as_secs_f64();
    out.blocks = blocks.map(|(_, r)| r);
    Ok(())
}

/// The fused EXR write ([`BuildPath::FusedExr`]): `Ok(build seconds)`,
/// or the source back when the band-by-band builders do not take it
/// after all (a float source holding NaN or infinities, tile heights no
/// group of bands fits).
#[allow(clippy::too_many_arguments)]
fn write_fused(
    job: &Job,
    s: &Settings,
    plan: &Plan,
    base: Texture,
    src: Format,
    prepared: Option<Vec<Texels>>,
    save: &SaveOptions,
    progress: &mut dyn FnMut(Stage),
) -> Result<std::result::Result<f64, Texture>> {
    let (width, height) = (base.width(), base.height());
    let st = match mip::band::Stream::new(
        base,
        &plan.options,
        src,
        plan.out_format,
        plan.association,
        plan.route,
        prepared,
    )? {
        Ok(st) => st,
        Err(base) => return Ok(Err(base)),
    };
    let Some(group) = plan::fused_group(st.band(), s.exr.tile.1 as usize) else {
        return Ok(Err(st.into_base()));
    };
    let mut source = plan::Fused {
        st: Some(st),
        group,
        build: std::time::Duration::ZERO,
        progress,
    };
    io::exr::save_streamed(
        width,
        height,
        plan.out_format,
        s.rounding,
        &job.output,
        save,
        &mut source,
    )?;
    Ok(Ok(source.build.as_secs_f64()))
}

/// What is said when an sRGB-encoded cube map, array or lat-long map is
/// stored as float levels: they hold its values decoded to linear light
/// (OpenEXR has no sRGB; a float `--type` elsewhere). A 2-D job's summary
/// line says `linear` and a batch of them says nothing more.
fn decoded_note(src: Format, out: Format) -> Option<Note> {
    (src.color_space == ColorSpace::Srgb
        && out.color_space == ColorSpace::Linear
        && out.channel_type.is_float())
    .then(|| {
        Note::Text(format!(
            "the sRGB-encoded input is stored decoded to linear light ({} levels hold linear \
             values)",
            out.channel_type.name()
        ))
    })
}

/// The note for sRGB-encoded integer codes an integer output cannot keep
/// as sRGB (KTX2, DDS and OpenEXR have no 16-bit sRGB form): they are
/// decoded to linear codes of the same type, which changes every value,
/// so it is said, with the flag that keeps the codes.
fn codes_decoded_note(src: Format, out: Format) -> Option<Note> {
    (src.color_space == ColorSpace::Srgb
        && !src.channel_type.is_float()
        && out.color_space == ColorSpace::Linear
        && !out.channel_type.is_float())
    .then(|| {
        Note::Text(format!(
            "the output has no sRGB {} form: the sRGB-encoded {} codes are decoded to linear {} \
             ({} linear keeps the stored codes, read as linear data)",
            out.channel_type.name(),
            src.channel_type.name(),
            out.channel_type.name(),
            crate::setting::Setting::Color
        ))
    })
}

/// Level files an earlier, longer chain left behind under `template`
/// (the chain now has `levels`), removed, and what was said of them.
fn stale_level_notes(template: &Path, levels: usize) -> Result<Vec<Note>> {
    let stale = io::png_levels::remove_stale(template, levels)?;
    let list = |v: &[PathBuf]| {
        v.iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut notes = Vec::new();
    if !stale.removed.is_empty() {
        notes.push(Note::Text(format!(
            "removed {} stale level file(s) of an earlier run: {}",
            stale.removed.len(),
            list(&stale.removed)
        )));
    }
    if !stale.foreign.is_empty() {
        notes.push(Note::Text(format!(
            "left alone (not written by parvo): {}",
            list(&stale.foreign)
        )));
    }
    Ok(notes)
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
