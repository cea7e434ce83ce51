//! Texel memory layouts: the byte address of texel (level, x, y) of a whole
//! mip chain in one address space (SPEC.md, "Texel memory layouts").
//!
//! Levels lie one after another, each starting at a multiple of 4096 bytes;
//! a texel takes `channels × bytes per channel`, three channels padded to
//! four as GPUs store them. Within a level:
//! - `linear`: `(y·w + x)·b`;
//! - `tiled:TWxTH`: whole tiles in row-major order, row-major inside;
//! - `morton`: the Z-order index of (x, y), x in the even bits, over the
//!   power-of-two square holding the level; `morton:TWxTH` is tiled with
//!   Morton order inside each (power-of-two) tile;
//! - `blocked:TWxTH:SWxSH`: super-tiles of SW×SH texels made of TW×TH
//!   tiles (Hakura & Gupta's "6D" blocking), each level row-major.
//!
//! Block-compressed chains ([`ChainLayout::blocks`]) lay out 4×4 blocks
//! instead of texels: the layout's unit is the block (`tiled:4x4` is then 4×4
//! blocks), a texel's address is its block's, and an access reads the
//! whole block (8 or 16 bytes), as a GPU's texture unit fetches it.
//!
//! [`ChainLayout::address`] is a pure function; every layout maps the
//! texels of a chain to distinct, non-overlapping byte ranges inside
//! [`ChainLayout::total_bytes`] (tested for odd and non-square sizes). A
//! summed-area table is a region of its own after the chain
//! ([`ChainLayout::with_sat`]): entries row-major, entry size = channels ×
//! accumulator bytes.

use std::fmt;
use std::str::FromStr;

use crate::error::{Error, Result};
use crate::scene::order::interleave;

/// Alignment of every level (and of the summed-area table).
pub const LEVEL_ALIGN: u64 = 4096;

/// A texel memory layout (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Layout {
    /// Row-major.
    #[default]
    Linear,
    /// Row-major tiles of `tw × th` texels, row-major inside.
    Tiled {
        /// Tile width.
        tw: u32,
        /// Tile height.
        th: u32,
    },
    /// Z-order over the power-of-two square holding the level.
    Morton,
    /// Row-major tiles, Z-order inside each (power-of-two) tile.
    MortonTiled {
        /// Tile width (a power of two).
        tw: u32,
        /// Tile height (a power of two).
        th: u32,
    },
    /// Super-tiles of `sw × sh` texels made of `tw × th` tiles.
    Blocked {
        /// Tile width.
        tw: u32,
        /// Tile height.
        th: u32,
        /// Super-tile width (a multiple of `tw`).
        sw: u32,
        /// Super-tile height (a multiple of `th`).
        sh: u32,
    },
}

impl fmt::Display for Layout {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Layout::Linear => f.write_str("linear"),
            Layout::Tiled { tw, th } => write!(f, "tiled:{tw}x{th}"),
            Layout::Morton => f.write_str("morton"),
            Layout::MortonTiled { tw, th } => write!(f, "morton:{tw}x{th}"),
            Layout::Blocked { tw, th, sw, sh } => write!(f, "blocked:{tw}x{th}:{sw}x{sh}"),
        }
    }
}

fn dims(what: &'static str, s: &str, t: &str) -> Result<(u32, u32)> {
    let bad = || {
        Error::parse(
            what,
            s,
            format!("`{t}` is not WxH with W and H from 1 to 4096"),
        )
    };
    let (a, b) = t.split_once(['x', 'X']).ok_or_else(bad)?;
    let p = |v: &str| {
        v.parse::<u32>()
            .ok()
            .filter(|n| (1..=4096).contains(n))
            .ok_or_else(bad)
    };
    Ok((p(a)?, p(b)?))
}

