//! Chains stored in another format than their source's, built band by
//! band: the colour chain of [`crate::pipeline`] (an 8-bit sRGB PNG to
//! half EXR, a u16 TIFF to f32 KTX2, ...) without a full-resolution f32
//! copy of level 0.
//!
//! [`build_converted`] is the whole-chain entry: it takes the band-by-band
//! builders where they apply and otherwise decodes level 0 once to linear
//! f32, builds with [`crate::mip::build_with_progress`] and converts each level
//! once. [`Stream`] hands level 0's rows out band by band for a writer
//! that never holds level 0 in the output type (the fused EXR write,
//! [`crate::io::exr::save_streamed`]), then the rest of the chain.
//!
//! Two builders, both bit for bit the whole-image chain
//! (`tests/files/mip_streamed.rs`):
//! - [`Streamer`], the 2×2 box of levels that halve exactly: the box row
//!   kernel of [`crate::mip::band::boxes`] (the whole-level build's own band kernel)
//!   with each level's rows associated and encoded into the output type;
//! - [`Banded`], every other filter, size and wrap mode: level 0 encoded
//!   band by band, level 1 filtered from level-0 rows
//!   ([`crate::mip::separable::Reducer::band`]), the rest built from level 1.
//!
//! Both share the tail with the whole-level build: the chain below the
//! levels made band by band is [`crate::mip::build_with_progress`]'s.

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::mip::{MipChain, MipFilter, MipOptions, Progress};
use crate::texel::{AlphaMode, ChannelType, ColorSpace, Format, Texels};
use crate::texture::Texture;

