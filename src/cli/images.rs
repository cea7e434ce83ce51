//! Writing the images `render` and `tradeoff` produce: linear RGB to sRGB
//! 8-bit PNG (written atomically), error maps and level tints.

use std::path::Path;

use anyhow::{Context, Result};
use parvo::Texture;
use parvo::scene::Frame;
use parvo::texel::{ChannelType, ColorSpace, Format};

/// Pixels that show no texture.
const BACKGROUND: [f32; 3] = [0.02, 0.02, 0.03];

/// Write linear RGB values (row-major, `None` = background) as an sRGB PNG.
pub fn write_rgb(path: &Path, frame: Frame, px: &[Option<[f32; 3]>]) -> Result<()> {
    let lin: Vec<f32> = px
        .iter()
        .flat_map(|p| p.unwrap_or(BACKGROUND).map(|c| c.clamp(0.0, 1.0)))
        .collect();
    let t = Texture::from_linear(
        frame.width,
        frame.height,
        Format::new(3, ChannelType::U8, ColorSpace::Srgb),
        &lin,
    )?;
    parvo::io::atomic::write(path, |w| parvo::io::png_levels::write_png(&t, w))
        .with_context(|| format!("writing {}", path.display()))
}

/// Write a rendered image (linear RGBA; alpha dropped).
pub fn write_image(path: &Path, frame: Frame, img: &[Option<[f32; 4]>]) -> Result<()> {
    let rgb: Vec<Option<[f32; 3]>> = img.iter().map(|p| p.map(|c| [c[0], c[1], c[2]])).collect();
    write_rgb(path, frame, &rgb)
}

/// A perceptually ordered colour map (black, purple, red, yellow, white)
/// at `t` in [0, 1].
fn heat(t: f32) -> [f32; 3] {
    const STOPS: [[f32; 3]; 5] = [
        [0.0, 0.0, 0.0],
        [0.25, 0.0, 0.45],
        [0.85, 0.1, 0.1],
        [1.0, 0.85, 0.1],
        [1.0, 1.0, 1.0],
    ];
    let x = t.clamp(0.0, 1.0) * (STOPS.len() - 1) as f32;
    let i = (x as usize).min(STOPS.len() - 2);
    let f = x - i as f32;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    // The map is defined in display (sRGB-encoded) values: decode so the
    // PNG shows these colours.
    [0, 1, 2].map(|c| srgb_decode(a[c] + (b[c] - a[c]) * f))
}

fn srgb_decode(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Write the absolute error of `img` against `reference` (mean over R, G,
/// B), divided by `scale` and colour-mapped; returns nothing, the caller
/// states the scale.
pub fn write_error_map(
    path: &Path,
    frame: Frame,
    img: &[Option<[f32; 4]>],
    reference: &[Option<[f32; 4]>],
    scale: f64,
) -> Result<()> {
    let px: Vec<Option<[f32; 3]>> = img
        .iter()
        .zip(reference)
        .map(|(a, r)| {
            let (a, r) = (a.as_ref()?, r.as_ref()?);
            let e = (0..3).map(|c| (a[c] - r[c]).abs() as f64).sum::<f64>() / 3.0;
            Some(heat((e / scale.max(1e-9)) as f32))
        })
        .collect();
    write_rgb(path, frame, &px)
}

/// Writes `text` to `path` atomically (a temporary file renamed into
/// place); `format` names the file type in the error.
pub fn write_text(path: &Path, format: &'static str, text: &str) -> Result<()> {
    use std::io::Write;
    parvo::io::atomic::write(path, |w| {
        w.write_all(text.as_bytes())
            .map_err(|e| parvo::Error::Encode {
                format,
                reason: e.to_string(),
            })
    })
    .with_context(|| format!("cannot write {}", path.display()))
}
