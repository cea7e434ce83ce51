//! What the lookup commands (`parvo sample`, with or without
//! `--direction`) share: the image `--layer` picks and the output lines.

use anyhow::{Result, anyhow};
use parvo::ImageKind;
use parvo::env::layer_index;

/// The image `--layer` picks in `spec`, a texture of `kind`: for a 2-D
/// array the layer, for a cube-map array the cube, as GL rounds an array
/// coordinate ([`parvo::env::layer_index`]); 0 for one image. An array of
/// more than one layer or cube without `--layer`, and `--layer` on a
/// texture that is not an array, are refused saying why.
pub(super) fn pick_image(spec: &str, kind: ImageKind, layer: Option<f32>) -> Result<usize> {
    let (count, noun, what) = match kind {
        ImageKind::Array { layers } => (
            layers as usize,
            "layer",
            format!("a 2-D array of {layers} layers"),
        ),
        ImageKind::CubeArray { cubes } => (
            cubes as usize,
            "cube",
            format!("a cube-map array of {cubes} cubes"),
        ),
        _ => {
            let what = match kind {
                ImageKind::Plain => "one 2-D image".to_string(),
                ImageKind::Cube => "one cube map".to_string(),
                ImageKind::LatLong => "a lat-long environment map".to_string(),
                other => other.describe(),
            };
            return match layer {
                None => Ok(0),
                Some(_) => Err(anyhow!(
                    "--layer picks a layer of a 2-D array (or, with --direction, a cube of a \
                     cube-map array), and `{spec}` is {what}, not an array"
                )),
            };
        }
    };
    match layer {
        Some(l) => Ok(layer_index(l, count)),
        None if count <= 1 => Ok(0),
        None => Err(anyhow!(
            "`{spec}` is {what}: say which {noun} to sample with --layer N, N from 0 to {} \
             (rounded as GL rounds an array layer, clamped to that range)",
            count - 1
        )),
    }
}

/// One line of output: the texture's channels of an RGBA colour.
pub(super) fn format_colour(s: &mut String, c: &[f32; 4], channels: usize) {
    use std::fmt::Write as _;
    let vals: &[f32] = match channels {
        1 => &c[..1],
        2 => &[c[0], c[3]],
        3 => &c[..3],
        _ => &c[..],
    };
    for (i, v) in vals.iter().enumerate() {
        if i > 0 {
            s.push(' ');
        }
        let _ = write!(s, "{v}");
    }
    s.push('\n');
}
