//! The pipeline's path for every image that is not one 2-D texture: cube
//! maps (a KTX2 or DDS cube, an OpenEXR strip, a strip or a cross, six
//! face files, or one made from a lat-long map), arrays and cube-map
//! arrays, and lat-long maps (or one made from a cube map). Planned,
//! fingerprinted, checked against the settings, built, block-compressed
//! and written as [`super::process`] does a 2-D texture; only the build
//! follows the image's kind ([`BuildPath`]).

use std::time::Instant;

use super::blocks::{BlockReport, compress_notes, encode_chain};
use super::check::kind_not_stored;
use super::plan::{self, BuildPath, Plan};
use super::{
    Job, Note, Outcome, Settings, Stage, Status, Usage, block_label, fingerprint_text, load_notes,
    output_format_of, read_as, resize, save_options,
};
use crate::compress::BlockChain;
use crate::env::{Placement, convert, cube, latlong, prefilter};
use crate::error::{Error, Result};
use crate::io::source::{self, Source};
use crate::io::{self, Environment, EnvironmentMaps, LoadOptions, Loaded, OutputKind, SaveOptions};
use crate::mip::{self, MipChain, MipFilter, MipOptions, Rounding};
use crate::setting::Setting;
use crate::texel::{ChannelType, ColorSpace, Format};
use crate::texture::{ImageKind, Texture};
use crate::wrap::{Wrap, WrapMode};

/// The pipeline's load options: the settings' own, with every face, layer
/// and recorded environment accepted (what the file holds decides the
/// path, [`holds_images`]).
pub(super) fn load_options(s: &Settings) -> LoadOptions {
    LoadOptions {
        environment: EnvironmentMaps::Accept,
        ..s.load.clone()
    }
}

/// True when `loaded` goes this way: it holds faces or layers, records an
/// environment, or the settings ask for one.
pub(super) fn holds_images(loaded: &Loaded, s: &Settings) -> bool {
    loaded.info.kind != ImageKind::Plain || loaded.info.environment.is_some() || s.env.asked()
}

/// Runs `job` (see the module docs); `loaded` is its input, or `None` for
/// a job of six face files.
pub(super) fn process(
    job: &Job,
    s: &Settings,
    loaded: Option<Loaded>,
    t_read: Instant,
    progress: &mut dyn FnMut(Stage),
) -> Result<Outcome> {
    let (source, mut input) = read(job, s, loaded, t_read)?;
    let mut target = target_kind(source, s)?;
    // One layer is all of a one-layer array: a container that holds no
    // arrays (PNG levels, OpenEXR) gets it as the one 2-D image it is.
    if target == (ImageKind::Array { layers: 1 }) && !job.kind.holds(target) {
        target = ImageKind::Plain;
    }
    let path = build_path(source, target, s);
    check_kind(job, s, source, target, path)?;
    let bases = std::mem::take(&mut input.images);
    let src = input.src;
    let out_format = output_format_for(job, s, src, path)?;
    let plan = images_plan(
        job,
        s,
        &bases,
        src,
        target,
        path,
        out_format,
        input.file_wrap,
    );
    if job.kind.stores().whole_chain {
        let (w, h) = plan.level_sizes[0];
        let full = mip::level_count(w, h, s.rounding, None);
        if s.levels.is_some_and(|n| n < full) {
            return Err(Error::from(Usage::ExrLevels { full }));
        }
    }
    let fingerprint = fingerprint(s, &plan, &bases);
    let mut out = Outcome {
        output: job.output.clone(),
        status: Status::DryRun,
        width: plan.level_sizes[0].0,
        height: plan.level_sizes[0].1,
        format: out_format,
        level_sizes: plan.level_sizes.clone(),
        read_s: input.read_s,
        build_s: 0.0,
        write_s: 0.0,
        notes: std::mem::take(&mut input.notes)
            .into_iter()
            .chain(super::decoded_note(src, out_format))
            .chain(super::codes_decoded_note(src, out_format))
            .collect(),
        blocks: None,
        block_format: s.compress.map(|(bf, _)| block_label(bf, out_format)),
        image_kind: target,
        plan: plan.clone(),
        lighting: super::lighting(s, &plan),
    };
    if s.dry_run {
        return Ok(out);
    }
    let stored = |p: &std::path::Path, k| {
        io::stored_fingerprint(p, k).as_deref() == Some(fingerprint.as_str())
    };
    if s.update
        && stored(&job.output, job.kind)
        && s.env.irradiance.as_ref().is_none_or(|(p, k)| stored(p, *k))
        && s.env
            .brdf_lut
            .as_ref()
            .is_none_or(|(p, k, _)| stored(p, *k))
    {
        out.status = Status::UpToDate;
        return Ok(out);
    }
    out.status = Status::Written;
    let t_build = Instant::now();
    let images = build(
        bases,
        source,
        target,
        &plan,
        src,
        s,
        &mut out.notes,
        progress,
    )?;
    if let Some(l) = &mut out.lighting {
        l.sh9 = Some(prefilter::sh9(&environment_faces(&images, target)?)?);
    }
    out.build_s = t_build.elapsed().as_secs_f64();
    let blocks = match s.compress {
        Some((bf, quality)) => {
            out.notes.extend(compress_notes(bf, src, &plan.level_sizes));
            Some(encode_images(&images, bf, quality, s, progress)?)
        }
        None => None,
    };
    progress(Stage::Writing);
    let t_write = Instant::now();
    let mut save = save_options(s, &plan, src, fingerprint, None);
    save.one_d = input.one_d && source == target && images.iter().all(|l| l[0].height() == 1);
    let kept = kept_level0(job, source, target, input.placed, &images)?;
    write(
        job,
        s,
        &plan,
        &save,
        &images,
        blocks.as_ref().map(|b| &b.0),
        kept,
    )?;
    out.write_s = t_write.elapsed().as_secs_f64();
    out.blocks = blocks.and_then(|(_, r)| r);
    Ok(out)
}

