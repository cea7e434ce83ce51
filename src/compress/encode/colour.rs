//! The BC1 colour-block fitter behind `--quality normal` and `slow` (BC1
//! and the colour half of BC3).
//!
//! Written here because neither encoder crate offers the step between
//! them: ISPC's BC1 kernel (`fast`) has no settings, and libsquish's
//! cluster fit (texpresso) is 400× slower. The fit is the one nvtt and
//! libsquish use after their first guess, done until it stops paying:
//!
//! 1. start from endpoints (ISPC's block, the principal axis of the
//!    block's colours, the optimal pair for the mean colour; at `slow`
//!    also libsquish's iterative cluster fit);
//! 2. give every texel the nearest palette colour, then solve the
//!    least-squares endpoints for those indices, round them to 5:6:5 and
//!    repeat while the error falls;
//! 3. try every ±1 step of the six 5:6:5 endpoint components (rounding
//!    each channel on its own is not the best 5:6:5 pair), keeping the best,
//!    while the error falls.
//!
//! The error is the squared difference of the stored codes, each channel
//! weighted alike (nvtt's default; what `psnr` measures), each texel by its
//! weight (0 outside the level, alpha for straight-alpha BC3). The four
//! palette colours of a pair lie on one line, so the nearest one is found
//! by projecting onto it; the palette is the exact one (2/3, 1/3 of the
//! expanded 8-bit endpoints), which decoders round to within one code.
//!
//! BC1's three-colour mode (endpoint 0 ≤ endpoint 1: the two endpoints and
//! their midpoint) is tried at `slow` for opaque BC1; its fourth index
//! (transparent black) is never used, so every reader decodes the block
//! alike. BC3's colour half decodes four colours whatever the endpoint
//! order, and is always written in BC1's four-colour order.

use std::sync::OnceLock;

/// One block's texels, channel-planar (0..255 codes as floats), with a
/// weight per texel (0 for texels outside the level).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct BlockTexels {
    pub r: [f32; 16],
    pub g: [f32; 16],
    pub b: [f32; 16],
    pub w: [f32; 16],
}

/// How hard the fit searches.
#[derive(Clone, Copy, Debug)]
pub(super) struct Effort {
    /// Rounds of least squares on the chosen indices.
    pub least_squares: u32,
    /// Passes of the ±1 search over the six endpoint components.
    pub neighbour_passes: u32,
    /// Refine every start rather than only the best one.
    pub refine_all_starts: bool,
    /// Also fit BC1's three-colour mode (opaque BC1 only).
    pub three_colour: bool,
}

/// A 5:6:5 endpoint pair: `a` at the palette's start (t = 0), `b` at its
/// end (t = 1), with `steps` + 1 evenly spaced colours (3: four colours,
/// 2: three colours).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Pair {
    a: u16,
    b: u16,
    steps: u8,
}

/// 5:6:5 → 8-bit codes, by bit replication (as every decoder expands).
#[inline]
fn expand(c: u16) -> [f32; 3] {
    let (r, g, b) = ((c >> 11) & 31, (c >> 5) & 63, c & 31);
    [
        ((r << 3) | (r >> 2)) as f32,
        ((g << 2) | (g >> 4)) as f32,
        ((b << 3) | (b >> 2)) as f32,
    ]
}

/// 8-bit codes (any real value) → the nearest 5:6:5 colour.
#[inline]
fn quantize(e: [f32; 3]) -> u16 {
    let q = |v: f32, max: f32| (v.clamp(0.0, 255.0) * (max / 255.0) + 0.5) as u16;
    (q(e[0], 31.0) << 11) | (q(e[1], 63.0) << 5) | q(e[2], 31.0)
}

/// Round to the nearest integer for 0 ≤ v < 2²², without a libm call (so
/// the loops below vectorise on the baseline x86-64 target).
#[inline(always)]
fn round_small(v: f32) -> f32 {
    const MAGIC: f32 = 12_582_912.0; // 1.5 · 2²³
    (v + MAGIC) - MAGIC
}

/// The palette line of a pair: its start and direction, and the factor
/// turning a projection onto the direction into palette steps.
#[inline]
fn line(p: Pair) -> ([f32; 3], [f32; 3], f32) {
    let (e0, e1) = (expand(p.a), expand(p.b));
    let d = [e1[0] - e0[0], e1[1] - e0[1], e1[2] - e0[2]];
    let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    let k = if dd > 0.0 { p.steps as f32 / dd } else { 0.0 };
    (e0, d, k)
}

