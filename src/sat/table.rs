//! [`SummedAreaTable`]: the table, its parallel build and its queries.

use std::borrow::Cow;

use rayon::prelude::*;

use super::accum::{Accumulator, AccumulatorKind};
use super::axis::Axis;
use super::{Rect, required_bits, value_bits};
use crate::error::{Error, Result};
use crate::texel::{AlphaMode, ChannelType, ColorSpace, Texels};
use crate::texture::Texture;
use crate::wrap::Wrap;

/// How the stored sums relate to linear-light values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Units {
    /// Linear value = stored value / `unit`: 255 or 65535 for integer
    /// tables (they sum codes), 1 for float tables.
    pub unit: f64,
    /// Straight alpha: the alpha channel's index. Colour channels then hold
    /// sums of colour × alpha (in `unit²`), so averages can divide the
    /// alpha back out (SPEC "Colour").
    pub alpha_weighted: Option<usize>,
}

/// The result of [`SummedAreaTable::sum_box`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoxSum {
    /// Per-channel sums in the table's stored units (see [`Units`]) over
    /// the texels the rectangle covers, each weighted by its covered area;
    /// border reads are not included. Channels past `channels()` are 0.
    pub sum: [f64; 4],
    /// Area of the rectangle in texels.
    pub area: f64,
    /// Part of `area` that reads the border colour (clamp to border).
    pub border: f64,
    /// Bound on the absolute error of each entry of `sum` (stored units):
    /// `Σ|coefficient| · max_entry_error` plus the rounding of combining the
    /// reads; 0 for integer tables read with whole-texel coefficients.
    pub error: f64,
}

/// A summed-area table of one level, all channels (Crow 1984; SPEC.md
/// "Summed-area tables").
///
/// Entry `S(x, y)` (`0 ≤ x ≤ w`, `0 ≤ y ≤ h`) holds, per channel, the sum
/// of the texels with `i < x`, `j < y`; row 0 and column 0 are zero. The
/// table takes `(w + 1)·(h + 1)·channels` entries of `A`: see
/// [`SummedAreaTable::memory_bytes`].
#[derive(Clone, Debug)]
pub struct SummedAreaTable<A: Accumulator> {
    width: u32,
    height: u32,
    channels: usize,
    data: Vec<A>,
    offset: [f64; 4],
    units: Units,
    entry_error: f64,
    /// Upper bound on |entry| (stored units), for the combination error.
    max_abs: f64,
}

