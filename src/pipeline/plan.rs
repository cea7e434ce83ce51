//! A job's [`Plan`]: how its chain is built and written, decided once.

use std::time::Instant;

use super::{Job, Settings, Stage};
use crate::error::{Error, Result};
use crate::io::{self, OutputKind};
use crate::mip::band::Route;
use crate::mip::{self, MipOptions};
use crate::texel::{AlphaMode, ChannelType, ColorSpace, Format, Texels};
use crate::texture::{ImageKind, Texture};
use crate::wrap::Wrap;

/// How one job is built and written, decided once per job from its
/// output, the settings and the input's size and format: the output
/// format, the path through the builder, and the memory that path holds.
/// The buffers faulted in during the read (the fused write's levels)
/// and the write both follow [`Plan::fuses`].
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// The output container.
    pub kind: OutputKind,
    /// What the output holds (a 2-D image, a cube map, an array, ...).
    pub image_kind: ImageKind,
    /// The stored texel format.
    pub out_format: Format,
    /// The chain's options (the file's wrap mode when no setting names one).
    pub options: MipOptions,
    /// Every level's size.
    pub level_sizes: Vec<(u32, u32)>,
    /// The alpha mode the levels change to, when the output's differs from
    /// the source's.
    pub association: Option<AlphaMode>,
    /// The way through the builder.
    pub path: BuildPath,
    /// The colour chain's route through `mip::band::build_converted`
    /// (per image for arrays and faces), decided with `path`.
    pub(crate) route: Route,
    /// Estimated bytes the build holds at its peak: the source, the
    /// output chain and the f32 working levels of `path` (not measured;
    /// see the band builders of `mip::band` for the figures).
    pub memory_bytes: u64,
}

/// The way a chain goes through the builder.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BuildPath {
    /// Normal vectors and a roughness chain ([`mip::roughness`]).
    Roughness,
    /// Normal vectors ([`mip::normal`]).
    Normal,
    /// Colour in the source's own format, the whole-level build
    /// ([`mip::build`]).
    Whole,
    /// Colour converted to another format with level 0 decoded whole to
    /// linear f32 (alpha coverage, a single level, a float source to an
    /// integer output).
    Decoded,
    /// Colour converted band by band with the 2×2 box of levels that
    /// halve exactly (`mip::band`).
    Streamed,
    /// Colour converted band by band with the general filters.
    Banded,
    /// [`BuildPath::Streamed`] or [`BuildPath::Banded`] with level 0
    /// written to OpenEXR as its bands are made, never held whole
    /// ([`io::exr::save_streamed`]).
    FusedExr,
    /// The layers of an array, each built as a 2-D colour chain (or normal
    /// vectors) by the whole-level builder.
    Layers,
    /// The six faces of each cube map, each built on its own with clamped
    /// edges, then joined at the edges
    /// ([`crate::env::cube::fix_edges`]).
    Faces,
    /// A lat-long map's levels weighted by solid angle
    /// ([`crate::env::latlong::build_chain`]), or a cube map made from
    /// one, or one made from a cube map ([`crate::env::convert`]), in
    /// linear f32.
    Environment,
    /// Prefiltered specular levels of a cube map
    /// ([`crate::env::prefilter::specular`]), in linear f32.
    Prefiltered,
}

impl Plan {
    /// Whether a colour chain that converts goes to the fused EXR write:
    /// a question of the container and the settings alone, so the
    /// prefault during the read (which knows no more) and the write ask
    /// the same one.
    pub fn fuses(kind: OutputKind, s: &Settings) -> bool {
        kind.stores().streamed_level0
            && s.compress.is_none()
            && s.roughness.is_none()
            && !s.normal_map
    }

