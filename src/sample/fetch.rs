//! Texel fetch: the view of a chain that every filter reads, and the
//! functions that turn an integer texel index into a linear-light colour.
//!
//! # Texels as stored, decoded at fetch
//! Filters work in linear light on RGBA `f32` (sRGB decoded first, as GPUs
//! do; grey replicated, missing alpha 1, as
//! [`crate::texture::expand_to_rgba`] defines). The texels stay in the
//! layout the [`MipChain`] stores them in — 1 to 4 channels of `u8`,
//! `u16`, `f16` or `f32` — and are decoded and expanded at fetch. Every
//! filter is generic over the stored texel (the `Pixel` trait, one
//! implementation per type and channel count), so the choice costs no
//! branch per texel. What a fetch returns is exactly what decoding the
//! whole level with [`crate::texel::decode_to_linear`] and expanding it
//! with `expand_to_rgba` gives (`tests/core/sampling_core/sample_storage.rs` checks every
//! format against that widened chain):
//!
//! - **`u8`**: a 256-entry table per channel (4 KiB, filled by
//!   [`crate::texel::decode_u8`]), plus, for RGBA8, the colour and alpha
//!   tables as byte planes (2 KiB) for the SIMD paths, which look up 64
//!   codes at a time.
//! - **`u16`**: linear channels are `code · (1/65535)`, as
//!   [`crate::texel::decode_u16`] computes them; sRGB channels read the
//!   crate's 65536-entry decode table (256 KiB, one per process, the same
//!   table `decode_u16` reads). A formula per fetch would be a `powf` per
//!   channel; widening to `f32` would double the bytes.
//! - **`f16`**: linear channels are converted by a branch-free bit
//!   conversion (exact, the same bits as `half`'s conversion, NaN quieted
//!   as F16C does; tested on all 65536 codes) that inlines into the
//!   filters, where `half::f16::to_f32` is an out-of-line call behind a
//!   run-time CPU check per value. sRGB channels read a 65536-entry table
//!   of the crate's float sRGB decode (256 KiB, one per process, built on
//!   first use).
//! - **`f32`**: read as stored. An sRGB `f32` chain (rare: float data is
//!   linear by convention) is decoded once to a linear `f32` copy with the
//!   same channel count, since its decode is an `f64` `powf` per channel.
//!
//! # Memory and sharing
//! A [`LinearChain`] reads the texel buffers of an `Arc<MipChain>`
//! ([`LinearChain::shared`]): no copy, only the per-chain decode tables
//! (6 KiB for 8-bit chains, nothing for the others). [`LinearChain::new`]
//! copies the chain once and shares the copy. The levels keep the `Arc`
//! alive and index into it; the source cannot change while it is shared
//! (an `Arc` gives no mutable access). The exceptions to "no copy" are sRGB
//! `f32` chains (the decoded copy above). Process-wide tables (the 256 KiB
//! sRGB tables of `u16` and `f16`) are not counted per chain.
//!
//! The trade-off against the former widened storage (every non-8-bit
//! chain decoded to 16-byte RGBA `f32`, every 1–3 channel 8-bit chain
//! padded to 4 bytes): a fetch decodes, where a widened texel was one
//! 16-byte load, but a texel is 1–16 bytes instead of 4 or 16, so a level
//! takes up to 8× fewer cache lines. The AVX-512 bilinear, trilinear and
//! footprint-assembly paths (`simd`) decode RGBA8 and RGBA `f32` blocks
//! in registers as before, and the other storages' blocks with
//! `Pixel::decode` per texel; the AVX-512 EWA sums (`ewa_simd`) read
//! RGBA8 only, the other storages take the AVX2 or portable EWA.
//!
//! # Addressing
//! Filters test once per footprint whether all the texels they need lie
//! inside the level (the common case) and then index the rows directly;
//! only footprints that cross the edge take the filters' general paths,
//! which wrap integer indices with [`wrap_index`] (once per axis for
//! bilinear, per texel in `Level::fetch` for nearest and EWA).

use std::fmt;
use std::sync::{Arc, OnceLock};

use half::f16;

