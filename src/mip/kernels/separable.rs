//! The general downsampling path: separable polyphase filtering in linear
//! light, for every filter, channel type, size and wrap mode.
//!
//! Per destination row (in parallel): a vertical pass accumulates the rows
//! the row's weights name into a scratch row, 32 values at a time held in
//! registers across all taps (AVX2/FMA when the CPU has them, detected at
//! run time; a portable version otherwise), then a horizontal pass applies
//! the column weights, reading each destination texel's taps as one
//! contiguous run except at wrapped edges. Vertical first halves the work
//! of the horizontal pass.
//!
//! Straight alpha is decided per destination row: if every texel of the
//! source rows it reads has the same alpha, weighting cancels and the
//! plain filter runs; otherwise those rows are premultiplied into scratch,
//! filtered, and the colour is divided back by the filtered alpha. Where
//! that alpha is zero (all contributing texels transparent) the colour
//! falls back to the unweighted filter, so fully transparent regions keep
//! their colour.
//!
//! Each output row is checked for non-finite values while in cache; a
//! level that comes out all finite proves its source finite, which lets the
//! chain builder skip its deferred NaN scan.

use std::borrow::Cow;
use std::sync::OnceLock;

use rayon::prelude::*;

use crate::error::Result;
use crate::mip::MipOptions;
use crate::mip::weights::{self, AxisWeights};
use crate::texel::{self, AlphaMode, ChannelType, ColorSpace, Format, Texels};
use crate::texture::Texture;

/// Filtered alpha below this is treated as zero when un-weighting colour.
const ALPHA_EPS: f32 = 1e-7;

/// Reduce `src` to `w × h` (see the module docs). The flag is true when
/// every filtered value was finite (checked row by row while in cache, so
/// the deferred NaN check need not scan the level again).
pub(crate) fn reduce(
    src: &Texture,
    w: u32,
    h: u32,
    options: &MipOptions,
) -> Result<(Texture, bool)> {
    let (linear, finite) = reduce_linear_checked(src, w, h, options);
    let fmt = src.format();
    if fmt.channel_type == ChannelType::F32 && fmt.color_space == ColorSpace::Linear {
        // Already the stored form: no encode, no copy.
        return Ok((
            Texture::from_texels(w, h, fmt, Texels::F32(linear))?,
            finite,
        ));
    }
    let mut out = Texture::new(w, h, src.format())?;
    texel::encode_from_linear(&src.format(), &linear, out.texels_mut());
    Ok((out, finite))
}

/// The source as linear f32, borrowed when it already is.
pub(crate) fn linear_source(src: &Texture) -> Cow<'_, [f32]> {
    match src.texels() {
        Texels::F32(v) if src.format().color_space == ColorSpace::Linear => Cow::Borrowed(v),
        _ => Cow::Owned(src.to_linear()),
    }
}

/// Reduce to linear f32 values (`w · h · channels`), before encoding.
///
/// Straight alpha is decided per destination row: when every texel of the
/// source rows it reads has one alpha (the opaque case, and any uniform
/// alpha), weighting by alpha cancels and the plain filter is used;
/// otherwise those rows are premultiplied into scratch on the fly. Each
/// source row's "one alpha" test runs once, just before its first use,
/// while the row is being brought into cache anyway (no separate pass over
/// the level). Also returns whether every value is finite.
pub(crate) fn reduce_linear_checked(
    src: &Texture,
    w: u32,
    h: u32,
    options: &MipOptions,
) -> (Vec<f32>, bool) {
    use std::sync::atomic::{AtomicBool, Ordering};
    let finite = AtomicBool::new(true);
    let fmt = src.format();
    let r = Reducer::new(fmt, src.width(), src.height(), w, h, options);
    let (ch, sw) = (r.ch, r.sw);
    let data = linear_source(src);
    let data: &[f32] = &data;
    let row_of = |j: u32| &data[j as usize * sw * ch..][..sw * ch];
    // Per source row: Some(alpha bits) when the whole row has that alpha.
    let row_alpha: Vec<OnceLock<Option<u32>>> = match r.straight {
        Some(_) => (0..src.height()).map(|_| OnceLock::new()).collect(),
        None => Vec::new(),
    };
    let alpha_of =
        |j: u32, a: usize| *row_alpha[j as usize].get_or_init(|| one_alpha(row_of(j), ch, a));
    let row_len = w as usize * ch;
    let mut out: Vec<f32> = crate::mem::zeroed(row_len * h as usize);
    out.par_chunks_mut(row_len).enumerate().for_each_init(
        || (vec![0f32; sw * ch], Vec::<f32>::new()),
        |(tmp, scratch), (y, dst)| {
            if !r.row(y, &row_of, &alpha_of, tmp, scratch, dst) {
                finite.store(false, Ordering::Relaxed);
            }
        },
    );
    (out, finite.into_inner())
}