impl FromStr for Layout {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        let what = "memory layout";
        let t = s.trim().to_ascii_lowercase();
        let parts: Vec<&str> = t.split(':').collect();
        let layout = match parts.as_slice() {
            ["linear"] => Layout::Linear,
            ["morton"] => Layout::Morton,
            ["tiled", d] => {
                let (tw, th) = dims(what, s, d)?;
                Layout::Tiled { tw, th }
            }
            ["morton", d] => {
                let (tw, th) = dims(what, s, d)?;
                if !tw.is_power_of_two() || !th.is_power_of_two() {
                    return Err(Error::parse(
                        what,
                        s,
                        "morton tiles must be powers of two (Z-order fills a power-of-two tile)",
                    ));
                }
                Layout::MortonTiled { tw, th }
            }
            ["blocked", d, e] => {
                let (tw, th) = dims(what, s, d)?;
                let (sw, sh) = dims(what, s, e)?;
                if sw % tw != 0 || sh % th != 0 {
                    return Err(Error::parse(
                        what,
                        s,
                        "the super-tile must be a whole number of tiles in each direction",
                    ));
                }
                Layout::Blocked { tw, th, sw, sh }
            }
            _ => {
                return Err(Error::parse(
                    what,
                    s,
                    "expected linear, tiled:WxH, morton, morton:WxH or blocked:WxH:SWxSH",
                ));
            }
        };
        Ok(layout)
    }
}

/// Z-order index inside a `tw × th` power-of-two tile: the low bits of x
/// and y interleaved as far as both reach, then the rest of the longer
/// side's bits above them.
fn morton_in_tile(x: u32, y: u32, tw: u32, th: u32) -> u64 {
    let (bx, by) = (tw.trailing_zeros(), th.trailing_zeros());
    let k = bx.min(by);
    let mask = (1u32 << k) - 1;
    let low = interleave(x & mask, y & mask);
    let high = if bx > by {
        (x >> k) as u64
    } else {
        (y >> k) as u64
    };
    low | (high << (2 * k))
}

impl Layout {
    /// Bytes a `w × h` level of `texel`-byte texels occupies, padded as the
    /// layout pads it.
    pub fn level_bytes(&self, w: u32, h: u32, texel: u64) -> u64 {
        let (w, h) = (w as u64, h as u64);
        let texels = match *self {
            Layout::Linear => w * h,
            Layout::Tiled { tw, th } | Layout::MortonTiled { tw, th } => {
                w.div_ceil(tw as u64) * tw as u64 * h.div_ceil(th as u64) * th as u64
            }
            Layout::Morton => {
                let side = w.max(h).next_power_of_two();
                side * side
            }
            Layout::Blocked { sw, sh, .. } => {
                w.div_ceil(sw as u64) * sw as u64 * h.div_ceil(sh as u64) * sh as u64
            }
        };
        texels * texel
    }

    /// Texel offset (in texels) of `(x, y)` inside a level of width `w`.
    #[inline]
    pub fn offset(&self, w: u32, x: u32, y: u32) -> u64 {
        match *self {
            Layout::Linear => y as u64 * w as u64 + x as u64,
            Layout::Tiled { tw, th } => {
                let tiles_x = w.div_ceil(tw) as u64;
                ((y / th) as u64 * tiles_x + (x / tw) as u64) * (tw as u64 * th as u64)
                    + (y % th) as u64 * tw as u64
                    + (x % tw) as u64
            }
            Layout::Morton => interleave(x, y),
            Layout::MortonTiled { tw, th } => {
                let tiles_x = w.div_ceil(tw) as u64;
                ((y / th) as u64 * tiles_x + (x / tw) as u64) * (tw as u64 * th as u64)
                    + morton_in_tile(x % tw, y % th, tw, th)
            }
            Layout::Blocked { tw, th, sw, sh } => {
                let supers_x = w.div_ceil(sw) as u64;
                let (xs, ys) = (x % sw, y % sh);
                ((y / sh) as u64 * supers_x + (x / sw) as u64) * (sw as u64 * sh as u64)
                    + ((ys / th) as u64 * (sw / tw) as u64 + (xs / tw) as u64)
                        * (tw as u64 * th as u64)
                    + (ys % th) as u64 * tw as u64
                    + (xs % tw) as u64
            }
        }
    }
}