use crate::mip::MipChain;
use crate::texel::{ChannelType, ColorSpace, Format, Texels};
use crate::texture::Texture;
use crate::wrap::{Wrap, wrap_index};

use crate::trace::TexelSink;

/// A stored texel that decodes to linear RGBA `f32`.
pub(crate) trait Pixel: bytemuck::Pod + Send + Sync + 'static {
    /// What decoding needs besides the texel (a table, or nothing).
    type Lut: Send + Sync + fmt::Debug + Clone;
    /// Texels are RGBA `f32`, the layout the AVX-512 paths read as it is.
    const RGBA_F32: bool = false;
    /// Texels are packed RGBA8 (`[u8; 4]`), the only storage the AVX-512
    /// EWA kernel reads: a constant, so the kernel is compiled for that
    /// storage alone instead of for all sixteen.
    const PACKED_RGBA8: bool = false;
    /// The linear-light RGBA value.
    fn decode(self, lut: &Self::Lut) -> [f32; 4];

    /// The decode table of a packed RGBA8 texel, `None` for every other
    /// storage (the SIMD paths read RGBA8 through it).
    #[inline(always)]
    fn packed(_lut: &Self::Lut) -> Option<&Lut8> {
        None
    }

    /// The stored values of a level as texels of this type, `None` when
    /// they are of another type.
    fn view(t: &Texels) -> Option<&[Self]>;

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

/// `N` decoded channel values as RGBA, exactly as
/// [`crate::texture::expand_to_rgba`] expands them (inlined).
#[inline(always)]
fn expand<const N: usize>(v: [f32; N]) -> [f32; 4] {
    match v.as_slice() {
        &[g] => [g, g, g, 1.0],
        &[g, a] => [g, g, g, a],
        &[r, g, b] => [r, g, b, 1.0],
        &[r, g, b, a, ..] => [r, g, b, a],
        [] => [0.0, 0.0, 0.0, 1.0],
    }
}

/// Per-channel decode table of an 8-bit chain: `table[c][i]` is the
/// linear value of code `i` in channel `c` of the texel expanded to RGBA.
#[derive(Clone)]
pub(crate) struct Lut8 {
    table: Box<[[f32; 256]; 4]>,
    /// The tables of channel 0 (colour) and channel 3 (alpha) as byte
    /// planes: `planes[k][p][i]` is byte `p` (little-endian) of the `f32`
    /// value of code `i`. The SIMD paths look up 64 codes at a time in
    /// them (`simd`); only RGBA8 chains have them.
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

impl Lut8 {
    fn bytes(&self) -> usize {
        std::mem::size_of_val(&*self.table) + std::mem::size_of_val(&*self.planes)
    }
}

impl<const N: usize> Pixel for [u8; N]
where
    [u8; N]: bytemuck::Pod,
{
    type Lut = Lut8;
    const PACKED_RGBA8: bool = N == 4;
    #[inline(always)]
    fn decode(self, lut: &Lut8) -> [f32; 4] {
        let t = &*lut.table;
        let v = |c: usize, k: usize| t[c][self[k] as usize];
        match N {
            1 => {
                let g = v(0, 0);
                [g, g, g, 1.0]
            }
            2 => {
                let g = v(0, 0);
                [g, g, g, v(3, 1)]
            }
            3 => [v(0, 0), v(1, 1), v(2, 2), 1.0],
            _ => [v(0, 0), v(1, 1), v(2, 2), v(3, 3)],
        }
    }

    #[inline(always)]
    fn packed(lut: &Lut8) -> Option<&Lut8> {
        (N == 4).then_some(lut)
    }

    fn view(t: &Texels) -> Option<&[Self]> {
        match t {
            Texels::U8(v) => bytemuck::try_cast_slice(v).ok(),
            _ => None,
        }
    }
}

/// Decode rule of a 16-bit chain (`u16` or `f16`): which stored channels
/// are sRGB, and the process-wide table they read.
#[derive(Clone, Copy)]
pub(crate) struct Lut16 {
    srgb: [bool; 4],
    table: Option<&'static [f32; 65536]>,
}

impl fmt::Debug for Lut16 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Lut16 {{ srgb: {:?} }}", self.srgb)
    }
}