/// Each texel's palette position (0..=steps) under the nearest-colour rule,
/// and the weighted squared error of the block.
#[inline]
fn assign(px: &BlockTexels, p: Pair) -> ([f32; 16], f32) {
    let (e0, d, k) = line(p);
    let n = p.steps as f32;
    let inv_n = 1.0 / n;
    let mut s = [0f32; 16];
    let mut e = [0f32; 16];
    for i in 0..16 {
        let (x, y, z) = (px.r[i] - e0[0], px.g[i] - e0[1], px.b[i] - e0[2]);
        let t = (x * d[0] + y * d[1] + z * d[2]) * k;
        let si = round_small(t.max(0.0).min(n));
        let f = si * inv_n;
        let (dx, dy, dz) = (x - f * d[0], y - f * d[1], z - f * d[2]);
        e[i] = px.w[i] * (dx * dx + dy * dy + dz * dz);
        s[i] = si;
    }
    (s, sum16(&e))
}

/// The sum of 16 values in a fixed order that vectorises (four running
/// sums), where a plain running sum would be a chain of scalar adds.
#[inline(always)]
fn sum16(e: &[f32; 16]) -> f32 {
    let mut a = [0f32; 4];
    for row in e.chunks_exact(4) {
        for j in 0..4 {
            a[j] += row[j];
        }
    }
    (a[0] + a[1]) + (a[2] + a[3])
}

/// The weighted squared error of the block under pair `p`.
#[inline]
fn error(px: &BlockTexels, p: Pair) -> f32 {
    assign(px, p).1
}

/// The least-squares endpoints for given palette positions, rounded to
/// 5:6:5 at the best of the four roundings per channel (with the indices
/// fixed the error is a quadratic in each channel's two endpoint values,
/// channel by channel); `None` when the positions do not determine two
/// endpoints (all texels at one position).
fn least_squares(px: &BlockTexels, s: &[f32; 16], steps: u8) -> Option<Pair> {
    let inv_n = 1.0 / steps as f32;
    let (mut aa, mut ab, mut bb) = ([0f32; 16], [0f32; 16], [0f32; 16]);
    let (mut x0, mut x1) = ([[0f32; 16]; 3], [[0f32; 16]; 3]);
    for i in 0..16 {
        let beta = s[i] * inv_n;
        let alpha = 1.0 - beta;
        let w = px.w[i];
        aa[i] = w * alpha * alpha;
        ab[i] = w * alpha * beta;
        bb[i] = w * beta * beta;
        for (ch, c) in [&px.r, &px.g, &px.b].into_iter().enumerate() {
            x0[ch][i] = w * alpha * c[i];
            x1[ch][i] = w * beta * c[i];
        }
    }
    let (aa, ab, bb) = (sum16(&aa), sum16(&ab), sum16(&bb));
    let det = aa * bb - ab * ab;
    if det.abs() <= 1e-6 * (aa * bb).max(1e-12) {
        return None;
    }
    let inv = 1.0 / det;
    let (mut a, mut b) = (0u16, 0u16);
    for (ch, (shift, max)) in [(11u16, 31u16), (5, 63), (0, 31)].into_iter().enumerate() {
        let (x0, x1) = (sum16(&x0[ch]), sum16(&x1[ch]));
        let e0 = (bb * x0 - ab * x1) * inv;
        let e1 = (aa * x1 - ab * x0) * inv;
        // Error up to a constant: aa·u² + 2·ab·u·v + bb·v² − 2(u·x0 + v·x1).
        let cost =
            |u: f32, v: f32| aa * u * u + 2.0 * ab * u * v + bb * v * v - 2.0 * (u * x0 + v * x1);
        let lo = |e: f32| ((e.clamp(0.0, 255.0) * max as f32 / 255.0) as u16).min(max - 1);
        let (l0, l1) = (lo(e0), lo(e1));
        let mut best = (f32::INFINITY, 0u16, 0u16);
        for q0 in [l0, l0 + 1] {
            for q1 in [l1, l1 + 1] {
                let c = cost(expand_field(q0, max), expand_field(q1, max));
                if c < best.0 {
                    best = (c, q0, q1);
                }
            }
        }
        a |= best.1 << shift;
        b |= best.2 << shift;
    }
    Some(Pair { a, b, steps })
}