/// A chain's levels (and optionally a summed-area table) in one address
/// space.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ChainLayout {
    layout: Layout,
    /// [`Layout::offset`] as [`ChainLayout::address`] computes it.
    fast: Fast,
    /// Bytes of one access: a texel, or a block.
    texel: u64,
    /// log2 of the block side in texels: 0 for texels, 2 for 4×4 blocks.
    block_shift: u32,
    /// Per level: width, height, base address.
    levels: Vec<(u32, u32, u64)>,
    /// Per level: the width in units of the layout's row-major grid (texels
    /// for `linear`, tiles for `tiled` and `morton:WxH`, super-tiles for
    /// `blocked`).
    rows: Vec<u64>,
    /// Summed-area table: entries per row, entry bytes, base address.
    sat: Option<(u64, u64, u64)>,
    total: u64,
}

/// [`Layout::offset`] with the tile sides as shifts when they are powers
/// of two (the tiles GPUs use): the same offsets without a division per
/// texel (`tests/core/cache_report/cache_fast_paths.rs` compares them for every texel of
/// odd-sized chains). Other sides use [`Layout::offset`] itself.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Fast {
    Linear,
    Morton,
    /// Tiles of 2^bx × 2^by, row-major (or Z-order) inside.
    Tiled {
        bx: u32,
        by: u32,
        morton: bool,
    },
    /// Tiles of 2^tx × 2^ty in super-tiles of 2^sx × 2^sy.
    Blocked {
        tx: u32,
        ty: u32,
        sx: u32,
        sy: u32,
    },
    Plain,
}

impl Fast {
    fn of(layout: Layout) -> Self {
        let p2 = |v: &[u32]| v.iter().all(|n| n.is_power_of_two());
        let lg = u32::trailing_zeros;
        match layout {
            Layout::Linear => Fast::Linear,
            Layout::Morton => Fast::Morton,
            Layout::Tiled { tw, th } if p2(&[tw, th]) => Fast::Tiled {
                bx: lg(tw),
                by: lg(th),
                morton: false,
            },
            Layout::MortonTiled { tw, th } => Fast::Tiled {
                bx: lg(tw),
                by: lg(th),
                morton: true,
            },
            Layout::Blocked { tw, th, sw, sh } if p2(&[tw, th, sw, sh]) => Fast::Blocked {
                tx: lg(tw),
                ty: lg(th),
                sx: lg(sw),
                sy: lg(sh),
            },
            _ => Fast::Plain,
        }
    }

    /// Units per row of a level `w` texels wide.
    fn row(layout: Layout, w: u32) -> u64 {
        match layout {
            Layout::Linear | Layout::Morton => w as u64,
            Layout::Tiled { tw, .. } | Layout::MortonTiled { tw, .. } => w.div_ceil(tw) as u64,
            Layout::Blocked { sw, .. } => w.div_ceil(sw) as u64,
        }
    }
}

impl ChainLayout {
    /// The layout of levels of the given sizes (level 0 first) with
    /// `texel_bytes` per texel (already padded: 3 channels as 4).
    pub fn new(layout: Layout, sizes: &[(u32, u32)], texel_bytes: u64) -> Self {
        let mut at = 0u64;
        let mut levels = Vec::with_capacity(sizes.len());
        for &(w, h) in sizes {
            levels.push((w, h, at));
            at = (at + layout.level_bytes(w, h, texel_bytes)).next_multiple_of(LEVEL_ALIGN);
        }
        ChainLayout {
            layout,
            fast: Fast::of(layout),
            texel: texel_bytes,
            block_shift: 0,
            rows: sizes.iter().map(|&(w, _)| Fast::row(layout, w)).collect(),
            levels,
            sat: None,
            total: at,
        }
    }

    /// The layout of a block-compressed chain with levels of the given
    /// sizes (in texels): 4×4 blocks of `block_bytes` each are the unit
    /// (see the module docs).
    pub fn blocks(layout: Layout, sizes: &[(u32, u32)], block_bytes: u64) -> Self {
        let in_blocks: Vec<(u32, u32)> = sizes
            .iter()
            .map(|&(w, h)| (w.div_ceil(4), h.div_ceil(4)))
            .collect();
        let mut c = ChainLayout::new(layout, &in_blocks, block_bytes);
        c.block_shift = 2;
        c
    }

