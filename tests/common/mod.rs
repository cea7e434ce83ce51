//! Shared helpers for the integration tests: a seeded RNG, random textures
//! of every storage type, and a plain f64 reference of SPEC.md's mip
//! formulas written independently of the library.
#![allow(dead_code)]

pub mod replay;

use half::f16;
use parvo::{AlphaMode, ChannelType, ColorSpace, Format, Texels, Texture};

/// SplitMix64: small, seeded, good enough for test data.
pub struct Rng(pub u64);
impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform in [0, 1) as f32.
    pub fn f(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// Every sampling filter preset (anisotropic ones at 4 and 16; the other
/// presets built with `max_aniso`), for tests that run a property over all
/// of them.
pub fn sampler_presets(max_aniso: u32) -> Vec<parvo::sample::SamplerOptions> {
    use parvo::sample::{Filter, SamplerOptions};
    let mut v: Vec<SamplerOptions> = [
        Filter::Nearest,
        Filter::Bilinear,
        Filter::Trilinear,
        Filter::Ewa,
        Filter::Supersample,
    ]
    .into_iter()
    .map(|f| SamplerOptions::preset(f, max_aniso))
    .collect();
    v.push(SamplerOptions::aniso(4));
    v.push(SamplerOptions::aniso(16));
    v
}

pub const AWKWARD: [(u32, u32); 6] = [(1, 1), (1, 9), (9, 1), (3, 5), (12, 19), (257, 129)];

/// A random texture of the given format (floats in [0, 4)).
pub fn random_texture(rng: &mut Rng, w: u32, h: u32, format: Format) -> Texture {
    let n = w as usize * h as usize * format.channels as usize;
    let texels = match format.channel_type {
        ChannelType::U8 => Texels::U8((0..n).map(|_| rng.next_u64() as u8).collect()),
        ChannelType::U16 => Texels::U16((0..n).map(|_| rng.next_u64() as u16).collect()),
        ChannelType::F16 => Texels::F16((0..n).map(|_| f16::from_f64(rng.unit() * 4.0)).collect()),
        ChannelType::F32 => Texels::F32((0..n).map(|_| (rng.unit() * 4.0) as f32).collect()),
    };
    Texture::from_texels(w, h, format, texels).unwrap()
}

pub fn srgb_decode(c: f64) -> f64 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}
pub fn srgb_encode(l: f64) -> f64 {
    if l <= 0.0031308 {
        l * 12.92
    } else {
        1.055 * l.powf(1.0 / 2.4) - 0.055
    }
}

/// Stored values as f64 in "storage units": codes for unorm, values for
/// floats.
pub fn raw(t: &Texture) -> Vec<f64> {
    match t.texels() {
        Texels::U8(v) => v.iter().map(|&x| x as f64).collect(),
        Texels::U16(v) => v.iter().map(|&x| x as f64).collect(),
        Texels::F16(v) => v.iter().map(|&x| x.to_f64()).collect(),
        Texels::F32(v) => v.iter().map(|&x| x as f64).collect(),
    }
}

/// Linear-light f64 values of a texture, decoded with the SPEC formulas.
pub fn decode(t: &Texture) -> Vec<f64> {
    let f = t.format();
    let ch = f.channels as usize;
    let scale = match f.channel_type {
        ChannelType::U8 => 255.0,
        ChannelType::U16 => 65535.0,
        _ => 1.0,
    };
    raw(t)
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            let v = v / scale;
            if f.color_space == ColorSpace::Srgb && is_color(&f, i % ch) {
                v.signum() * srgb_decode(v.abs())
            } else {
                v
            }
        })
        .collect()
}

pub fn is_color(f: &Format, c: usize) -> bool {
    !(f.channels == 2 || f.channels == 4) || c + 1 < f.channels as usize
}

/// Linear value to storage units (unclamped code for unorm: encode·scale).
pub fn to_storage_units(f: &Format, c: usize, v: f64) -> f64 {
    let srgb = f.color_space == ColorSpace::Srgb && is_color(f, c);
    match f.channel_type {
        ChannelType::U8 | ChannelType::U16 => {
            let scale = if f.channel_type == ChannelType::U8 {
                255.0
            } else {
                65535.0
            };
            let v = v.clamp(0.0, 1.0);
            (if srgb { srgb_encode(v) } else { v }) * scale
        }
        _ => {
            if srgb {
                v.signum() * srgb_encode(v.abs())
            } else {
                v
            }
        }
    }
}

pub fn mirror(n: i64) -> i64 {
    if n >= 0 { n } else { -(1 + n) }
}

