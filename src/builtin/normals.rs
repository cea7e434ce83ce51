//! The procedural normal maps: Gaussian bumps (`builtin:bumps`), V-grooves
//! and a rough height field, each the normals of a height field. The
//! shading validation of [`crate::shade`] runs on them.

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::texel::{ChannelType, ColorSpace, Format, Texels};
use crate::texture::Texture;

pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(crate) fn unit(v: [f64; 3]) -> [f64; 3] {
    let l = dot(v, v).sqrt();
    v.map(|c| c / l)
}

/// The float normal map of a height field `height(x, y)` (texel units;
/// central differences, wrapping), `size`². The heights are evaluated
/// once per texel, rows in parallel.
pub fn normals_of_height(size: u32, height: impl Fn(f64, f64) -> f64 + Sync) -> Result<Texture> {
    let n = size as usize;
    let h: Vec<f64> = (0..n * n)
        .into_par_iter()
        .map(|i| height((i % n) as f64, (i / n) as f64))
        .collect();
    let at = |x: usize, y: usize| h[(y % n) * n + (x % n)];
    let v: Vec<f32> = (0..n * n)
        .into_par_iter()
        .flat_map_iter(|i| {
            let (x, y) = (i % n, i / n);
            let hx = (at(x + 1, y) - at(x + n - 1, y)) * 0.5;
            let hy = (at(x, y + 1) - at(x, y + n - 1)) * 0.5;
            unit([-hx, -hy, 1.0]).map(|c| c as f32)
        })
        .collect();
    Texture::from_f32(
        size,
        size,
        Format::new(3, ChannelType::F32, ColorSpace::Linear),
        v,
    )
}

/// A deterministic generator for the procedural maps (SplitMix64).
struct Mix(u64);

impl Mix {
    fn unit(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Gaussian bumps of standard deviation `sigma` texels and height
/// `height`·sigma at random places (`count` of them, wrapping), `size`².
pub fn bumps(size: u32, sigma: f64, height: f64, count: usize, seed: u64) -> Result<Texture> {
    let h = bump_height(size, sigma, height, count, seed);
    normals_of_height(size, h)
}

/// The height field of [`bumps`]: each bump reaches 4σ, so the centres
/// are binned in cells of at least 4σ and a point looks at the 3×3 cells
/// around its own (wrapping).
fn bump_height(
    size: u32,
    sigma: f64,
    height: f64,
    count: usize,
    seed: u64,
) -> impl Fn(f64, f64) -> f64 {
    let mut r = Mix(seed);
    let s = size as f64;
    let cells = ((s / (4.0 * sigma)).floor() as usize).max(1);
    let cell = s / cells as f64;
    let mut bins: Vec<Vec<(f64, f64, f64)>> = vec![Vec::new(); cells * cells];
    for _ in 0..count {
        let (cx, cy) = (r.unit() * s, r.unit() * s);
        let sign = if r.unit() < 0.5 { -1.0 } else { 1.0 };
        let (i, j) = (
            ((cx / cell) as usize).min(cells - 1),
            ((cy / cell) as usize).min(cells - 1),
        );
        bins[j * cells + i].push((cx, cy, sign));
    }
    move |x, y| {
        let (i, j) = ((x / cell) as i64, (y / cell) as i64);
        let mut z = 0.0;
        let near: &[i64] = if cells >= 3 { &[-1, 0, 1] } else { &[0] };
        let mut seen = [usize::MAX; 9];
        let mut k = 0;
        for dj in near {
            for di in near {
                let ci = (i + di).rem_euclid(cells as i64) as usize;
                let cj = (j + dj).rem_euclid(cells as i64) as usize;
                let b = cj * cells + ci;
                if seen[..k].contains(&b) {
                    continue;
                }
                seen[k] = b;
                k += 1;
                for &(cx, cy, sign) in &bins[b] {
                    let wrap = |d: f64| {
                        if d > s * 0.5 {
                            d - s
                        } else if d < -s * 0.5 {
                            d + s
                        } else {
                            d
                        }
                    };
                    let (dx, dy) = (wrap(x - cx), wrap(y - cy));
                    let d2 = dx * dx + dy * dy;
                    if d2 < 16.0 * sigma * sigma {
                        z += sign * height * sigma * (-d2 / (2.0 * sigma * sigma)).exp();
                    }
                }
            }
        }
        z
    }
}

/// `builtin:bumps[:SIZE]`: Gaussian bumps at two scales (σ = SIZE/170 and
/// SIZE/64 texels, at least 1) as an RGB8 normal map (codes `(n + 1)/2`).
pub fn builtin_bumps(size: u32) -> Result<Texture> {
    let s = size as f64;
    let area = s * s / 65536.0;
    let small = bump_height(
        size,
        (s / 170.0).max(1.0),
        1.0,
        (2500.0 * area).ceil() as usize,
        1,
    );
    let large = bump_height(
        size,
        (s / 64.0).max(1.0),
        1.0,
        (400.0 * area).ceil() as usize,
        2,
    );
    let n = normals_of_height(size, |x, y| small(x, y) + large(x, y))?;
    let Texels::F32(v) = n.texels() else {
        return Err(Error::InvalidOption("expected f32 normals".into()));
    };
    let codes = v
        .iter()
        .map(|c| ((c + 1.0) * 0.5 * 255.0).round() as u8)
        .collect();
    Texture::from_u8(
        size,
        size,
        Format::new(3, ChannelType::U8, ColorSpace::Linear),
        codes,
    )
}

/// Parallel V-grooves along y, `period` texels apart, walls at
/// `slope_deg` degrees.
pub fn v_grooves(size: u32, period: f64, slope_deg: f64) -> Result<Texture> {
    let t = slope_deg.to_radians().tan();
    normals_of_height(size, |x, _| {
        let p = (x / period).fract();
        (0.5 - (p - 0.5).abs()) * period * t
    })
}

/// A rough, natural-looking height field: octaves of smooth value noise
/// (periods from `size`/4 down to 2 texels, amplitude ∝ period).
pub fn height_field(size: u32, roughness: f64, seed: u64) -> Result<Texture> {
    let mut r = Mix(seed);
    let mut octaves = Vec::new();
    let mut period = (size / 4).max(2) as usize;
    while period >= 2 {
        let n = (size as usize).div_ceil(period);
        let grid: Vec<f64> = (0..n * n).map(|_| r.unit() - 0.5).collect();
        octaves.push((period, n, grid));
        period /= 2;
    }
    normals_of_height(size, |x, y| {
        let mut z = 0.0;
        for (p, n, g) in &octaves {
            let (fx, fy) = (x / *p as f64, y / *p as f64);
            let (ix, iy) = (fx.floor() as usize, fy.floor() as usize);
            let (tx, ty) = (fx - ix as f64, fy - iy as f64);
            let (sx, sy) = (tx * tx * (3.0 - 2.0 * tx), ty * ty * (3.0 - 2.0 * ty));
            let at = |i: usize, j: usize| g[(j % n) * n + (i % n)];
            let a = at(ix, iy) + (at(ix + 1, iy) - at(ix, iy)) * sx;
            let b = at(ix, iy + 1) + (at(ix + 1, iy + 1) - at(ix, iy + 1)) * sx;
            z += (a + (b - a) * sy) * *p as f64 * roughness;
        }
        z
    })
}