    /// The plan of `job` for a level 0 `base` read as `src` (the source's
    /// texels as the build reads them), stored as `out_format`; `same`:
    /// the chain is built in the source's format.
    pub(crate) fn new(
        job: &Job,
        s: &Settings,
        base: &Texture,
        src: Format,
        out_format: Format,
        options: MipOptions,
    ) -> Plan {
        let (w, h) = (base.width(), base.height());
        let level_sizes = mip::level_sizes(w, h, s.rounding, s.levels);
        let association =
            (out_format.has_alpha() && src.alpha != out_format.alpha).then_some(out_format.alpha);
        let route = colour_route(src, out_format, association, s, &options, &level_sizes);
        let path = if s.roughness.is_some() {
            BuildPath::Roughness
        } else if s.normal_map {
            BuildPath::Normal
        } else {
            converted_path(job.kind, s, route, &options, &level_sizes)
        };
        let memory_bytes = memory(path, base, src, out_format, &level_sizes);
        Plan {
            kind: job.kind,
            image_kind: ImageKind::Plain,
            out_format,
            options,
            level_sizes,
            association,
            path,
            route,
            memory_bytes,
        }
    }
}

/// A colour chain is built in linear f32 and converted (the source is not
/// the output format, or alpha coverage needs unrounded alpha).
pub(crate) fn converts(
    src: Format,
    out: Format,
    association: Option<AlphaMode>,
    s: &Settings,
) -> bool {
    // Alpha coverage is matched on the unrounded filtered alpha (rounding
    // each level to 8 bits first would tie texels the test must separate),
    // so it always builds in f32.
    let same = src.channel_type == out.channel_type
        && src.color_space == out.color_space
        && association.is_none()
        && s.alpha_coverage.is_none();
    !same
}

/// The route of a colour chain: in the source's format when it is the
/// output's, else band by band where a band builder applies, else decoded
/// whole. A float source holding NaN or infinities is found only when the
/// build reads it, and is decoded whole then (the NaN policy applies to
/// level 0 whole).
pub(crate) fn colour_route(
    src: Format,
    out: Format,
    association: Option<AlphaMode>,
    s: &Settings,
    options: &MipOptions,
    sizes: &[(u32, u32)],
) -> Route {
    if !converts(src, out, association, s) {
        return Route::Whole;
    }
    let (w, h) = sizes[0];
    // A float source to a normalised output clips: decoded whole.
    if src.channel_type.is_float() && !out.channel_type.is_float() {
        return Route::Decoded;
    }
    if mip::band::box_band_rows(w, h, options).is_some() {
        Route::Streamed
    } else if sizes.len() >= 2 && options.alpha_coverage.is_none() && !options.normal_map {
        Route::Banded
    } else {
        Route::Decoded
    }
}

/// The build path of a colour chain taking `route`: the fused EXR write
/// when the output and the band height allow it.
fn converted_path(
    kind: OutputKind,
    s: &Settings,
    route: Route,
    options: &MipOptions,
    sizes: &[(u32, u32)],
) -> BuildPath {
    let (path, band) = match route {
        Route::Whole => return BuildPath::Whole,
        Route::Decoded => return BuildPath::Decoded,
        Route::Streamed => {
            let (w, h) = sizes[0];
            let rows = mip::band::box_band_rows(w, h, options).unwrap_or(1);
            (BuildPath::Streamed, rows)
        }
        Route::Banded => (BuildPath::Banded, 1),
    };
    if Plan::fuses(kind, s) && fused_group(band, s.exr.tile.1 as usize).is_some() {
        BuildPath::FusedExr
    } else {
        path
    }
}

/// The peak bytes `path` holds, estimated (see [`Plan::memory_bytes`]).
pub(crate) fn memory(
    path: BuildPath,
    base: &Texture,
    src: Format,
    out: Format,
    sizes: &[(u32, u32)],
) -> u64 {
    let texels = |k: usize| sizes[k].0 as u64 * sizes[k].1 as u64;
    let source = base.byte_len() as u64;
    let level0 = texels(0) * out.texel_bytes() as u64;
    let above0: u64 = (1..sizes.len())
        .map(|k| texels(k) * out.texel_bytes() as u64)
        .sum();
    // Linear f32 of the source's channels.
    let f32_of = |k: usize| texels(k) * src.channels as u64 * 4;
    let f32_1 = if sizes.len() > 1 { f32_of(1) } else { 0 };
    match path {
        // The working level after level 0 (level 1 at most) in f32.
        BuildPath::Whole | BuildPath::Streamed | BuildPath::Banded => {
            source + level0 + above0 + f32_1
        }
        BuildPath::FusedExr => source + above0 + f32_1,
        // The f32 chain whole, then converted smallest level first.
        BuildPath::Decoded => f32_of(0) * 4 / 3 + level0 + above0,
        // Vectors (three f32 channels) of the whole chain.
        BuildPath::Normal | BuildPath::Roughness => {
            source + texels(0) * 12 * 4 / 3 + level0 + above0
        }
        // Per image: one image's working chain beside the output chain
        // (the images' figures are multiplied by their count).
        BuildPath::Layers | BuildPath::Faces => source + f32_of(0) * 4 / 3 + level0 + above0,
        // The f32 chain whole (RGBA for prefiltered levels), then converted.
        BuildPath::Environment | BuildPath::Prefiltered => {
            source + texels(0) * 16 * 4 / 3 + level0 + above0
        }
    }
}