/// Every image's levels encoded as `bf` blocks, and one report of them
/// all ([`merge_reports`]).
fn encode_images(
    images: &[Vec<Texture>],
    bf: crate::compress::BlockFormat,
    quality: crate::compress::Quality,
    s: &Settings,
    progress: &mut dyn FnMut(Stage),
) -> Result<(Vec<BlockChain>, Option<BlockReport>)> {
    let mut chains = Vec::with_capacity(images.len());
    let mut report: Option<BlockReport> = None;
    for levels in images {
        let (chain, r) = encode_chain(levels, bf, quality, s.measure_blocks, progress)?;
        chains.push(chain);
        report = Some(match report {
            None => r,
            Some(sum) => merge_reports(sum, r),
        });
    }
    Ok((chains, report))
}

/// The fingerprint of a job of `plan` over its images `bases` (every
/// image's level 0 and every setting that changes the output).
fn fingerprint(s: &Settings, plan: &Plan, bases: &[Texture]) -> String {
    let mut text = fingerprint_text(s, &plan.options, &plan.out_format, plan.kind);
    text += &format!(" image={:?} env={:?}", plan.image_kind, s.env);
    for b in &bases[1..] {
        text += " ";
        text += &io::fingerprint(b, "");
    }
    io::fingerprint(&bases[0], &text)
}

/// The input's level 0 of each image, as the file placed its texels and
/// in the built levels' formats, where the output container places them
/// the same way (an OpenEXR environment written to OpenEXR) and the
/// image stays of its kind: written as it was read rather than resampled
/// to centred texels and back.
fn kept_level0(
    job: &Job,
    source: ImageKind,
    target: ImageKind,
    placed: Option<(Placement, Vec<Texture>)>,
    images: &[Vec<Texture>],
) -> Result<Option<(Placement, Vec<Texture>)>> {
    let Some((placement, levels)) = placed else {
        return Ok(None);
    };
    if placement != job.kind.placement() || source != target || levels.len() != images.len() {
        return Ok(None);
    }
    let kept = levels
        .into_iter()
        .zip(images)
        .map(|(t, built)| mip::band::convert_level(t, built[0].format()))
        .collect::<Result<Vec<_>>>()?;
    Ok(Some((placement, kept)))
}

