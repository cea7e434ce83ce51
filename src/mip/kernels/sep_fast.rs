//! The fast separable reduction (Kaiser, Lanczos3, Mitchell, triangle,
//! and the box where it does not halve) of a whole level, beside the plain
//! path of [`crate::mip::separable`] (the reference, `fast_paths: false`).
//!
//! The plain path decodes the whole source to linear f32 first: for a
//! 4096² RGBA8 level 0 that is 256 MiB of fresh pages written and read
//! back, more time than all the filtering. Here destination rows are made
//! band by band on rayon, and each band keeps a small cache of the source
//! rows its taps name ([`RowCache`], `taps + 1` rows: about 13 rows of
//! 64 KiB at 2:1 for a 4096-wide RGBA level, in L2), each decoded once per
//! band through the 256-entry tables (8-bit) or the 16-bit ones, in place
//! for a linear f32 level (the working levels of the chain). Each new row
//! goes through the fast row kernel ([`crate::mip::sep_simd`]) and, when the
//! chain asks for it, is encoded to the stored format while in cache, so
//! no separate encode pass reads the level back.
//!
//! Straight alpha, the "one alpha per row" test, the fully transparent
//! fallback and the finite check are the plain path's own
//! ([`crate::mip::separable::Reducer::row`]); only the order of the sums in the
//! row kernel differs (`tests/files/mip_separable_fast.rs` holds every level of
//! the fast chains within one code of the plain ones).

use rayon::prelude::*;

use crate::mip::MipOptions;
use crate::mip::fast::ReducedLinear;
use crate::mip::separable::{Reducer, one_alpha, one_alpha_u8};
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

/// Levels 1 and 2 of a chain made together by [`try_reduce_two`].
pub(crate) struct TwoLevels {
    /// Level 1 in the stored format (it is never whole in f32).
    pub stored1: Texels,
    /// Level 2 in linear f32, unrounded, and in the stored format.
    pub linear2: Vec<f32>,
    pub stored2: Texels,
}