    /// The side of the unit in texels: 1, or 4 for block-compressed chains.
    pub fn block_side(&self) -> u32 {
        1 << self.block_shift
    }

    /// The layout of `chain`'s levels in its stored format.
    pub fn of_chain(chain: &crate::MipChain, layout: Layout) -> Self {
        let f = chain.levels()[0].format();
        let sizes: Vec<(u32, u32)> = chain
            .levels()
            .iter()
            .map(|l| (l.width(), l.height()))
            .collect();
        ChainLayout::new(
            layout,
            &sizes,
            ChainLayout::texel_bytes(f.channels, f.channel_type.bytes()),
        )
    }

    /// The layout a sampler reads: `chain`'s levels, and its summed-area
    /// table after them when the sampler filters with one (`sat`).
    pub fn for_sampler(chain: &crate::MipChain, sampler: &crate::Sampler, layout: Layout) -> Self {
        let c = Self::of_chain(chain, layout);
        match sampler.sat() {
            Some(s) => {
                let l0 = &chain.levels()[0];
                c.with_sat(l0.width(), l0.height(), s.table().entry_bytes())
            }
            None => c,
        }
    }

    /// [`ChainLayout::for_sampler`] for a chain stored as `blocks` (see
    /// [`ChainLayout::blocks`]), or as texels when `None`.
    pub fn for_sampler_stored(
        chain: &crate::MipChain,
        sampler: &crate::Sampler,
        layout: Layout,
        blocks: Option<crate::compress::BlockFormat>,
    ) -> Self {
        let Some(bf) = blocks else {
            return Self::for_sampler(chain, sampler, layout);
        };
        let sizes: Vec<(u32, u32)> = chain
            .levels()
            .iter()
            .map(|l| (l.width(), l.height()))
            .collect();
        let c = Self::blocks(layout, &sizes, bf.block_bytes() as u64);
        match sampler.sat() {
            Some(s) => c.with_sat(sizes[0].0, sizes[0].1, s.table().entry_bytes()),
            None => c,
        }
    }

    /// Texel bytes for `channels` channels of `bytes_per_channel` bytes:
    /// three channels are padded to four.
    pub fn texel_bytes(channels: u8, bytes_per_channel: usize) -> u64 {
        let ch = if channels == 3 { 4 } else { channels as u64 };
        ch * bytes_per_channel as u64
    }

    /// Add a summed-area table of a `w × h` level-0 after the chain: `(w +
    /// 1) × (h + 1)` entries of `entry_bytes`, row-major.
    pub fn with_sat(mut self, w: u32, h: u32, entry_bytes: u64) -> Self {
        let base = self.total;
        let row = w as u64 + 1;
        self.sat = Some((row, entry_bytes, base));
        self.total = (base + row * (h as u64 + 1) * entry_bytes).next_multiple_of(LEVEL_ALIGN);
        self
    }

    /// The layout.
    pub fn layout(&self) -> Layout {
        self.layout
    }

    /// Bytes of one texel access (the whole block for block-compressed
    /// chains).
    pub fn texel(&self) -> u64 {
        self.texel
    }

    /// Bytes per summed-area table entry, if the table is laid out.
    pub fn sat_entry(&self) -> Option<u64> {
        self.sat.map(|s| s.1)
    }

    /// Number of levels.
    pub fn levels(&self) -> usize {
        self.levels.len()
    }

    /// Size of the whole address space (a multiple of 4096).
    pub fn total_bytes(&self) -> u64 {
        self.total
    }

    /// Base address of level `k`.
    pub fn level_base(&self, k: usize) -> u64 {
        self.levels[k].2
    }

