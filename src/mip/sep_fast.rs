//! The fast separable reduction (Kaiser, Lanczos3, Mitchell, triangle,
//! and the box where it does not halve) of a whole level, beside the plain
//! path of [`super::separable`] (the reference, `fast_paths: false`).
//!
//! The plain path decodes the whole source to linear f32 first: for a
//! 4096² RGBA8 level 0 that is 256 MiB of fresh pages written and read
//! back, more time than all the filtering. Here destination rows are made
//! band by band on rayon, and each band keeps a small cache of the source
//! rows its taps name ([`RowCache`], `taps + 1` rows: about 13 rows of
//! 64 KiB at 2:1 for a 4096-wide RGBA level, in L2), each decoded once per
//! band through the 256-entry tables (8-bit) or the 16-bit ones, in place
//! for a linear f32 level (the working levels of the chain). Each new row
//! goes through the fast row kernel ([`super::sep_simd`]) and, when the
//! chain asks for it, is encoded to the stored format while in cache, so
//! no separate encode pass reads the level back.
//!
//! Straight alpha, the "one alpha per row" test, the fully transparent
//! fallback and the finite check are the plain path's own
//! ([`super::separable::Reducer::row`]); only the order of the sums in the
//! row kernel differs (`tests/mip_separable_fast.rs` holds every level of
//! the fast chains within one code of the plain ones).

use rayon::prelude::*;

use super::MipOptions;
use super::fast::ReducedLinear;
use super::separable::{Reducer, one_alpha};
use crate::texel::{ChannelType, ColorSpace, Format, Texels, TexelsMut};
use crate::texture::Texture;

/// Destination rows per rayon task at most: rows at the band's edges are
/// decoded by both neighbours, so bands are long, but there are at least
/// eight per thread for balance.
const MAX_BAND: usize = 64;

/// The reduction of `src` to `w × h` in linear f32 (and, with `encode`,
/// in that format too), or `None` when the source type has no fast path
/// here (f16, or sRGB-encoded floats: they take the plain path).
pub(crate) fn try_reduce_linear(
    src: &Texture,
    w: u32,
    h: u32,
    options: &MipOptions,
    encode: Option<Format>,
) -> Option<ReducedLinear> {
    let fmt = src.format();
    let in_place = match (src.texels(), fmt.color_space) {
        (Texels::F32(v), ColorSpace::Linear) => Some(v.as_slice()),
        (Texels::U8(_) | Texels::U16(_), _) => None,
        _ => return None,
    };
    let r = Reducer::new(fmt, src.width(), src.height(), w, h, options).fast();
    let ch = r.ch;
    let row = w as usize * ch;
    let h = h as usize;
    let encode =
        encode.filter(|f| f.channels == fmt.channels && f.channel_type != ChannelType::F32);
    let mut linear: Vec<f32> = crate::mem::zeroed(row * h);
    let mut stored = encode.map(|f| Texels::zeroed(f.channel_type, row * h));
    let threads = rayon::current_num_threads().max(1);
    let band = h.div_ceil(8 * threads).clamp(1, MAX_BAND);
    let coded: Vec<Option<TexelsMut<'_>>> = match stored.as_mut() {
        Some(t) => t
            .chunks_mut((row * band).max(1))
            .into_iter()
            .map(Some)
            .collect(),
        None => (0..h.div_ceil(band)).map(|_| None).collect(),
    };
    let source = Source {
        fmt,
        texels: src.texels(),
        in_place,
        n: r.sw * ch,
    };
    let finite = std::sync::atomic::AtomicBool::new(true);
    linear
        .par_chunks_mut((row * band).max(1))
        .zip(coded)
        .enumerate()
        .for_each(|(b, (out, coded))| {
            let ok = reduce_band(&r, &source, b * band, out, row, coded, encode.as_ref());
            if !ok {
                finite.store(false, std::sync::atomic::Ordering::Relaxed);
            }
        });
    Some(ReducedLinear {
        linear,
        stored,
        finite: finite.into_inner(),
    })
}

/// Where a band's source rows come from.
struct Source<'a> {
    fmt: Format,
    texels: &'a Texels,
    /// The level itself when it is linear f32 (nothing to decode).
    in_place: Option<&'a [f32]>,
    /// Values per source row.
    n: usize,
}

