//! Texel fetch: the copy of a chain that every filter reads, and the
//! functions that turn an integer texel index into a linear-light colour.
//!
//! # Two storages, one decode step
//! Filters work in linear light on RGBA `f32` (sRGB decoded first, as GPUs
//! do; grey replicated, missing alpha 1, as
//! [`crate::texture::expand_to_rgba`] defines). Where that decode happens
//! depends on the storage type, and every filter is generic over it (the
//! `Pixel` trait), so the choice costs no branch per texel:
//!
//! - **8-bit chains** (any channel count, sRGB or linear) are kept packed,
//!   one `[u8; 4]` per texel (grey replicated, missing alpha stored as
//!   255), and decoded at fetch through a 256-entry table per channel
//!   (4 KiB, in L1 next to the texels), plus the colour and alpha tables as
//!   byte planes (2 KiB) for the SIMD paths, which look up 64 codes at a
//!   time. The table is filled by the same
//!   decoder the rest of the crate uses ([`crate::texel::decode_u8`] then
//!   `expand_to_rgba`), so a fetch returns exactly what decoding the whole
//!   chain up front would.
//! - **16-bit and float chains** are decoded once to RGBA `f32`: there is
//!   no small table for f16 or u16 sRGB, and a fetch of a decoded texel is a
//!   single 16-byte load.
//!
//! # Memory cost
//! An RGBA8 chain stays at 4 bytes per texel, about 4/3 × 4 bytes per
//! level-0 texel for a full chain (21 MiB for a 2048² texture) plus the
//! 4 KiB table; a 1–3 channel 8-bit chain grows to 4 bytes per texel. The
//! other types take 16 bytes per texel (85 MiB for a 2048² chain).
//!
//! The trade-off, measured rather than assumed (`benches/sample.rs` runs
//! the same queries on both storages): the decode costs a table load per
//! channel, sixteen per bilinear lookup, and the instructions to extract
//! the bytes and assemble the vectors — about a third of an RGBA8 bilinear
//! lookup. When the texels a query set touches fit in the caches, the
//! `f32` storage is therefore the faster one per lookup; the packed
//! storage is four times smaller and fetches four times fewer cache lines
//! per texel, which wins when the working set does not fit. 8-bit chains
//! are packed because a whole chain at 16 bytes per texel is the larger
//! cost for most textures. [`LinearChain`] can be shared between samplers
//! with different options through an `Arc`.
//!
//! # Addressing
//! Filters test once per footprint whether all the texels they need lie
//! inside the level (the common case) and then index the rows directly;
//! only footprints that cross the edge take the filters' general paths,
//! which wrap integer indices with [`wrap_index`] (once per axis for
//! bilinear, per texel in `Level::fetch` for nearest and EWA).

use std::fmt;

use rayon::prelude::*;

use crate::mip::MipChain;
use crate::texel::{Format, Texels};
use crate::texture::{Texture, expand_to_rgba};
use crate::wrap::{Wrap, wrap_index};

use super::trace::TexelSink;

/// A stored texel that decodes to linear RGBA `f32`.
pub(crate) trait Pixel: Copy + Send + Sync + 'static {
    /// What decoding needs besides the texel (a table, or nothing).
    type Lut: Send + Sync + fmt::Debug + Clone;
    /// The linear-light RGBA value.
    fn decode(self, lut: &Self::Lut) -> [f32; 4];

    /// The decode table of a packed texel, `None` for texels stored as
    /// linear RGBA `f32` (the SIMD paths read either).
    fn packed(lut: &Self::Lut) -> Option<&Lut8>;

    /// Bilinear blend of a 2×2 block `[t00, t10, t01, t11]` with fractions
    /// α (along x) and β (along y): `lerp(lerp(t00, t10, α), lerp(t01,
    /// t11, α), β)` in linear light.
    #[inline(always)]
    fn bilerp(t: [Self; 4], lut: &Self::Lut, al: f32, be: f32) -> [f32; 4] {
        lerp(
            lerp(t[0].decode(lut), t[1].decode(lut), al),
            lerp(t[2].decode(lut), t[3].decode(lut), al),
            be,
        )
    }
}

impl Pixel for [f32; 4] {
    type Lut = ();
    #[inline(always)]
    fn decode(self, _: &()) -> [f32; 4] {
        self
    }

    #[inline(always)]
    fn packed(_: &()) -> Option<&Lut8> {
        None
    }
}

/// Per-channel decode table of a packed 8-bit chain: `table[c][i]` is the
/// linear value of code `i` in channel `c`.
#[derive(Clone)]
pub(crate) struct Lut8 {
    table: Box<[[f32; 256]; 4]>,
    /// The tables of channel 0 (colour) and channel 3 (alpha) as byte
    /// planes: `planes[k][p][i]` is byte `p` (little-endian) of the `f32`
    /// value of code `i`. The SIMD paths look up 64 codes at a time in
    /// them (`simd`).
    pub planes: Box<[[[u8; 256]; 4]; 2]>,
    /// Channels 0, 1 and 2 share one table (true for every format: a
    /// format has one colour space, and grey is replicated).
    pub shared: bool,
    /// The alpha table is the colour table too (linear formats).
    pub alpha_same: bool,
    /// The colour and the alpha table are `code as f32 * (1.0 / 255.0)`,
    /// which the SIMD paths compute instead of looking up.
    pub colour_linear: bool,
    pub alpha_linear: bool,
}