    /// Byte address of texel `(x, y)` of level `level` (in range).
    #[inline(always)]
    pub fn address(&self, level: u32, x: u32, y: u32) -> u64 {
        let k = level as usize;
        let (w, _, base) = self.levels[k];
        let row = self.rows[k];
        let (x, y) = (x >> self.block_shift, y >> self.block_shift);
        let offset = match self.fast {
            Fast::Linear => y as u64 * w as u64 + x as u64,
            Fast::Morton => interleave(x, y),
            Fast::Tiled {
                bx,
                by,
                morton: false,
            } => tiled_offset(row, bx, by, x, y),
            Fast::Tiled {
                bx,
                by,
                morton: true,
            } => {
                let tile = ((y >> by) as u64 * row + (x >> bx) as u64) << (bx + by);
                let (mx, my) = ((1u32 << bx) - 1, (1u32 << by) - 1);
                tile + morton_in_tile(x & mx, y & my, 1 << bx, 1 << by)
            }
            Fast::Blocked { tx, ty, sx, sy } => {
                let start = ((y >> sy) as u64 * row + (x >> sx) as u64) << (sx + sy);
                let (xs, ys) = (x & ((1u32 << sx) - 1), y & ((1u32 << sy) - 1));
                let inner = ((ys >> ty) << (sx - tx)) + (xs >> tx);
                let (mx, my) = ((1u32 << tx) - 1, (1u32 << ty) - 1);
                start + ((inner as u64) << (tx + ty)) + ((((ys & my) << tx) | (xs & mx)) as u64)
            }
            Fast::Plain => self.plain_offset(w, x, y),
        };
        base + offset * self.texel
    }

    /// [`Layout::offset`], out of line: tile sides that are not powers of
    /// two are rare, and the shifted paths stay small where they are
    /// inlined.
    #[cold]
    #[inline(never)]
    fn plain_offset(&self, w: u32, x: u32, y: u32) -> u64 {
        self.layout.offset(w, x, y)
    }

    /// The addresses of the 2×2 block at `(x, y)` (inside the level) in
    /// read order, `(x, y)`, `(x + 1, y)`, `(x, y + 1)`, `(x + 1, y + 1)`,
    /// worked out together for row-major levels and row-major tiles of
    /// power-of-two sides (the block inside one tile or across tiles).
    /// `None` otherwise (take [`ChainLayout::address`] per texel). The
    /// first address is the lowest and the last the highest, so the two
    /// tell whether all four share a cache line.
    #[inline(always)]
    pub fn block_addresses(&self, level: u32, x: u32, y: u32) -> Option<[u64; 4]> {
        if self.block_shift != 0 {
            return None;
        }
        let t = self.texel;
        let k = level as usize;
        let (w, _, base) = self.levels[k];
        // One match on the layout per block, not one per texel.
        match self.fast {
            Fast::Linear => {
                let a = base + (y as u64 * w as u64 + x as u64) * t;
                let dy = w as u64 * t;
                Some([a, a + t, a + dy, a + dy + t])
            }
            Fast::Tiled {
                bx,
                by,
                morton: false,
            } => {
                let row = self.rows[k];
                let at = |x, y| base + tiled_offset(row, bx, by, x, y) * t;
                if (!x & ((1 << bx) - 1)) != 0 && (!y & ((1 << by) - 1)) != 0 {
                    let (a, dy) = (at(x, y), t << bx);
                    Some([a, a + t, a + dy, a + dy + t])
                } else {
                    Some([at(x, y), at(x + 1, y), at(x, y + 1), at(x + 1, y + 1)])
                }
            }
            _ => None,
        }
    }

    /// What the 8-lane address code of [`crate::cache::isotropic`]'s
    /// `trace_all` needs of this
    /// layout: row-major levels or row-major tiles of power-of-two sides
    /// (the two [`ChainLayout::block_addresses`] works out), texels as the
    /// unit, at most [`LANE_LEVELS`] levels; `None` otherwise.
    pub(crate) fn lanes(&self) -> Option<Lanes> {
        if self.block_shift != 0 || self.levels.len() > LANE_LEVELS {
            return None;
        }
        let (bx, by) = match self.fast {
            // Row-major levels are tiles of one texel, a row of tiles
            // being a row of texels (`Fast::row`).
            Fast::Linear => (0, 0),
            Fast::Tiled {
                bx,
                by,
                morton: false,
            } => (bx, by),
            _ => return None,
        };
        let mut l = Lanes {
            bx,
            by,
            texel: self.texel,
            base: [0; LANE_LEVELS],
            row: [0; LANE_LEVELS],
        };
        for (k, (&(_, _, base), &row)) in self.levels.iter().zip(&self.rows).enumerate() {
            (l.base[k], l.row[k]) = (base, row);
        }
        Some(l)
    }