impl Lut16 {
    /// The rule for `format`, with `table` giving the sRGB channels'
    /// values (built only when a channel needs it).
    fn new(format: &Format, table: fn() -> &'static [f32; 65536]) -> Self {
        let srgb = std::array::from_fn(|c| format.is_srgb_channel(c));
        Lut16 {
            srgb,
            table: srgb.contains(&true).then(table),
        }
    }

    /// The values of `codes`: `other` of each code when no channel is
    /// sRGB (one conversion over the whole texel, which vectorises), else
    /// the table's value for the sRGB channels.
    #[inline(always)]
    fn decode<const N: usize>(&self, codes: [u16; N], other: impl Fn(u16) -> f32) -> [f32; N] {
        match self.table {
            None => codes.map(other),
            Some(t) => std::array::from_fn(|c| {
                if self.srgb[c] {
                    t[codes[c] as usize]
                } else {
                    other(codes[c])
                }
            }),
        }
    }
}

/// Linear value of every 16-bit sRGB code: the crate's table
/// ([`crate::texel::decode_u16`] reads the same one).
fn srgb_u16_table() -> &'static [f32; 65536] {
    match crate::texel::srgb::decode16().try_into() {
        Ok(t) => t,
        Err(_) => unreachable!("the 16-bit sRGB table has an entry per code"),
    }
}

/// Linear value of every `f16` code as an sRGB colour channel: the crate's
/// float decode ([`crate::texel::decode_to_linear`]) of each code, built on
/// first use.
fn srgb_f16_table() -> &'static [f32; 65536] {
    static T: OnceLock<Box<[f32; 65536]>> = OnceLock::new();
    T.get_or_init(|| {
        let f = Format::new(1, ChannelType::F16, ColorSpace::Srgb);
        let codes = Texels::F16((0..=u16::MAX).map(f16::from_bits).collect());
        let mut t = Box::new([0f32; 65536]);
        crate::texel::decode_to_linear(&f, &codes, &mut t[..]);
        t
    })
}

/// `h` as `f32`, exactly (what `half` and F16C give, signalling NaNs
/// quieted): the exponent and mantissa moved into place and rescaled by
/// 2^112 with one multiply, which also normalises subnormals; infinities
/// and NaNs get the all-ones exponent. No branch, no table.
#[inline(always)]
pub(crate) fn f16_to_f32(h: u16) -> f32 {
    let h = h as u32;
    let em = h & 0x7fff;
    let scaled = (f32::from_bits(em << 13) * f32::from_bits(0x7780_0000)).to_bits();
    let special = (em << 13) | 0x7f80_0000 | if em > 0x7c00 { 0x0040_0000 } else { 0 };
    let bits = if em >= 0x7c00 { special } else { scaled };
    f32::from_bits(bits | (h & 0x8000) << 16)
}

impl<const N: usize> Pixel for [u16; N]
where
    [u16; N]: bytemuck::Pod,
{
    type Lut = Lut16;
    #[inline(always)]
    fn decode(self, lut: &Lut16) -> [f32; 4] {
        expand(lut.decode(self, |x| x as f32 * (1.0 / 65535.0)))
    }

    fn view(t: &Texels) -> Option<&[Self]> {
        match t {
            Texels::U16(v) => bytemuck::try_cast_slice(v).ok(),
            _ => None,
        }
    }
}

impl<const N: usize> Pixel for [f16; N]
where
    [f16; N]: bytemuck::Pod,
{
    type Lut = Lut16;
    #[inline(always)]
    fn decode(self, lut: &Lut16) -> [f32; 4] {
        expand(lut.decode(self.map(f16::to_bits), f16_to_f32))
    }

    fn view(t: &Texels) -> Option<&[Self]> {
        match t {
            Texels::F16(v) => bytemuck::try_cast_slice(v).ok(),
            _ => None,
        }
    }
}