/// The values a table sums, one row at a time.
enum Source<'a> {
    U8(&'a [u8]),
    U16(&'a [u16]),
    Linear(Cow<'a, [f32]>),
}

struct Prepared<'a> {
    src: Source<'a>,
    w: usize,
    ch: usize,
    /// Alpha channel index when colour is weighted by alpha.
    alpha: Option<usize>,
    offset: [f64; 4],
}

impl Prepared<'_> {
    /// Fill `out` (w·ch values) with row `y`'s summands.
    #[inline]
    fn row<A: Accumulator>(&self, y: usize, out: &mut [A::Wide]) {
        let n = self.w * self.ch;
        let ch = self.ch;
        match (&self.src, self.alpha) {
            (Source::U8(v), None) => {
                for (o, &c) in out.iter_mut().zip(&v[y * n..][..n]) {
                    *o = A::from_code(c as u32);
                }
            }
            (Source::U16(v), None) => {
                for (o, &c) in out.iter_mut().zip(&v[y * n..][..n]) {
                    *o = A::from_code(c as u32);
                }
            }
            (Source::U8(v), Some(a)) => {
                for (o, t) in out
                    .chunks_exact_mut(ch)
                    .zip(v[y * n..][..n].chunks_exact(ch))
                {
                    let al = t[a] as u32;
                    for c in 0..ch {
                        o[c] = A::from_code(if c == a { al } else { t[c] as u32 * al });
                    }
                }
            }
            (Source::U16(v), Some(a)) => {
                for (o, t) in out
                    .chunks_exact_mut(ch)
                    .zip(v[y * n..][..n].chunks_exact(ch))
                {
                    let al = t[a] as u32;
                    for c in 0..ch {
                        o[c] = A::from_code(if c == a { al } else { t[c] as u32 * al });
                    }
                }
            }
            (Source::Linear(v), alpha) => {
                let off = &self.offset;
                for (o, t) in out
                    .chunks_exact_mut(ch)
                    .zip(v[y * n..][..n].chunks_exact(ch))
                {
                    let al = alpha.map_or(1.0, |a| t[a] as f64);
                    for c in 0..ch {
                        let x = if Some(c) == alpha {
                            al
                        } else {
                            t[c] as f64 * al
                        };
                        o[c] = A::from_linear(x - off[c]);
                    }
                }
            }
        }
    }

    /// Table row for level row `y`: `carry` (running column sums,
    /// `(w+1)·ch`) gains the row's prefix sums and is stored into `dst`.
    /// Plain sources are read in place; alpha-weighted ones go through
    /// `buf`.
    #[inline]
    fn accumulate<A: Accumulator>(
        &self,
        y: usize,
        buf: &mut [A::Wide],
        carry: &mut [A::Wide],
        dst: &mut [A],
    ) {
        let n = self.w * self.ch;
        let off = self.offset;
        match (&self.src, self.alpha) {
            (Source::U8(v), None) => accumulate_row::<u8, A>(
                &v[y * n..][..n],
                |c, _| A::from_code(c as u32),
                carry,
                dst,
                self.ch,
            ),
            (Source::U16(v), None) => accumulate_row::<u16, A>(
                &v[y * n..][..n],
                |c, _| A::from_code(c as u32),
                carry,
                dst,
                self.ch,
            ),
            (Source::Linear(v), None) => accumulate_row::<f32, A>(
                &v[y * n..][..n],
                |x, c| A::from_linear(x as f64 - off[c]),
                carry,
                dst,
                self.ch,
            ),
            _ => {
                self.row::<A>(y, buf);
                accumulate_row::<A::Wide, A>(buf, |x, _| x, carry, dst, self.ch);
            }
        }
    }

    /// `tot[i] += summand i of row y` (w·ch column totals).
    #[inline]
    fn add_to_totals<A: Accumulator>(&self, y: usize, buf: &mut [A::Wide], tot: &mut [A::Wide]) {
        let n = self.w * self.ch;
        match (&self.src, self.alpha) {
            (Source::U8(v), None) => {
                for (t, &c) in tot.iter_mut().zip(&v[y * n..][..n]) {
                    *t = A::add(*t, A::from_code(c as u32));
                }
            }
            (Source::U16(v), None) => {
                for (t, &c) in tot.iter_mut().zip(&v[y * n..][..n]) {
                    *t = A::add(*t, A::from_code(c as u32));
                }
            }
            _ => {
                self.row::<A>(y, buf);
                for (t, &v) in tot.iter_mut().zip(buf.iter()) {
                    *t = A::add(*t, v);
                }
            }
        }
    }

    /// Per-channel sum of `|summand|` and of the summand (float sources).
    fn float_sums(&self, h: usize) -> ([f64; 4], [f64; 4]) {
        let ch = self.ch;
        (0..h)
            .into_par_iter()
            .fold(
                || ([0f64; 4], [0f64; 4], vec![0f64; self.w * ch]),
                |(mut abs, mut sum, mut buf), y| {
                    self.row::<f64>(y, &mut buf);
                    for t in buf.chunks_exact(ch) {
                        for c in 0..ch {
                            abs[c] += t[c].abs();
                            sum[c] += t[c];
                        }
                    }
                    (abs, sum, buf)
                },
            )
            .map(|(a, s, _)| (a, s))
            .reduce(
                || ([0f64; 4], [0f64; 4]),
                |(a, s), (b, t)| {
                    (
                        std::array::from_fn(|c| a[c] + b[c]),
                        std::array::from_fn(|c| s[c] + t[c]),
                    )
                },
            )
    }
}

/// Straight-alpha textures weight colour by alpha; others sum as stored.
fn alpha_weighting(tex: &Texture) -> Option<usize> {
    let f = tex.format();
    match f.alpha_channel() {
        Some(a) if f.alpha == AlphaMode::Straight => Some(a),
        _ => None,
    }
}