/// Write the built `images` (or their `blocks`) and the irradiance beside
/// them, through the containers' `save`; `kept` replaces level 0 of each
/// image (already placed as the container places texels,
/// [`kept_level0`]).
fn write(
    job: &Job,
    s: &Settings,
    plan: &Plan,
    save: &SaveOptions,
    images: &[Vec<Texture>],
    blocks: Option<&Vec<BlockChain>>,
    kept: Option<(Placement, Vec<Texture>)>,
) -> Result<()> {
    let target = plan.image_kind;
    let refs: Vec<&[Texture]> = images.iter().map(Vec::as_slice).collect();
    match (blocks, kept) {
        (Some(chains), _) => io::save_blocks(chains, target, &job.output, job.kind, save)?,
        (None, Some((placement, level0))) => {
            let mut placed = io::exr::edges_from_centred(&refs, target, 1)?;
            for (levels, t) in placed.iter_mut().zip(level0) {
                levels[0] = t;
            }
            let refs: Vec<&[Texture]> = placed.iter().map(Vec::as_slice).collect();
            let save = SaveOptions {
                placement,
                ..save.clone()
            };
            io::save_images(&refs, target, s.rounding, &job.output, job.kind, &save)?
        }
        (None, None) => io::save_images(&refs, target, s.rounding, &job.output, job.kind, save)?,
    }
    if let Some((path, kind)) = &s.env.irradiance {
        write_irradiance(images, target, s, path, *kind, save)?;
    }
    if let Some((path, kind, size)) = &s.env.brdf_lut {
        write_brdf_lut(*size, s, path, *kind, save)?;
    }
    Ok(())
}

/// The input's images (level 0 of each), read as [`super::read`] reads a
/// 2-D image: interpreted under the settings, NaN policy applied, resized.
struct Images {
    images: Vec<Texture>,
    /// Level 0 of each image as the file places its texels, where that
    /// is not centred (an OpenEXR environment; `images` holds them
    /// resampled to centred) and no resize changed them: written back
    /// as they are to a container of the same placement.
    placed: Option<(crate::env::Placement, Vec<Texture>)>,
    src: Format,
    file_wrap: Option<Wrap>,
    notes: Vec<Note>,
    read_s: f64,
    /// The source is a 1-D texture or array (see [`io::SourceInfo::one_d`]).
    one_d: bool,
}

/// Load (six face files) or interpret `loaded` as a [`Source`], and read
/// its images.
fn read(
    job: &Job,
    s: &Settings,
    loaded: Option<Loaded>,
    t_read: Instant,
) -> Result<(ImageKind, Images)> {
    let options = load_options(s);
    let one_d = loaded.as_ref().is_some_and(|l| l.info.one_d);
    let (source, (mut notes, data), file_wrap) = match loaded {
        Some(l) => {
            let notes = load_notes(&l, s, job.kind);
            let wrap = l.info.wrap;
            (source::interpret(l, &job.input, s.env.target)?, notes, wrap)
        }
        None => {
            let faces = job
                .faces
                .iter()
                .map(|f| io::load_with(f, &s.limits, &options))
                .collect::<Result<Vec<_>>>()?;
            let notes = load_notes(&faces[0], s, job.kind);
            (source::from_faces(faces, &job.faces)?, notes, None)
        }
    };
    let Source {
        kind,
        images,
        placement,
    } = source;
    let mut placed = (placement != Placement::Centred).then(Vec::new);
    let mut bases = Vec::with_capacity(images.len());
    let mut src = None;
    let read_s = t_read.elapsed().as_secs_f64();
    let wrap = image_wrap(kind, s, file_wrap);
    for mut levels in images {
        let base = levels.swap_remove(0);
        let f = read_as(base.format(), s, data);
        let mut base = base.reinterpret(f)?;
        if base.channel_type().is_float() {
            mip::nan::apply(&mut base, s.nan_policy)?;
        }
        if let Some(p) = &mut placed {
            let centred = io::exr::centred_from_edges(&base)?;
            p.push(std::mem::replace(&mut base, centred));
        }
        let (base, resized) = resize(base, s, wrap)?;
        if resized.is_some() {
            placed = None;
        }
        if bases.is_empty() {
            notes.extend(resized);
        }
        src.get_or_insert(f);
        bases.push(base);
    }
    let src = src.ok_or_else(|| Error::InvalidOption("the input holds no image".into()))?;
    Ok((
        kind,
        Images {
            images: bases,
            placed: placed.map(|p| (placement, p)),
            src,
            file_wrap,
            notes,
            read_s,
            one_d,
        },
    ))
}

