//! One axis of a rectangle query, turned into table reads.
//!
//! A table holds prefix sums `P[k]` (the sum of the first `k` texels of an
//! axis, `0 ≤ k ≤ n`). Any interval `[x0, x1)` of the infinite, wrapped
//! axis — fractional ends, any length, any wrap mode — is a short linear
//! combination `Σ coef · P[idx]`, because the wrapped texel sequence has a
//! cumulative function `C(X)` (signed, from origin 0) that is itself such a
//! combination:
//!
//! - repeat: `C(X) = q·P[n] + P[r]` with `X = q·n + r`;
//! - mirrored repeat (period 2n): `C(X) = 2q·P[n] + P[r]` for `r ≤ n`,
//!   else `2(q+1)·P[n] − P[2n − r]`;
//! - clamp to edge: `X·P[1]` below 0, `P[X]` inside, and
//!   `P[n] + (X − n)·(P[n] − P[n−1])` beyond;
//! - clamp to border: `P[clamp(X, 0, n)]`, the rest reads the border;
//! - mirror clamp to edge: clamp to edge for `X ≥ 0`, `−C(−X)` below 0;
//!
//! and a fractional end `i + a` adds `a · (P[w(i)+1] − P[w(i)])` for the
//! wrapped texel `w(i)` it cuts (area weighting = interpolating the table
//! linearly). The interval is `C(x1) − C(x0)`: at most a handful of terms,
//! whatever the length, so a footprint a million periods wide costs what a
//! small one does. The integer coefficients of both ends are merged in
//! `i64` (coordinates are at most 2⁵² texels, so they cannot overflow)
//! before they become floats, so two huge nearly equal period counts cancel
//! exactly instead of in floating point. Rectangles inside the level take a
//! shortcut: the four reads of each end, nothing to wrap.

use crate::wrap::{WrapMode, floor_index, period, wrap_index};

const N: usize = 12;

/// `Σ coef · P[idx]` for one axis, plus the weights needed to normalise.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Axis {
    pub idx: [u32; N],
    pub coef: [f64; N],
    pub len: usize,
    /// Total weight (length of the interval, in texels).
    pub total: f64,
    /// Weight that falls on texels (`total` minus what reads the border).
    pub inside: f64,
}

struct IntTerms {
    idx: [u32; N],
    coef: [i64; N],
    len: usize,
}

impl IntTerms {
    fn push(&mut self, idx: i64, c: i64) {
        // P[0] = 0: the term vanishes.
        if idx == 0 || c == 0 {
            return;
        }
        let idx = idx as u32;
        if let Some(k) = self.idx[..self.len].iter().position(|&i| i == idx) {
            self.coef[k] += c;
        } else {
            self.idx[self.len] = idx;
            self.coef[self.len] = c;
            self.len += 1;
        }
    }

    /// Clamp-to-edge cumulative function.
    fn clamp_edge(&mut self, x: i64, n: i64, sign: i64) {
        if x < 0 {
            self.push(1, sign * x);
        } else if x <= n {
            self.push(x, sign);
        } else {
            let beyond = x - n;
            self.push(n, sign * (1 + beyond));
            self.push(n - 1, -sign * beyond);
        }
    }

    fn cumulative(&mut self, mode: WrapMode, x: i64, n: i64, sign: i64) {
        if let Some(p) = period(mode, n) {
            // Whole periods and the rest, `x = q · p + r`: a period holds
            // the tile once (repeat) or twice (mirror, the tile and its
            // mirror image); a rest past the tile (mirror only) is the
            // next period less the mirrored part it lacks.
            let (q, r) = (x.div_euclid(p), x.rem_euclid(p));
            if r <= n {
                self.push(n, sign * (p / n) * q);
                self.push(r, sign);
            } else {
                self.push(n, sign * (2 * q + 2));
                self.push(2 * n - r, -sign);
            }
            return;
        }
        match mode {
            WrapMode::ClampToEdge => self.clamp_edge(x, n, sign),
            WrapMode::ClampToBorder => self.push(x.clamp(0, n), sign),
            WrapMode::MirrorClampToEdge => {
                if x >= 0 {
                    self.clamp_edge(x, n, sign);
                } else {
                    self.clamp_edge(-x, n, -sign);
                }
            }
            // Periodic: done above.
            WrapMode::Repeat | WrapMode::MirroredRepeat => {}
        }
    }
}

impl Axis {
    /// The interval `[x0, x1)` (texel units, `x0 ≤ x1`, both finite and
    /// within ±2⁵²) of an axis of `n ≥ 1` texels under `mode`.
    pub(crate) fn new(mode: WrapMode, x0: f64, x1: f64, n: u32) -> Axis {
        let n64 = n as i64;
        let ((i0, a0), (i1, a1)) = (split(x0), split(x1));
        if i0 >= 0 && (i1 < n64 || (i1 == n64 && a1 == 0.0)) {
            return Self::inside(x0, x1, i0, a0, i1, a1);
        }
        let mut it = IntTerms {
            idx: [0; N],
            coef: [0; N],
            len: 0,
        };
        it.cumulative(mode, i1, n64, 1);
        it.cumulative(mode, i0, n64, -1);
        let mut ax = Axis {
            idx: [0; N],
            coef: [0.0; N],
            len: 0,
            total: (i1 - i0) as f64 + (a1 - a0),
            inside: 0.0,
        };
        for k in 0..it.len {
            ax.push(it.idx[k], it.coef[k] as f64);
        }
        for (i, a, sign) in [(i1, a1, 1.0), (i0, a0, -1.0)] {
            if a > 0.0
                && let Some(t) = wrap_index(mode, i, n)
            {
                ax.push(t + 1, sign * a);
                ax.push(t, -sign * a);
            }
        }
        ax.inside = if mode == WrapMode::ClampToBorder {
            // Σ coef·idx: every term is a prefix P[idx] of idx texels.
            (0..ax.len).map(|k| ax.coef[k] * ax.idx[k] as f64).sum()
        } else {
            ax.total
        };
        ax
    }