impl<const N: usize> Pixel for [f32; N]
where
    [f32; N]: bytemuck::Pod,
{
    type Lut = ();
    const RGBA_F32: bool = N == 4;
    #[inline(always)]
    fn decode(self, _: &()) -> [f32; 4] {
        expand(self)
    }

    fn view(t: &Texels) -> Option<&[Self]> {
        match t {
            Texels::F32(v) => bytemuck::try_cast_slice(v).ok(),
            _ => None,
        }
    }
}

/// The texels of one level: a slice of a stored level of a [`MipChain`]
/// that this value keeps alive through its `Arc`, read as `[P]`.
///
/// The slice is kept as a pointer and a length rather than re-derived from
/// the chain at every access (a match on the storage type and a length
/// check per lookup); it dereferences to `&[P]`, and nothing else about it
/// leaves this type.
pub(crate) struct Buf<P> {
    ptr: *const P,
    len: usize,
    owner: Arc<MipChain>,
}

// SAFETY: a `Buf` is a shared slice of `P` plus the `Arc` that keeps it
// alive, both of which may be sent and shared when `P: Sync` (the slice is
// never written).
#[allow(unsafe_code)]
unsafe impl<P: Sync> Send for Buf<P> {}
// SAFETY: as above.
#[allow(unsafe_code)]
unsafe impl<P: Sync> Sync for Buf<P> {}

impl<P: Pixel> Buf<P> {
    /// Level `k` of `owner` as texels `P`, or `None` when its storage is
    /// another type.
    fn new(owner: Arc<MipChain>, k: usize) -> Option<Self> {
        let s = P::view(owner.level(k)?.texels())?;
        let (ptr, len) = (s.as_ptr(), s.len());
        Some(Buf { ptr, len, owner })
    }
}

impl<P> std::ops::Deref for Buf<P> {
    type Target = [P];
    #[inline(always)]
    fn deref(&self) -> &[P] {
        #[allow(unsafe_code)]
        // SAFETY: `ptr` and `len` are a slice of the `Vec` of one level of
        // the chain behind `owner` (`Buf::new`). That `Vec` is neither
        // written, reallocated nor dropped while the `Arc` lives (an `Arc`
        // gives shared access only, and `Arc::get_mut` fails while this
        // clone exists); moving the `Arc` does not move the buffer.
        unsafe {
            std::slice::from_raw_parts(self.ptr, self.len)
        }
    }
}

impl<P> Clone for Buf<P> {
    fn clone(&self) -> Self {
        Buf {
            ptr: self.ptr,
            len: self.len,
            owner: self.owner.clone(),
        }
    }
}

impl<P> fmt::Debug for Buf<P> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Buf({} texels)", self.len)
    }
}

/// One level, row-major.
#[derive(Clone, Debug)]
pub(crate) struct Level<P> {
    pub w: u32,
    pub h: u32,
    pub wf: f64,
    pub hf: f64,
    pub texels: Buf<P>,
}

/// Every level of a chain in one storage, with its decode table.
#[derive(Clone, Debug)]
pub(crate) struct Chain<P: Pixel> {
    pub levels: Box<[Level<P>]>,
    pub lut: P::Lut,
}

impl<P: Pixel> Chain<P> {
    /// The levels of `src` read as `P`, or `None` when they are stored
    /// otherwise.
    fn new(src: &Arc<MipChain>, lut: P::Lut) -> Option<Self> {
        let levels = (0..src.len())
            .map(|k| {
                let t = src.level(k)?;
                Some(Level {
                    w: t.width(),
                    h: t.height(),
                    wf: t.width() as f64,
                    hf: t.height() as f64,
                    texels: Buf::new(src.clone(), k)?,
                })
            })
            .collect::<Option<_>>()?;
        Some(Chain { levels, lut })
    }

    fn texel_bytes(&self) -> usize {
        self.levels
            .iter()
            .map(|l| std::mem::size_of_val(&*l.texels))
            .sum()
    }
}