fn first_non_finite(tex: &Texture) -> Result<()> {
    let ch = tex.channels();
    let w = tex.width() as usize;
    let bad = match tex.texels() {
        Texels::F32(v) => v.iter().position(|x| !x.is_finite()).map(|i| (i, v[i])),
        Texels::F16(v) => v
            .iter()
            .position(|x| !x.is_finite())
            .map(|i| (i, v[i].to_f32())),
        _ => None,
    };
    match bad {
        Some((i, value)) => Err(Error::NonFinite {
            level: 0,
            x: ((i / ch) % w) as u32,
            y: (i / ch / w) as u32,
            channel: (i % ch) as u8,
            value,
        }),
        None => Ok(()),
    }
}

impl<A: Accumulator> SummedAreaTable<A> {
    /// Build the table of `tex`.
    ///
    /// Integer accumulators need 8- or 16-bit data in linear colour space
    /// (they sum the stored codes, and averaging sRGB codes is not
    /// linear-light filtering) and refuse, before allocating, any size for
    /// which SPEC's rule `value bits + ceil(log2(w·h))` exceeds their width
    /// ([`Error::InvalidOption`]). Value bits are the texel bits, doubled
    /// for straight alpha (colour × alpha products).
    ///
    /// Float accumulators sum linear-light values; NaN or infinite input is
    /// refused ([`Error::NonFinite`]; clean it with
    /// [`crate::mip::nan::apply`] first), and an f32 table whose entries
    /// would exceed the f32 range is refused rather than storing infinities.
    pub fn build(tex: &Texture) -> Result<Self> {
        let (w, h, ch) = (tex.width() as usize, tex.height() as usize, tex.channels());
        let data = reserve::<A>(w, h, ch)?;
        let alpha = alpha_weighting(tex);
        let kind = A::KIND;
        let (mut prep, unit) = match kind.integer_bits() {
            Some(bits) => prepare_codes(tex, kind, bits, alpha)?,
            None => (prepare_linear(tex, alpha), 1.0),
        };
        let sum_abs = if kind.is_integer() {
            [0.0; 4]
        } else {
            float_sums(&mut prep, tex, kind)?
        };
        let data = build_bands::<A>(&prep, w, h, ch, data);
        let (entry_error, max_abs) = if kind.is_integer() {
            // Non-negative summands: the far corner holds each channel's
            // largest entry.
            let max_abs = data[data.len() - ch..]
                .iter()
                .fold(0.0f64, |m, e| m.max(e.to_f64()));
            (0.0, max_abs)
        } else {
            float_error::<A>(&data, w, h, &sum_abs)?
        };
        Ok(SummedAreaTable {
            width: tex.width(),
            height: tex.height(),
            channels: ch,
            data,
            offset: prep.offset,
            units: Units {
                unit,
                alpha_weighted: alpha,
            },
            entry_error,
            max_abs,
        })
    }

    /// Width of the level in texels (the table has one more column).
    pub fn width(&self) -> u32 {
        self.width
    }
    /// Height of the level in texels (the table has one more row).
    pub fn height(&self) -> u32 {
        self.height
    }
    /// Channels per entry.
    pub fn channels(&self) -> usize {
        self.channels
    }
    /// The accumulator kind.
    pub fn kind(&self) -> AccumulatorKind {
        A::KIND
    }
    /// How stored sums map to linear values.
    pub fn units(&self) -> Units {
        self.units
    }
    /// Per-channel offsets subtracted before summing (non-zero only for
    /// offset tables: the channel means).
    pub fn offset(&self) -> [f64; 4] {
        self.offset
    }
    /// Bytes held by the entries: `(w + 1)·(h + 1)·channels·size_of::<A>()`.
    pub fn memory_bytes(&self) -> usize {
        self.data.len() * std::mem::size_of::<A>()
    }
    /// The entries, row-major, `(w + 1)·channels` per row.
    pub fn entries(&self) -> &[A] {
        &self.data
    }

    /// Upper bound on the absolute error of any one entry, in stored units:
    /// 0 for integer tables; for float tables
    /// `2(w + h)·2⁻⁵³·Σ|v|·(1 + s) + s·max|S|`, where `Σ|v|` is the largest
    /// per-channel sum of |summand| over the level, `max|S|` the largest
    /// entry magnitude and `s` the storage rounding (2⁻²⁴ for f32 kinds, 0
    /// for f64). A query's error is at most `Σ|coefficient|` times this:
    /// 4× for an in-range whole-texel rectangle.
    pub fn max_entry_error(&self) -> f64 {
        self.entry_error
    }