    /// `[x0, x1)` within `[0, n]`: `C(i + a) = (1 − a)·P[i] + a·P[i+1]` at
    /// both ends, no wrapping (duplicate indices are left unmerged).
    #[inline]
    fn inside(x0: f64, x1: f64, i0: i64, a0: f64, i1: i64, a1: f64) -> Axis {
        let mut ax = Axis {
            idx: [0; N],
            coef: [0.0; N],
            len: 0,
            total: x1 - x0,
            inside: x1 - x0,
        };
        for (i, c) in [(i1, 1.0 - a1), (i1 + 1, a1), (i0, a0 - 1.0), (i0 + 1, -a0)] {
            if i != 0 && c != 0.0 {
                ax.idx[ax.len] = i as u32;
                ax.coef[ax.len] = c;
                ax.len += 1;
            }
        }
        ax
    }

    fn push(&mut self, idx: u32, c: f64) {
        if idx == 0 || c == 0.0 {
            return;
        }
        if let Some(k) = self.idx[..self.len].iter().position(|&i| i == idx) {
            self.coef[k] += c;
        } else {
            self.idx[self.len] = idx;
            self.coef[self.len] = c;
            self.len += 1;
        }
    }

    /// The terms as `(index, coefficient)` pairs.
    pub(crate) fn terms(&self) -> impl Iterator<Item = (u32, f64)> + '_ {
        (0..self.len).map(|k| (self.idx[k], self.coef[k]))
    }
}

/// Fractional part of `x` given its floor index (0 when `x` is so large
/// that it has none).
#[inline]
/// `x` as a texel index and the fraction of that texel before it, `x =
/// i + a` with `0 ≤ a < 1`. Just below an integer `k`, `x − floor(x)`
/// rounds to 1 (−2⁻¹⁰⁰ − (−1) is 1 in `f64`): that is `k` itself, `(k,
/// 0)`, not `(k − 1, 0)`, a whole texel off (fuzzing found the case).
fn split(x: f64) -> (i64, f64) {
    let i = floor_index(x);
    let f = x - i as f64;
    if (0.0..1.0).contains(&f) {
        (i, f)
    } else if f >= 1.0 {
        (i.saturating_add(1), 0.0)
    } else {
        (i, 0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Weight of each texel of the level, by brute force over the interval.
    fn brute(mode: WrapMode, x0: f64, x1: f64, n: u32) -> (Vec<f64>, f64) {
        let mut w = vec![0.0; n as usize];
        let mut border = 0.0;
        let mut i = x0.floor() as i64;
        while (i as f64) < x1 {
            let lo = (i as f64).max(x0);
            let hi = ((i + 1) as f64).min(x1);
            match wrap_index(mode, i, n) {
                Some(t) => w[t as usize] += hi - lo,
                None => border += hi - lo,
            }
            i += 1;
        }
        (w, border)
    }

    #[test]
    fn axis_terms_match_brute_force_weights_in_every_mode() {
        let modes = [
            WrapMode::Repeat,
            WrapMode::MirroredRepeat,
            WrapMode::ClampToEdge,
            WrapMode::ClampToBorder,
            WrapMode::MirrorClampToEdge,
        ];
        for mode in modes {
            for n in [1u32, 2, 3, 7] {
                for &(x0, x1) in &[
                    (0.0, 1.0),
                    (-3.25, 2.5),
                    (-17.5, -0.25),
                    (1.5, 1.75),
                    (2.0, 30.0),
                    (-40.125, 41.0),
                    (5.0, 5.0),
                ] {
                    let ax = Axis::new(mode, x0, x1, n);
                    // Recover per-texel weights: P[k] = Σ_{t<k} w_t, so
                    // texel t gets Σ_{idx > t} coef.
                    let mut got = vec![0.0; n as usize];
                    for (idx, c) in ax.terms() {
                        for g in got.iter_mut().take(idx as usize) {
                            *g += c;
                        }
                    }
                    let (want, border) = brute(mode, x0, x1, n);
                    for t in 0..n as usize {
                        assert!(
                            (got[t] - want[t]).abs() < 1e-9,
                            "{mode} n={n} [{x0},{x1}) texel {t}: {} vs {}",
                            got[t],
                            want[t]
                        );
                    }
                    assert!((ax.total - (x1 - x0)).abs() < 1e-9);
                    assert!((ax.total - ax.inside - border).abs() < 1e-9, "{mode}");
                }
            }
        }
    }
}
