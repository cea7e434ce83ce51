//! Raster orders: the order in which a frame's pixels are filtered (SPEC.md).
//!
//! - `scanline`: rows top to bottom, each left to right;
//! - `tiled:N`: N×N tiles in scanline order of tiles, scanline inside each
//!   tile, partial tiles at the right and bottom edges;
//! - `morton`: Z-order of (px, py), px in the even bits, pixels outside the
//!   frame skipped;
//! - `hilbert`: the Hilbert curve over the smallest power-of-two square
//!   holding the frame, pixels outside skipped.

use std::fmt;
use std::str::FromStr;

use super::Frame;
use crate::error::{Error, Result};

/// A raster order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum RasterOrder {
    /// Rows top to bottom.
    #[default]
    Scanline,
    /// N×N-pixel tiles.
    Tiled(u32),
    /// Z-order.
    Morton,
    /// Hilbert curve.
    Hilbert,
}

impl fmt::Display for RasterOrder {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RasterOrder::Scanline => f.write_str("scanline"),
            RasterOrder::Tiled(n) => write!(f, "tiled:{n}"),
            RasterOrder::Morton => f.write_str("morton"),
            RasterOrder::Hilbert => f.write_str("hilbert"),
        }
    }
}

impl FromStr for RasterOrder {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        let t = s.trim().to_ascii_lowercase();
        Ok(match t.as_str() {
            "scanline" => RasterOrder::Scanline,
            "morton" => RasterOrder::Morton,
            "hilbert" => RasterOrder::Hilbert,
            _ => match t.strip_prefix("tiled:") {
                Some(n) => RasterOrder::Tiled(
                    n.parse::<u32>()
                        .ok()
                        .filter(|&n| (1..=4096).contains(&n))
                        .ok_or_else(|| {
                            Error::parse("raster order", s, "tiled:N needs N from 1 to 4096")
                        })?,
                ),
                None => {
                    return Err(Error::parse(
                        "raster order",
                        s,
                        "expected scanline, tiled:N, morton or hilbert",
                    ));
                }
            },
        })
    }
}

/// x in the even bits, y in the odd bits (16 bits each).
pub(crate) fn interleave(x: u32, y: u32) -> u64 {
    fn spread(v: u32) -> u64 {
        let mut v = v as u64 & 0xffff_ffff;
        v = (v | (v << 16)) & 0x0000_ffff_0000_ffff;
        v = (v | (v << 8)) & 0x00ff_00ff_00ff_00ff;
        v = (v | (v << 4)) & 0x0f0f_0f0f_0f0f_0f0f;
        v = (v | (v << 2)) & 0x3333_3333_3333_3333;
        v = (v | (v << 1)) & 0x5555_5555_5555_5555;
        v
    }
    spread(x) | (spread(y) << 1)
}

fn compact(v: u64) -> u32 {
    let mut v = v & 0x5555_5555_5555_5555;
    v = (v | (v >> 1)) & 0x3333_3333_3333_3333;
    v = (v | (v >> 2)) & 0x0f0f_0f0f_0f0f_0f0f;
    v = (v | (v >> 4)) & 0x00ff_00ff_00ff_00ff;
    v = (v | (v >> 8)) & 0x0000_ffff_0000_ffff;
    v = (v | (v >> 16)) & 0x0000_0000_ffff_ffff;
    v as u32
}

/// Position `d` along the Hilbert curve of an `n × n` square (n a power of
/// two), the classic `d2xy`.
fn hilbert_d2xy(n: u64, d: u64) -> (u32, u32) {
    let (mut x, mut y) = (0u64, 0u64);
    let mut t = d;
    let mut s = 1u64;
    while s < n {
        let rx = 1 & (t / 2);
        let ry = 1 & (t ^ rx);
        if ry == 0 {
            if rx == 1 {
                x = s - 1 - x;
                y = s - 1 - y;
            }
            std::mem::swap(&mut x, &mut y);
        }
        x += s * rx;
        y += s * ry;
        t /= 4;
        s *= 2;
    }
    (x as u32, y as u32)
}