    #[inline(always)]
    fn at(&self, x: u32, y: u32) -> usize {
        (y as usize * (self.width as usize + 1) + x as usize) * self.channels
    }

    /// The raw combination `S(x1,y1) − S(x0,y1) − S(x1,y0) + S(x0,y0)` in
    /// the accumulator type, for the in-range texel rectangle
    /// `[x0, x1) × [y0, y1)` (ends clamped to the level; an empty rectangle
    /// gives zeros). Exact for integer tables. Offset tables leave out the
    /// `offset · area` term; use [`Self::sum_box`] for that.
    pub fn raw_sum(&self, x0: u32, y0: u32, x1: u32, y1: u32) -> [A; 4] {
        let (x1, y1) = (x1.min(self.width), y1.min(self.height));
        let (x0, y0) = (x0.min(x1), y0.min(y1));
        let (a, b, c, d) = (
            self.at(x1, y1),
            self.at(x0, y1),
            self.at(x1, y0),
            self.at(x0, y0),
        );
        let mut out = [A::default(); 4];
        for (ch, o) in out.iter_mut().enumerate().take(self.channels) {
            let e = &self.data;
            *o = e[a + ch].sub(e[b + ch]).sub(e[c + ch]).plus(e[d + ch]);
        }
        out
    }

    /// Sum over the rectangle `rect` (texel units of the level, any
    /// position and size, fractional edges weighted by covered area) under
    /// `wrap`, in O(1): each axis becomes a few prefix reads (see the
    /// `axis` module docs), so repeat and mirror split the rectangle into
    /// as many pieces as it crosses edges, and whole periods are counted
    /// arithmetically. The rectangle is first [`Rect::sanitized`].
    pub fn sum_box(&self, rect: Rect, wrap: Wrap) -> BoxSum {
        let r = rect.sanitized();
        let ax = Axis::new(wrap.u, r.x0, r.x1, self.width);
        let ay = Axis::new(wrap.v, r.y0, r.y1, self.height);
        self.combine(&ax, &ay)
    }

    fn combine(&self, ax: &Axis, ay: &Axis) -> BoxSum {
        let sum = match self.channels {
            1 => widen(self.combine_n::<1>(ax, ay)),
            2 => widen(self.combine_n::<2>(ax, ay)),
            3 => widen(self.combine_n::<3>(ax, ay)),
            _ => widen(self.combine_n::<4>(ax, ay)),
        };
        let mut sum = sum;
        let integral = |a: &Axis| a.terms().all(|(_, c)| c == (c as i64) as f64);
        let whole = integral(ax) && integral(ay);
        let weight: f64 = {
            let wx: f64 = ax.terms().map(|(_, c)| c.abs()).sum();
            let wy: f64 = ay.terms().map(|(_, c)| c.abs()).sum();
            wx * wy
        };
        let inside = ax.inside * ay.inside;
        if A::KIND == AccumulatorKind::OffsetF32 {
            for (s, o) in sum.iter_mut().zip(self.offset) {
                *s += o * inside;
            }
        }
        let area = ax.total * ay.total;
        // Combining n products in f64 rounds at most 2n times, each by at
        // most 2⁻⁵³ of a partial sum, itself at most Σ|k|·max|S|; integer
        // tables with whole-texel rectangles combine exactly.
        let n = (ax.len * ay.len) as f64;
        let partial = weight * self.max_abs;
        let exact = A::KIND.is_integer() && whole && partial < 2f64.powi(53);
        let combine = if exact {
            0.0
        } else {
            2.0 * n * partial * (f64::EPSILON / 2.0)
        };
        BoxSum {
            sum,
            area,
            border: (area - inside).max(0.0),
            error: weight * self.entry_error + combine,
        }
    }

    /// `Σ_y cy · Σ_x cx · S(x, y)` per channel, `C` channels in registers.
    #[inline(always)]
    fn combine_n<const C: usize>(&self, ax: &Axis, ay: &Axis) -> [f64; C] {
        let stride = (self.width as usize + 1) * C;
        let mut sum = [0f64; C];
        for (iy, cy) in ay.terms() {
            let row = &self.data[iy as usize * stride..][..stride];
            let mut acc = [0f64; C];
            for (ix, cx) in ax.terms() {
                let e = &row[ix as usize * C..][..C];
                for c in 0..C {
                    acc[c] += cx * e[c].to_f64();
                }
            }
            for c in 0..C {
                sum[c] += cy * acc[c];
            }
        }
        sum
    }

