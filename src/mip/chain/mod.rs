//! The chain builder: [`build`] (level 0 to the last level, every
//! reduction in linear light from the unrounded level before, rounded
//! once as stored), [`build_reduced_levels`] (levels 1.. without taking
//! level 0), [`reduce`] (one level, stored type in and out), and the
//! per-level passes the build applies: NaN/Inf policy ([`nan`]), alpha-test
//! coverage ([`alpha`]), normal maps ([`normal`]) and roughness from
//! normal variance ([`roughness`]). The reductions themselves are
//! [`super::kernels`]'; the box levels made band by band,
//! [`super::band::boxes`].

pub mod alpha;
pub mod nan;
pub mod normal;
pub mod roughness;

use crate::error::{Error, Result};
use crate::mip::band::boxes;
use crate::mip::{
    MipChain, MipFilter, MipOptions, Progress, fast, level_count, level_sizes, sep_fast, separable,
};
use crate::texel::{ChannelType, ColorSpace, Format, Texels};
use crate::texture::Texture;
use nan::NanPolicy;

/// Levels 1.. of `base`'s chain without taking or copying level 0 (for
/// callers that keep the source elsewhere). NaN policies other than
/// [`NanPolicy::Error`] need to modify level 0 and are refused here.
pub fn build_reduced_levels(base: &Texture, options: &MipOptions) -> Result<Vec<Texture>> {
    validate(base, options)?;
    if options.normal_map {
        let vectors = normal::build_levels(base, options, &mut |_| {})?;
        return vectors[1..]
            .iter()
            .map(|v| normal::encode(v, base.format()))
            .collect();
    }
    if options.nan_policy != NanPolicy::Error {
        return Err(Error::InvalidOption(
            "build_reduced_levels cannot repair level 0: use build with this NaN policy".into(),
        ));
    }
    let deferred = defer_nan_check(base, options)?;
    let sizes = level_sizes(
        base.width(),
        base.height(),
        options.rounding,
        options.max_levels,
    );
    reduced_levels(base, &sizes, options, deferred, &mut |_, _| {})
}

/// The form every level is reduced from: linear f32 with the source's
/// channels and alpha mode, never rounded to the stored type.
fn working_format(f: Format) -> Format {
    Format::new(f.channels, ChannelType::F32, ColorSpace::Linear).with_alpha(f.alpha)
}

/// Levels 1.. of `base`'s chain of `sizes`, each reduced from the
/// unrounded level before it (level 0 as stored, then linear f32) and
/// rounded to `base`'s format once, as it is stored; `done(k, texels)`
/// after level `k`. A chain of linear f32 keeps no second copy: its stored
/// levels are the working ones.
fn reduced_levels(
    base: &Texture,
    sizes: &[(u32, u32)],
    options: &MipOptions,
    deferred: bool,
    done: &mut dyn FnMut(usize, u64),
) -> Result<Vec<Texture>> {
    let stored = base.format();
    let separate = stored != working_format(stored);
    let coverage0 = coverage_target(base, options);
    let mut levels: Vec<Texture> = Vec::with_capacity(sizes.len().saturating_sub(1));
    // The unrounded last level, when it is not the stored one.
    let mut work: Option<Texture> = None;
    // Box levels made band by band first, where they apply (stream).
    let m = boxes::levels(sizes, options);
    if m >= 1 {
        let made = boxes::box_levels(base, m, stored);
        for (k, t) in made.stored.into_iter().enumerate() {
            let (w, h) = sizes[k + 1];
            levels.push(Texture::from_texels(w, h, stored, t)?);
            if k == 0 && deferred && !made.finite {
                nan::check_via_reduced(base, &levels[0])?;
            }
            done(k + 1, w as u64 * h as u64);
        }
        let (wm, hm) = sizes[m];
        work = Some(Texture::from_f32(
            wm,
            hm,
            working_format(stored),
            made.last,
        )?);
    }
    // Levels 1 and 2 at once from 8- and 16-bit level 0 (the separable
    // filters), level 1 never whole in f32 (sep_fast::try_reduce_two).
    let fuse = m == 0
        && sizes.len() > 2
        && separate
        && options.fast_paths
        && options.filter != MipFilter::Box
        && options.alpha_coverage.is_none();
    let two = fuse
        .then(|| sep_fast::try_reduce_two(base, sizes[1], sizes[2], options, stored))
        .flatten();
    let mut from = m + 1;
    if let Some(two) = two {
        for (k, t) in [(1, two.stored1), (2, two.stored2)] {
            let (w, h) = sizes[k];
            levels.push(Texture::from_texels(w, h, stored, t)?);
            done(k, w as u64 * h as u64);
        }
        let (w2, h2) = sizes[2];
        work = Some(Texture::from_f32(
            w2,
            h2,
            working_format(stored),
            two.linear2,
        )?);
        from = 3;
    }
    for (k, &(w, h)) in sizes.iter().enumerate().skip(from) {
        let prev = match (&work, levels.last()) {
            (Some(t), _) => t,
            (None, Some(t)) => t,
            (None, None) => base,
        };
        // The stored level comes with the reduction (8-bit box) unless
        // alpha coverage must change the level first.
        let encode = (separate && options.alpha_coverage.is_none()).then_some(stored);
        let (mut next, coded, finite) = reduce_working(prev, w, h, options, encode)?;
        if let (Some(r), Some(c0)) = (options.alpha_coverage, coverage0) {
            let store = options.alpha_store.unwrap_or(stored.channel_type);
            alpha::preserve_coverage(&mut next, r, c0, store);
        }
        if deferred && k == 1 && !finite {
            nan::check_via_reduced(base, &next)?;
        }
        if separate {
            let out = match coded {
                Some(t) => Texture::from_texels(w, h, stored, t)?,
                None => {
                    let mut out = Texture::new(w, h, stored)?;
                    let Texels::F32(lin) = next.texels() else {
                        return Err(Error::InvalidOption("working levels are f32".into()));
                    };
                    crate::texel::encode_from_linear(&stored, lin, out.texels_mut());
                    out
                }
            };
            levels.push(out);
            work = Some(next);
        } else {
            // The stored level is the working one.
            levels.push(next);
            work = None;
        }
        done(k, w as u64 * h as u64);
    }
    Ok(levels)
}