/// One reduction of a `sw × sh` level to `w × h` (see the module docs):
/// the weights of both axes and what every destination row shares. Rows
/// can be computed one by one, from any source of rows: the whole level
/// ([`reduce`]), or bands of rows decoded as they are needed
/// ([`Reducer::band`]); either way a row's values are the same, bit for
/// bit.
pub(crate) struct Reducer {
    wx: AxisWeights,
    pub(crate) wy: AxisWeights,
    runs: Vec<Option<u32>>,
    pub(crate) ch: usize,
    pub(crate) sw: usize,
    /// The straight alpha channel, if the texels have one.
    pub(crate) straight: Option<usize>,
    /// The fast row kernel's expanded weights ([`Reducer::fast`]); `None`:
    /// the plain kernel, the reference.
    ex: Option<crate::mip::sep_simd::Expanded>,
}

impl Reducer {
    /// The reduction of a `sw × sh` level of format `fmt` (channels and
    /// alpha mode; the values are linear f32) to `w × h`.
    pub(crate) fn new(
        fmt: Format,
        sw: u32,
        sh: u32,
        w: u32,
        h: u32,
        options: &MipOptions,
    ) -> Reducer {
        let wx = weights::axis(options.filter, sw, w, options.wrap.u);
        // Square levels with one wrap mode share their weights (kernel
        // evaluation is not free: Kaiser sums a Bessel series per tap).
        let wy = if (sh, h, options.wrap.v) == (sw, w, options.wrap.u) {
            wx.clone()
        } else {
            weights::axis(options.filter, sh, h, options.wrap.v)
        };
        let runs = wx.contiguous_runs();
        let straight = fmt
            .alpha_channel()
            .filter(|_| fmt.alpha == AlphaMode::Straight);
        Reducer {
            wx,
            wy,
            runs,
            ch: fmt.channels as usize,
            sw: sw as usize,
            straight,
            ex: None,
        }
    }

    /// The same reduction with the fast row kernel ([`crate::mip::sep_simd`]):
    /// the same values up to the order of the sums.
    pub(crate) fn fast(mut self) -> Reducer {
        self.ex = Some(crate::mip::sep_simd::Expanded::new(&self.wx, self.ch));
        self
    }

    /// Filter the weighted `rows` into destination row `dst` with this
    /// reducer's kernel (plain or fast).
    fn filter(&self, rows: &[(&[f32], f32)], tmp: &mut [f32], dst: &mut [f32]) {
        match &self.ex {
            Some(ex) => {
                crate::mip::sep_simd::filter_row(rows, tmp, dst, &self.wx, &self.runs, ex, self.ch)
            }
            None => filter_row(rows, tmp, dst, &self.wx, &self.runs, self.ch),
        }
    }