/// The chain's options under `s` for a file whose own wrap mode is
/// `file_wrap`, stored as `out`.
pub(crate) fn mip_options(s: &Settings, file_wrap: Option<Wrap>, out: Format) -> MipOptions {
    MipOptions {
        filter: s.filter,
        wrap: s.wrap.or(file_wrap).unwrap_or_default(),
        rounding: s.rounding,
        max_levels: s.levels,
        alpha_coverage: s.alpha_coverage,
        alpha_store: Some(out.channel_type),
        normal_map: s.normal_map,
        nan_policy: s.nan_policy,
        fast_paths: true,
    }
}

/// Level-0 rows per group of a fused EXR write: a multiple of both the
/// band height and the tile height, and at least 4 bands so that the
/// threads share each group (`None` past 256 rows: odd tile heights).
pub(crate) fn fused_group(band: usize, tile_h: usize) -> Option<usize> {
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
/// shortcut of [`mip::band::Stream`] under [`Fused`]) for a `w`×`h` source
/// of `ch` channels of `ty`, allocated and faulted in: called from
/// [`io::load_overlapped`] on the core a single-threaded decoder leaves
/// idle, it takes the OS's clearing of fresh pages off the build (0.67 GiB
/// of half at 16384² RGBA, about 1.3 s of first touches on the project's
/// VM, some 0.7 s of the build's wall time on two threads). `None` where
/// that path will not run ([`Plan::fuses`]; nor before a resize, whose
/// size the read does not know yet); the buffers are checked again before
/// use.
pub(crate) fn prefault_streamed(
    job: &Job,
    s: &Settings,
    w: u32,
    h: u32,
    ch: u8,
    ty: ChannelType,
) -> Option<Vec<Texels>> {
    // (A dry run builds nothing: no buffers to make.)
    let fused = Plan::fuses(job.kind, s) && !s.dry_run && s.resize_to.is_none();
    let out = super::output_format(Format::new(ch, ty, ColorSpace::Linear), job.kind, s).ok()?;
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
    if !fused || out.channel_type == ty || fused_group(band, s.exr.tile.1 as usize).is_none() {
        return None;
    }
    mip::band::prefault(w, h, &options, out)
}

/// A band-by-band builder as the level-0 source of a streamed EXR write,
/// timing the build and reporting progress.
pub(crate) struct Fused<'a, 'p> {
    pub st: Option<mip::band::Stream<'a>>,
    pub group: usize,
    pub build: std::time::Duration,
    pub progress: &'p mut dyn FnMut(Stage),
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
    use std::path::Path;

    use super::*;
    use crate::mip::MipFilter;
    use crate::mip::band::Stream;

    fn rgba8(w: u32, h: u32) -> Texture {
        let v = (0..w as usize * h as usize * 4)
            .map(|i| (i * 7 % 251) as u8)
            .collect();
        Texture::from_u8(w, h, Format::new(4, ChannelType::U8, ColorSpace::Srgb), v).unwrap()
    }

    fn first_ptr(t: &mut Texels) -> *const u8 {
        t.bytes_mut().as_ptr()
    }

    /// The plan of a straight-alpha sRGB RGBA8 source of `w`×`h` to
    /// `out` under `s`.
    fn plan_of(out: &str, s: &Settings, w: u32, h: u32) -> Plan {
        let job = Job::new("in.png", Path::new(out)).unwrap();
        let src = Format::new(4, ChannelType::U8, ColorSpace::Srgb).with_alpha(AlphaMode::Straight);
        let base = rgba8(w, h).reinterpret(src).unwrap();
        let out = super::super::output_format(src, job.kind, s).unwrap();
        Plan::new(&job, s, &base, src, out, mip_options(s, None, out))
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
        let out = super::super::output_format(src, OutputKind::EXR, &s).unwrap();
        let assoc = Some(AlphaMode::Premultiplied);
        let base = rgba8(w, h).reinterpret(src).unwrap();
        let Ok(mut st) =
            Stream::new(base, &options, src, out, assoc, Route::Streamed, Some(bufs)).unwrap()
        else {
            panic!("the box shortcut applies to 256x96");
        };
        let got: Vec<*const u8> = st.level_buffers().iter_mut().map(first_ptr).collect();
        assert_eq!(got, ptrs);
        // Buffers of another shape are not taken.
        let mut wrong = prefault_streamed(&exr, &s, 128, 96, 4, ChannelType::U8).unwrap();
        let wrong_ptr = first_ptr(&mut wrong[0]);
        let base = rgba8(w, h).reinterpret(src).unwrap();
        let Ok(mut st) = Stream::new(
            base,
            &options,
            src,
            out,
            assoc,
            Route::Streamed,
            Some(wrong),
        )
        .unwrap() else {
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
            exr: io::exr::ExrOptions {
                tile: (64, 63),
                ..Default::default()
            },
            ..Settings::default()
        };
        assert!(none(&exr, &tall_tiles, w, h, ChannelType::U8));
    }

    /// The plan's path and the prefault agree: buffers are made exactly
    /// for the fused box write (the general band build takes none).
    #[test]
    fn the_plan_and_the_prefault_agree_on_the_fused_write() {
        let (w, h) = (256, 96);
        let cases = [
            ("out.exr", Settings::default(), BuildPath::FusedExr, true),
            (
                "out.exr",
                Settings {
                    filter: MipFilter::Kaiser,
                    ..Settings::default()
                },
                BuildPath::FusedExr,
                false,
            ),
            (
                "out.exr",
                Settings {
                    exr: io::exr::ExrOptions {
                        tile: (64, 63),
                        ..Default::default()
                    },
                    ..Settings::default()
                },
                BuildPath::Streamed,
                false,
            ),
            (
                "out.exr",
                Settings {
                    alpha_coverage: Some(0.5),
                    ..Settings::default()
                },
                BuildPath::Decoded,
                false,
            ),
            ("out.ktx2", Settings::default(), BuildPath::Whole, false),
            (
                "out.ktx2",
                Settings {
                    out_type: Some(ChannelType::F32),
                    ..Settings::default()
                },
                BuildPath::Streamed,
                false,
            ),
            (
                "out.dds",
                Settings {
                    out_type: Some(ChannelType::F16),
                    filter: MipFilter::Lanczos3,
                    ..Settings::default()
                },
                BuildPath::Banded,
                false,
            ),
        ];
        for (out, s, path, prefault) in cases {
            let plan = plan_of(out, &s, w, h);
            assert_eq!(plan.path, path, "{out} {:?}", s.filter);
            let job = Job::new("in.png", Path::new(out)).unwrap();
            let made = prefault_streamed(&job, &s, w, h, 4, ChannelType::U8).is_some();
            assert_eq!(made, prefault, "{out} {:?}", s.filter);
            assert_eq!(
                made,
                plan.path == BuildPath::FusedExr && s.filter == MipFilter::Box
            );
        }
        // The fused write never holds level 0 in the output type: 256x96
        // of RGBA half (196608 bytes) less than the same chain to KTX2.
        let fused = plan_of("out.exr", &Settings::default(), w, h);
        let ktx2 = plan_of(
            "out.ktx2",
            &Settings {
                out_type: Some(ChannelType::F16),
                ..Settings::default()
            },
            w,
            h,
        );
        assert_eq!(ktx2.memory_bytes - fused.memory_bytes, 256 * 96 * 8);
    }
}