/// Levels 1 (`s1`) and 2 (`s2`) of an 8- or 16-bit `src` at once, level
/// 1 only in the stored format `encode`; `None` when the source is not
/// 8- or 16-bit or `encode` has other channels or is f32.
///
/// [`try_reduce_linear`] twice would write level 1 whole in linear f32
/// and read it back: for a 4096² RGBA8 level 0 that is 64 MiB of fresh
/// pages, a fifth of the Kaiser chain's time on Zen 4. Here each band of
/// level-2 rows makes the level-1 rows its taps read into a ring of
/// `taps + 1` rows, from level-0 rows decoded into a ring of their own.
/// A band owns the level-1 rows in proportion to its level-2 rows and
/// encodes each of them once (those no level-2 tap reads are made at the
/// end of the band); rows near a band's edge are also made by the
/// neighbour (about `taps / (2 · band)` more level-1 rows). Every row is
/// made by the same code from the same rows as on the two-pass path, so
/// the values are the same bit for bit. (8- and 16-bit sources are
/// finite, so no finite flag comes back.)
pub(crate) fn try_reduce_two(
    src: &Texture,
    s1: (u32, u32),
    s2: (u32, u32),
    options: &MipOptions,
    encode: Format,
) -> Option<TwoLevels> {
    let fmt = src.format();
    if !matches!(src.texels(), Texels::U8(_) | Texels::U16(_))
        || encode.channels != fmt.channels
        || encode.channel_type == ChannelType::F32
    {
        return None;
    }
    let r1 = Reducer::new(fmt, src.width(), src.height(), s1.0, s1.1, options).fast();
    let r2 = Reducer::new(fmt, s1.0, s1.1, s2.0, s2.1, options).fast();
    let ch = r1.ch;
    let (row1, row2) = (s1.0 as usize * ch, s2.0 as usize * ch);
    let (h1, h2) = (s1.1 as usize, s2.1 as usize);
    let mut stored1 = Texels::zeroed(encode.channel_type, row1 * h1);
    let mut linear2: Vec<f32> = crate::mem::zeroed(row2 * h2);
    let mut stored2 = Texels::zeroed(encode.channel_type, row2 * h2);
    let threads = rayon::current_num_threads().max(1);
    // Longer bands than one level's: fewer level-1 rows made twice.
    let band = h2.div_ceil(4 * threads).clamp(1, 2 * MAX_BAND);
    let bands = h2.div_ceil(band);
    // Band b owns level-1 rows own(b)..own(b + 1).
    let own = |b: usize| if b >= bands { h1 } else { b * band * h1 / h2 };
    let mut rows1 = stored1.chunks_mut(row1.max(1)).into_iter();
    let owned: Vec<(usize, Vec<Option<TexelsMut<'_>>>)> = (0..bands)
        .map(|b| {
            let rows = rows1.by_ref().take(own(b + 1) - own(b)).map(Some);
            (own(b), rows.collect())
        })
        .collect();
    let source = Source {
        fmt,
        texels: src.texels(),
        in_place: None,
        n: r1.sw * ch,
    };
    linear2
        .par_chunks_mut((row2 * band).max(1))
        .zip(stored2.chunks_mut((row2 * band).max(1)))
        .zip(owned)
        .enumerate()
        .for_each(|(b, ((out, coded), (first, owned)))| {
            let mut ring = Level1Ring {
                r1: &r1,
                source: &source,
                encode: &encode,
                below: RowCache::new(r1.wy.taps + 1, source.n),
                rows: RowCache::new(r2.wy.taps + 1, row1),
                first,
                owned,
                made: 0,
                tmp: vec![0f32; source.n],
                scratch: Vec::new(),
            };
            let (mut tmp, mut scratch) = (vec![0f32; row1], Vec::new());
            let mut coded_rows = split_rows(coded, row2);
            let y0 = b * band;
            for (i, dst) in out.chunks_exact_mut(row2.max(1)).enumerate() {
                let y = y0 + i;
                for (j, _) in r2.wy.of(y) {
                    ring.ensure(j, y);
                }
                let rows = &ring.rows;
                let row_of = |j: u32| rows.held(j);
                let alpha_of = |j: u32, _: usize| rows.alpha(j);
                r2.row(y, &row_of, &alpha_of, &mut tmp, &mut scratch, dst);
                if let Some(c) = coded_rows.get_mut(i).and_then(Option::take) {
                    crate::texel::encode_into(&encode, dst, c);
                }
            }
            // Owned level-1 rows no level-2 row of the band read.
            let mut clock = y0 + out.len() / row2.max(1);
            for k in 0..ring.owned.len() {
                if ring.owned[k].is_some() {
                    ring.ensure((first + k) as u32, clock);
                    clock += 1;
                }
            }
        });
    Some(TwoLevels {
        stored1,
        linear2,
        stored2,
    })
}

/// The level-1 rows one band of [`try_reduce_two`] reads, made from the
/// level-0 rows below them on demand.
struct Level1Ring<'a, 's> {
    r1: &'a Reducer,
    source: &'a Source<'s>,
    encode: &'a Format,
    /// Level-0 rows, decoded.
    below: RowCache,
    /// Level-1 rows, made.
    rows: RowCache,
    /// The first level-1 row the band owns, and the owned rows' stored
    /// values not yet written.
    first: usize,
    owned: Vec<Option<TexelsMut<'a>>>,
    /// Level-1 rows made so far (the clock of `below`).
    made: usize,
    tmp: Vec<f32>,
    scratch: Vec<f32>,
}

impl Level1Ring<'_, '_> {
    /// Make level-1 row `j` present for level-2 row (or clock) `y`,
    /// writing its stored values if the band owns it.
    fn ensure(&mut self, j: u32, y: usize) {
        let Some(k) = self.rows.claim(j, y) else {
            return;
        };
        for (i, _) in self.r1.wy.of(j as usize) {
            self.below
                .ensure(i, self.made, self.source, self.r1.straight);
        }
        self.made += 1;
        let (below, source) = (&self.below, self.source);
        let row_of = |i: u32| below.row(i, source);
        let alpha_of = |i: u32, _: usize| below.alpha(i);
        let dst = self.rows.slot_data(k);
        self.r1.row(
            j as usize,
            &row_of,
            &alpha_of,
            &mut self.tmp,
            &mut self.scratch,
            dst,
        );
        let alpha = self.r1.straight.and_then(|a| one_alpha(dst, self.r1.ch, a));
        if let Some(c) = (j as usize)
            .checked_sub(self.first)
            .and_then(|o| self.owned.get_mut(o))
            .and_then(Option::take)
        {
            crate::texel::encode_into(self.encode, dst, c);
        }
        self.rows.slots[k] = (j, y + 1, alpha);
    }
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

    /// Claim a slot for source row `j`, read by destination row `y`:
    /// `None` when the row is present (now marked as read by `y`), else
    /// the slot to fill (the least recently read one).
    fn claim(&mut self, j: u32, y: usize) -> Option<usize> {
        if let Some(k) = self.slot(j) {
            self.slots[k].1 = y + 1;
            return None;
        }
        let k = self
            .slots
            .iter()
            .enumerate()
            .min_by_key(|(_, s)| s.1)
            .map_or(0, |(k, _)| k);
        debug_assert!(self.slots[k].1 <= y, "a row in use is never evicted");
        Some(k)
    }

    /// The data of slot `k` (allocated on first use: a cache over a
    /// level read in place never needs it).
    fn slot_data(&mut self, k: usize) -> &mut [f32] {
        if self.data.is_empty() {
            self.data = vec![0f32; self.slots.len() * self.n];
        }
        &mut self.data[k * self.n..][..self.n]
    }

    /// Make source row `j` present for destination row `y`.
    fn ensure(&mut self, j: u32, y: usize, source: &Source<'_>, straight: Option<usize>) {
        let Some(k) = self.claim(j, y) else { return };
        let n = self.n;
        let start = j as usize * n;
        let row: &[f32] = match source.in_place {
            Some(v) => &v[start..][..n],
            None => {
                let d = self.slot_data(k);
                crate::texel::decode_range_to_linear(&source.fmt, source.texels, start, d);
                d
            }
        };
        let ch = source.fmt.channels as usize;
        let alpha = straight.and_then(|a| match source.texels {
            Texels::U8(codes) if source.in_place.is_none() => {
                one_alpha_u8(&codes[start..][..n], ch, a).then(|| row[a].to_bits())
            }
            _ => one_alpha(row, ch, a),
        });
        self.slots[k] = (j, y + 1, alpha);
    }

    /// Row `j` as held in this cache's own slots (present).
    fn held(&self, j: u32) -> &[f32] {
        let k = self.slot(j).unwrap_or_default();
        &self.data[k * self.n..][..self.n]
    }

    /// Source row `j` (present: see [`RowCache::ensure`]).
    fn row<'s>(&'s self, j: u32, source: &Source<'s>) -> &'s [f32] {
        // Always present (see `ensure`); never a panic path.
        match source.in_place {
            Some(v) => &v[j as usize * self.n..][..self.n],
            None => self.held(j),
        }
    }

    fn alpha(&self, j: u32) -> Option<u32> {
        self.slot(j).and_then(|k| self.slots[k].2)
    }
}