    /// Destination row `y` into `dst` (`w · channels` values) from the
    /// source rows `row_of(j)`; `alpha_of(j, a)` is `Some(bits)` when every
    /// texel of source row `j` has alpha (channel `a`) with these bits.
    /// Returns whether every value is finite.
    pub(crate) fn row<'a>(
        &self,
        y: usize,
        row_of: &impl Fn(u32) -> &'a [f32],
        alpha_of: &impl Fn(u32, usize) -> Option<u32>,
        tmp: &mut [f32],
        scratch: &mut Vec<f32>,
        dst: &mut [f32],
    ) -> bool {
        let (ch, sw) = (self.ch, self.sw);
        let taps: Vec<(u32, f32)> = self.wy.of(y).collect();
        let weighted = self.straight.filter(|&a| {
            let mut common = None;
            !taps.iter().all(|&(j, _)| {
                let sig = alpha_of(j, a);
                sig.is_some() && *common.get_or_insert(sig) == sig
            })
        });
        match weighted {
            None => {
                let rows: Vec<(&[f32], f32)> =
                    taps.iter().map(|&(j, wt)| (row_of(j), wt)).collect();
                self.filter(&rows, tmp, dst);
            }
            Some(a) => {
                // Premultiply the rows this destination row reads.
                let n = sw * ch;
                scratch.resize(taps.len() * n, 0.0);
                for (k, &(j, _)) in taps.iter().enumerate() {
                    let pm = &mut scratch[k * n..][..n];
                    pm.copy_from_slice(row_of(j));
                    for t in pm.chunks_exact_mut(ch) {
                        for c in (0..ch).filter(|&c| c != a) {
                            t[c] *= t[a];
                        }
                    }
                }
                let rows: Vec<(&[f32], f32)> = taps
                    .iter()
                    .enumerate()
                    .map(|(k, &(_, wt))| (&scratch[k * n..][..n], wt))
                    .collect();
                self.filter(&rows, tmp, dst);
                unpremultiply(dst, a, ch, |x| {
                    unweighted(row_of, ch, &self.wx, &self.wy, x, y)
                });
            }
        }
        !dst.iter().fold(false, |acc, v| {
            acc | (v.to_bits() & 0x7f80_0000 == 0x7f80_0000)
        })
    }

    /// The source rows destination rows `y0..y1` read, sorted, each once.
    #[cfg_attr(not(feature = "io"), allow(dead_code))] // the file pipeline's
    pub(crate) fn source_rows(&self, y0: usize, y1: usize) -> Vec<u32> {
        let mut rows: Vec<u32> = (y0..y1)
            .flat_map(|y| self.wy.of(y).map(|(j, _)| j))
            .collect();
        rows.sort_unstable();
        rows.dedup();
        rows
    }

    /// Destination rows `y0..y1` into `out` (`(y1 − y0) · w · channels`
    /// values), from the source rows `decode(j, row)` writes (row `j` as
    /// linear f32, `sw · channels` values); each source row the band reads
    /// is decoded once. The rows are the ones the whole-level reduction
    /// gives, bit for bit. Returns whether every value is finite.
    #[cfg_attr(not(feature = "io"), allow(dead_code))] // the file pipeline's
    pub(crate) fn band(
        &self,
        y0: usize,
        y1: usize,
        decode: impl Fn(u32, &mut [f32]),
        out: &mut [f32],
    ) -> bool {
        let (ch, sw) = (self.ch, self.sw);
        let n = sw * ch;
        let rows = self.source_rows(y0, y1);
        let mut buf = vec![0f32; rows.len() * n];
        for (&j, dst) in rows.iter().zip(buf.chunks_exact_mut(n.max(1))) {
            decode(j, dst);
        }
        let slot = |j: u32| rows.binary_search(&j).unwrap_or_default();
        let row_of = |j: u32| &buf[slot(j) * n..][..n];
        let alphas: Vec<Option<u32>> = match self.straight {
            Some(a) => (0..rows.len())
                .map(|k| one_alpha(&buf[k * n..][..n], ch, a))
                .collect(),
            None => Vec::new(),
        };
        let alpha_of = |j: u32, _: usize| alphas[slot(j)];
        let (mut tmp, mut scratch) = (vec![0f32; n], Vec::new());
        let row_len = out.len() / (y1 - y0).max(1);
        let mut finite = true;
        for (y, dst) in (y0..y1).zip(out.chunks_exact_mut(row_len.max(1))) {
            finite &= self.row(y, &row_of, &alpha_of, &mut tmp, &mut scratch, dst);
        }
        finite
    }
}

