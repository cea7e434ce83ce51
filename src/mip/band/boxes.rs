//! Several box levels at once, band by band.
//!
//! A chain that rounds once keeps every level unrounded (linear f32) until
//! it is stored. Doing that level by level means writing level 1 in f32 —
//! four times the bytes of an RGBA8 level 0 — and reading it back for
//! level 2: on a 4096² RGBA8 image 64 MiB of fresh pages, whose first
//! touch alone costs more than the whole chain's arithmetic. Here level 0
//! is cut into bands of 2^m rows; each band is decoded to linear f32 in a
//! per-thread scratch buffer, reduced through levels 1..=m with the 2×2
//! row kernel ([`crate::mip::fast::box_row_f32`]), and each level's new rows
//! are encoded to the stored type while they are in cache. Only level m
//! is kept in f32 (1/4^m of level 0), to build the rest of the chain from.
//! Decoding, the row kernel and encoding are row-local, so the levels are
//! the ones the whole-level path makes, bit for bit.

use rayon::prelude::*;

use crate::mip::fast::box_row_f32;
use crate::mip::{MipFilter, MipOptions, srgb_simd};
use crate::texel::{AlphaMode, ChannelType, ColorSpace, Format, Texels, TexelsMut};
use crate::texture::Texture;

/// Most levels made per band (bands of up to 2^4 = 16 level-0 rows: a
/// band of a 16384-wide RGBA level 0 is 4 MiB of f32).
pub const MAX_LEVELS: u32 = 4;

/// How many levels after level 0 a band-by-band box build makes for a
/// chain of `sizes` (level 0 first) under `options`: 0 when it does not
/// apply (another filter, the fast paths off, alpha coverage, a first
/// reduction that does not halve both sides).
pub fn levels(sizes: &[(u32, u32)], options: &MipOptions) -> usize {
    let Some(&(w, h)) = sizes.first() else {
        return 0;
    };
    if options.filter != MipFilter::Box || !options.fast_paths || options.alpha_coverage.is_some() {
        return 0;
    }
    let m = w
        .trailing_zeros()
        .min(h.trailing_zeros())
        .min(MAX_LEVELS)
        .min(sizes.len().saturating_sub(1) as u32) as usize;
    // Every level up to m halves exactly (true for even sides; checked
    // against the chain's own sizes all the same).
    (0..=m)
        .take_while(|&k| sizes[k] == (w >> k, h >> k))
        .last()
        .unwrap_or(0)
}

/// One band's next level: `lr` rows of `lw` texels of linear f32 (`ch`
/// channels, alpha-weighted by channel `straight`) reduced by the 2×2 box
/// into `next` (resized to `lw / 2` × `lr / 2`). The level kernel of every
/// band-by-band box build: the whole-level one here ([`box_levels`]) and
/// the one that stores another format ([`crate::mip::band`]). True when every
/// value came out finite.
pub(crate) fn reduce_band(
    prev: &[f32],
    lw: usize,
    lr: usize,
    ch: usize,
    straight: Option<usize>,
    next: &mut Vec<f32>,
) -> bool {
    let nw = lw / 2;
    next.resize(nw * (lr / 2) * ch, 0.0);
    let mut all_finite = true;
    for (r, o) in next.chunks_exact_mut(nw * ch).enumerate() {
        let r0 = &prev[2 * r * lw * ch..(2 * r + 1) * lw * ch];
        let r1 = &prev[(2 * r + 1) * lw * ch..(2 * r + 2) * lw * ch];
        all_finite &= box_row_f32(r0, r1, o, ch, straight);
    }
    all_finite
}

/// Level 1 of a band of RGBA8 sRGB level 0 (`band`: rows of `w` texels),
/// stored as `codes` and unrounded in linear f32 as `next`, by the
/// AVX-512 sRGB box kernel ([`srgb_simd::row_rgba8_linear`]): level 0 is
/// neither decoded to f32 nor written anywhere. Row pairs of straight
/// alpha whose alphas differ take the decode-and-reduce path instead (the
/// kernel's sums are unweighted).
fn fused_level1(
    band: &[u8],
    w: usize,
    fmt: Format,
    straight: Option<usize>,
    next: &mut Vec<f32>,
    codes: &mut [u8],
) {
    let (row, nrow) = (4 * w, 2 * w);
    let rows = band.len() / row.max(1);
    next.resize(nrow * (rows / 2), 0.0);
    let t = crate::mip::fast::fixed_tables();
    let mut scratch = Vec::new();
    for (r, (d, lin)) in codes
        .chunks_exact_mut(nrow)
        .zip(next.chunks_exact_mut(nrow))
        .enumerate()
    {
        let (r0, r1) = (
            &band[2 * r * row..][..row],
            &band[(2 * r + 1) * row..][..row],
        );
        let constant = srgb_simd::row_rgba8_linear(r0, r1, d, lin, t);
        if straight.is_some() && !constant {
            scratch.resize(2 * row, 0.0);
            let (f0, f1) = scratch.split_at_mut(row);
            crate::texel::decode_u8(&fmt, r0, f0);
            crate::texel::decode_u8(&fmt, r1, f1);
            box_row_f32(f0, f1, lin, 4, straight);
            crate::texel::encode_u8(&fmt, lin, d);
        }
    }
}