impl RasterOrder {
    /// [`RasterOrder::pixels`] collected (by [`RasterOrder::pixel_range`]'s
    /// plain loops for `scanline` and `tiled:N`, the common orders).
    pub fn pixel_list(self, frame: Frame) -> Vec<(u32, u32)> {
        let mut v = Vec::with_capacity(frame.pixels() as usize);
        if self.has_ranges() {
            self.pixel_range(frame, 0, usize::MAX, &mut v);
        } else {
            v.extend(self.pixels(frame));
        }
        v
    }

    /// Whether [`RasterOrder::pixel_range`] works out a range from its
    /// start (`scanline` and `tiled:N`); for the others it walks the
    /// order from the first pixel, and a caller wants the list instead.
    pub fn has_ranges(self) -> bool {
        matches!(self, RasterOrder::Scanline | RasterOrder::Tiled(_))
    }

    /// Pixels `start .. start + len` of [`RasterOrder::pixels`]
    /// appended to `out` (fewer past the frame's end), without the list:
    /// a frame's pieces made where they are used, so no thread waits for
    /// (and no memory holds) the whole list. Worked out from `start` for
    /// the orders of [`RasterOrder::has_ranges`].
    pub fn pixel_range(self, frame: Frame, start: u64, len: usize, out: &mut Vec<(u32, u32)>) {
        let (w, h) = (frame.width, frame.height);
        let (tw, th) = match self {
            RasterOrder::Scanline => (w.max(1), 1),
            RasterOrder::Tiled(n) => (n.max(1), n.max(1)),
            _ => {
                let len = len.min(usize::MAX - out.len());
                out.extend(self.pixels(frame).skip(start as usize).take(len));
                return;
            }
        };
        let total = frame.pixels();
        if start >= total {
            return;
        }
        let end = out.len() + len.min((total - start).try_into().unwrap_or(usize::MAX));
        // The band of tile rows `start` is in, the tile in the band, the
        // row in the tile and the column: every band but the last holds
        // w·th pixels, every tile of a band but its last tw·(band height).
        let (w64, tw64, th64) = (w as u64, tw as u64, th as u64);
        let band = start / (w64 * th64);
        let mut y0 = (band * th64) as u32;
        let r = start - band * w64 * th64;
        let hb = th64.min((h - y0) as u64);
        let tile = r / (tw64 * hb);
        let mut x0 = (tile * tw64) as u32;
        let r = r - tile * tw64 * hb;
        let wt = tw64.min((w - x0) as u64);
        let (mut yy, mut xx) = ((r / wt) as u32, (r % wt) as u32);
        while out.len() < end {
            let (hb, wt) = (th.min(h - y0), tw.min(w - x0));
            let run = (wt - xx).min((end - out.len()) as u32);
            out.extend((xx..xx + run).map(|x| (x0 + x, y0 + yy)));
            xx += run;
            if xx == wt {
                xx = 0;
                yy += 1;
                if yy == hb {
                    yy = 0;
                    x0 = x0.saturating_add(tw);
                    if x0 >= w {
                        x0 = 0;
                        y0 = y0.saturating_add(th);
                    }
                }
            }
        }
    }

    /// The 2×2 quads of `frame` in this order: quad `(qx, qy)` holds pixels
    /// `2qx ..= 2qx + 1` × `2qy ..= 2qy + 1` (those inside the frame), and
    /// the order runs over the ⌈W/2⌉ × ⌈H/2⌉ grid of quads, `tiled:N` in
    /// tiles of ⌈N/2⌉ quads (N pixels, rounded up to whole quads).
    pub fn quads(self, frame: Frame) -> Vec<(u32, u32)> {
        let grid = Frame::new(frame.width.div_ceil(2), frame.height.div_ceil(2));
        let order = match self {
            RasterOrder::Tiled(n) => RasterOrder::Tiled(n.div_ceil(2)),
            other => other,
        };
        order.pixel_list(grid)
    }