    /// [`ChainLayout::address`] by [`Layout::offset`], the formula as
    /// SPEC.md states it (the reference the address is tested against).
    pub fn address_plain(&self, level: u32, x: u32, y: u32) -> u64 {
        let (w, _, base) = self.levels[level as usize];
        let (x, y) = (x >> self.block_shift, y >> self.block_shift);
        base + self.layout.offset(w, x, y) * self.texel
    }

    /// Width and height of level `k` in the layout's units (texels, or
    /// 4×4 blocks).
    pub fn level_size(&self, k: usize) -> (u32, u32) {
        let (w, h, _) = self.levels[k];
        (w, h)
    }

    /// Byte address of summed-area table entry `(x, y)` (0 ≤ x ≤ w,
    /// 0 ≤ y ≤ h); `None` if no table is laid out (see
    /// [`ChainLayout::with_sat`]).
    #[inline]
    pub fn sat_address(&self, x: u32, y: u32) -> Option<u64> {
        let (row, entry, base) = self.sat?;
        Some(base + (y as u64 * row + x as u64) * entry)
    }

    /// Which region an address belongs to: `Some(level)` for a texel of
    /// a level, `None` for the summed-area table or padding past the end.
    pub fn level_of(&self, address: u64) -> Option<u32> {
        let k = self.levels.partition_point(|l| l.2 <= address);
        (k > 0)
            .then(|| k as u32 - 1)
            .filter(|&k| self.sat.is_none_or(|s| address < s.2) && (k as usize) < self.levels.len())
    }
}

/// Levels [`ChainLayout::lanes`] covers: two registers of 8 lanes.
pub(crate) const LANE_LEVELS: usize = 16;

/// A layout as [`ChainLayout::lanes`] gives it: texel `(x, y)` of level
/// `k` is at `base[k] + tiled_offset(row[k], bx, by, x, y) · texel`.
#[derive(Clone, Debug)]
pub(crate) struct Lanes {
    pub bx: u32,
    pub by: u32,
    pub texel: u64,
    pub base: [u64; LANE_LEVELS],
    pub row: [u64; LANE_LEVELS],
}