/// Progress through a chain of `sizes`, counting the texels of levels
/// above 0.
fn chain_progress(sizes: &[(u32, u32)], levels_done: u32, texels_done: u64) -> Progress {
    Progress {
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
    progress: &mut dyn FnMut(Progress),
) -> Result<Vec<Texture>> {
    progress(chain_progress(sizes, first as u32 + 1, done));
    let rest_options = MipOptions {
        max_levels: Some((sizes.len() - first) as u32),
        ..*options
    };
    let chain = crate::mip::build_with_progress(level, &rest_options, &mut |q| {
        progress(chain_progress(
            sizes,
            q.levels_done + first as u32,
            done + q.texels_done,
        ))
    })?;
    Ok(chain.into_levels())
}

/// A band-by-band builder of a chain stored in another format than its
/// source's: the box shortcut ([`Streamer`]) or the general one
/// ([`Banded`]). Level 0's rows come out band by band ([`Stream::rows`]),
/// then the rest of the chain ([`Stream::finish`]).
pub(crate) enum Stream<'a> {
    /// The 2×2 box of levels that halve exactly.
    Box(Streamer<'a>),
    /// Every other filter, size and wrap mode.
    General(Banded<'a>),
}

impl<'a> Stream<'a> {
    /// The builder `route` names ([`Route::Streamed`] or
    /// [`Route::Banded`]); `Err(base)` for another route, or when the
    /// source turns out not to be bandable (a float source holding NaN or
    /// infinities, found only as it is read). `src` is `base`'s format as
    /// the build reads it, `out_format` the stored one, `association` the
    /// alpha mode the levels change to. `prepared`: the box shortcut's
    /// levels 1..=m, if made beforehand ([`prefault`]).
    pub(crate) fn new(
        base: Texture,
        options: &'a MipOptions,
        src: Format,
        out_format: Format,
        association: Option<AlphaMode>,
        route: Route,
        prepared: Option<Vec<Texels>>,
    ) -> Result<std::result::Result<Self, Texture>> {
        Ok(match route {
            Route::Streamed => {
                Streamer::new(base, options, src, out_format, association, prepared)?
                    .map(Stream::Box)
            }
            Route::Banded => {
                Banded::new(base, options, src, out_format, association).map(Stream::General)
            }
            Route::Whole | Route::Decoded => Err(base),
        })
    }

    /// The whole chain, level 0 into one buffer.
    fn build_all(mut self, progress: &mut dyn FnMut(Progress)) -> Result<Vec<Texture>> {
        let (base, out_format, sizes) = match &self {
            Stream::Box(st) => (&st.base, st.out_format, &st.sizes),
            Stream::General(bd) => (&bd.base, bd.out_format, &bd.sizes),
        };
        progress(chain_progress(sizes, 1, 0));
        let (w, h) = (base.width(), base.height());
        // Level 0 as little-endian bytes written in place by the bands on
        // all threads (zero pages from the OS: no zeroing pass).
        let n = w as usize * h as usize * out_format.channels as usize;
        let mut out0 = Texels::zeroed(out_format.channel_type, n);
        self.rows(0, out0.bytes_mut())?;
        let mut levels = vec![Texture::from_texels(w, h, out_format, out0)?];
        levels.extend(self.finish(progress)?);
        Ok(levels)
    }

    /// Level-0 rows a call of [`Self::rows`] must start and end on.
    pub(crate) fn band(&self) -> usize {
        match self {
            Stream::Box(st) => st.band,
            Stream::General(_) => 1,
        }
    }

    /// Level-0 rows `y0 ..` (as many as `dst` holds, whole bands)
    /// encoded into `dst` as little-endian bytes of the output format.
    /// Returns the texels of levels above 0 made so far (the box
    /// shortcut makes levels 1..=m with level 0's rows; the general build
    /// makes them all in [`Self::finish`]).
    pub(crate) fn rows(&mut self, y0: usize, dst: &mut [u8]) -> Result<u64> {
        match self {
            Stream::Box(st) => {
                st.rows(y0, dst)?;
                let w = st.base.width() as usize;
                let y1 = (y0 + dst.len() / (w * st.out_format.texel_bytes())) as u64;
                Ok((1..=st.m).map(|k| (w as u64 >> k) * (y1 >> k)).sum())
            }
            Stream::General(bd) => {
                bd.rows(y0, dst)?;
                Ok(0)
            }
        }
    }

    /// The source, for the whole-image build when the caller does not
    /// take the stream after all.
    pub(crate) fn into_base(self) -> Texture {
        match self {
            Stream::Box(st) => st.base,
            Stream::General(bd) => bd.base,
        }
    }

    /// The box shortcut's buffers of levels 1..=m (none for the general
    /// build), for tests that check which buffers it took.
    #[cfg(test)]
    pub(crate) fn level_buffers(&mut self) -> &mut [Texels] {
        match self {
            Stream::Box(st) => &mut st.outs,
            Stream::General(_) => &mut [],
        }
    }

    /// Levels 1.., once every row of level 0 went through [`Self::rows`].
    pub(crate) fn finish(self, progress: &mut dyn FnMut(Progress)) -> Result<Vec<Texture>> {
        match self {
            Stream::Box(st) => st.finish(progress),
            Stream::General(bd) => bd.finish(progress),
        }
    }
}

/// Level-0 rows per band of the box shortcut for a `w`×`h` level 0 built
/// with `options`, when it applies (whatever the texels).
pub(crate) fn box_band_rows(w: u32, h: u32, options: &MipOptions) -> Option<usize> {
    Streamer::plan(w, h, options).map(|(_, m)| 1 << m)
}

/// The buffers of the box shortcut's levels 1..=m for a `w`×`h` level 0
/// built with `options` and stored as `out`, allocated and faulted in
/// (`None` where the shortcut does not apply): made ahead, on a core a
/// decoder leaves idle, and handed to [`Stream::new`], which checks them
/// again before use.
pub(crate) fn prefault(w: u32, h: u32, options: &MipOptions, out: Format) -> Option<Vec<Texels>> {
    let (sizes, m) = Streamer::plan(w, h, options)?;
    let mut bufs = Streamer::level_buffers(&sizes, m, out);
    for b in &mut bufs {
        let bytes = b.bytes_mut();
        crate::mem::populate(bytes.as_ptr(), bytes.len());
    }
    Some(bufs)
}

/// A band-by-band box build ([`Stream`]): the colour chain of a source (u8, u16, or f16/f32 without NaN or
/// infinities) converted to another type, box filter, even-sized levels, without a full-resolution f32 copy
/// of any level: level 0 is cut into bands of 2^m rows (m ≤ 6 levels that
/// halve exactly: both sides divisible by 2^m, m ≤ 4), and each band, on its own
/// thread, is decoded to linear f32, reduced through levels 1..m with the
/// box row kernel of the whole-level path ([`crate::mip::fast`]), and every
/// level's rows are alpha-associated and encoded into the output type as
/// soon as they exist. Level m's f32 rows are kept (1/4^m of level 0) and
/// the rest of the chain is built from them as before. Decoding, the row
/// kernel, association and encoding are row-local, so the chain is bit for
/// bit the whole-image one (`tests/files/mip_streamed.rs`).
///
/// [`Streamer::new`] hands the source back when the shortcut does not
/// apply (other filters, odd sizes, alpha coverage, float sources holding
/// NaN or infinities): [`Stream::new`] then tries [`Banded`].
/// Memory: the source, the output chain and two threads' bands (about
/// 1.4 × 16 level-0 rows of f32 each): for RGBA8 → half EXR
/// 4 + 8 × 4/3 bytes per level-0 texel (4 + 8/3 to EXR, which never holds
/// level 0: [`crate::io::exr::save_streamed`]), where decoding level 0 whole held
/// 4 + 16 + 8 × 4/3 at the end of the build. The struct holds the source,
/// levels 1..=m in the output type (filled band by band) and level m's f32
/// rows, kept to build the rest of the chain from.
pub(crate) struct Streamer<'a> {
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
        let sizes = crate::mip::level_sizes(w, h, options.rounding, options.max_levels);
        // The whole-level build's own rule for its band-by-band levels.
        let m = crate::mip::band::boxes::levels(&sizes, options);
        (m >= 1 && !options.normal_map).then_some((sizes, m))
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
                crate::mip::band::boxes::reduce_band(cur, lw, lr, ch, straight, next);
                std::mem::swap(cur, next);
                (lw, lr) = (lw / 2, lr / 2);
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
    fn finish(self, progress: &mut dyn FnMut(Progress)) -> Result<Vec<Texture>> {
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
        dst.copy_from_slice(&crate::texel::le_bytes(t.texels()));
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
                out.channel_type.is_float() && crate::mip::nan::check(base).is_ok()
            }
        }
}