    /// Average linear value per channel over `rect` under `wrap`
    /// (channels past `channels()` are 0). `border` is the linear RGBA
    /// border colour for clamp to border (mapped to the texture's
    /// channels: grey takes R, grey+alpha takes R and A).
    ///
    /// An axis of zero length is widened to the texel containing it (the
    /// limit of ever thinner boxes), so a zero-area rectangle returns the
    /// texel under its corner. Straight alpha: colour is the alpha-weighted
    /// average, 0 where the covered alpha sums to 0.
    pub fn average(&self, rect: Rect, wrap: Wrap, border: [f32; 4]) -> [f32; 4] {
        let s = self.sum_box(rect.widened(), wrap);
        self.finish(&s, border)
    }

    /// Turn a [`BoxSum`] into linear averages (see [`Self::average`]).
    pub fn finish(&self, s: &BoxSum, border: [f32; 4]) -> [f32; 4] {
        let ch = self.channels;
        let u = self.units.unit;
        let b = border_channels(border, ch);
        let mut total = s.sum;
        let weighted = self.units.alpha_weighted;
        if s.border > 0.0 {
            let ba = weighted.map_or(1.0, |a| b[a] as f64);
            for c in 0..ch {
                let stored = if weighted.is_some() && Some(c) != weighted {
                    b[c] as f64 * ba * u * u
                } else {
                    b[c] as f64 * u
                };
                total[c] += stored * s.border;
            }
        }
        let mut out = [0f32; 4];
        if s.area.is_nan() || s.area <= 0.0 {
            return out;
        }
        for c in 0..ch {
            out[c] = match weighted {
                Some(a) if c != a => {
                    // Covered alpha indistinguishable from 0 (within the
                    // query's error bound): transparent, colour 0.
                    if total[a] > s.error.max(ALPHA_EPS * s.area * u) {
                        (total[c] / (total[a] * u)) as f32
                    } else {
                        0.0
                    }
                }
                _ => (total[c] / (s.area * u)) as f32,
            };
        }
        out
    }
}

/// `[f64; C]` padded to four channels.
#[inline(always)]
fn widen<const C: usize>(v: [f64; C]) -> [f64; 4] {
    std::array::from_fn(|c| if c < C { v[c] } else { 0.0 })
}

/// Average alpha below this counts as zero when dividing colour by alpha
/// (the mip builder's threshold).
const ALPHA_EPS: f64 = 1e-7;

/// Border colour (linear RGBA) in the texture's channel layout.
fn border_channels(b: [f32; 4], ch: usize) -> [f32; 4] {
    match ch {
        1 => [b[0], 0.0, 0.0, 0.0],
        2 => [b[0], b[3], 0.0, 0.0],
        _ => b,
    }
}

/// The table's storage, reserved before any other work, so that a size
/// the machine cannot hold is an error (not an abort while filling: an
/// 8-bit RGBA level above 4096² needs 8 times its bytes).
fn reserve<A: Accumulator>(w: usize, h: usize, ch: usize) -> Result<Vec<A>> {
    let entries = (w + 1).checked_mul(h + 1).and_then(|n| n.checked_mul(ch));
    let mut data: Vec<A> = Vec::new();
    if entries.is_none_or(|n| data.try_reserve_exact(n).is_err()) {
        let bytes =
            (w as f64 + 1.0) * (h as f64 + 1.0) * ch as f64 * std::mem::size_of::<A>() as f64;
        return Err(Error::Limits(format!(
            "a summed-area table of {w}x{h} with {ch} channels in {} entries needs \
             {:.1} GiB, which cannot be allocated",
            A::KIND,
            bytes / (1u64 << 30) as f64
        )));
    }
    Ok(data)
}