/// A 5- or 6-bit field (`max` 31 or 63) expanded to 8 bits.
#[inline]
fn expand_field(v: u16, max: u16) -> f32 {
    if max == 31 {
        ((v << 3) | (v >> 2)) as f32
    } else {
        ((v << 2) | (v >> 4)) as f32
    }
}

/// The ±1 neighbours of a pair: each of the six 5:6:5 components moved by
/// one, where it stays in range.
fn neighbours(p: Pair) -> impl Iterator<Item = Pair> {
    const FIELDS: [(u16, u16); 3] = [(11, 31), (5, 63), (0, 31)];
    (0..12).filter_map(move |j| {
        let (end, field, up) = (j / 6, (j / 2) % 3, j % 2 == 1);
        let (shift, max) = FIELDS[field];
        let c = if end == 0 { p.a } else { p.b };
        let v = (c >> shift) & max;
        let v = match (up, v) {
            (true, v) if v < max => v + 1,
            (false, v) if v > 0 => v - 1,
            _ => return None,
        };
        let c = (c & !(max << shift)) | (v << shift);
        Some(if end == 0 {
            Pair { a: c, ..p }
        } else {
            Pair { b: c, ..p }
        })
    })
}

/// Refine a start: least squares on the chosen indices while the error
/// falls, then the ±1 search (each improving pass followed by one more
/// least-squares round).
fn refine(px: &BlockTexels, start: Pair, effort: &Effort) -> (Pair, f32) {
    let (mut s, mut err) = assign(px, start);
    let mut best = start;
    let ls = |best: &mut Pair, s: &mut [f32; 16], err: &mut f32, rounds: u32| {
        for _ in 0..rounds {
            let Some(p) = least_squares(px, s, best.steps) else {
                break;
            };
            if p == *best {
                break;
            }
            let (s2, e2) = assign(px, p);
            if e2 < *err {
                (*best, *s, *err) = (p, s2, e2);
            } else {
                break;
            }
        }
    };
    ls(&mut best, &mut s, &mut err, effort.least_squares);
    for _ in 0..effort.neighbour_passes {
        if err == 0.0 {
            break;
        }
        let mut cand = (best, err);
        for p in neighbours(best) {
            let e = error(px, p);
            if e < cand.1 {
                cand = (p, e);
            }
        }
        if cand.1 >= err {
            break;
        }
        best = cand.0;
        (s, err) = assign(px, best);
        ls(&mut best, &mut s, &mut err, effort.least_squares.min(1));
    }
    (best, err)
}

/// Per 8-bit value, the 5- and 6-bit endpoint pairs (a, b) whose colour
/// 2/3·a + 1/3·b is nearest the value (ties: the closer pair, so decoders'
/// rounding matters least): the optimal fit of a one-colour block.
fn single_colour_tables() -> &'static [[(u8, u8); 256]; 2] {
    static TABLES: OnceLock<[[(u8, u8); 256]; 2]> = OnceLock::new();
    TABLES.get_or_init(|| {
        let mut t = [[(0u8, 0u8); 256]; 2];
        for (ti, max) in [31u16, 63].into_iter().enumerate() {
            for (v, slot) in t[ti].iter_mut().enumerate() {
                let mut best = (f32::INFINITY, f32::INFINITY, (0u8, 0u8));
                for a in 0..=max {
                    // 2/3·a + 1/3·b grows with b: the nearest values to v
                    // are at the b around (3v − 2a) / 1.
                    let ea = expand_field(a, max);
                    let target = 3.0 * v as f32 - 2.0 * ea;
                    let b0 = (target.clamp(0.0, 255.0) * max as f32 / 255.0) as u16;
                    for b in b0.saturating_sub(1)..=(b0 + 2).min(max) {
                        let eb = expand_field(b, max);
                        let c = (2.0 * ea + eb) / 3.0;
                        let key = ((c - v as f32).abs(), (ea - eb).abs());
                        if key < (best.0, best.1) {
                            best = (key.0, key.1, (a as u8, b as u8));
                        }
                    }
                }
                *slot = best.2;
            }
        }
        t
    })
}