/// Rows per band of [`Banded`].
const BAND_ROWS: usize = 16;

/// The general band-by-band build ([`Stream`]): the colour chain of a
/// source converted to another type, for the filters and sizes
/// [`Streamer`] does not take (Kaiser, Lanczos,
/// Mitchell, triangle; the polyphase box of odd sizes; every wrap mode),
/// without a full-resolution f32 copy of level 0:
/// - level 0 is decoded, alpha-associated and encoded into the output type
///   band by band ([`BAND_ROWS`] rows per band, in parallel);
/// - level 1 is filtered band by band ([`crate::mip::separable::Reducer::band`]):
///   each band decodes the level-0 rows its taps name (wrapped rows from
///   the far edge included), so bands meet exactly;
/// - the rest of the chain is built from level 1 in f32 as before.
///
/// Decoding, the filter's rows, association and encoding are the
/// whole-image build's own, row by row, so the chain is bit for bit the
/// whole-image one (`tests/files/mip_streamed.rs`). Memory: the source, the
/// output chain and level 1 in f32 (a quarter of level 0 in f32), where
/// the whole-image build holds level 0 in f32 too.
///
/// [`Banded::new`] hands the source back when it does not apply (alpha
/// coverage, normal maps, a single level, a box filter the whole-image
/// build reduces with its fast 2×2 kernel, float sources holding NaN or
/// infinities).
pub(crate) struct Banded<'a> {
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
        let sizes = crate::mip::level_sizes(
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
    fn finish(self, progress: &mut dyn FnMut(Progress)) -> Result<Vec<Texture>> {
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
        let reducer = crate::mip::separable::Reducer::new(
            f32fmt, w as u32, h as u32, w1 as u32, h1 as u32, options,
        );
        // The fast row kernel whenever fast paths are on: the whole-image
        // build of the same f32 rows takes it (`sep_fast`), so both
        // builds give the same levels.
        let reducer = if options.fast_paths {
            reducer.fast()
        } else {
            reducer
        };
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
pub(crate) fn convert_level(l: Texture, out: Format) -> Result<Texture> {
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

/// Texels a chain clipped: float values (HDR) written to a normalised
/// type are clipped to [0, 1].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Clipped {
    /// Texels with a channel outside 0..1 (all levels).
    pub clipped: u64,
    /// Texels of all levels.
    pub texels: u64,
}

/// How a colour chain is built, as the pipeline's plan chose it (the
/// plan is the one place that decides; see `pipeline::BuildPath`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Route {
    /// In the source's own format, the whole-level build.
    Whole,
    /// Level 0 decoded whole to linear f32, then the whole-level build.
    Decoded,
    /// Band by band, the 2×2 box of levels that halve exactly
    /// ([`Streamer`]).
    Streamed,
    /// Band by band, the general filters ([`Banded`]).
    Banded,
}

/// The colour chain of `base` (read as `src`) stored as `out_format`,
/// built the way `route` says: in the source format
/// ([`Route::Whole`], it is the output format), band by band, or in
/// linear f32 from a single decode of level 0 (see the module docs); each
/// level's alpha association changed and converted to the output format
/// once, the texels counted when float values went to a normalised
/// output and were clipped. A band route falls back to the decode only
/// for a float source holding NaN or infinities (found as it is read).
pub(crate) fn build_converted(
    base: Texture,
    options: &MipOptions,
    src: Format,
    out_format: Format,
    association: Option<AlphaMode>,
    route: Route,
    progress: &mut dyn FnMut(Progress),
) -> Result<(Vec<Texture>, Option<Clipped>)> {
    let same = route == Route::Whole;
    let base = match Stream::new(base, options, src, out_format, association, route, None)? {
        Ok(b) => return Ok((b.build_all(progress)?, None)),
        Err(base) => base,
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
    let chain: MipChain = crate::mip::build_with_progress(work_base, options, progress)?;
    // Float data (HDR) written to a normalised type is clipped to [0, 1]:
    // count the texels that lose something, to say so once.
    let count_clipped = src.channel_type.is_float() && !out_format.channel_type.is_float();
    finish_levels(chain.into_levels(), association, out_format, count_clipped)
}

/// Levels built unrounded (a source-format chain, or linear f32) stored as
/// `out_format`: each level's alpha association changed (f32 levels) and
/// converted once, smallest level first, so that level 0's f32 and
/// converted copies never coexist with the unconverted rest of the
/// chain; with `count_clipped`, the texels clipped to a normalised
/// type's range counted.
pub(crate) fn finish_levels(
    built: Vec<Texture>,
    association: Option<AlphaMode>,
    out_format: Format,
    count_clipped: bool,
) -> Result<(Vec<Texture>, Option<Clipped>)> {
    let mut clipped = 0u64;
    let mut texels = 0u64;
    let mut levels: Vec<Texture> = Vec::with_capacity(built.len());
    for l in built.into_iter().rev() {
        let l = associate(l, association)?;
        if count_clipped {
            clipped += outside_unit_range(&l);
            texels += l.texel_count() as u64;
        }
        levels.push(convert_level(l, out_format)?);
    }
    levels.reverse();
    Ok((levels, (clipped > 0).then_some(Clipped { clipped, texels })))
}