impl fmt::Debug for Lut8 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("Lut8")
    }
}

impl Pixel for [u8; 4] {
    type Lut = Lut8;
    #[inline(always)]
    fn decode(self, lut: &Lut8) -> [f32; 4] {
        let t = &*lut.table;
        [
            t[0][self[0] as usize],
            t[1][self[1] as usize],
            t[2][self[2] as usize],
            t[3][self[3] as usize],
        ]
    }

    #[inline(always)]
    fn packed(lut: &Lut8) -> Option<&Lut8> {
        Some(lut)
    }
}

/// One level, row-major.
#[derive(Clone, Debug)]
pub(crate) struct Level<P> {
    pub w: u32,
    pub h: u32,
    pub wf: f64,
    pub hf: f64,
    pub texels: Box<[P]>,
}

/// Every level of a chain in one storage, with its decode table.
#[derive(Clone, Debug)]
pub(crate) struct Chain<P: Pixel> {
    pub levels: Box<[Level<P>]>,
    pub lut: P::Lut,
}

/// The storage a chain is kept in (see the module docs).
#[derive(Clone, Debug)]
pub(crate) enum Store {
    /// Packed 8-bit texels, decoded at fetch.
    Rgba8(Chain<[u8; 4]>),
    /// Texels decoded to linear RGBA `f32` up front.
    F32(Chain<[f32; 4]>),
}

/// A mip chain as the samplers read it: packed RGBA8 with a decode table
/// for 8-bit textures, linear RGBA `f32` for the others (see the module
/// docs for the memory cost). Every accessor returns decoded linear-light
/// values whatever the storage.
#[derive(Clone, Debug)]
pub struct LinearChain {
    pub(crate) store: Store,
    format: Format,
}

fn level<P>(t: &Texture, texels: Vec<P>) -> Level<P> {
    Level {
        w: t.width(),
        h: t.height(),
        wf: t.width() as f64,
        hf: t.height() as f64,
        texels: texels.into_boxed_slice(),
    }
}

/// Pack 1–4 channel 8-bit values into RGBA8: grey replicated, missing
/// alpha 255 (the table decodes it to 1 anyway).
fn pack8(v: &[u8]) -> [u8; 4] {
    match *v {
        [g] => [g, g, g, 255],
        [g, a] => [g, g, g, a],
        [r, g, b] => [r, g, b, 255],
        [r, g, b, a, ..] => [r, g, b, a],
        [] => [0, 0, 0, 255],
    }
}

/// The levels of an 8-bit chain packed to RGBA8, or `None` when the chain
/// is not 8-bit.
fn packed8(chain: &MipChain) -> Option<Box<[Level<[u8; 4]>]>> {
    chain
        .levels()
        .iter()
        .map(|t| match t.texels() {
            Texels::U8(v) => {
                let texels = v
                    .par_chunks_exact(t.channels())
                    .with_min_len(4096)
                    .map(pack8)
                    .collect();
                Some(level(t, texels))
            }
            _ => None,
        })
        .collect()
}

/// The decode table of 8-bit `format`: code `i` in every channel, decoded
/// by the crate's decoder and expanded to RGBA.
fn lut8(format: &Format) -> Lut8 {
    let ch = format.channels as usize;
    let mut t = Box::new([[0f32; 256]; 4]);
    for i in 0..256 {
        let codes = [i as u8; 4];
        let mut lin = [0f32; 4];
        crate::texel::decode_u8(format, &codes[..ch], &mut lin[..ch]);
        for (c, x) in expand_to_rgba(&lin[..ch]).into_iter().enumerate() {
            t[c][i] = x;
        }
    }
    let mut planes = Box::new([[[0u8; 256]; 4]; 2]);
    for (k, c) in [0, 3].into_iter().enumerate() {
        for (i, x) in t[c].iter().enumerate() {
            for (p, b) in x.to_le_bytes().into_iter().enumerate() {
                planes[k][p][i] = b;
            }
        }
    }
    let same = |a: usize, b: usize| t[a].map(f32::to_bits) == t[b].map(f32::to_bits);
    let linear =
        |c: usize| (0..256).all(|i| t[c][i].to_bits() == (i as f32 * (1.0 / 255.0)).to_bits());
    Lut8 {
        shared: same(0, 1) && same(0, 2),
        alpha_same: same(0, 3),
        colour_linear: linear(0),
        alpha_linear: linear(3),
        planes,
        table: t,
    }
}