/// The wrap modes images of `kind` are filtered with: the settings' or
/// the file's for a 2-D image or an array's layers; clamp to edge for
/// cube faces (their neighbours are joined after, [`cube::fix_edges`])
/// and lat-long maps (whose builder wraps by longitude itself).
fn image_wrap(kind: ImageKind, s: &Settings, file_wrap: Option<Wrap>) -> Wrap {
    match kind {
        ImageKind::Array { .. } | ImageKind::Plain => s.wrap.or(file_wrap).unwrap_or_default(),
        _ => Wrap::both(WrapMode::ClampToEdge),
    }
}

/// The kind the output holds: the source's, or the environment the
/// settings ask for (a lat-long map made a cube map, or the reverse).
fn target_kind(source: ImageKind, s: &Settings) -> Result<ImageKind> {
    use Environment as E;
    use ImageKind as K;
    match (source, s.env.target) {
        (K::Plain, _) => Err(Error::from(plain_refusal(s))),
        (k, None) => Ok(k),
        (K::LatLong | K::Cube, Some(E::LatLong)) => Ok(K::LatLong),
        (K::LatLong | K::Cube, Some(E::Cube)) => Ok(K::Cube),
        (kind, Some(target)) => Err(Error::from(Usage::NotAnEnvironment { kind, target })),
    }
}

/// Why an environment setting does not apply to one 2-D image.
fn plain_refusal(s: &Settings) -> Usage {
    let not = |setting| Usage::NotForKind {
        setting,
        kind: ImageKind::Plain,
        why: "it applies to environment maps (set EnvSettings::target for a 2-D image that \
              holds one)",
    };
    if s.env.irradiance.is_some() {
        Usage::IrradianceNeedsEnvironment
    } else if s.env.face_size.is_some() {
        not(Setting::FaceSize)
    } else if !s.env.edge_fixup {
        not(Setting::NoEdgeFixup)
    } else {
        not(Setting::Prefilter)
    }
}

/// The one place the build path of an image of `source` made into
/// `target` is decided.
fn build_path(source: ImageKind, target: ImageKind, s: &Settings) -> BuildPath {
    if s.env.prefilter.is_some() {
        BuildPath::Prefiltered
    } else if source == ImageKind::LatLong || target == ImageKind::LatLong {
        // A lat-long map, one made from a cube map, or a cube map made
        // from one.
        BuildPath::Environment
    } else if target.is_cube() {
        BuildPath::Faces
    } else {
        BuildPath::Layers
    }
}

/// Every setting that does not apply to this build refused, with why.
fn check_kind(
    job: &Job,
    s: &Settings,
    source: ImageKind,
    target: ImageKind,
    path: BuildPath,
) -> Result<()> {
    let not = |setting, why| {
        Err(Error::from(Usage::NotForKind {
            setting,
            kind: target,
            why,
        }))
    };
    if !job.kind.holds(target) {
        return Err(kind_not_stored(target, job.kind));
    }
    job.kind.check_path(&job.output, target)?;
    let environment = target.is_cube() || target == ImageKind::LatLong;
    if s.roughness.is_some() {
        return not(
            Setting::Roughness,
            "a roughness chain is built beside one 2-D normal map",
        );
    }
    if s.normal_map && path != BuildPath::Layers {
        return not(
            Setting::NormalMap,
            "normal maps are built as 2-D textures or arrays of them",
        );
    }
    if environment && s.wrap.is_some() {
        return not(
            Setting::Wrap,
            "cube faces meet their neighbours at the edges and a lat-long map wraps by longitude",
        );
    }
    if environment && s.rounding == Rounding::Up {
        return not(
            Setting::Rounding,
            "cube faces and lat-long maps halve by rounding down, as the GPU and OpenEXR's \
             environment maps define them",
        );
    }
    if matches!(path, BuildPath::Environment | BuildPath::Prefiltered) && s.alpha_coverage.is_some()
    {
        return not(
            Setting::AlphaCoverage,
            "alpha coverage is kept per 2-D image (arrays and cube faces), not through a \
             conversion or a prefilter",
        );
    }
    if target == ImageKind::LatLong && s.filter != MipFilter::Box {
        return not(
            Setting::Filter,
            "a lat-long map's levels are boxes weighted by solid angle (maketx --envlatl's \
             filter)",
        );
    }
    if s.env.face_size.is_some() && !(source == ImageKind::LatLong && target == ImageKind::Cube) {
        return not(
            Setting::FaceSize,
            "only a lat-long map made into a cube map takes a new face size",
        );
    }
    if !s.env.edge_fixup && !target.is_cube() {
        return not(Setting::NoEdgeFixup, "only cube faces have edges to join");
    }
    if s.env.irradiance.is_some() && !environment {
        return Err(Error::from(Usage::IrradianceNeedsEnvironment));
    }
    Ok(())
}