/// The offset in texels of `(x, y)` in row-major tiles of 2^bx × 2^by,
/// row-major inside, `row` tiles to a row of tiles.
#[inline(always)]
fn tiled_offset(row: u64, bx: u32, by: u32, x: u32, y: u32) -> u64 {
    let tile = ((y >> by) as u64 * row + (x >> bx) as u64) << (bx + by);
    let (mx, my) = ((1u32 << bx) - 1, (1u32 << by) - 1);
    tile + ((((y & my) << bx) | (x & mx)) as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_bad_ones_say_why() {
        for n in [
            "linear",
            "tiled:4x4",
            "tiled:8x2",
            "morton",
            "morton:8x4",
            "blocked:4x4:32x32",
        ] {
            assert_eq!(n.parse::<Layout>().unwrap().to_string(), n);
        }
        for bad in [
            "tiled",
            "tiled:0x4",
            "morton:3x4",
            "blocked:4x4:30x32",
            "zorder",
        ] {
            assert!(bad.parse::<Layout>().is_err(), "{bad}");
        }
    }

    #[test]
    fn spec_formulas_on_hand_worked_texels() {
        // tiled:4x2, level 10 wide: texel (5, 3) is in tile (1, 1), tiles
        // per row 3: ((1·3 + 1)·8 + (3 mod 2)·4 + 5 mod 4) = 37.
        assert_eq!(Layout::Tiled { tw: 4, th: 2 }.offset(10, 5, 3), 37);
        // morton: (3, 5) → x bits 011 in even, y 101 in odd: 0b100111 = 39.
        assert_eq!(Layout::Morton.offset(8, 3, 5), 39);
        // blocked 2x2 tiles in 4x4 super-tiles, level 8 wide: (5, 6) is in
        // super (1, 1) [2 per row → index 3, ·16 = 48], tile (0, 1) inside
        // [index 2, ·4 = 8], texel (1, 0) inside [1]: 57.
        let b = Layout::Blocked {
            tw: 2,
            th: 2,
            sw: 4,
            sh: 4,
        };
        assert_eq!(b.offset(8, 5, 6), 57);
    }

    /// Where `block_addresses` answers, its four addresses are the SPEC
    /// formula's for the 2×2 block, the first the lowest and the last the
    /// highest; it answers for every block of a row-major level or of a
    /// power-of-two tiled layout, and for no other (awkward level sizes,
    /// several texel sizes).
    #[test]
    fn block_addresses_equal_the_formula() {
        let sizes = [(37, 23), (18, 11), (9, 5), (4, 2), (2, 1), (1, 1)];
        for layout in [
            Layout::Linear,
            Layout::Tiled { tw: 4, th: 4 },
            Layout::Tiled { tw: 8, th: 2 },
            Layout::Tiled { tw: 2, th: 16 },
            Layout::Tiled { tw: 1, th: 1 },
            Layout::Tiled { tw: 3, th: 4 },
            Layout::Morton,
            Layout::MortonTiled { tw: 4, th: 4 },
        ] {
            for texel in [1, 4, 16] {
                let c = ChainLayout::new(layout, &sizes, texel);
                let (mut blocks, mut answered) = (0, 0);
                for (k, &(w, h)) in sizes.iter().enumerate() {
                    for y in 0..h.saturating_sub(1) {
                        for x in 0..w.saturating_sub(1) {
                            blocks += 1;
                            let Some(a) = c.block_addresses(k as u32, x, y) else {
                                continue;
                            };
                            answered += 1;
                            let f = |x, y| c.address_plain(k as u32, x, y);
                            assert_eq!(
                                a,
                                [f(x, y), f(x + 1, y), f(x, y + 1), f(x + 1, y + 1)],
                                "{layout} texel {texel} level {k} ({x}, {y})"
                            );
                            assert!(a.iter().all(|&b| a[0] <= b && b <= a[3]), "{a:?}");
                        }
                    }
                }
                let per_texel = matches!(
                    layout,
                    Layout::Morton | Layout::MortonTiled { .. } | Layout::Tiled { tw: 3, .. }
                );
                assert_eq!(
                    answered,
                    if per_texel { 0 } else { blocks },
                    "{layout} {texel}"
                );
            }
        }
    }

    /// Block-compressed chains: the texels of one 4×4 block share its
    /// address, distinct blocks get distinct `block_bytes` ranges, and
    /// levels hold whole blocks (a 5×3 level is 2×1 blocks).
    #[test]
    fn block_layouts_address_whole_blocks() {
        let sizes = [(10, 6), (5, 3), (2, 1), (1, 1)];
        for layout in [
            Layout::Linear,
            Layout::Tiled { tw: 2, th: 2 },
            Layout::Morton,
        ] {
            let c = ChainLayout::blocks(layout, &sizes, 16);
            assert_eq!(c.texel(), 16);
            assert_eq!(c.block_side(), 4);
            let mut seen = std::collections::HashMap::new();
            for (k, &(w, h)) in sizes.iter().enumerate() {
                for y in 0..h {
                    for x in 0..w {
                        let a = c.address(k as u32, x, y);
                        assert_eq!(a % 16, 0);
                        assert!(a + 16 <= c.total_bytes());
                        let block = (k, x / 4, y / 4);
                        if let Some(prev) = seen.insert(a, block) {
                            assert_eq!(prev, block, "{layout}: two blocks at {a}");
                        }
                    }
                }
            }
            // 3x2 + 2x1 + 1 + 1 blocks.
            assert_eq!(seen.len(), 6 + 2 + 1 + 1, "{layout}");
        }
    }
}
