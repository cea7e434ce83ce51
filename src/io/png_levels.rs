//! One PNG per mip level: an output name containing `{level}` (e.g.
//! `out_{level}.png`) becomes `out_0.png`, `out_1.png`, ... 8- or 16-bit,
//! 1–4 channels as stored. All files are staged first and renamed only when
//! every level has been encoded (see [`atomic`]).

use std::path::{Path, PathBuf};

use image::ExtendedColorType;
use image::ImageEncoder;
use image::codecs::png::PngEncoder;

use super::atomic;
use crate::error::{Error, Result};
use crate::texel::Texels;
use crate::texture::Texture;

fn encode_err(reason: impl std::fmt::Display) -> Error {
    Error::Encode {
        format: "PNG",
        reason: reason.to_string(),
    }
}

/// The file name of level `k` for a `{level}` template.
pub fn level_path(template: &Path, k: usize) -> PathBuf {
    PathBuf::from(
        template
            .to_string_lossy()
            .replace("{level}", &k.to_string()),
    )
}

/// Encode one texture as PNG into `out`. PNG's two-channel layout is grey +
/// alpha, so R, G data (no alpha) is written as RGB with B = 0.
pub fn write_png(t: &Texture, out: &mut impl std::io::Write) -> Result<()> {
    use ExtendedColorType::*;
    if t.channels() == 2 && !t.format().has_alpha() {
        return write_png(&super::expand_channels(t, 3)?, out);
    }
    let (bytes, color): (&[u8], _) = match t.texels() {
        Texels::U8(v) => (v.as_slice(), [L8, La8, Rgb8, Rgba8][t.channels() - 1]),
        Texels::U16(v) => (
            bytemuck::cast_slice(v.as_slice()),
            [L16, La16, Rgb16, Rgba16][t.channels() - 1],
        ),
        _ => return Err(encode_err("PNG stores 8- or 16-bit texels, not floats")),
    };
    PngEncoder::new(out)
        .write_image(bytes, t.width(), t.height(), color)
        .map_err(encode_err)
}

/// Write every level to its own PNG, atomically as a set.
pub fn save(levels: &[Texture], template: &Path) -> Result<()> {
    let mut staged = Vec::with_capacity(levels.len());
    for (k, l) in levels.iter().enumerate() {
        staged.push(atomic::stage(&level_path(template, k), |w| {
            write_png(l, w)
        })?);
    }
    for s in staged {
        s.commit()?;
    }
    Ok(())
}
