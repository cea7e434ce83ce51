//! Block compression of a built chain: the encode on all threads, its
//! figures, and what a block format does that the user should hear of.

#[cfg(feature = "encode")]
use std::time::Instant;

#[cfg(feature = "encode")]
use rayon::prelude::*;

use super::{Note, Stage};
use crate::compress::{BlockChain, BlockFormat, Quality};
use crate::error::{Error, Result};
#[cfg(feature = "encode")]
use crate::texel::AlphaMode;
use crate::texel::{ColorSpace, Format};
use crate::texture::Texture;

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
    /// [`super::Settings::measure_blocks`].
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
pub(crate) fn compress_notes(bf: BlockFormat, src: Format, sizes: &[(u32, u32)]) -> Vec<Note> {
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
    let mut notes: Vec<Note> = notes.into_iter().map(Note::Text).collect();
    if let Some((level, size)) = webgl_misfit(sizes) {
        notes.push(Note::WebGlMisfit { level, size });
    }
    notes
}

/// Encode every level as `bf` blocks: levels (and bands of large levels)
/// on all threads, progress reported from the calling thread; with
/// `measure`, each level decoded again (by `bcdec_rs`, independent of the
/// encoders) and scored against the uncompressed level.
pub(crate) fn encode_chain(
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
                        // Block row by block row (a 4096² level is most
                        // of a chain's work).
                        let ticked = AtomicU64::new(0);
                        let tick = |n: u64| {
                            ticked.fetch_add(n, Ordering::Relaxed);
                            done.fetch_add(n, Ordering::Relaxed);
                        };
                        let data =
                            crate::compress::encode::encode_with(bf, quality, &input, &tick)?;
                        let encode_s = t.elapsed().as_secs_f64();
                        let rest = (l.texel_count() as u64).saturating_sub(ticked.into_inner());
                        done.fetch_add(rest, Ordering::Relaxed);
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
            measure_psnr(levels, &data, bf, want, &mut report_levels)?;
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

/// Each level's PSNR against the uncompressed level, the blocks decoded
/// again by the independent decoder (`compress::decode`).
#[cfg(feature = "encode")]
fn measure_psnr(
    levels: &[Texture],
    data: &[Vec<u8>],
    bf: BlockFormat,
    want: crate::texel::Format,
    report: &mut [BlockLevel],
) -> Result<()> {
    let ch = match bf {
        BlockFormat::Bc4 { .. } => 1,
        BlockFormat::Bc5 { .. } => 2,
        BlockFormat::Bc6h { .. } => 3,
        _ if want.alpha == AlphaMode::None => 3,
        _ => 4,
    };
    let scores = levels
        .par_iter()
        .zip(data)
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
    for (lv, p) in report.iter_mut().zip(scores) {
        lv.psnr_db = Some(p);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mip::{self, Rounding};

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
}
