//! The general downsampling path: separable polyphase filtering in linear
//! light, for every filter, channel type, size and wrap mode.
//!
//! Per destination row (in parallel): a vertical pass accumulates the rows
//! the row's weights name into a scratch row (weighting colour by alpha for
//! straight alpha), then a horizontal pass applies the column weights.
//! Vertical first halves the work of the horizontal pass. With straight
//! alpha the colour is divided back by the filtered alpha; where that alpha
//! is zero (all contributing texels transparent) the colour falls back to
//! the unweighted filter, so fully transparent regions keep their colour.

use std::borrow::Cow;

use rayon::prelude::*;

use super::MipOptions;
use super::weights::{self, AxisWeights};
use crate::error::Result;
use crate::texel::{self, AlphaMode, ColorSpace, Texels};
use crate::texture::Texture;

/// Filtered alpha below this is treated as zero when un-weighting colour.
const ALPHA_EPS: f32 = 1e-7;

/// Reduce `src` to `w × h` (see the module docs).
pub fn reduce(src: &Texture, w: u32, h: u32, options: &MipOptions) -> Result<Texture> {
    let linear = reduce_linear(src, w, h, options);
    let mut out = Texture::new(w, h, src.format())?;
    texel::encode_from_linear(&src.format(), &linear, out.texels_mut());
    Ok(out)
}

/// The source as linear f32, borrowed when it already is.
pub(crate) fn linear_source(src: &Texture) -> Cow<'_, [f32]> {
    match src.texels() {
        Texels::F32(v) if src.format().color_space == ColorSpace::Linear => Cow::Borrowed(v),
        _ => Cow::Owned(src.to_linear()),
    }
}

/// Reduce to linear f32 values (`w · h · channels`), before encoding.
pub fn reduce_linear(src: &Texture, w: u32, h: u32, options: &MipOptions) -> Vec<f32> {
    let fmt = src.format();
    let ch = fmt.channels as usize;
    let sw = src.width() as usize;
    let wx = weights::axis(options.filter, src.width(), w, options.wrap.u);
    let wy = weights::axis(options.filter, src.height(), h, options.wrap.v);
    let data = linear_source(src);
    let data: &[f32] = &data;
    // With one alpha everywhere (the opaque case) weighting by alpha
    // cancels out exactly, so the cheaper unweighted filter is the same.
    let straight = match fmt.alpha_channel() {
        Some(a) if fmt.alpha == AlphaMode::Straight && !alpha_is_constant(data, ch, a) => Some(a),
        _ => None,
    };
    // Straight alpha: filter colour·alpha (premultiplied once, here) and
    // divide afterwards; `data` stays for the unweighted fallback.
    let premultiplied: Option<Vec<f32>> = straight.map(|a| {
        let mut pm = data.to_vec();
        pm.par_chunks_mut(ch * 4096).for_each(|c| {
            for t in c.chunks_exact_mut(ch) {
                for k in (0..ch).filter(|&k| k != a) {
                    t[k] *= t[a];
                }
            }
        });
        pm
    });
    let filtered: &[f32] = premultiplied.as_deref().unwrap_or(data);
    let row_len = w as usize * ch;
    let mut out: Vec<f32> = crate::mem::zeroed(row_len * h as usize);
    out.par_chunks_mut(row_len).enumerate().for_each_init(
        || vec![0f32; sw * ch],
        |tmp, (y, dst)| {
            tmp.fill(0.0);
            for (j, wgt) in wy.of(y) {
                let row = &filtered[j as usize * sw * ch..][..sw * ch];
                for (t, &s) in tmp.iter_mut().zip(row) {
                    *t += wgt * s;
                }
            }
            horizontal(tmp, dst, &wx, ch);
            if let Some(a) = straight {
                for (x, t) in dst.chunks_exact_mut(ch).enumerate() {
                    let alpha = t[a];
                    if alpha > ALPHA_EPS {
                        for c in (0..ch).filter(|&c| c != a) {
                            t[c] /= alpha;
                        }
                    } else {
                        let plain = unweighted(data, sw, ch, &wx, &wy, x, y);
                        for c in (0..ch).filter(|&c| c != a) {
                            t[c] = plain[c];
                        }
                        // Negative overshoot becomes 0; NaN and -Inf stay visible.
                        t[a] = if alpha < 0.0 && alpha.is_finite() {
                            0.0
                        } else {
                            alpha
                        };
                    }
                }
            }
        },
    );
    out
}

fn alpha_is_constant(data: &[f32], ch: usize, a: usize) -> bool {
    let first = data[a];
    data.par_chunks(ch * 4096).all(|c| {
        c.chunks_exact(ch)
            .all(|t| t[a].to_bits() == first.to_bits())
    })
}

fn horizontal(tmp: &[f32], dst: &mut [f32], wx: &AxisWeights, ch: usize) {
    match ch {
        1 => horizontal_n::<1>(tmp, dst, wx),
        2 => horizontal_n::<2>(tmp, dst, wx),
        3 => horizontal_n::<3>(tmp, dst, wx),
        _ => horizontal_n::<4>(tmp, dst, wx),
    }
}

fn horizontal_n<const CH: usize>(tmp: &[f32], dst: &mut [f32], wx: &AxisWeights) {
    let taps = wx.taps;
    for (x, d) in dst.chunks_exact_mut(CH).enumerate() {
        let mut acc = [0f32; CH];
        let idx = &wx.index[x * taps..][..taps];
        let wgt = &wx.weight[x * taps..][..taps];
        for (&i, &w) in idx.iter().zip(wgt) {
            let s = &tmp[i as usize * CH..][..CH];
            for c in 0..CH {
                acc[c] += w * s[c];
            }
        }
        d.copy_from_slice(&acc);
    }
}

/// Unweighted 2-D filter of one destination texel (the rare fallback for
/// fully transparent footprints).
fn unweighted(
    data: &[f32],
    sw: usize,
    ch: usize,
    wx: &AxisWeights,
    wy: &AxisWeights,
    x: usize,
    y: usize,
) -> [f32; 4] {
    let mut acc = [0f32; 4];
    for (j, wj) in wy.of(y) {
        for (i, wi) in wx.of(x) {
            let s = &data[(j as usize * sw + i as usize) * ch..][..ch];
            for c in 0..ch {
                acc[c] += wi * wj * s[c];
            }
        }
    }
    acc
}
