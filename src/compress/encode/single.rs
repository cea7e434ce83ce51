//! A refit of one-channel blocks (BC4, and each half of BC5) at `normal`
//! and `slow`: ISPC's kernel takes the block's minimum and maximum as the
//! endpoints, which leaves the interpolated values where the range puts
//! them. Here each block also tries the endpoints in a window around its
//! maximum and minimum (moving them outwards centres the steps on the
//! values), in both of BC4's modes (eight interpolated values; six plus 0
//! and 255), then a least-squares fit of the endpoints to the chosen
//! steps, and keeps ISPC's block unless one of these has a smaller
//! squared error. The palette is the one the decoders compute: the
//! weighted mean rounded to the nearest code, as bcdec does (an odd
//! divisor never leaves a half).

/// The eight values endpoints `a0`, `a1` decode to.
fn palette(a0: u8, a1: u8) -> [u8; 8] {
    let (a, b) = (a0 as u32, a1 as u32);
    let mut p = [a0, a1, 0, 0, 0, 0, 0, 0];
    if a > b {
        for i in 1..7u32 {
            p[1 + i as usize] = ((2 * ((7 - i) * a + i * b) + 7) / 14) as u8;
        }
    } else {
        for i in 1..5u32 {
            p[1 + i as usize] = ((2 * ((5 - i) * a + i * b) + 5) / 10) as u8;
        }
        p[6] = 0;
        p[7] = 255;
    }
    p
}

/// The squared error of `values` (the texels in `mask`) with each texel
/// on its nearest palette entry, those entries' indices, and the largest
/// difference of one texel.
fn fit(values: &[u8; 16], mask: u16, pal: &[u8; 8]) -> (u32, [u8; 16], u32) {
    let mut err = 0u32;
    let mut worst = 0u32;
    let mut idx = [0u8; 16];
    for i in 0..16 {
        let v = values[i] as i32;
        let (mut best, mut at) = (u32::MAX, 0u8);
        for (k, &p) in pal.iter().enumerate() {
            let d = (p as i32 - v).unsigned_abs();
            if d * d < best {
                best = d * d;
                at = k as u8;
            }
        }
        idx[i] = at;
        if mask & (1 << i) != 0 {
            err += best;
            worst = worst.max(best);
        }
    }
    (err, idx, worst)
}

/// An 8-byte BC4 block of endpoints `a0`, `a1` and 3-bit `indices`.
fn pack(a0: u8, a1: u8, indices: &[u8; 16]) -> [u8; 8] {
    let mut bits = 0u64;
    for (i, &k) in indices.iter().enumerate() {
        bits |= (k as u64 & 7) << (3 * i);
    }
    let mut b = [0u8; 8];
    b[0] = a0;
    b[1] = a1;
    b[2..8].copy_from_slice(&bits.to_le_bytes()[..6]);
    b
}

/// Least-squares endpoints for the 8-value mode's `indices` (the
/// weights of `a0` and `a1` each index gives), rounded; `None` when the
/// indices do not determine them.
fn least_squares(values: &[u8; 16], mask: u16, indices: &[u8; 16]) -> Option<(u8, u8)> {
    const W: [f64; 8] = [
        1.0,
        0.0,
        6.0 / 7.0,
        5.0 / 7.0,
        4.0 / 7.0,
        3.0 / 7.0,
        2.0 / 7.0,
        1.0 / 7.0,
    ];
    let (mut aa, mut ab, mut bb, mut av, mut bv) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for i in (0..16).filter(|i| mask & (1 << i) != 0) {
        let (wa, v) = (W[indices[i] as usize], values[i] as f64);
        let wb = 1.0 - wa;
        aa += wa * wa;
        ab += wa * wb;
        bb += wb * wb;
        av += wa * v;
        bv += wb * v;
    }
    let det = aa * bb - ab * ab;
    if det.abs() < 1e-9 {
        return None;
    }
    let a = (av * bb - bv * ab) / det;
    let b = (bv * aa - av * ab) / det;
    let q = |x: f64| x.round().clamp(0.0, 255.0) as u8;
    Some((q(a), q(b)))
}