/// Destination rows `y0..` of one band into `out` (whole rows of `row`
/// values), each encoded into `coded` too when given. True when every
/// value is finite.
fn reduce_band(
    r: &Reducer,
    source: &Source<'_>,
    y0: usize,
    out: &mut [f32],
    row: usize,
    coded: Option<TexelsMut<'_>>,
    encode: Option<&Format>,
) -> bool {
    let mut cache = RowCache::new(r.wy.taps + 1, source.n);
    let mut coded_rows = coded.map(|c| split_rows(c, row));
    let (mut tmp, mut scratch) = (vec![0f32; source.n], Vec::new());
    let mut finite = true;
    for (i, dst) in out.chunks_exact_mut(row.max(1)).enumerate() {
        let y = y0 + i;
        for (j, _) in r.wy.of(y) {
            cache.ensure(j, y, source, r.straight);
        }
        let row_of = |j: u32| cache.row(j, source);
        let alpha_of = |j: u32, _: usize| cache.alpha(j);
        finite &= r.row(y, &row_of, &alpha_of, &mut tmp, &mut scratch, dst);
        if let (Some(f), Some(rows)) = (encode, coded_rows.as_mut())
            && let Some(c) = rows.get_mut(i).and_then(Option::take)
        {
            crate::texel::encode_into(f, dst, c);
        }
    }
    finite
}

/// A run of stored values cut into rows of `n` values.
fn split_rows(t: TexelsMut<'_>, n: usize) -> Vec<Option<TexelsMut<'_>>> {
    let n = n.max(1);
    match t {
        TexelsMut::U8(v) => v.chunks_mut(n).map(|c| Some(TexelsMut::U8(c))).collect(),
        TexelsMut::U16(v) => v.chunks_mut(n).map(|c| Some(TexelsMut::U16(c))).collect(),
        TexelsMut::F16(v) => v.chunks_mut(n).map(|c| Some(TexelsMut::F16(c))).collect(),
        TexelsMut::F32(v) => v.chunks_mut(n).map(|c| Some(TexelsMut::F32(c))).collect(),
    }
}

/// The source rows a band is reading, decoded once each: `slots` rows,
/// the least recently used one replaced when a new row is needed. With
/// one more slot than a destination row has taps, a row is never evicted
/// while the destination row that needs it is being made.
struct RowCache {
    /// Per slot: source row (`u32::MAX`: empty), last destination row
    /// that used it plus one, and its "one alpha" signature.
    slots: Vec<(u32, usize, Option<u32>)>,
    data: Vec<f32>,
    n: usize,
}

impl RowCache {
    fn new(slots: usize, n: usize) -> RowCache {
        RowCache {
            slots: vec![(u32::MAX, 0, None); slots],
            data: Vec::new(),
            n,
        }
    }

    fn slot(&self, j: u32) -> Option<usize> {
        self.slots.iter().position(|s| s.0 == j)
    }

    /// Make source row `j` present for destination row `y`.
    fn ensure(&mut self, j: u32, y: usize, source: &Source<'_>, straight: Option<usize>) {
        if let Some(k) = self.slot(j) {
            self.slots[k].1 = y + 1;
            return;
        }
        let k = self
            .slots
            .iter()
            .enumerate()
            .min_by_key(|(_, s)| s.1)
            .map_or(0, |(k, _)| k);
        debug_assert!(self.slots[k].1 <= y, "a row in use is never evicted");
        let n = self.n;
        let start = j as usize * n;
        let row: &[f32] = match source.in_place {
            Some(v) => &v[start..][..n],
            None => {
                if self.data.is_empty() {
                    self.data = vec![0f32; self.slots.len() * n];
                }
                let d = &mut self.data[k * n..][..n];
                crate::texel::decode_range_to_linear(&source.fmt, source.texels, start, d);
                d
            }
        };
        let alpha = straight.and_then(|a| one_alpha(row, source.fmt.channels as usize, a));
        self.slots[k] = (j, y + 1, alpha);
    }

    /// Source row `j` (present: see [`RowCache::ensure`]).
    fn row<'s>(&'s self, j: u32, source: &Source<'s>) -> &'s [f32] {
        // Always present (see `ensure`); never a panic path.
        let k = self.slot(j).unwrap_or_default();
        match source.in_place {
            Some(v) => &v[j as usize * self.n..][..self.n],
            None => &self.data[k * self.n..][..self.n],
        }
    }

    fn alpha(&self, j: u32) -> Option<u32> {
        self.slot(j).and_then(|k| self.slots[k].2)
    }
}