/// The optimal pair for one colour (four-colour mode, every texel at
/// position 1 of 3).
fn single_colour(c: [u8; 3]) -> Pair {
    let t = single_colour_tables();
    let (r, g, b) = (
        t[0][c[0] as usize],
        t[1][c[1] as usize],
        t[0][c[2] as usize],
    );
    Pair {
        a: ((r.0 as u16) << 11) | ((g.0 as u16) << 5) | b.0 as u16,
        b: ((r.1 as u16) << 11) | ((g.1 as u16) << 5) | b.1 as u16,
        steps: 3,
    }
}

/// Two colours: the ends of a segment in RGB.
type Segment = ([f32; 3], [f32; 3]);

/// The weighted mean colour of the block and the ends of its principal
/// axis (the extreme projections of the texels onto it); `None` for a
/// block of one colour.
fn principal_axis(px: &BlockTexels) -> ([f32; 3], Option<Segment>) {
    let wsum: f32 = px.w.iter().sum();
    let inv = 1.0 / wsum.max(f32::MIN_POSITIVE);
    let mut m = [0f32; 3];
    for i in 0..16 {
        m[0] += px.w[i] * px.r[i];
        m[1] += px.w[i] * px.g[i];
        m[2] += px.w[i] * px.b[i];
    }
    m = m.map(|v| v * inv);
    let mut c = [0f32; 6]; // rr rg rb gg gb bb
    for i in 0..16 {
        let (x, y, z) = (px.r[i] - m[0], px.g[i] - m[1], px.b[i] - m[2]);
        let w = px.w[i];
        c[0] += w * x * x;
        c[1] += w * x * y;
        c[2] += w * x * z;
        c[3] += w * y * y;
        c[4] += w * y * z;
        c[5] += w * z * z;
    }
    if c[0] + c[3] + c[5] <= 1e-3 * wsum {
        return (m, None);
    }
    // Power iteration from the row of the largest variance.
    let mut v = if c[0] >= c[3] && c[0] >= c[5] {
        [c[0], c[1], c[2]]
    } else if c[3] >= c[5] {
        [c[1], c[3], c[4]]
    } else {
        [c[2], c[4], c[5]]
    };
    for _ in 0..8 {
        let nv = [
            c[0] * v[0] + c[1] * v[1] + c[2] * v[2],
            c[1] * v[0] + c[3] * v[1] + c[4] * v[2],
            c[2] * v[0] + c[4] * v[1] + c[5] * v[2],
        ];
        let n = nv[0].abs().max(nv[1].abs()).max(nv[2].abs());
        if n <= 0.0 {
            break;
        }
        v = nv.map(|x| x / n);
    }
    let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if len <= 0.0 || !len.is_finite() {
        return (m, None);
    }
    v = v.map(|x| x / len);
    let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
    for i in 0..16 {
        if px.w[i] > 0.0 {
            let t = (px.r[i] - m[0]) * v[0] + (px.g[i] - m[1]) * v[1] + (px.b[i] - m[2]) * v[2];
            lo = lo.min(t);
            hi = hi.max(t);
        }
    }
    let at = |t: f32| [m[0] + t * v[0], m[1] + t * v[1], m[2] + t * v[2]];
    (m, Some((at(lo), at(hi))))
}

/// The most starts [`fit`] takes from its caller.
pub(super) const MAX_STARTS: usize = 2;

/// Fit one block: the best pair found from `starts` (endpoints of other
/// encoders' blocks, read as a pair in the order stored) and the block's
/// own starts, as 8 bytes of a BC1 colour block. `three_colour_allowed`:
/// opaque BC1 (not BC3's colour half, not BC1 with alpha).
pub(super) fn fit(
    px: &BlockTexels,
    starts: &[(u16, u16)],
    effort: &Effort,
    three_colour_allowed: bool,
) -> [u8; 8] {
    let (mean, axis) = principal_axis(px);
    let mean_u8 = mean.map(|v| v.clamp(0.0, 255.0).round() as u8);
    // At most 2 own starts and MAX_STARTS given ones, in two modes.
    let mut cands = [Pair {
        a: 0,
        b: 0,
        steps: 3,
    }; 2 * (2 + MAX_STARTS)];
    let mut n = 0;
    let mut push = |p: Pair| {
        cands[n] = p;
        n += 1;
    };
    push(single_colour(mean_u8));
    if let Some((lo, hi)) = axis {
        push(Pair {
            a: quantize(lo),
            b: quantize(hi),
            steps: 3,
        });
    }
    for &(a, b) in starts.iter().take(MAX_STARTS) {
        push(Pair { a, b, steps: 3 });
    }
    if three_colour_allowed && effort.three_colour {
        for i in 0..n {
            cands[n + i] = Pair {
                steps: 2,
                ..cands[i]
            };
        }
        n *= 2;
    }
    let cands = &cands[..n];
    let mut best = (cands[0], f32::INFINITY);
    if effort.refine_all_starts {
        for &c in cands {
            let r = refine(px, c, effort);
            if r.1 < best.1 {
                best = r;
            }
        }
    } else {
        for &c in cands {
            let e = error(px, c);
            if e < best.1 {
                best = (c, e);
            }
        }
        best = refine(px, best.0, effort);
    }
    pack(px, best.0)
}

