//! One PNG per mip level: an output name containing `{level}` (e.g.
//! `out_{level}.png`) becomes `out_0.png`, `out_1.png`, ... 8- or 16-bit,
//! 1–4 channels as stored. A cube map's faces go to the names `{face}`
//! makes (`px`, `nx`, `py`, `ny`, `pz`, `nz`: +X, −X, +Y, −Y, +Z, −Z, the
//! names six face files are usually given), an array's layers to those
//! `{layer}` makes (`0`, `1`, ...). All files are staged first and renamed
//! only when every level of every image has been encoded (see
//! [`atomic`]).

use std::path::{Path, PathBuf};

use super::atomic;
use crate::error::{Error, Result};
use crate::texel::{ColorSpace, Texels};
use crate::texture::{ImageKind, Texture};

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

/// The names `{face}` takes in a cube map's file names, in face order.
pub const FACE_NAMES: [&str; 6] = ["px", "nx", "py", "ny", "pz", "nz"];

/// The placeholder that tells an image of `kind` apart from the others
/// of its texture in a file name: `{face}` for a cube map, `{layer}` for
/// an array; none for one image.
fn placeholder(kind: ImageKind) -> Option<&'static str> {
    match kind {
        ImageKind::Cube => Some("{face}"),
        ImageKind::Array { layers } if layers > 1 => Some("{layer}"),
        _ => None,
    }
}

/// The `{level}` template of image `i` (a face or a layer) of a texture
/// of `kind` written to `template`.
pub fn image_template(template: &Path, kind: ImageKind, i: usize) -> PathBuf {
    let name = template.to_string_lossy();
    PathBuf::from(match placeholder(kind) {
        Some("{face}") => name.replace("{face}", FACE_NAMES[i % 6]),
        Some(p) => name.replace(p, &i.to_string()),
        None => name.into_owned(),
    })
}

/// Encode one texture as PNG into `out`, with the chunk that says its
/// transfer: `sRGB` (with the `gAMA` and `cHRM` that go with it) for sRGB
/// data, `gAMA` 1.0 for linear data, so that parvo and OpenImageIO read the
/// levels back as what they are; and a `Software` text chunk naming parvo.
/// PNG's two-channel layout is grey + alpha, so R, G data (no alpha) is
/// written as RGB with B = 0.
pub fn write_png(t: &Texture, out: &mut impl std::io::Write) -> Result<()> {
    if t.channels() == 2 && !t.format().has_alpha() {
        return write_png(&t.expand_channels(3)?, out);
    }
    let color = [
        png::ColorType::Grayscale,
        png::ColorType::GrayscaleAlpha,
        png::ColorType::Rgb,
        png::ColorType::Rgba,
    ][t.channels() - 1];
    let be16;
    let (bytes, depth): (&[u8], _) = match t.texels() {
        Texels::U8(v) => (v.as_slice(), png::BitDepth::Eight),
        Texels::U16(v) => {
            be16 = v.iter().flat_map(|x| x.to_be_bytes()).collect::<Vec<u8>>();
            (be16.as_slice(), png::BitDepth::Sixteen)
        }
        _ => return Err(encode_err("PNG stores 8- or 16-bit texels, not floats")),
    };
    let mut enc = png::Encoder::new(out, t.width(), t.height());
    enc.set_color(color);
    enc.set_depth(depth);
    enc.set_compression(png::Compression::Balanced);
    match t.format().color_space {
        ColorSpace::Srgb => enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual),
        ColorSpace::Linear => enc.set_source_gamma(png::ScaledFloat::new(1.0)),
    }
    enc.add_text_chunk("Software".into(), SOFTWARE.into())
        .map_err(encode_err)?;
    let mut w = enc.write_header().map_err(encode_err)?;
    w.write_image_data(bytes).map_err(encode_err)?;
    w.finish().map_err(encode_err)
}

/// The `Software` text parvo writes into its PNG levels (and looks for
/// before it removes a stale level).
pub const SOFTWARE: &str = concat!("parvo ", env!("CARGO_PKG_VERSION"));

/// Write every level to its own PNG, atomically as a set.
pub fn save(levels: &[Texture], template: &Path) -> Result<()> {
    save_images(&[levels], ImageKind::Plain, template)
}