/// Divide colour by the filtered alpha; where that alpha is (near) zero
/// use the unweighted filter's colour instead.
fn unpremultiply(dst: &mut [f32], a: usize, ch: usize, plain: impl Fn(usize) -> [f32; 4]) {
    for (x, t) in dst.chunks_exact_mut(ch).enumerate() {
        let alpha = t[a];
        if alpha > ALPHA_EPS {
            for c in (0..ch).filter(|&c| c != a) {
                t[c] /= alpha;
            }
        } else {
            let plain = plain(x);
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

/// `Some(bits)` when every texel of `row` has alpha with these bits.
/// Alpha-carrying layouts have 2 or 4 channels, so the alpha lanes repeat
/// every 8 values: the row is XORed 8 lanes at a time against the first
/// alpha under a lane mask (this vectorises; the row is read from memory
/// here for the first time, so it runs at memory speed).
pub(crate) fn one_alpha(row: &[f32], ch: usize, a: usize) -> Option<u32> {
    debug_assert!(ch == 2 || ch == 4);
    let first = row[a].to_bits();
    let mask: [u32; 8] = std::array::from_fn(|i| if i % ch == a { !0 } else { 0 });
    let bits: &[u32] = bytemuck::cast_slice(row);
    let words = bits.chunks_exact(8);
    let rest = words.remainder();
    let mut acc = [0u32; 8];
    for w in words {
        for i in 0..8 {
            acc[i] |= (w[i] ^ first) & mask[i];
        }
    }
    let diff =
        acc.iter().fold(0, |x, y| x | y) | rest.chunks_exact(ch).fold(0, |x, t| x | (t[a] ^ first));
    (diff == 0).then_some(first)
}

/// [`one_alpha`] of an 8-bit row before it is decoded: the decode of an
/// alpha code is one float per code and no two codes share one, so the
/// codes are all equal exactly when the decoded alphas are (a quarter of
/// the bytes to read). True when every texel has the first texel's alpha.
pub(crate) fn one_alpha_u8(row: &[u8], ch: usize, a: usize) -> bool {
    debug_assert!(ch == 2 || ch == 4);
    let first = row[a];
    let mask: [u8; 64] = std::array::from_fn(|i| if i % ch == a { !0 } else { 0 });
    let (words, rest) = row.as_chunks::<64>();
    let mut acc = [0u8; 64];
    for w in words {
        for i in 0..64 {
            acc[i] |= (w[i] ^ first) & mask[i];
        }
    }
    acc.iter().fold(0, |x, y| x | y) | rest.chunks_exact(ch).fold(0, |x, t| x | (t[a] ^ first)) == 0
}

/// Vertical then horizontal pass of one destination row: with AVX2 and
/// FMA when the CPU has them (detected once at run time; setting
/// `PARVO_NO_AVX` turns it off for comparisons), else the portable code
/// below, which is also the test reference for the AVX path (see the unit
/// test at the end of this file).
pub(crate) fn filter_row(
    rows: &[(&[f32], f32)],
    tmp: &mut [f32],
    dst: &mut [f32],
    wx: &AxisWeights,
    runs: &[Option<u32>],
    ch: usize,
) {
    #[cfg(target_arch = "x86_64")]
    if avx::available() {
        #[allow(unsafe_code)]
        // SAFETY: `available()` checked that this CPU has AVX2 and FMA,
        // the only features `avx::filter_row` is compiled for.
        unsafe {
            avx::filter_row(rows, tmp, dst, wx, runs, ch)
        };
        return;
    }
    vertical(rows, tmp);
    horizontal(tmp, dst, wx, runs, ch);
}

/// The AVX2/FMA row kernel (used when the CPU has both features and
/// `PARVO_NO_AVX` is not set).
#[cfg(target_arch = "x86_64")]
mod avx {
    use std::arch::x86_64::*;

    use super::AxisWeights;

    pub fn available() -> bool {
        crate::cpu::avx2_fma()
    }

    #[target_feature(enable = "avx2,fma")]
    pub fn filter_row(
        rows: &[(&[f32], f32)],
        tmp: &mut [f32],
        dst: &mut [f32],
        wx: &AxisWeights,
        runs: &[Option<u32>],
        ch: usize,
    ) {
        vertical(rows, tmp);
        match ch {
            4 => horizontal4(tmp, dst, wx, runs),
            _ => super::horizontal(tmp, dst, wx, runs, ch),
        }
    }

    /// 32 values per step in four registers, one fused multiply-add per
    /// register and row.
    #[target_feature(enable = "avx2,fma")]
    fn vertical(rows: &[(&[f32], f32)], tmp: &mut [f32]) {
        const B: usize = 32;
        let full = tmp.len() / B * B;
        let ld = |s: &[f32; 8]| -> __m256 { bytemuck::cast(*s) };
        for (k, out) in tmp[..full].chunks_exact_mut(B).enumerate() {
            let mut acc = [_mm256_setzero_ps(); 4];
            for &(row, wt) in rows {
                let r: &[f32; B] = &row.as_chunks::<B>().0[k];
                let w = _mm256_set1_ps(wt);
                for (a, r8) in acc.iter_mut().zip(r.as_chunks::<8>().0) {
                    *a = _mm256_fmadd_ps(w, ld(r8), *a);
                }
            }
            for (o, a) in out.chunks_exact_mut(8).zip(acc) {
                o.copy_from_slice(&bytemuck::cast::<__m256, [f32; 8]>(a));
            }
        }
        for (i, t) in tmp[full..].iter_mut().enumerate() {
            *t = rows.iter().map(|&(row, wt)| wt * row[full + i]).sum();
        }
    }

    /// RGBA: one texel per SSE register, one fused multiply-add per tap.
    #[target_feature(enable = "avx2,fma")]
    fn horizontal4(tmp: &[f32], dst: &mut [f32], wx: &AxisWeights, runs: &[Option<u32>]) {
        let taps = wx.taps;
        let ld = |s: &[f32; 4]| -> __m128 { bytemuck::cast(*s) };
        let (texels, _) = tmp.as_chunks::<4>();
        for (x, d) in dst.chunks_exact_mut(4).enumerate() {
            let wgt = &wx.weight[x * taps..][..taps];
            let mut acc = _mm_setzero_ps();
            match runs[x] {
                Some(i0) => {
                    let s = &texels[i0 as usize..][..taps];
                    for (px, &w) in s.iter().zip(wgt) {
                        acc = _mm_fmadd_ps(_mm_set1_ps(w), ld(px), acc);
                    }
                }
                None => {
                    let idx = &wx.index[x * taps..][..taps];
                    for (&i, &w) in idx.iter().zip(wgt) {
                        acc = _mm_fmadd_ps(_mm_set1_ps(w), ld(&texels[i as usize]), acc);
                    }
                }
            }
            d.copy_from_slice(&bytemuck::cast::<__m128, [f32; 4]>(acc));
        }
    }
}

/// `tmp = Σ weight · row` over the given rows, 16 values at a time kept in
/// registers across all rows (one store per value instead of one
/// load-add-store per row).
fn vertical(rows: &[(&[f32], f32)], tmp: &mut [f32]) {
    const B: usize = 16;
    let n = tmp.len();
    let full = n / B * B;
    for (k, out) in tmp[..full].chunks_exact_mut(B).enumerate() {
        let mut acc = [0f32; B];
        for &(row, wt) in rows {
            let r: &[f32; B] = &row.as_chunks::<B>().0[k];
            for i in 0..B {
                acc[i] += wt * r[i];
            }
        }
        out.copy_from_slice(&acc);
    }
    for (i, t) in tmp[full..].iter_mut().enumerate() {
        *t = rows.iter().map(|&(row, wt)| wt * row[full + i]).sum();
    }
}

fn horizontal(tmp: &[f32], dst: &mut [f32], wx: &AxisWeights, runs: &[Option<u32>], ch: usize) {
    match ch {
        1 => horizontal_n::<1>(tmp, dst, wx, runs),
        2 => horizontal_n::<2>(tmp, dst, wx, runs),
        3 => horizontal_n::<3>(tmp, dst, wx, runs),
        _ => horizontal_n::<4>(tmp, dst, wx, runs),
    }
}

/// One destination texel per step; where its taps are one contiguous run
/// of source texels (everywhere but wrapped edges) they are read as one
/// slice, with no per-tap index load or bounds check.
fn horizontal_n<const CH: usize>(
    tmp: &[f32],
    dst: &mut [f32],
    wx: &AxisWeights,
    runs: &[Option<u32>],
) {
    let taps = wx.taps;
    for (x, d) in dst.chunks_exact_mut(CH).enumerate() {
        let mut acc = [0f32; CH];
        let wgt = &wx.weight[x * taps..][..taps];
        match runs[x] {
            Some(i0) => {
                let s = &tmp[i0 as usize * CH..][..taps * CH];
                for (px, &w) in s.chunks_exact(CH).zip(wgt) {
                    for c in 0..CH {
                        acc[c] += w * px[c];
                    }
                }
            }
            None => {
                let idx = &wx.index[x * taps..][..taps];
                for (&i, &w) in idx.iter().zip(wgt) {
                    let px = &tmp[i as usize * CH..][..CH];
                    for c in 0..CH {
                        acc[c] += w * px[c];
                    }
                }
            }
        }
        d.copy_from_slice(&acc);
    }
}

/// Unweighted 2-D filter of one destination texel (the rare fallback for
/// fully transparent footprints).
fn unweighted<'a>(
    row_of: &impl Fn(u32) -> &'a [f32],
    ch: usize,
    wx: &AxisWeights,
    wy: &AxisWeights,
    x: usize,
    y: usize,
) -> [f32; 4] {
    let mut acc = [0f32; 4];
    for (j, wj) in wy.of(y) {
        let row = row_of(j);
        for (i, wi) in wx.of(x) {
            let s = &row[i as usize * ch..][..ch];
            for c in 0..ch {
                acc[c] += wi * wj * s[c];
            }
        }
    }
    acc
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mip::MipFilter;
    use crate::wrap::WrapMode;

    /// The 8-bit "one alpha" test against the decoded one, on rows of
    /// awkward lengths (tails of the 64-byte blocks) with one alpha code
    /// changed at every position in turn, or none.
    #[test]
    fn one_alpha_u8_agrees_with_the_decoded_test() {
        let mut s = 0x2545_F491u32;
        for (ch, a) in [(2usize, 1usize), (4, 3), (4, 0), (2, 0)] {
            for texels in [1usize, 7, 16, 33, 97] {
                let mut row: Vec<u8> = (0..texels * ch)
                    .map(|_| {
                        s ^= s << 13;
                        s ^= s >> 17;
                        s ^= s << 5;
                        s as u8
                    })
                    .collect();
                let alpha = row[a];
                for t in 0..texels {
                    row[t * ch + a] = alpha;
                }
                for changed in (0..texels).map(Some).chain([None]) {
                    let mut r = row.clone();
                    if let Some(t) = changed {
                        r[t * ch + a] = alpha.wrapping_add(1 + t as u8 % 200);
                    }
                    let decoded: Vec<f32> = r.iter().map(|&c| c as f32 / 255.0).collect();
                    let want = one_alpha(&decoded, ch, a).is_some();
                    assert_eq!(
                        one_alpha_u8(&r, ch, a),
                        want,
                        "{ch} ch, {texels}, {changed:?}"
                    );
                    assert_eq!(want, changed.is_none_or(|t| t == 0 && texels == 1));
                }
            }
        }
    }

    /// The AVX2/FMA row kernel against the portable one: every channel
    /// count, widths with and without a remainder of the 32-value blocks,
    /// wrapped edges (non-contiguous taps) and odd sizes.
    #[test]
    #[cfg(target_arch = "x86_64")]
    fn avx_row_kernel_matches_portable() {
        if !crate::cpu::avx2_fma_detected() {
            return;
        }
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut rnd = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 40) as f32 / (1u64 << 24) as f32 * 4.0 - 1.0
        };
        for ch in 1..=4usize {
            for (sw, dw) in [
                (1u32, 1u32),
                (9, 4),
                (17, 8),
                (64, 32),
                (257, 128),
                (300, 150),
            ] {
                for wrap in [
                    WrapMode::Repeat,
                    WrapMode::ClampToEdge,
                    WrapMode::MirroredRepeat,
                ] {
                    let wx = weights::axis(MipFilter::Kaiser, sw, dw, wrap);
                    let runs = wx.contiguous_runs();
                    let n = sw as usize * ch;
                    let rows: Vec<Vec<f32>> =
                        (0..5).map(|_| (0..n).map(|_| rnd()).collect()).collect();
                    let taps: Vec<(&[f32], f32)> = rows
                        .iter()
                        .zip([0.1, -0.2, 0.5, 0.4, 0.2])
                        .map(|(r, w)| (&r[..], w))
                        .collect();
                    let (mut t0, mut t1) = (vec![0f32; n], vec![0f32; n]);
                    let (mut d0, mut d1) =
                        (vec![0f32; dw as usize * ch], vec![0f32; dw as usize * ch]);
                    vertical(&taps, &mut t0);
                    horizontal(&t0, &mut d0, &wx, &runs, ch);
                    #[allow(unsafe_code)]
                    // SAFETY: AVX2 and FMA were detected above.
                    unsafe {
                        avx::filter_row(&taps, &mut t1, &mut d1, &wx, &runs, ch)
                    };
                    for (a, b) in t0.iter().zip(&t1).chain(d0.iter().zip(&d1)) {
                        assert!(
                            (a - b).abs() <= 1e-5,
                            "ch {ch} {sw}->{dw} {wrap:?}: {a} vs {b}"
                        );
                    }
                }
            }
        }
    }
}
