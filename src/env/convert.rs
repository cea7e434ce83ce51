//! Conversions between a lat-long map and a cube map: each texel of the
//! new image is a filtered lookup of the old one in the direction of the
//! texel's centre, with the texel's own footprint as the derivatives
//! (EWA, so the lat-long map's stretched rows near the poles are read
//! with the ellipse they need and a large texel averages what it covers).

use crate::error::Result;
use crate::mip::MipChain;
use crate::sample::{Method, SamplerOptions};
use crate::texel::Format;
use crate::texture::Texture;

use super::cube::face_direction;
use super::latlong::st_to_direction;
use super::{CubeSampler, DirQuery, LatLongSampler};

/// The filter a conversion reads with: EWA (every footprint's shape).
fn options() -> SamplerOptions {
    SamplerOptions {
        method: Method::Ewa,
        max_aniso: 16,
        ..SamplerOptions::default()
    }
}

fn to_f32(d: [f64; 3]) -> [f32; 3] {
    d.map(|x| x as f32)
}

fn minus(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// Fill a `w × h` image of `format` with `lookup(i, j)` (linear RGBA).
fn render(
    w: u32,
    h: u32,
    format: Format,
    lookup: impl Fn(u32, u32) -> [f32; 4] + Sync,
) -> Result<Texture> {
    use rayon::prelude::*;
    let ch = format.channels as usize;
    let mut lin = vec![0f32; w as usize * h as usize * ch];
    lin.par_chunks_mut(w as usize * ch)
        .enumerate()
        .for_each(|(j, row)| {
            for (i, px) in row.chunks_exact_mut(ch).enumerate() {
                let v = lookup(i as u32, j as u32);
                px.copy_from_slice(&channels_of(v, ch));
            }
        });
    Texture::from_linear(w, h, format, &lin)
}

/// RGBA as `ch` channels (grey from the first, grey + alpha, RGB, RGBA).
fn channels_of(v: [f32; 4], ch: usize) -> Vec<f32> {
    match ch {
        1 => vec![v[0]],
        2 => vec![v[0], v[3]],
        3 => vec![v[0], v[1], v[2]],
        _ => v.to_vec(),
    }
}

/// The six `n × n` faces (+X, −X, +Y, −Y, +Z, −Z) of the lat-long map
/// `chain` (OpenImageIO's orientation, y up), in `chain`'s format.
pub fn latlong_to_cube(chain: &MipChain, n: u32) -> Result<Vec<Texture>> {
    let s = LatLongSampler::new(chain, options())?;
    let format = chain.levels()[0].format();
    let nf = n as f64;
    (0..6)
        .map(|f| {
            render(n, n, format, |i, j| {
                let (u, v) = ((i as f64 + 0.5) / nf, (j as f64 + 0.5) / nf);
                let d = face_direction(f, u, v);
                let dx = minus(face_direction(f, u + 1.0 / nf, v), d);
                let dy = minus(face_direction(f, u, v + 1.0 / nf), d);
                s.sample(&DirQuery::new(to_f32(d), to_f32(dx), to_f32(dy)))
            })
        })
        .collect()
}

/// The `width × height` lat-long map (y up, OpenImageIO's orientation)
/// of the cube map `faces` (six face chains), in the faces' format.
pub fn cube_to_latlong(faces: &[MipChain], width: u32, height: u32) -> Result<Texture> {
    let s = CubeSampler::new(faces, options())?;
    let format = faces[0].levels()[0].format();
    let (wf, hf) = (width as f64, height as f64);
    render(width, height, format, |i, j| {
        let (u, v) = ((i as f64 + 0.5) / wf, (j as f64 + 0.5) / hf);
        let d = st_to_direction(u, v);
        let dx = minus(st_to_direction(u + 1.0 / wf, v), d);
        let dy = minus(st_to_direction(u, v + 1.0 / hf), d);
        s.sample(&DirQuery::new(to_f32(d), to_f32(dx), to_f32(dy)))
    })
}