/// Write every level of every image (faces or layers of a texture of
/// `kind`) to its own PNG, atomically as a set.
fn save_images(images: &[&[Texture]], kind: ImageKind, template: &Path) -> Result<()> {
    let mut staged = Vec::new();
    for (i, levels) in images.iter().enumerate() {
        let template = image_template(template, kind, i);
        for (k, l) in levels.iter().enumerate() {
            staged.push(atomic::stage(&level_path(&template, k), |w| {
                write_png(l, w)
            })?);
        }
    }
    for s in staged {
        s.commit()?;
    }
    Ok(())
}

/// What [`remove_stale`] did with level files past the new chain.
#[derive(Debug, Default, PartialEq, Eq)]
pub struct Stale {
    /// Files parvo had written (their `Software` text says so), removed.
    pub removed: Vec<PathBuf>,
    /// Files of the template's names that parvo did not write, left alone.
    pub foreign: Vec<PathBuf>,
}

/// After writing `count` levels to `template`, remove the levels `count`,
/// `count + 1`, ... that an earlier, longer chain left behind, but only
/// files whose PNG `Software` text names parvo; other files of those names
/// are kept and listed.
pub fn remove_stale(template: &Path, count: usize) -> Result<Stale> {
    let mut out = Stale::default();
    for k in count..64 {
        let p = level_path(template, k);
        if !p.is_file() {
            continue;
        }
        let ours = std::fs::File::open(&p)
            .ok()
            .and_then(|f| {
                png::Decoder::new(std::io::BufReader::new(f))
                    .read_info()
                    .ok()
            })
            .is_some_and(|r| {
                r.info()
                    .uncompressed_latin1_text
                    .iter()
                    .any(|t| t.keyword == "Software" && t.text.starts_with("parvo "))
            });
        if ours {
            std::fs::remove_file(&p).map_err(|e| Error::Io {
                path: p.clone(),
                action: "cannot remove a stale level".into(),
                error: e,
            })?;
            out.removed.push(p);
        } else {
            out.foreign.push(p);
        }
    }
    Ok(out)
}

/// One PNG per level in the container table (write only; PNG files are
/// read by [`super::image_codecs`]): u8 or u16, straight alpha as PNG
/// defines it, sizes rounded down or up, no fingerprint.
pub struct PngLevels;

impl super::Container for PngLevels {
    fn id(&self) -> &'static str {
        "png"
    }
    fn name(&self) -> &'static str {
        "PNG"
    }
    fn tag(&self) -> &'static str {
        "PngLevels"
    }
    fn summary(&self) -> &'static str {
        "One PNG per level (`NAME_{level}.png`)"
    }
    fn stores(&self) -> Option<super::Stores> {
        Some(super::Stores {
            integer: true,
            round_up: true,
            file_per_level: true,
            alpha: Some(crate::texel::AlphaMode::Straight),
            ..super::Stores::NOTHING
        })
    }
    fn output_hint(&self) -> String {
        "a name with {level} for one PNG per level".into()
    }
    fn holds(&self, kind: ImageKind) -> bool {
        matches!(
            kind,
            ImageKind::Plain | ImageKind::LatLong | ImageKind::Cube | ImageKind::Array { .. }
        )
    }
    fn check_path(&self, path: &Path, kind: ImageKind) -> Result<()> {
        match placeholder(kind) {
            Some(p) if !path.to_string_lossy().contains(p) => Err(Error::InvalidOption(format!(
                "the name needs {p} as well as {{level}} for one PNG per level of a {} (e.g. \
                 `sky_{p}_{{level}}.png`{})",
                kind.describe(),
                if kind == ImageKind::Cube {
                    ": {face} becomes px nx py ny pz nz"
                } else {
                    ""
                }
            ))),
            _ => Ok(()),
        }
    }
    fn batch_path(&self, dir: &Path, stem: &str) -> PathBuf {
        dir.join(format!("{stem}_{{level}}.png"))
    }
    fn default_type(&self, src: crate::texel::ChannelType) -> crate::texel::ChannelType {
        use crate::texel::ChannelType::{U8, U16};
        if src == U8 { U8 } else { U16 }
    }
    fn data_type(&self, main: crate::texel::ChannelType) -> crate::texel::ChannelType {
        use crate::texel::ChannelType::{U8, U16};
        if main == U16 { U16 } else { U8 }
    }
    fn save(
        &self,
        images: &[&[Texture]],
        kind: ImageKind,
        _rounding: crate::mip::Rounding,
        path: &Path,
        _options: &super::SaveOptions,
    ) -> Result<()> {
        save_images(images, kind, path)
    }
}