/// The plan of an image of `target` from `bases` (level 0 of each source
/// image, read as `src`).
#[allow(clippy::too_many_arguments)]
fn images_plan(
    job: &Job,
    s: &Settings,
    bases: &[Texture],
    src: Format,
    target: ImageKind,
    path: BuildPath,
    out_format: Format,
    file_wrap: Option<Wrap>,
) -> Plan {
    let (w, h) = (bases[0].width(), bases[0].height());
    let (w, h) = match (bases.len(), target) {
        // A lat-long map made a cube map: faces of a quarter of its width.
        (1, ImageKind::Cube) => {
            let n = s.env.face_size.unwrap_or((w / 4).max(1));
            (n, n)
        }
        // A cube map made a lat-long map: 4n x 2n.
        (6, ImageKind::LatLong) => (4 * w, 2 * w),
        _ => (w, h),
    };
    let mut options = plan::mip_options(s, file_wrap, out_format);
    options.wrap = image_wrap(target, s, file_wrap);
    let level_sizes = mip::level_sizes(w, h, s.rounding, s.levels);
    let work = match path {
        BuildPath::Prefiltered | BuildPath::Environment => {
            Format::new(4, ChannelType::F32, ColorSpace::Linear).with_alpha(src.alpha)
        }
        _ => src,
    };
    let association =
        (out_format.has_alpha() && work.alpha != out_format.alpha).then_some(out_format.alpha);
    let per_image = plan::memory(path, &bases[0], src, out_format, &level_sizes);
    let route = plan::colour_route(src, out_format, association, s, &options, &level_sizes);
    Plan {
        kind: job.kind,
        image_kind: target,
        out_format,
        options,
        level_sizes,
        association,
        path,
        route,
        memory_bytes: per_image * target.images() as u64,
    }
}

/// Build every image's chain as `plan` says, stored as its output format.
#[allow(clippy::too_many_arguments)]
fn build(
    bases: Vec<Texture>,
    source: ImageKind,
    target: ImageKind,
    plan: &Plan,
    src: Format,
    s: &Settings,
    notes: &mut Vec<Note>,
    progress: &mut dyn FnMut(Stage),
) -> Result<Vec<Vec<Texture>>> {
    let per_image: u64 = plan.level_sizes[1..]
        .iter()
        .map(|&(w, h)| w as u64 * h as u64)
        .sum();
    progress(Stage::Building {
        total_texels: per_image * target.images() as u64,
    });
    let (images, clipped) = match plan.path {
        BuildPath::Layers | BuildPath::Faces => layers(bases, plan, src, s, per_image, progress)?,
        _ => environment(bases, source, target, plan, src, s)?,
    };
    let mut images = images;
    // Prefiltered levels are the integral at each texel's own direction:
    // joining their edges would move them off it.
    if target.is_cube() && s.env.edge_fixup && plan.path != BuildPath::Prefiltered {
        images = join_edges(images, &plan.options)?;
    }
    if let Some(c) = clipped {
        notes.push(Note::Clipped {
            clipped: c.clipped,
            texels: c.texels,
            to: plan.out_format.channel_type,
        });
    }
    Ok(images)
}

/// Each image built as a 2-D colour chain (or normal vectors), straight
/// into the output format.
fn layers(
    bases: Vec<Texture>,
    plan: &Plan,
    src: Format,
    s: &Settings,
    per_image: u64,
    progress: &mut dyn FnMut(Stage),
) -> Result<(Vec<Vec<Texture>>, Option<mip::band::Clipped>)> {
    let mut images = Vec::with_capacity(bases.len());
    let mut clipped: Option<mip::band::Clipped> = None;
    for (i, base) in bases.into_iter().enumerate() {
        let before = i as u64 * per_image;
        let mut on_progress = |p: mip::Progress| {
            progress(Stage::Built {
                texels_done: before + p.texels_done,
            })
        };
        let levels = if s.normal_map {
            mip::normal::build(base, &plan.options, plan.out_format, &mut on_progress)?
        } else {
            let (levels, c) = mip::band::build_converted(
                base,
                &plan.options,
                src,
                plan.out_format,
                plan.association,
                plan.route,
                &mut on_progress,
            )?;
            add_clipped(&mut clipped, c);
            levels
        };
        images.push(levels);
    }
    Ok((images, clipped))
}