/// SPEC wrap formulas restated; None = border.
pub fn wrap(mode: &str, i: i64, size: i64) -> Option<i64> {
    let m = |a: i64, b: i64| ((a % b) + b) % b;
    match mode {
        "repeat" => Some(m(i, size)),
        "mirror" => Some((size - 1) - mirror(m(i, 2 * size) - size)),
        "clamp" => Some(i.clamp(0, size - 1)),
        "border" => (0..size).contains(&i).then_some(i),
        "mirror-clamp" => Some(mirror(i).clamp(0, size - 1)),
        _ => panic!("unknown wrap {mode}"),
    }
}

pub fn sinc(x: f64) -> f64 {
    if x == 0.0 {
        1.0
    } else {
        (std::f64::consts::PI * x).sin() / (std::f64::consts::PI * x)
    }
}
pub fn i0(x: f64) -> f64 {
    (0..40)
        .map(|k| {
            let mut t = 1.0;
            for j in 1..=k {
                t *= (x / 2.0) * (x / 2.0) / (j * j) as f64;
            }
            t
        })
        .sum()
}

/// (radius, kernel) of the named filter, from the SPEC formulas.
pub fn kernel(name: &str) -> (f64, Box<dyn Fn(f64) -> f64>) {
    match name {
        "triangle" => (1.0, Box::new(|x: f64| (1.0 - x.abs()).max(0.0))),
        "kaiser" => (
            3.0,
            Box::new(|x: f64| {
                let t = x / 3.0;
                if t.abs() >= 1.0 {
                    0.0
                } else {
                    sinc(x) * i0(4.0 * (1.0 - t * t).sqrt()) / i0(4.0)
                }
            }),
        ),
        "lanczos3" => (
            3.0,
            Box::new(|x: f64| {
                if x.abs() >= 3.0 {
                    0.0
                } else {
                    sinc(x) * sinc(x / 3.0)
                }
            }),
        ),
        "mitchell" => (
            2.0,
            Box::new(|x: f64| {
                let (b, c, x) = (1.0 / 3.0, 1.0 / 3.0, x.abs());
                (if x < 1.0 {
                    (12.0 - 9.0 * b - 6.0 * c) * x.powi(3)
                        + (-18.0 + 12.0 * b + 6.0 * c) * x * x
                        + (6.0 - 2.0 * b)
                } else if x < 2.0 {
                    (-b - 6.0 * c) * x.powi(3)
                        + (6.0 * b + 30.0 * c) * x * x
                        + (-12.0 * b - 48.0 * c) * x
                        + (8.0 * b + 24.0 * c)
                } else {
                    0.0
                }) / 6.0
            }),
        ),
        _ => panic!("no kernel {name}"),
    }
}

/// Reference weights of one axis: SPEC's box (2-tap even, polyphase
/// (n−x, n, x+1)/(2n+1) odd, area overlap when rounding up) or a stretched
/// kernel, wrapped, border taps dropped, normalised.
pub fn axis_weights(
    filter: &str,
    src: usize,
    dst: usize,
    wrap_mode: &str,
) -> Vec<Vec<(usize, f64)>> {
    (0..dst)
        .map(|x| {
            let mut taps: Vec<(i64, f64)> = Vec::new();
            if src == dst {
                taps.push((x as i64, 1.0));
            } else if filter == "box" {
                if src == 2 * dst {
                    taps = vec![(2 * x as i64, 0.5), (2 * x as i64 + 1, 0.5)];
                } else if src == 2 * dst + 1 {
                    let n = dst as f64;
                    let d = 2.0 * n + 1.0;
                    let x = x as f64;
                    taps = vec![
                        (2 * x as i64, (n - x) / d),
                        (2 * x as i64 + 1, n / d),
                        (2 * x as i64 + 2, (x + 1.0) / d),
                    ];
                } else {
                    let s = src as f64 / dst as f64;
                    let (lo, hi) = (x as f64 * s, (x as f64 + 1.0) * s);
                    for i in 0..src as i64 {
                        let w = (hi.min(i as f64 + 1.0) - lo.max(i as f64)).max(0.0) / s;
                        if w > 0.0 {
                            taps.push((i, w));
                        }
                    }
                }
            } else {
                let (r, k) = kernel(filter);
                let s = src as f64 / dst as f64;
                let c = (x as f64 + 0.5) * s;
                for i in (c - r * s - 2.0) as i64 - 1..(c + r * s + 2.0) as i64 + 1 {
                    let w = k((i as f64 + 0.5 - c) / s);
                    if w != 0.0 {
                        taps.push((i, w));
                    }
                }
            }
            let taps: Vec<(usize, f64)> = taps
                .into_iter()
                .filter_map(|(i, w)| wrap(wrap_mode, i, src as i64).map(|j| (j as usize, w)))
                .collect();
            let sum: f64 = taps.iter().map(|t| t.1).sum();
            taps.into_iter().map(|(i, w)| (i, w / sum)).collect()
        })
        .collect()
}