/// The source of an integer table of `bits`-bit entries: the stored
/// codes of linear u8 or u16 data, refused when SPEC's rule says the
/// sums would overflow; with the unit of the codes (255 or 65535).
fn prepare_codes<'a>(
    tex: &'a Texture,
    kind: AccumulatorKind,
    bits: u32,
    alpha: Option<usize>,
) -> Result<(Prepared<'a>, f64)> {
    let fmt = tex.format();
    let (w, h) = (tex.width() as usize, tex.height() as usize);
    let srgb = fmt.color_space == ColorSpace::Srgb && fmt.color_channels() > 0;
    let src = match tex.texels() {
        Texels::U8(v) if !srgb => Source::U8(v),
        Texels::U16(v) if !srgb => Source::U16(v),
        _ => {
            return Err(Error::InvalidOption(format!(
                "a {kind} summed-area table sums integer codes and needs linear \
                 u8 or u16 data, not {fmt}; use an f64 or offset-f32 table"
            )));
        }
    };
    let need = required_bits(value_bits(&fmt), tex.width(), tex.height());
    if need > bits {
        return Err(Error::InvalidOption(format!(
            "a {kind} summed-area table of {w}x{h} {} texels needs {need} bits \
             and would overflow; use {} or the automatic choice",
            fmt.channel_type,
            if need <= 64 { "u64" } else { "u128" }
        )));
    }
    let unit = if fmt.channel_type == ChannelType::U8 {
        255.0
    } else {
        65535.0
    };
    let prep = Prepared {
        src,
        w,
        ch: tex.channels(),
        alpha,
        offset: [0.0; 4],
    };
    Ok((prep, unit))
}

/// The source of a float table: linear-light values (the texels
/// themselves when they are linear f32).
fn prepare_linear(tex: &Texture, alpha: Option<usize>) -> Prepared<'_> {
    let fmt = tex.format();
    let lin = match tex.texels() {
        Texels::F32(v) if fmt.color_space == ColorSpace::Linear => Cow::Borrowed(&v[..]),
        _ => Cow::Owned(tex.to_linear()),
    };
    Prepared {
        src: Source::Linear(lin),
        w: tex.width() as usize,
        ch: tex.channels(),
        alpha,
        offset: [0.0; 4],
    }
}

/// Per-channel sums of `|summand|` of a float table's source, which
/// bound its error; refuses NaN or infinite input. An offset-f32 table
/// gets its per-channel offset (the mean) here, and the sums are of the
/// offset summands.
fn float_sums(prep: &mut Prepared<'_>, tex: &Texture, kind: AccumulatorKind) -> Result<[f64; 4]> {
    let (w, h, ch) = (prep.w, tex.height() as usize, prep.ch);
    let (abs, sum) = prep.float_sums(h);
    if abs.iter().any(|a| !a.is_finite()) {
        // Only NaN or ±Inf input makes these sums non-finite (finite
        // f32 sums stay below 2¹²⁸·2⁶⁴); find the first for the error.
        first_non_finite(tex)?;
        return Err(Error::InvalidOption(
            "finite texels decode to infinite linear values (sRGB beyond the f32 range)".into(),
        ));
    }
    if kind != AccumulatorKind::OffsetF32 {
        return Ok(abs);
    }
    let n = (w * h) as f64;
    prep.offset = std::array::from_fn(|c| if c < ch { sum[c] / n } else { 0.0 });
    // Entries now sum value − offset: recompute the |·| sums.
    Ok(prep.float_sums(h).0)
}

/// A float table's bound on the error of each entry, and on |entry|
/// (both in stored units), from its `w × h` level's sums of `|summand|`;
/// an f32 table whose entries overflowed is refused.
fn float_error<A: Accumulator>(
    data: &[A],
    w: usize,
    h: usize,
    sum_abs: &[f64; 4],
) -> Result<(f64, f64)> {
    let kind = A::KIND;
    // f64 entries cannot overflow (see above) and are not rounded
    // again when stored: only f32 kinds need their largest entry.
    let max_entry = if kind == AccumulatorKind::F64 {
        0.0
    } else {
        data.par_iter()
            .map(|e| e.to_f64().abs())
            .reduce(|| 0.0, f64::max)
    };
    if max_entry.is_infinite() {
        return Err(Error::InvalidOption(format!(
            "the sums of this texture exceed the {kind} range; use an f64 table"
        )));
    }
    // Running sums in f64: each summand passes fewer than 2(w + h)
    // additions (row run, band totals, band scan, column run; the
    // γ bound); f32 entries add one rounding of the entry.
    let u64 = f64::EPSILON / 2.0;
    let store = if kind == AccumulatorKind::F64 {
        0.0
    } else {
        f32::EPSILON as f64 / 2.0
    };
    let total_abs = sum_abs.iter().fold(0.0f64, |m, &s| m.max(s));
    let entry_error = 2.0 * (w + h) as f64 * u64 * total_abs * (1.0 + store) + store * max_entry;
    Ok((entry_error, max_entry.max(total_abs) + entry_error))
}