/// One reduction to `w × h` in the working form (see [`working_format`]),
/// with the fast box where it applies; with `encode`, the level in that
/// format too when the fast path made it on the way. The flag says every
/// value came out finite.
fn reduce_working(
    src: &Texture,
    w: u32,
    h: u32,
    options: &MipOptions,
    encode: Option<Format>,
) -> Result<(Texture, Option<Texels>, bool)> {
    let fast = options
        .fast_paths
        .then(|| {
            fast::try_reduce_linear(src, w, h, options, encode)
                .or_else(|| sep_fast::try_reduce_linear(src, w, h, options, encode))
        })
        .flatten();
    let (v, coded, finite) = match fast {
        Some(r) => (r.linear, r.stored, r.finite),
        None => {
            let (v, finite) = separable::reduce_linear_checked(src, w, h, options);
            (v, None, finite)
        }
    };
    Ok((
        Texture::from_f32(w, h, working_format(src.format()), v)?,
        coded,
        finite,
    ))
}

fn coverage_target(base: &Texture, options: &MipOptions) -> Option<f32> {
    match (options.alpha_coverage, base.format().alpha_channel()) {
        (Some(r), Some(_)) => Some(alpha::coverage(base, r)),
        _ => None,
    }
}

/// Build the full chain of `base` (see the module docs).
pub fn build(base: Texture, options: &MipOptions) -> Result<MipChain> {
    build_with_progress(base, options, &mut |_| {})
}

/// [`build`] with a callback after each level (called on the caller's
/// thread; the library never prints).
pub fn build_with_progress(
    mut base: Texture,
    options: &MipOptions,
    progress: &mut dyn FnMut(Progress),
) -> Result<MipChain> {
    validate(&base, options)?;
    if options.normal_map {
        let f = base.format();
        let levels = normal::build(base, options, f, progress)?;
        return Ok(MipChain {
            levels,
            options: *options,
        });
    }
    let deferred = defer_nan_check(&base, options)?;
    if !deferred {
        nan::apply(&mut base, options.nan_policy)?;
    }
    let sizes = level_sizes(
        base.width(),
        base.height(),
        options.rounding,
        options.max_levels,
    );
    let texels_total: u64 = sizes[1..].iter().map(|&(w, h)| w as u64 * h as u64).sum();
    let mut p = Progress {
        levels_done: 1,
        levels_total: sizes.len() as u32,
        texels_done: 0,
        texels_total,
    };
    progress(p);
    let rest = reduced_levels(&base, &sizes, options, deferred, &mut |_, texels| {
        p.levels_done += 1;
        p.texels_done += texels;
        progress(p);
    })?;
    let mut levels = Vec::with_capacity(sizes.len());
    levels.push(base);
    levels.extend(rest);
    Ok(MipChain {
        levels,
        options: *options,
    })
}

/// Under [`NanPolicy::Error`] the full scan of level 0 is deferred when a
/// reduction follows: every texel of level 0 has a non-zero weight in
/// level 1 and NaN/Inf propagate through the filters, so a clean level 1
/// proves a clean level 0 and the scan (a whole extra pass over the
/// largest level) is only run to name the bad texel. Returns whether the
/// check was deferred; a single-level chain is checked here.
/// Post-processing that could hide a NaN (normal renormalisation, alpha
/// scaling) also turns the deferral off.
fn defer_nan_check(base: &Texture, options: &MipOptions) -> Result<bool> {
    if options.nan_policy != NanPolicy::Error || !base.channel_type().is_float() {
        return Ok(false);
    }
    let levels = level_count(
        base.width(),
        base.height(),
        options.rounding,
        options.max_levels,
    );
    if levels < 2 || options.normal_map || options.alpha_coverage.is_some() {
        nan::check(base)?;
        return Ok(false);
    }
    Ok(true)
}

fn validate(base: &Texture, options: &MipOptions) -> Result<()> {
    if let Some(r) = options.alpha_coverage {
        if !(r > 0.0 && r < 1.0) {
            return Err(Error::InvalidOption(format!(
                "alpha coverage reference {r} must be between 0 and 1 (exclusive)"
            )));
        }
        if !base.format().has_alpha() && !options.normal_map {
            return Err(Error::InvalidOption(
                "alpha coverage needs a texture with an alpha channel".into(),
            ));
        }
    }

    if options.max_levels == Some(0) {
        return Err(Error::InvalidOption(
            "the chain needs at least one level".into(),
        ));
    }
    Ok(())
}

/// Reduce one level to `w × h` with the chosen filter (fast path if one
/// applies, otherwise the separable path).
pub fn reduce(src: &Texture, w: u32, h: u32, options: &MipOptions) -> Result<Texture> {
    reduce_tracked(src, w, h, options).map(|(t, _)| t)
}

/// [`reduce`], and whether the kernel already proved every output value
/// finite (then the deferred NaN check need not scan the result).
fn reduce_tracked(src: &Texture, w: u32, h: u32, options: &MipOptions) -> Result<(Texture, bool)> {
    if options.fast_paths
        && let Some(t) = fast::try_reduce(src, w, h, options)?
    {
        return Ok(t);
    }
    separable::reduce(src, w, h, options)
}