/// The 8 bytes of a pair's block: endpoints in the order that selects its
/// mode (four colours: colour 0 > colour 1; three: colour 0 ≤ colour 1),
/// each texel's index of its nearest palette colour.
fn pack(px: &BlockTexels, p: Pair) -> [u8; 8] {
    let (s, _) = assign(px, p);
    // Palette position (0..=steps, from a to b) → index, per stored order.
    let (c0, c1, map): (u16, u16, [u32; 4]) = if p.a == p.b {
        (p.a, p.b, [0, 0, 0, 0])
    } else if p.steps == 3 {
        if p.a > p.b {
            (p.a, p.b, [0, 2, 3, 1])
        } else {
            (p.b, p.a, [1, 3, 2, 0])
        }
    } else if p.a < p.b {
        (p.a, p.b, [0, 2, 1, 1])
    } else {
        (p.b, p.a, [1, 2, 0, 0])
    };
    let mut idx = 0u32;
    for (i, &si) in s.iter().enumerate() {
        idx |= map[si as usize] << (2 * i);
    }
    let mut out = [0u8; 8];
    out[0..2].copy_from_slice(&c0.to_le_bytes());
    out[2..4].copy_from_slice(&c1.to_le_bytes());
    out[4..8].copy_from_slice(&idx.to_le_bytes());
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Decode a colour block the way the D3D specification defines it (exact
    /// thirds and halves of the expanded endpoints, no rounding),
    /// four-colour mode forced for BC3's colour half.
    fn decode(block: &[u8; 8], force_four: bool) -> [[f32; 3]; 16] {
        let c0 = u16::from_le_bytes([block[0], block[1]]);
        let c1 = u16::from_le_bytes([block[2], block[3]]);
        let (e0, e1) = (expand(c0), expand(c1));
        let mix = |f: f32| [0, 1, 2].map(|k| e0[k] * (1.0 - f) + e1[k] * f);
        let pal = if c0 > c1 || force_four {
            [e0, e1, mix(1.0 / 3.0), mix(2.0 / 3.0)]
        } else {
            [e0, e1, mix(0.5), [f32::NAN; 3]]
        };
        let idx = u32::from_le_bytes([block[4], block[5], block[6], block[7]]);
        std::array::from_fn(|i| pal[((idx >> (2 * i)) & 3) as usize])
    }

    fn sse(px: &BlockTexels, d: &[[f32; 3]; 16]) -> f32 {
        (0..16)
            .map(|i| {
                px.w[i]
                    * ((px.r[i] - d[i][0]).powi(2)
                        + (px.g[i] - d[i][1]).powi(2)
                        + (px.b[i] - d[i][2]).powi(2))
            })
            .sum()
    }

    fn block(seed: u64) -> BlockTexels {
        let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 40) as f32 / (1u64 << 24) as f32
        };
        let base = [next() * 255.0, next() * 255.0, next() * 255.0];
        let spread = next() * 80.0;
        let mut px = BlockTexels::default();
        for i in 0..16 {
            let t = next() - 0.5;
            px.r[i] = (base[0] + t * spread + (next() - 0.5) * 10.0)
                .clamp(0.0, 255.0)
                .round();
            px.g[i] = (base[1] + t * spread * 0.8 + (next() - 0.5) * 10.0)
                .clamp(0.0, 255.0)
                .round();
            px.b[i] = (base[2] - t * spread * 0.5 + (next() - 0.5) * 10.0)
                .clamp(0.0, 255.0)
                .round();
            px.w[i] = 1.0;
        }
        px
    }

    const NORMAL: Effort = Effort {
        least_squares: 4,
        neighbour_passes: 2,
        refine_all_starts: false,
        three_colour: false,
    };

    /// The error the fitter optimises is the error of the block it writes,
    /// decoded by the specification's rule (the packing's index mapping and
    /// endpoint order are right), in both modes.
    #[test]
    fn written_block_decodes_to_the_fitted_error() {
        for seed in 0..500 {
            let px = block(seed);
            for steps in [2u8, 3] {
                let p = Pair {
                    a: quantize([px.r[0], px.g[0], px.b[0]]),
                    b: quantize([px.r[15], px.g[15], px.b[15]]),
                    steps,
                };
                let blk = pack(&px, p);
                let got = sse(&px, &decode(&blk, false));
                let want = error(&px, p);
                assert!(
                    (got - want).abs() <= 1e-3 * want.max(1.0),
                    "seed {seed} steps {steps}: decoded {got}, fitted {want}"
                );
                if steps == 3 && p.a != p.b {
                    let c0 = u16::from_le_bytes([blk[0], blk[1]]);
                    let c1 = u16::from_le_bytes([blk[2], blk[3]]);
                    assert!(c0 > c1, "four-colour block stored in three-colour order");
                }
            }
        }
    }

    /// A one-colour block gets the pair that brute force over every 5:6:5
    /// pair says is best for each channel.
    #[test]
    fn single_colour_fit_is_optimal_per_channel() {
        for v in 0..=255u8 {
            let p = single_colour([v, v, v]);
            let px = BlockTexels {
                r: [v as f32; 16],
                g: [v as f32; 16],
                b: [v as f32; 16],
                w: [1.0; 16],
            };
            let got = error(&px, p) / 16.0;
            // Brute force: best |colour − v| per channel over all pairs and
            // all four palette positions.
            let best = |bits: u32| -> f32 {
                let max = (1u16 << bits) - 1;
                let e = |x: u16| {
                    if bits == 5 {
                        ((x << 3) | (x >> 2)) as f32
                    } else {
                        ((x << 2) | (x >> 4)) as f32
                    }
                };
                let mut b = f32::INFINITY;
                for a in 0..=max {
                    for c in 0..=max {
                        for f in [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0] {
                            let d = e(a) * (1.0 - f) + e(c) * f - v as f32;
                            b = b.min(d * d);
                        }
                    }
                }
                b
            };
            let want = 2.0 * best(5) + best(6);
            assert!(got <= want + 1e-3, "value {v}: {got} > {want}");
        }
    }

    /// Refinement never makes a start worse, and the fit is at least as
    /// good as every start it is given.
    #[test]
    fn fit_is_no_worse_than_its_starts() {
        for seed in 0..300 {
            let px = block(seed);
            let start = (
                quantize([px.r[3], px.g[3], px.b[3]]),
                quantize([px.r[9], px.g[9], px.b[9]]),
            );
            let e_start = error(
                &px,
                Pair {
                    a: start.0,
                    b: start.1,
                    steps: 3,
                },
            );
            let blk = fit(&px, &[start], &NORMAL, false);
            let e = sse(&px, &decode(&blk, true));
            assert!(
                e <= e_start * (1.0 + 1e-5) + 1e-3,
                "seed {seed}: {e} > {e_start}"
            );
        }
    }

    /// Texels of weight 0 (outside the level) do not pull the endpoints: a
    /// block whose visible texels are two colours of a palette line fits
    /// them exactly whatever the hidden texels hold.
    #[test]
    fn zero_weight_texels_are_ignored() {
        let mut px = BlockTexels::default();
        let (c0, c1) = (expand(0xF81F), expand(0x07E0)); // magenta, green
        for i in 0..16 {
            let visible = i % 4 < 2;
            let c = if i % 2 == 0 { c0 } else { c1 };
            let c = if visible { c } else { [30.0, 200.0, 90.0] };
            (px.r[i], px.g[i], px.b[i]) = (c[0], c[1], c[2]);
            px.w[i] = if visible { 1.0 } else { 0.0 };
        }
        let blk = fit(&px, &[], &NORMAL, false);
        assert_eq!(sse(&px, &decode(&blk, true)), 0.0);
    }
}