impl LinearChain {
    /// Prepare every level of `chain` (in parallel): packed for 8-bit
    /// storage, decoded to linear `f32` otherwise.
    pub fn new(chain: &MipChain) -> Self {
        let format = chain.levels()[0].format();
        let store = match packed8(chain) {
            Some(levels) => Store::Rgba8(Chain {
                levels,
                lut: lut8(&format),
            }),
            None => {
                let levels = chain
                    .levels()
                    .iter()
                    .map(|t| {
                        let ch = t.channels();
                        let linear = t.to_linear();
                        let texels: Vec<[f32; 4]> = linear
                            .par_chunks_exact(ch)
                            .with_min_len(4096)
                            .map(expand_to_rgba)
                            .collect();
                        level(t, texels)
                    })
                    .collect();
                Store::F32(Chain { levels, lut: () })
            }
        };
        LinearChain { store, format }
    }

    /// Format of the source chain (its channel count decides how many
    /// values the CLI prints).
    pub fn format(&self) -> Format {
        self.format
    }

    /// Number of levels.
    pub fn len(&self) -> usize {
        match &self.store {
            Store::Rgba8(c) => c.levels.len(),
            Store::F32(c) => c.levels.len(),
        }
    }

    /// Always false: a chain has level 0.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Size of level `k`.
    pub fn level_size(&self, k: usize) -> Option<(u32, u32)> {
        match &self.store {
            Store::Rgba8(c) => c.levels.get(k).map(|l| (l.w, l.h)),
            Store::F32(c) => c.levels.get(k).map(|l| (l.w, l.h)),
        }
    }

    /// Bytes held by the stored texels and the decode table.
    pub fn memory_bytes(&self) -> usize {
        fn bytes<P: Pixel>(c: &Chain<P>) -> usize {
            c.levels
                .iter()
                .map(|l| std::mem::size_of_val(&*l.texels))
                .sum()
        }
        match &self.store {
            Store::Rgba8(c) => {
                bytes(c)
                    + std::mem::size_of_val(&*c.lut.table)
                    + std::mem::size_of_val(&*c.lut.planes)
            }
            Store::F32(c) => bytes(c),
        }
    }

    /// Decoded texel `(x, y)` of level `k`, or `None` out of range.
    pub fn texel(&self, k: usize, x: u32, y: u32) -> Option<[f32; 4]> {
        fn get<P: Pixel>(c: &Chain<P>, k: usize, x: u32, y: u32) -> Option<[f32; 4]> {
            let l = c.levels.get(k)?;
            (x < l.w && y < l.h)
                .then(|| l.texels[y as usize * l.w as usize + x as usize].decode(&c.lut))
        }
        match &self.store {
            Store::Rgba8(c) => get(c, k, x, y),
            Store::F32(c) => get(c, k, x, y),
        }
    }

    /// The width and height of level 0 as `f64`.
    pub(crate) fn size0(&self) -> (f64, f64) {
        match &self.store {
            Store::Rgba8(c) => (c.levels[0].wf, c.levels[0].hf),
            Store::F32(c) => (c.levels[0].wf, c.levels[0].hf),
        }
    }
}

/// Everything a fetch needs besides the level: wrap modes and border.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Addressing {
    pub wrap: Wrap,
    pub border: [f32; 4],
}

impl<P: Pixel> Level<P> {
    /// The texel at integer index `(i, j)` after wrapping, or the border
    /// colour; reports the read to `sink`.
    #[inline(always)]
    pub fn fetch<S: TexelSink>(
        &self,
        lut: &P::Lut,
        li: u32,
        i: i64,
        j: i64,
        a: &Addressing,
        sink: &mut S,
    ) -> [f32; 4] {
        if (i as u64) < self.w as u64 && (j as u64) < self.h as u64 {
            return self.at(lut, li, i as usize, j as usize, sink);
        }
        match (
            wrap_index(a.wrap.u, i, self.w),
            wrap_index(a.wrap.v, j, self.h),
        ) {
            (Some(x), Some(y)) => self.at(lut, li, x as usize, y as usize, sink),
            _ => a.border,
        }
    }

    /// Texel at an in-range index (caller checked `x < w`, `y < h`).
    #[inline(always)]
    pub fn at<S: TexelSink>(
        &self,
        lut: &P::Lut,
        li: u32,
        x: usize,
        y: usize,
        sink: &mut S,
    ) -> [f32; 4] {
        sink.texel(li, x as u32, y as u32);
        self.texels[y * self.w as usize + x].decode(lut)
    }
}

/// `a·x + b·y` per channel.
#[inline(always)]
pub(crate) fn mix(x: [f32; 4], a: f32, y: [f32; 4], b: f32) -> [f32; 4] {
    [
        x[0] * a + y[0] * b,
        x[1] * a + y[1] * b,
        x[2] * a + y[2] * b,
        x[3] * a + y[3] * b,
    ]
}

/// `(1 − t)·x + t·y`: a convex blend that is exact at t = 0 and t = 1 and
/// cannot overflow for finite inputs.
#[inline(always)]
pub(crate) fn lerp(x: [f32; 4], y: [f32; 4], t: f32) -> [f32; 4] {
    mix(x, 1.0 - t, y, t)
}