/// The storage a chain is read in: its channel type and count (see the
/// module docs). [`with_chain!`] runs code on whichever it is.
#[derive(Clone, Debug)]
pub(crate) enum Store {
    U8x1(Chain<[u8; 1]>),
    U8x2(Chain<[u8; 2]>),
    U8x3(Chain<[u8; 3]>),
    U8x4(Chain<[u8; 4]>),
    U16x1(Chain<[u16; 1]>),
    U16x2(Chain<[u16; 2]>),
    U16x3(Chain<[u16; 3]>),
    U16x4(Chain<[u16; 4]>),
    F16x1(Chain<[f16; 1]>),
    F16x2(Chain<[f16; 2]>),
    F16x3(Chain<[f16; 3]>),
    F16x4(Chain<[f16; 4]>),
    F32x1(Chain<[f32; 1]>),
    F32x2(Chain<[f32; 2]>),
    F32x3(Chain<[f32; 3]>),
    F32x4(Chain<[f32; 4]>),
}

/// `with_chain!(store, c => expr)`: `expr` with `c` bound to the
/// `&Chain<P>` of whichever storage `store` (a `&Store`) holds — the one
/// dispatch on the storage, compiled once per storage type.
macro_rules! with_chain {
    ($store:expr, $c:ident => $e:expr) => {{
        use $crate::sample::fetch::Store as S;
        match $store {
            S::U8x1($c) => $e,
            S::U8x2($c) => $e,
            S::U8x3($c) => $e,
            S::U8x4($c) => $e,
            S::U16x1($c) => $e,
            S::U16x2($c) => $e,
            S::U16x3($c) => $e,
            S::U16x4($c) => $e,
            S::F16x1($c) => $e,
            S::F16x2($c) => $e,
            S::F16x3($c) => $e,
            S::F16x4($c) => $e,
            S::F32x1($c) => $e,
            S::F32x2($c) => $e,
            S::F32x3($c) => $e,
            S::F32x4($c) => $e,
        }
    }};
}
pub(crate) use with_chain;

/// The storage type of a [`Store`] variant: `P::of(store)` is the chain
/// when `store` holds `Chain<P>`. A function monomorphised for one
/// storage reads its chain with it instead of dispatching per call.
pub(crate) trait Stored: Pixel {
    fn of(store: &Store) -> Option<&Chain<Self>>;
}

macro_rules! stored {
    ($($v:ident: $p:ty),*) => {$(
        impl Stored for $p {
            #[inline(always)]
            fn of(store: &Store) -> Option<&Chain<Self>> {
                match store {
                    Store::$v(c) => Some(c),
                    _ => None,
                }
            }
        }
    )*};
}
stored!(
    U8x1: [u8; 1], U8x2: [u8; 2], U8x3: [u8; 3], U8x4: [u8; 4],
    U16x1: [u16; 1], U16x2: [u16; 2], U16x3: [u16; 3], U16x4: [u16; 4],
    F16x1: [f16; 1], F16x2: [f16; 2], F16x3: [f16; 3], F16x4: [f16; 4],
    F32x1: [f32; 1], F32x2: [f32; 2], F32x3: [f32; 3], F32x4: [f32; 4]
);

impl Store {
    /// `src`'s levels as stored (all levels share `format`).
    fn new(src: &Arc<MipChain>, format: &Format) -> Option<Store> {
        use ChannelType as T;
        Some(match (format.channel_type, format.channels) {
            (T::U8, 1) => Store::U8x1(Chain::new(src, lut8(format))?),
            (T::U8, 2) => Store::U8x2(Chain::new(src, lut8(format))?),
            (T::U8, 3) => Store::U8x3(Chain::new(src, lut8(format))?),
            (T::U8, _) => Store::U8x4(Chain::new(src, lut8(format))?),
            (T::U16, c) => {
                let lut = Lut16::new(format, srgb_u16_table);
                match c {
                    1 => Store::U16x1(Chain::new(src, lut)?),
                    2 => Store::U16x2(Chain::new(src, lut)?),
                    3 => Store::U16x3(Chain::new(src, lut)?),
                    _ => Store::U16x4(Chain::new(src, lut)?),
                }
            }
            (T::F16, c) => {
                let lut = Lut16::new(format, srgb_f16_table);
                match c {
                    1 => Store::F16x1(Chain::new(src, lut)?),
                    2 => Store::F16x2(Chain::new(src, lut)?),
                    3 => Store::F16x3(Chain::new(src, lut)?),
                    _ => Store::F16x4(Chain::new(src, lut)?),
                }
            }
            (T::F32, 1) => Store::F32x1(Chain::new(src, ())?),
            (T::F32, 2) => Store::F32x2(Chain::new(src, ())?),
            (T::F32, 3) => Store::F32x3(Chain::new(src, ())?),
            (T::F32, _) => Store::F32x4(Chain::new(src, ())?),
        })
    }