/// A lat-long map's chain, a conversion between lat-long and cube maps,
/// or prefiltered levels: built in linear f32, stored once in the output
/// format.
fn environment(
    bases: Vec<Texture>,
    source: ImageKind,
    target: ImageKind,
    plan: &Plan,
    src: Format,
    s: &Settings,
) -> Result<(Vec<Vec<Texture>>, Option<mip::band::Clipped>)> {
    let f32_of = |b: Texture| {
        let f = Format::new(b.format().channels, ChannelType::F32, ColorSpace::Linear)
            .with_alpha(b.format().alpha);
        b.convert(f)
    };
    let mut lin = bases.into_iter().map(f32_of).collect::<Result<Vec<_>>>()?;
    let levels = plan.level_sizes.len();
    let full = MipOptions {
        max_levels: None,
        ..plan.options
    };
    let truncated = |chain: MipChain| {
        let mut l = chain.into_levels();
        l.truncate(levels);
        l
    };
    let mut chains: Vec<MipChain> = match (source, target) {
        (ImageKind::LatLong, ImageKind::LatLong) => {
            vec![latlong::build_chain(lin.swap_remove(0))?]
        }
        (ImageKind::LatLong, _) => {
            let ll = latlong::build_chain(lin.swap_remove(0))?;
            let faces = convert::latlong_to_cube(&ll, plan.level_sizes[0].0)?;
            cube::build_faces(faces, &plan.options)?
        }
        (_, ImageKind::LatLong) => {
            let faces = cube::build_faces(lin, &full)?;
            let n = faces[0].levels()[0].width();
            let base = convert::cube_to_latlong(&faces, 4 * n, 2 * n)?;
            vec![latlong::build_chain(base)?]
        }
        _ => cube::build_faces(lin, &plan.options)?,
    };
    if let Some((lobe, how)) = s.env.prefilter {
        chains = prefilter::specular(&chains, lobe, how)?;
    }
    let count_clipped = src.channel_type.is_float() && !plan.out_format.channel_type.is_float();
    let mut images = Vec::with_capacity(chains.len());
    let mut clipped: Option<mip::band::Clipped> = None;
    for chain in chains {
        let (l, c) = mip::band::finish_levels(
            truncated(chain),
            plan.association,
            plan.out_format,
            count_clipped,
        )?;
        add_clipped(&mut clipped, c);
        images.push(l);
    }
    Ok((images, clipped))
}

/// `c` (one image's clipped texels) added to the job's `sum`.
fn add_clipped(sum: &mut Option<mip::band::Clipped>, c: Option<mip::band::Clipped>) {
    if let Some(c) = c {
        let s = sum.get_or_insert(mip::band::Clipped {
            clipped: 0,
            texels: 0,
        });
        s.clipped += c.clipped;
        s.texels += c.texels;
    }
}

/// Every cube's faces joined at their edges from level 1 on
/// ([`cube::fix_edges`]).
fn join_edges(images: Vec<Vec<Texture>>, options: &MipOptions) -> Result<Vec<Vec<Texture>>> {
    let mut out = Vec::with_capacity(images.len());
    let mut faces = images.into_iter();
    loop {
        let cube: Vec<MipChain> = faces
            .by_ref()
            .take(6)
            .map(|l| MipChain::from_levels(l, *options))
            .collect::<Result<_>>()?;
        if cube.is_empty() {
            return Ok(out);
        }
        out.extend(
            cube::fix_edges(cube, 1)?
                .into_iter()
                .map(MipChain::into_levels),
        );
    }
}

/// Two block reports of one job's images as one: bytes and times summed
/// per level, the worst image's PSNR.
fn merge_reports(mut a: BlockReport, b: BlockReport) -> BlockReport {
    for (x, y) in a.levels.iter_mut().zip(b.levels) {
        x.bytes += y.bytes;
        x.encode_s += y.encode_s;
        x.psnr_db = match (x.psnr_db, y.psnr_db) {
            (Some(p), Some(q)) => Some(p.min(q)),
            (p, q) => p.or(q),
        };
    }
    a.uncompressed_bytes += b.uncompressed_bytes;
    a.encode_s += b.encode_s;
    a
}

