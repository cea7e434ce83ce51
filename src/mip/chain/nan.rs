//! What to do with NaN and ±Inf in float input.
//!
//! Non-finite values poison every level above them (a box of one NaN is
//! NaN), so level 0 is checked before any filtering. Integer types cannot
//! hold them and are never scanned.

use std::fmt;
use std::str::FromStr;

use half::slice::HalfFloatSliceExt;

use crate::error::{Error, Result};
use crate::texel::Texels;
use crate::texture::Texture;

/// Policy for non-finite values (NaN, +Inf, −Inf) in float textures.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum NanPolicy {
    /// Refuse with [`Error::NonFinite`] naming the first bad value in
    /// row-major order. The default: bad data should be seen, not hidden.
    #[default]
    Error,
    /// Replace each non-finite value by 0.
    Black,
    /// Replace each non-finite value by the average of the finite values of
    /// the same channel among its (up to 8) neighbours; 0 if none is finite.
    Neighbors,
}

impl fmt::Display for NanPolicy {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            NanPolicy::Error => "error",
            NanPolicy::Black => "black",
            NanPolicy::Neighbors => "neighbors",
        })
    }
}

impl FromStr for NanPolicy {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s.to_ascii_lowercase().as_str() {
            "error" => Ok(NanPolicy::Error),
            "black" => Ok(NanPolicy::Black),
            "neighbors" | "neighbours" => Ok(NanPolicy::Neighbors),
            _ => Err(Error::parse(
                "NaN policy",
                s,
                "expected error, black or neighbors",
            )),
        }
    }
}

/// [`NanPolicy::Error`] without modifying: the first non-finite value, as
/// an error.
pub fn check(tex: &Texture) -> Result<()> {
    let (w, ch) = (tex.width() as usize, tex.channels());
    let at = match tex.texels() {
        Texels::F32(v) => first_non_finite(v, bad_f32).map(|i| (i, v[i])),
        Texels::F16(v) => first_non_finite(v, bad_f16).map(|i| (i, v[i].to_f32())),
        Texels::U8(_) | Texels::U16(_) => None,
    };
    match at {
        None => Ok(()),
        Some((i, value)) => Err(Error::NonFinite {
            level: 0,
            x: ((i / ch) % w) as u32,
            y: ((i / ch) / w) as u32,
            channel: (i % ch) as u8,
            value,
        }),
    }
}

/// The deferred form of [`check`]: `reduced` is level 1 built from
/// `level0`. If it is all finite, so was level 0 (every source texel has a
/// non-zero weight); otherwise scan level 0 to name the first bad texel.
/// (Finite data whose filtered value overflows — possible only with
/// negative-lobe kernels near the top of the f32 range — passes.)
pub fn check_via_reduced(level0: &Texture, reduced: &Texture) -> Result<()> {
    let dirty = match reduced.texels() {
        Texels::F32(v) => first_non_finite(v, bad_f32).is_some(),
        Texels::F16(v) => first_non_finite(v, bad_f16).is_some(),
        Texels::U8(_) | Texels::U16(_) => false,
    };
    if dirty { check(level0) } else { Ok(()) }
}

/// NaN or ±Inf (all exponent bits set), as a bit test that vectorises.
fn bad_f32(x: &f32) -> bool {
    x.to_bits() & 0x7f80_0000 == 0x7f80_0000
}

/// The same test for half floats.
fn bad_f16(x: &half::f16) -> bool {
    x.to_bits() & 0x7c00 == 0x7c00
}

/// Index of the first value for which `bad` holds. Scans in parallel
/// chunks without short-circuiting inside a chunk (so the test
/// vectorises); only a chunk that has a bad value is searched again.
fn first_non_finite<T: Sync>(v: &[T], bad: impl Fn(&T) -> bool + Sync) -> Option<usize> {
    use rayon::prelude::*;
    const CHUNK: usize = 1 << 14;
    v.par_chunks(CHUNK)
        .enumerate()
        .filter(|(_, c)| c.iter().fold(false, |acc, x| acc | bad(x)))
        .min_by_key(|(k, _)| *k)
        .and_then(|(k, c)| c.iter().position(&bad).map(|i| k * CHUNK + i))
}

/// Apply `policy` to `tex` in place.
pub fn apply(tex: &mut Texture, policy: NanPolicy) -> Result<()> {
    let (w, h, ch) = (tex.width() as usize, tex.height() as usize, tex.channels());
    match tex.texels_mut() {
        Texels::F32(v) => {
            if let Some(i) = first_non_finite(v, bad_f32) {
                fix(v, i, w, h, ch, policy)?;
            }
        }
        Texels::F16(v) => {
            if let Some(i) = first_non_finite(v, bad_f16) {
                let mut f = v.to_f32_vec();
                fix(&mut f, i, w, h, ch, policy)?;
                v.convert_from_f32_slice(&f);
            }
        }
        Texels::U8(_) | Texels::U16(_) => {}
    }
    Ok(())
}

fn fix(
    v: &mut [f32],
    first: usize,
    w: usize,
    h: usize,
    ch: usize,
    policy: NanPolicy,
) -> Result<()> {
    match policy {
        NanPolicy::Error => {
            let t = first / ch;
            Err(Error::NonFinite {
                level: 0,
                x: (t % w) as u32,
                y: (t / w) as u32,
                channel: (first % ch) as u8,
                value: v[first],
            })
        }
        NanPolicy::Black => {
            for x in v.iter_mut().filter(|x| !x.is_finite()) {
                *x = 0.0;
            }
            Ok(())
        }
        NanPolicy::Neighbors => {
            let orig = v.to_vec();
            for i in (first..v.len()).filter(|&i| !orig[i].is_finite()) {
                let (t, c) = (i / ch, i % ch);
                let (x, y) = ((t % w) as isize, (t / w) as isize);
                let (mut sum, mut n) = (0f64, 0u32);
                for dy in -1..=1isize {
                    for dx in -1..=1isize {
                        let (nx, ny) = (x + dx, y + dy);
                        if (dx, dy) == (0, 0)
                            || nx < 0
                            || ny < 0
                            || nx >= w as isize
                            || ny >= h as isize
                        {
                            continue;
                        }
                        let s = orig[(ny as usize * w + nx as usize) * ch + c];
                        if s.is_finite() {
                            sum += s as f64;
                            n += 1;
                        }
                    }
                }
                v[i] = if n > 0 { (sum / n as f64) as f32 } else { 0.0 };
            }
            Ok(())
        }
    }
}