/// `block` (a BC4 block of the texels `values`, those in `mask` inside
/// the level) replaced by a better fit where one is found; `radius` is
/// the window around the minimum and maximum. A fit is better when its
/// squared error is smaller and no texel is further off than half a step
/// of the block's own range (min/max endpoints' guarantee) or than in
/// ISPC's block: a lower mean never costs one texel a larger error.
pub(super) fn refine(values: &[u8; 16], mask: u16, radius: i32, block: &mut [u8]) {
    let inside = || {
        (0..16)
            .filter(move |i| mask & (1 << i) != 0)
            .map(|i| values[i])
    };
    let (Some(lo), Some(hi)) = (inside().min(), inside().max()) else {
        return;
    };
    // ISPC's block with its own indices: the error to beat, and the cap.
    let pal = palette(block[0], block[1]);
    let own = u64::from_le_bytes([
        block[2], block[3], block[4], block[5], block[6], block[7], 0, 0,
    ]);
    let (mut own_err, mut own_worst) = (0u32, 0u32);
    for i in (0..16).filter(|i| mask & (1 << i) != 0) {
        let d = (pal[((own >> (3 * i)) & 7) as usize] as i32 - values[i] as i32).unsigned_abs();
        own_err += d * d;
        own_worst = own_worst.max(d * d);
    }
    let half_step = (hi - lo) as u32 / 14 + 1;
    let cap = own_worst.max(half_step * half_step);
    let mut best = (own_err, [0u8; 8]);
    best.1.copy_from_slice(&block[..8]);
    if best.0 == 0 {
        return;
    }
    let try_pair = |a0: u8, a1: u8, best: &mut (u32, [u8; 8])| {
        let (err, idx, worst) = fit(values, mask, &palette(a0, a1));
        if err < best.0 && worst <= cap {
            *best = (err, pack(a0, a1, &idx));
        }
    };
    try_pair(block[0], block[1], &mut best);
    let clamp = |x: i32| x.clamp(0, 255) as u8;
    let (lo, hi) = (lo as i32, hi as i32);
    for da in -radius..=radius {
        for db in -radius..=radius {
            let (a0, a1) = (clamp(hi + da), clamp(lo + db));
            if a0 > a1 {
                try_pair(a0, a1, &mut best);
            }
            // Six values plus 0 and 255: a0 <= a1.
            let (b0, b1) = (clamp(lo + db), clamp(hi + da));
            if b0 <= b1 {
                try_pair(b0, b1, &mut best);
            }
        }
    }
    // Least squares on the best 8-value fit's steps, twice.
    for _ in 0..2 {
        let (a0, a1) = (best.1[0], best.1[1]);
        if a0 <= a1 {
            break;
        }
        let idx = fit(values, mask, &palette(a0, a1)).1;
        match least_squares(values, mask, &idx) {
            Some((a, b)) if a > b && (a, b) != (a0, a1) => try_pair(a, b, &mut best),
            _ => break,
        }
    }
    block[..8].copy_from_slice(&best.1);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The palette and the packing agree with bcdec's decoder.
    #[test]
    fn packed_blocks_decode_to_their_palette() {
        for (a0, a1) in [(200u8, 13u8), (13, 200), (90, 90), (255, 0), (0, 255)] {
            let idx: [u8; 16] = std::array::from_fn(|i| (i * 5 % 8) as u8);
            let b = pack(a0, a1, &idx);
            let mut out = [0u8; 16];
            bcdec_rs::bc4(&b, &mut out, 4, false);
            let pal = palette(a0, a1);
            for i in 0..16 {
                assert_eq!(out[i], pal[idx[i] as usize], "({a0}, {a1}) texel {i}");
            }
        }
    }

    /// Over random blocks (clustered, ramps, noise; fixed seed), decoded by
    /// bcdec: the refit's squared error is never above the min/max block
    /// it starts from, and no texel is further off than that block's
    /// worst or half a step of the range.
    #[test]
    fn refit_keeps_the_error_and_the_worst_texel_bounded() {
        let mut s = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s
        };
        let mut improved = 0;
        for n in 0..3000 {
            let base = (next() % 256) as i32;
            let spread = [3, 20, 90, 255][n % 4];
            let values: [u8; 16] = std::array::from_fn(|i| {
                let v = match n % 3 {
                    0 => base + (next() % (spread as u64 + 1)) as i32 - spread / 2,
                    1 => base + (i as i32 * spread) / 15 - spread / 2,
                    _ => (next() % 256) as i32,
                };
                v.clamp(0, 255) as u8
            });
            let mask = if n % 7 == 0 { 0x0fff } else { 0xffff };
            let inside = (0..16).filter(|i| mask & (1 << i) != 0);
            let lo = inside.clone().map(|i| values[i]).min().unwrap();
            let hi = inside.clone().map(|i| values[i]).max().unwrap();
            let (a0, a1) = if hi > lo { (hi, lo) } else { (lo, hi) };
            let idx = fit(&values, mask, &palette(a0, a1)).1;
            let start = pack(a0, a1, &idx);
            let mut block = start;
            refine(&values, mask, 2, &mut block);
            let score = |b: &[u8; 8]| {
                let mut out = [0u8; 16];
                bcdec_rs::bc4(b, &mut out, 4, false);
                inside.clone().fold((0u32, 0u32), |(e, w), i| {
                    let d = (out[i] as i32 - values[i] as i32).unsigned_abs();
                    (e + d * d, w.max(d))
                })
            };
            let ((e0, w0), (e1, w1)) = (score(&start), score(&block));
            let half_step = (hi - lo) as u32 / 14 + 1;
            assert!(e1 <= e0, "block {n}: {e1} > {e0}");
            assert!(
                w1 <= w0.max(half_step),
                "block {n}: worst {w1} > {w0}, {half_step}"
            );
            improved += usize::from(e1 < e0);
        }
        assert!(improved > 500, "only {improved} blocks improved");
    }

    /// A refit block is never worse than the one it started from, and on
    /// a ramp it is better than min/max endpoints.
    #[test]
    fn refit_never_loses_and_centres_a_ramp() {
        let values: [u8; 16] = std::array::from_fn(|i| (40 + i * 9) as u8);
        let pal = palette(175, 40);
        let (start_err, idx, _) = fit(&values, 0xffff, &pal);
        let mut block = pack(175, 40, &idx);
        refine(&values, 0xffff, 2, &mut block);
        let mut out = [0u8; 16];
        bcdec_rs::bc4(&block, &mut out, 4, false);
        let err: u32 = (0..16)
            .map(|i| (out[i] as i32 - values[i] as i32).pow(2) as u32)
            .sum();
        assert!(err < start_err, "{err} vs {start_err}");
    }
}