/// The save options of a file written beside the job's output: its
/// attributes without the specular levels' own, and `what` it holds.
fn beside(save: &SaveOptions, what: (&str, &str)) -> SaveOptions {
    let mut save = save.clone();
    save.attributes
        .retain(|(k, _)| k != "parvo:prefilter" && k != "parvo:roughness");
    save.attributes.push((what.0.into(), what.1.into()));
    save
}

/// GGX's split-sum BRDF table ([`prefilter::dfg::table`]), `size²`,
/// written to `path`: as `--type` says where the container stores it,
/// else f16 (16-bit for PNG).
fn write_brdf_lut(
    size: u32,
    s: &Settings,
    path: &std::path::Path,
    kind: OutputKind,
    save: &SaveOptions,
) -> Result<()> {
    let table = prefilter::dfg::table(size)?;
    let ty = s
        .out_type
        .filter(|t| kind.supports(*t))
        .or([ChannelType::F16, ChannelType::U16]
            .into_iter()
            .find(|t| kind.supports(*t)))
        .unwrap_or(kind.default_type(ChannelType::F16));
    let out = kind.storable(Format {
        channel_type: ty,
        ..table.format()
    });
    let level = mip::band::convert_level(table, out)?;
    let save = beside(
        save,
        (
            "parvo:brdf-lut",
            "GGX split sum: R scale, G bias of F0; n.v across, roughness down",
        ),
    );
    let images = [std::slice::from_ref(&level)];
    io::save_images(&images, ImageKind::Plain, Rounding::Down, path, kind, &save)
}

/// The output format of a job of `path` over a source of format `src`:
/// prefiltered levels are linear RGBA floats (f32 for f32 sources).
fn output_format_for(job: &Job, s: &Settings, src: Format, path: BuildPath) -> Result<Format> {
    if path != BuildPath::Prefiltered {
        return output_format_of(job, s, src);
    }
    let ty = if src.channel_type == ChannelType::F32 {
        ChannelType::F32
    } else {
        ChannelType::F16
    };
    output_format_of(job, s, Format::new(4, ty, ColorSpace::Linear))
}

/// The first cube map of the built `images` (a cube map's faces, or a
/// lat-long map made one, faces a quarter of its width) as six face
/// chains, for the lighting computed from it.
fn environment_faces(images: &[Vec<Texture>], target: ImageKind) -> Result<Vec<MipChain>> {
    let chain = |l: &Vec<Texture>| MipChain::from_levels(l.clone(), MipOptions::default());
    if target == ImageKind::LatLong {
        let ll = chain(&images[0])?;
        let n = (ll.levels()[0].width() / 4).max(1);
        cube::build_faces(convert::latlong_to_cube(&ll, n)?, &MipOptions::default())
    } else {
        images[..6].iter().map(chain).collect()
    }
}

/// The diffuse irradiance of the environment `images` (a cube map's
/// faces, or a lat-long map made a cube map first), written as a cube
/// map of 32×32 faces to `path`.
fn write_irradiance(
    images: &[Vec<Texture>],
    target: ImageKind,
    s: &Settings,
    path: &std::path::Path,
    kind: OutputKind,
    save: &SaveOptions,
) -> Result<()> {
    let irr = prefilter::irradiance(&environment_faces(images, target)?, 32)?;
    let ty = s
        .out_type
        .filter(|t| kind.supports(*t))
        .unwrap_or(kind.default_type(ChannelType::F16));
    let stored = irr
        .into_iter()
        .map(|c| {
            let f = c.levels()[0].format();
            let out = kind.storable(Format {
                channel_type: ty,
                ..f
            });
            c.into_levels()
                .into_iter()
                .map(|l| mip::band::convert_level(l, out))
                .collect::<Result<Vec<_>>>()
        })
        .collect::<Result<Vec<_>>>()?;
    let refs: Vec<&[Texture]> = stored.iter().map(Vec::as_slice).collect();
    if !kind.holds(ImageKind::Cube) {
        return Err(kind_not_stored(ImageKind::Cube, kind));
    }
    let save = beside(save, ("parvo:irradiance", "cosine lobe / pi, quadrature"));
    io::save_images(&refs, ImageKind::Cube, Rounding::Down, path, kind, &save)
}