thread_local! {
    /// A band of level 0 decoded, then one band of each level 1..=m, in
    /// linear f32. One buffer per level, so none changes size from band
    /// to band (growing a `Vec` zero-fills the new part: a buffer shared
    /// by levels 1 and m re-zeroed a level-1 band, 2.4 % of the 4096²
    /// sRGB chain).
    static SCRATCH: std::cell::RefCell<Vec<Vec<f32>>> =
        const { std::cell::RefCell::new(Vec::new()) };
}

/// What [`box_levels`] made.
pub struct Levels {
    /// Levels 1..=m in the stored format.
    pub stored: Vec<Texels>,
    /// Level m in linear f32, unrounded.
    pub last: Vec<f32>,
    /// Every value of level 1 came out finite (tracked by the RGBA kernel
    /// only; `false` means "not known").
    pub finite: bool,
}

/// Levels 1..=`m` of `base` (box filter; both sides divisible by 2^m,
/// m ≥ 1) encoded to `stored` (the channels of `base`), and level m in
/// linear f32 (see the module docs).
pub fn box_levels(base: &Texture, m: usize, stored: Format) -> Levels {
    use std::sync::atomic::{AtomicBool, Ordering};
    let fmt = base.format();
    let ch = fmt.channels as usize;
    let (w, h) = (base.width() as usize, base.height() as usize);
    let rows = 1usize << m;
    let bands = h / rows;
    let straight = fmt
        .alpha_channel()
        .filter(|_| fmt.alpha == AlphaMode::Straight);
    let mut outs: Vec<Texels> = (1..=m)
        .map(|k| Texels::zeroed(stored.channel_type, (w >> k) * (h >> k) * ch))
        .collect();
    let per_last = (w >> m) * ch;
    let mut last: Vec<f32> = crate::mem::zeroed(per_last * bands);
    // Per band: level k's rows in each output, then level m's f32 row.
    let mut per_band: Vec<Vec<crate::texel::TexelsMut<'_>>> =
        (0..bands).map(|_| Vec::new()).collect();
    for (k, o) in outs.iter_mut().enumerate() {
        let n = (w >> (k + 1)) * (rows >> (k + 1)) * ch;
        for (b, c) in o.chunks_mut(n).into_iter().enumerate() {
            per_band[b].push(c);
        }
    }
    let finite = AtomicBool::new(ch == 4);
    let texels = base.texels();
    let in_place = match (texels, fmt.color_space, fmt.channel_type) {
        (Texels::F32(v), crate::texel::ColorSpace::Linear, _) => Some(v.as_slice()),
        _ => None,
    };
    let band_len = rows * w * ch;
    // RGBA8 sRGB stored as it came: level 1 straight from the codes.
    let fused = fmt.channel_type == ChannelType::U8
        && fmt.color_space == ColorSpace::Srgb
        && ch == 4
        && stored == fmt
        && srgb_simd::available();
    per_band
        .into_par_iter()
        .zip(last.par_chunks_mut(per_last))
        .enumerate()
        .for_each(|(b, (outs, kept))| {
            // Per-thread scratch that outlives the call: fresh buffers per
            // rayon job would fault in a megabyte of new pages each time.
            SCRATCH.with_borrow_mut(|bufs| {
                bufs.resize_with(m + 1, Vec::new);
                let (cur, lv) = bufs.split_at_mut(1);
                let cur = &mut cur[0];
                let reduce = |prev: &[f32], lw: usize, lr: usize, next: &mut Vec<f32>| {
                    reduce_band(prev, lw, lr, ch, straight, next)
                };
                let mut outs = outs.into_iter();
                // Level 1 from level 0's band: fused from the codes, or
                // decoded (or read in place), reduced and encoded.
                let level1_finite = match (in_place, fused, texels, outs.next()) {
                    (None, true, Texels::U8(v), Some(TexelsMut::U8(codes))) => {
                        let band = &v[b * band_len..][..band_len];
                        fused_level1(band, w, fmt, straight, &mut lv[0], codes);
                        true
                    }
                    (_, _, _, out) => {
                        let ok = match in_place {
                            Some(v) => reduce(&v[b * band_len..][..band_len], w, rows, &mut lv[0]),
                            None => {
                                cur.resize(band_len, 0.0);
                                crate::texel::decode_range_to_linear(
                                    &fmt,
                                    texels,
                                    b * band_len,
                                    cur,
                                );
                                reduce(cur, w, rows, &mut lv[0])
                            }
                        };
                        if let Some(out) = out {
                            crate::texel::encode_into(&stored, &lv[0], out);
                        }
                        ok
                    }
                };
                if !level1_finite {
                    finite.store(false, Ordering::Relaxed);
                }
                let (mut lw, mut lr) = (w / 2, rows / 2);
                for (k, out) in outs.enumerate() {
                    let (prev, next) = lv.split_at_mut(k + 1);
                    reduce(&prev[k], lw, lr, &mut next[0]);
                    (lw, lr) = (lw / 2, lr / 2);
                    crate::texel::encode_into(&stored, &next[0], out);
                }
                kept.copy_from_slice(&lv[m - 1][..per_last]);
            })
        });
    Levels {
        stored: outs,
        last,
        finite: finite.into_inner(),
    }
}