/// The parallel build: the level is cut into horizontal bands. Pass 1
/// sums each band's columns (reading only the source); a short sequential
/// scan turns those into the table row at the top of each band; pass 2
/// builds every band independently from its top row (a row prefix sum
/// added to a running column sum). Each entry is written once, computed in
/// the wide type from exact (integer) or f64 running sums, so float
/// entries are rounded once however the bands fall.
fn build_bands<A: Accumulator>(
    p: &Prepared<'_>,
    w: usize,
    h: usize,
    ch: usize,
    mut data: Vec<A>,
) -> Vec<A> {
    let stride = (w + 1) * ch;
    data.resize(stride * (h + 1), A::default());
    let bands = (rayon::current_num_threads() * 4).clamp(1, h);
    let band_rows = h.div_ceil(bands);
    let bands = h.div_ceil(band_rows);
    // Pass 1: column totals of every band but the last.
    let totals: Vec<Vec<A::Wide>> = (0..bands - 1)
        .into_par_iter()
        .map(|b| {
            let mut tot = vec![A::Wide::default(); w * ch];
            let mut row = vec![A::Wide::default(); w * ch];
            for y in b * band_rows..((b + 1) * band_rows).min(h) {
                p.add_to_totals::<A>(y, &mut row, &mut tot);
            }
            tot
        })
        .collect();
    // Scan: the running column sums at the top of each band, as table rows
    // (row prefix of the column sums of all rows above).
    let mut tops = Vec::with_capacity(bands);
    let mut col = vec![A::Wide::default(); w * ch];
    tops.push(vec![A::Wide::default(); stride]);
    for t in &totals {
        for (c, &v) in col.iter_mut().zip(t) {
            *c = A::add(*c, v);
        }
        let mut top = vec![A::Wide::default(); stride];
        let mut run = [A::Wide::default(); 4];
        for x in 0..w {
            for c in 0..ch {
                run[c] = A::add(run[c], col[x * ch + c]);
                top[(x + 1) * ch + c] = run[c];
            }
        }
        tops.push(top);
    }
    drop(totals);
    // Pass 2: each band from its top row.
    data[stride..]
        .par_chunks_mut(stride * band_rows)
        .zip(tops)
        .enumerate()
        .for_each(|(b, (out, mut carry))| {
            let mut row = vec![A::Wide::default(); w * ch];
            for (k, dst) in out.chunks_exact_mut(stride).enumerate() {
                p.accumulate::<A>(b * band_rows + k, &mut row, &mut carry, dst);
            }
        });
    data
}

/// One table row: `carry` (running column sums, `(w+1)·ch`) gains the
/// prefix sums of `src` (converted by `conv(value, channel)`) and is
/// stored into `dst`.
#[inline(always)]
fn accumulate_row<T: Copy, A: Accumulator>(
    src: &[T],
    conv: impl Fn(T, usize) -> A::Wide,
    carry: &mut [A::Wide],
    dst: &mut [A],
    ch: usize,
) {
    match ch {
        1 => {
            let mut run = A::Wide::default();
            for ((&v, c), d) in src.iter().zip(&mut carry[1..]).zip(&mut dst[1..]) {
                run = A::add(run, conv(v, 0));
                *c = A::add(*c, run);
                *d = A::store(*c);
            }
        }
        _ => {
            let mut run = [A::Wide::default(); 4];
            for ((v, c), d) in src
                .chunks_exact(ch)
                .zip(carry[ch..].chunks_exact_mut(ch))
                .zip(dst[ch..].chunks_exact_mut(ch))
            {
                for k in 0..ch {
                    run[k] = A::add(run[k], conv(v[k], k));
                    c[k] = A::add(c[k], run[k]);
                    d[k] = A::store(c[k]);
                }
            }
        }
    }
}