    /// Bytes of the per-chain decode table.
    fn table_bytes(&self) -> usize {
        match self {
            Store::U8x1(c) => c.lut.bytes(),
            Store::U8x2(c) => c.lut.bytes(),
            Store::U8x3(c) => c.lut.bytes(),
            Store::U8x4(c) => c.lut.bytes(),
            _ => 0,
        }
    }
}

/// A mip chain as the samplers read it: the texels as the chain stores
/// them, decoded at fetch (see the module docs for the decode rules and
/// the memory cost). Every accessor returns decoded linear-light values
/// whatever the storage. Samplers with different options share one
/// through an `Arc` ([`super::Sampler::from_linear`]).
#[derive(Clone)]
pub struct LinearChain {
    pub(crate) store: Store,
    format: Format,
    /// The chain this one was made from (the summed-area table is built
    /// from its level 0).
    source: Arc<MipChain>,
    /// The levels are a decoded copy, not `source`'s buffers (sRGB `f32`).
    copied: bool,
}

impl fmt::Debug for LinearChain {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("LinearChain")
            .field("format", &self.format)
            .field("levels", &self.len())
            .field("memory_bytes", &self.memory_bytes())
            .field("copied", &self.copied)
            .finish()
    }
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
        for (c, x) in crate::texture::expand_to_rgba(&lin[..ch])
            .into_iter()
            .enumerate()
        {
            t[c][i] = x;
        }
    }
    let mut planes = Box::new([[[0u8; 256]; 4]; 2]);
    if ch == 4 {
        for (k, c) in [0, 3].into_iter().enumerate() {
            for (i, x) in t[c].iter().enumerate() {
                for (p, b) in x.to_le_bytes().into_iter().enumerate() {
                    planes[k][p][i] = b;
                }
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

/// An sRGB `f32` chain's levels decoded to linear `f32`, same channel
/// count (values as [`crate::texel::decode_to_linear`] gives them).
fn decoded_f32(chain: &MipChain, format: &Format) -> MipChain {
    let lin = Format {
        color_space: ColorSpace::Linear,
        ..*format
    };
    let levels = chain
        .levels()
        .iter()
        .map(|t| Texture::from_f32(t.width(), t.height(), lin, t.to_linear()))
        .collect::<crate::Result<Vec<_>>>()
        .and_then(|levels| MipChain::from_levels(levels, *chain.options()));
    match levels {
        Ok(c) => c,
        Err(_) => unreachable!("a valid chain's levels, decoded, form a valid chain"),
    }
}

impl LinearChain {
    /// A copy of `chain`, read as stored (see [`LinearChain::shared`] to
    /// read the caller's chain without copying it).
    pub fn new(chain: &MipChain) -> Self {
        Self::shared(Arc::new(chain.clone()))
    }

    /// `chain`'s levels read where they are: the prepared chain holds
    /// the `Arc` and indexes into the chain's texel buffers, and adds only
    /// the decode table ([`LinearChain::added_bytes`]). Only an sRGB `f32`
    /// chain is copied, decoded to linear `f32` with the same channel
    /// count (its decode is too slow to run per fetch).
    pub fn shared(chain: Arc<MipChain>) -> Self {
        let format = chain.levels()[0].format();
        let srgb_float = format.channel_type == ChannelType::F32
            && (0..format.channels as usize).any(|c| format.is_srgb_channel(c));
        let decoded = srgb_float.then(|| Arc::new(decoded_f32(&chain, &format)));
        let (storage, copied) = match &decoded {
            Some(d) => (d.clone(), true),
            None => (chain.clone(), false),
        };
        // A `MipChain`'s levels share one format and hold whole texels, so
        // every level reads as that format's texel type.
        let Some(store) = Store::new(&storage, &format) else {
            unreachable!("a mip chain's levels hold whole texels of one format")
        };
        LinearChain {
            store,
            format,
            source: chain,
            copied,
        }
    }

    /// Format of the source chain (its channel count decides how many
    /// values the CLI prints).
    pub fn format(&self) -> Format {
        self.format
    }

    /// The chain this one reads (or, for an sRGB `f32` chain, decoded).
    pub fn source(&self) -> &Arc<MipChain> {
        &self.source
    }

    /// Number of levels.
    pub fn len(&self) -> usize {
        with_chain!(&self.store, c => c.levels.len())
    }

    /// Always false: a chain has level 0.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Size of level `k`.
    pub fn level_size(&self, k: usize) -> Option<(u32, u32)> {
        with_chain!(&self.store, c => c.levels.get(k).map(|l| (l.w, l.h)))
    }

    /// Bytes the samplers read: the texels (the source chain's own
    /// buffers unless it is sRGB `f32`) and the per-chain decode table.
    /// The 256 KiB sRGB tables of 16-bit chains exist once per process and
    /// are not counted.
    pub fn memory_bytes(&self) -> usize {
        with_chain!(&self.store, c => c.texel_bytes()) + self.store.table_bytes()
    }

    /// Bytes this prepared chain holds beyond its source chain's buffers:
    /// the decode table, plus the decoded copy of an sRGB `f32` chain.
    pub fn added_bytes(&self) -> usize {
        let copy = if self.copied {
            with_chain!(&self.store, c => c.texel_bytes())
        } else {
            0
        };
        copy + self.store.table_bytes()
    }

    /// Decoded texel `(x, y)` of level `k`, or `None` out of range.
    pub fn texel(&self, k: usize, x: u32, y: u32) -> Option<[f32; 4]> {
        fn get<P: Pixel>(c: &Chain<P>, k: usize, x: u32, y: u32) -> Option<[f32; 4]> {
            let l = c.levels.get(k)?;
            (x < l.w && y < l.h)
                .then(|| l.texels[y as usize * l.w as usize + x as usize].decode(&c.lut))
        }
        with_chain!(&self.store, c => get(c, k, x, y))
    }

    /// The width and height of level 0 as `f64`.
    pub(crate) fn size0(&self) -> (f64, f64) {
        with_chain!(&self.store, c => (c.levels[0].wf, c.levels[0].hf))
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn f16_bit_conversion_equals_half_on_every_code() {
        for h in 0..=u16::MAX {
            let want = f16::from_bits(h).to_f32();
            let got = f16_to_f32(h);
            // NaNs: the same quiet NaN (F16C and `half` quiet them).
            assert_eq!(got.to_bits(), want.to_bits(), "code {h:#06x}");
        }
    }

    #[test]
    fn expansion_equals_expand_to_rgba() {
        use crate::texture::expand_to_rgba;
        let v = [0.25f32, -3.0, 7.5, 0.125];
        assert_eq!(expand([v[0]]), expand_to_rgba(&v[..1]));
        assert_eq!(expand([v[0], v[1]]), expand_to_rgba(&v[..2]));
        assert_eq!(expand([v[0], v[1], v[2]]), expand_to_rgba(&v[..3]));
        assert_eq!(expand(v), expand_to_rgba(&v));
    }

    #[test]
    fn srgb_f16_table_is_the_crates_float_decode() {
        let f = Format::new(3, ChannelType::F16, ColorSpace::Srgb);
        let t = srgb_f16_table();
        for h in (0..=u16::MAX).step_by(7) {
            let mut out = [0f32; 3];
            let codes = Texels::F16(vec![f16::from_bits(h); 3]);
            crate::texel::decode_to_linear(&f, &codes, &mut out);
            assert_eq!(t[h as usize].to_bits(), out[0].to_bits(), "code {h:#06x}");
        }
    }
}