    /// Every pixel of `frame` exactly once, in this order.
    pub fn pixels(self, frame: Frame) -> Box<dyn Iterator<Item = (u32, u32)> + Send> {
        let (w, h) = (frame.width, frame.height);
        match self {
            RasterOrder::Scanline => {
                Box::new((0..h).flat_map(move |y| (0..w).map(move |x| (x, y))))
            }
            RasterOrder::Tiled(n) => {
                let n = n.max(1);
                Box::new((0..h.div_ceil(n)).flat_map(move |ty| {
                    (0..w.div_ceil(n)).flat_map(move |tx| {
                        let (x0, y0) = (tx * n, ty * n);
                        (y0..(y0 + n).min(h))
                            .flat_map(move |y| (x0..(x0 + n).min(w)).map(move |x| (x, y)))
                    })
                }))
            }
            RasterOrder::Morton => {
                let side = w.max(h).next_power_of_two() as u64;
                Box::new(
                    (0..side * side)
                        .map(|i| (compact(i), compact(i >> 1)))
                        .filter(move |&(x, y)| x < w && y < h),
                )
            }
            RasterOrder::Hilbert => {
                let side = w.max(h).next_power_of_two() as u64;
                Box::new(
                    (0..side * side)
                        .map(move |d| hilbert_d2xy(side, d))
                        .filter(move |&(x, y)| x < w && y < h),
                )
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for n in ["scanline", "tiled:8", "morton", "hilbert"] {
            assert_eq!(n.parse::<RasterOrder>().unwrap().to_string(), n);
        }
        for bad in ["tiled", "tiled:0", "zigzag"] {
            assert!(bad.parse::<RasterOrder>().is_err(), "{bad}");
        }
    }

    #[test]
    fn pixel_ranges_are_slices_of_the_order() {
        // Awkward frames (a last band and tile shorter than the rest,
        // tiles wider than the frame) and ranges at every kind of start.
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = |n: u64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed % n
        };
        for (w, h) in [(1, 1), (7, 5), (13, 29), (64, 3), (37, 41), (1, 19)] {
            let frame = Frame::new(w, h);
            for order in [
                RasterOrder::Scanline,
                RasterOrder::Tiled(1),
                RasterOrder::Tiled(3),
                RasterOrder::Tiled(8),
                RasterOrder::Tiled(100),
                RasterOrder::Morton,
                RasterOrder::Hilbert,
            ] {
                // The reference: the order's own iterator.
                let list: Vec<(u32, u32)> = order.pixels(frame).collect();
                assert_eq!(order.pixel_list(frame), list, "{order} {w}x{h}");
                let n = list.len() as u64;
                let mut starts: Vec<u64> = (0..n + 2).collect();
                starts.extend((0..20).map(|_| next(n + 1)));
                for start in starts {
                    for len in [0, 1, 2, 5, 9, next(n + 3) as usize, usize::MAX / 2] {
                        let mut got = vec![(u32::MAX, 0)];
                        order.pixel_range(frame, start, len, &mut got);
                        let s = (start as usize).min(list.len());
                        let e = s.saturating_add(len).min(list.len());
                        assert_eq!(got[0], (u32::MAX, 0), "kept what was there");
                        assert_eq!(&got[1..], &list[s..e], "{order} {w}x{h} at {start}+{len}");
                    }
                }
            }
        }
    }

    #[test]
    fn interleave_puts_x_in_the_even_bits() {
        assert_eq!(interleave(1, 0), 1);
        assert_eq!(interleave(0, 1), 2);
        assert_eq!(interleave(3, 3), 15);
        assert_eq!(interleave(0xffff, 0), 0x5555_5555);
        for (x, y) in [(0, 0), (12345, 54321), (65535, 1)] {
            let i = interleave(x, y);
            assert_eq!((compact(i), compact(i >> 1)), (x, y));
        }
    }

    #[test]
    fn hilbert_steps_to_a_neighbour_each_time() {
        let n = 16u64;
        let mut prev = hilbert_d2xy(n, 0);
        for d in 1..n * n {
            let p = hilbert_d2xy(n, d);
            let dist = prev.0.abs_diff(p.0) + prev.1.abs_diff(p.1);
            assert_eq!(dist, 1, "d = {d}");
            prev = p;
        }
    }
}