/// Reference reduction of `src` (linear f64 texels) to `dw × dh`, with
/// alpha weighting for straight alpha. Returns linear f64 values.
pub fn reference_reduce(
    src: &Texture,
    dw: usize,
    dh: usize,
    filter: &str,
    wrap_u: &str,
    wrap_v: &str,
) -> Vec<f64> {
    let (sw, sh) = (src.width() as usize, src.height() as usize);
    let lin = decode(src);
    reference_reduce_linear(
        &lin,
        src.format(),
        (sw, sh),
        (dw, dh),
        filter,
        wrap_u,
        wrap_v,
    )
}

/// The reference chain: levels 1.. (linear values, as [`reference_reduce`]
/// gives), each reduced from the unrounded level before it, with the sizes
/// of `sizes` (level 0's first).
pub fn reference_chain(
    base: &Texture,
    sizes: &[(u32, u32)],
    filter: &str,
    wrap_u: &str,
    wrap_v: &str,
) -> Vec<Vec<f64>> {
    let f = base.format();
    let mut prev = decode(base);
    let mut out = Vec::new();
    for p in sizes.windows(2) {
        let (s, d) = (p[0], p[1]);
        let next = reference_reduce_linear(
            &prev,
            f,
            (s.0 as usize, s.1 as usize),
            (d.0 as usize, d.1 as usize),
            filter,
            wrap_u,
            wrap_v,
        );
        out.push(next.clone());
        prev = next;
    }
    out
}

/// [`reference_reduce`] of linear values `lin` (`sw·sh` texels of `f`).
pub fn reference_reduce_linear(
    lin: &[f64],
    f: Format,
    (sw, sh): (usize, usize),
    (dw, dh): (usize, usize),
    filter: &str,
    wrap_u: &str,
    wrap_v: &str,
) -> Vec<f64> {
    let ch = f.channels as usize;
    let wx = axis_weights(filter, sw, dw, wrap_u);
    let wy = axis_weights(filter, sh, dh, wrap_v);
    let alpha = (f.alpha == AlphaMode::Straight && (ch == 2 || ch == 4)).then_some(ch - 1);
    let mut out = vec![0.0; dw * dh * ch];
    for y in 0..dh {
        for x in 0..dw {
            let mut acc = [0.0f64; 4];
            let mut plain = [0.0f64; 4];
            for &(j, wj) in &wy[y] {
                for &(i, wi) in &wx[x] {
                    let t = &lin[(j * sw + i) * ch..][..ch];
                    let w = wi * wj;
                    for c in 0..ch {
                        plain[c] += w * t[c];
                        acc[c] += match alpha {
                            Some(a) if c != a => w * t[a] * t[c],
                            _ => w * t[c],
                        };
                    }
                }
            }
            let o = &mut out[(y * dw + x) * ch..][..ch];
            for c in 0..ch {
                o[c] = match alpha {
                    Some(a) if c != a => {
                        if acc[a] > 1e-7 {
                            acc[c] / acc[a]
                        } else {
                            plain[c]
                        }
                    }
                    Some(a) if c == a => acc[a].max(0.0),
                    _ => acc[c],
                };
            }
        }
    }
    out
}

/// Largest distance between our level and the reference, in storage units
/// (codes for unorm types; relative for floats).
pub fn max_error(ours: &Texture, reference: &[f64]) -> f64 {
    let f = ours.format();
    let ch = f.channels as usize;
    raw(ours)
        .iter()
        .zip(reference)
        .enumerate()
        .map(|(i, (&o, &r))| {
            let want = to_storage_units(&f, i % ch, r);
            match f.channel_type {
                ChannelType::U8 | ChannelType::U16 => (o - want).abs(),
                _ => (o - want).abs() / want.abs().max(1.0),
            }
        })
        .fold(0.0, f64::max)
}

/// Tolerance for [`max_error`]: half a code plus computation slack for
/// unorm types (i.e. "correctly rounded"), relative precision for floats.
pub fn tolerance(t: ChannelType) -> f64 {
    match t {
        ChannelType::U8 => 0.5 + 0.01,
        ChannelType::U16 => 0.5 + 0.15,
        ChannelType::F16 => 1.0 / 1024.0,
        // Kernels with negative lobes cancel large terms (sRGB floats up to
        // 4 decode to ~28), so allow ~100 ulp of the result.
        ChannelType::F32 => 1e-5,
    }
}

pub fn all_formats() -> Vec<Format> {
    let mut v = Vec::new();
    for ty in [
        ChannelType::U8,
        ChannelType::U16,
        ChannelType::F16,
        ChannelType::F32,
    ] {
        for ch in 1..=4u8 {
            for cs in [ColorSpace::Linear, ColorSpace::Srgb] {
                for a in [AlphaMode::Straight, AlphaMode::Premultiplied] {
                    if a == AlphaMode::Premultiplied && !(ch == 2 || ch == 4) {
                        continue;
                    }
                    v.push(Format::new(ch, ty, cs).with_alpha(a));
                }
            }
        }
    }
    v
}
