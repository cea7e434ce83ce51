//! DDS (DirectDraw Surface) with a DX10 header and the full mip chain, via
//! the `ddsfile` crate; uncompressed DXGI formats matching the data.
//!
//! DXGI has no 3-channel 8/16-bit or half formats and sRGB only for RGBA8,
//! so [`storable`] says how data must be widened first (RGB gains an
//! opaque alpha, sRGB grey becomes sRGB RGBA, other sRGB data is stored
//! linear).

use std::path::Path;

use ddsfile::{AlphaMode as DdsAlpha, D3D10ResourceDimension, Dds, DxgiFormat, NewDxgiParams};

use super::{FileFormat, Limits, Loaded, SourceInfo, atomic};
use crate::error::{Error, Result};
use crate::texel::{AlphaMode, ChannelType, ColorSpace, Format};
use crate::texture::Texture;

fn encode_err(reason: impl std::fmt::Display) -> Error {
    Error::Encode {
        format: "DDS",
        reason: reason.to_string(),
    }
}

fn decode_err(reason: impl std::fmt::Display) -> Error {
    Error::Decode {
        format: "DDS",
        reason: reason.to_string(),
    }
}

const TABLE: [(DxgiFormat, u8, ChannelType, ColorSpace); 14] = {
    use ChannelType::*;
    use ColorSpace::*;
    [
        (DxgiFormat::R8_UNorm, 1, U8, Linear),
        (DxgiFormat::R8G8_UNorm, 2, U8, Linear),
        (DxgiFormat::R8G8B8A8_UNorm, 4, U8, Linear),
        (DxgiFormat::R8G8B8A8_UNorm_sRGB, 4, U8, Srgb),
        (DxgiFormat::R16_UNorm, 1, U16, Linear),
        (DxgiFormat::R16G16_UNorm, 2, U16, Linear),
        (DxgiFormat::R16G16B16A16_UNorm, 4, U16, Linear),
        (DxgiFormat::R16_Float, 1, F16, Linear),
        (DxgiFormat::R16G16_Float, 2, F16, Linear),
        (DxgiFormat::R16G16B16A16_Float, 4, F16, Linear),
        (DxgiFormat::R32_Float, 1, F32, Linear),
        (DxgiFormat::R32G32_Float, 2, F32, Linear),
        (DxgiFormat::R32G32B32_Float, 3, F32, Linear),
        (DxgiFormat::R32G32B32A32_Float, 4, F32, Linear),
    ]
};

/// The DXGI format for a texel format, if there is one.
pub fn dxgi_format(f: &Format) -> Option<DxgiFormat> {
    TABLE
        .iter()
        .find(|(_, c, t, s)| *c == f.channels && *t == f.channel_type && *s == f.color_space)
        .map(|e| e.0)
}

/// The closest format DDS can store `f` in (see the module docs).
pub fn storable(f: Format) -> Format {
    let mut out = f;
    if f.color_space == ColorSpace::Srgb && f.channel_type != ChannelType::U8 {
        out.color_space = ColorSpace::Linear;
    }
    if out.channels == 3 && out.channel_type != ChannelType::F32 {
        out.channels = 4;
    }
    if out.color_space == ColorSpace::Srgb && out.channels < 4 {
        out.channels = 4;
    }
    out
}

/// Write `levels` (level 0 first, rounding down) as a DDS file atomically.
pub fn save(levels: &[Texture], path: &Path) -> Result<()> {
    let first = &levels[0];
    let f = first.format();
    let format = dxgi_format(&f).ok_or_else(|| {
        encode_err(format!(
            "no DXGI format for {f} (convert it with dds::storable)"
        ))
    })?;
    let alpha_mode = match (f.has_alpha(), f.alpha) {
        (false, _) => DdsAlpha::Opaque,
        (true, AlphaMode::Straight) => DdsAlpha::Straight,
        (true, AlphaMode::Premultiplied) => DdsAlpha::PreMultiplied,
    };
    let mut dds = Dds::new_dxgi(NewDxgiParams {
        height: first.height(),
        width: first.width(),
        depth: None,
        format,
        mipmap_levels: Some(levels.len() as u32),
        array_layers: None,
        caps2: None,
        is_cubemap: false,
        resource_dimension: D3D10ResourceDimension::Texture2D,
        alpha_mode,
    })
    .map_err(encode_err)?;
    let total: usize = levels.iter().map(|l| l.byte_len()).sum();
    if dds.data.len() != total {
        return Err(encode_err(format!(
            "ddsfile expects {} bytes for the chain, the levels hold {total}",
            dds.data.len()
        )));
    }
    let mut at = 0;
    for l in levels {
        let b = super::le_bytes(l.texels());
        dds.data[at..at + b.len()].copy_from_slice(&b);
        at += b.len();
    }
    atomic::write(path, |w| dds.write(w).map_err(encode_err))
}

/// Load a DDS file with a DX10 header in one of the formats of [`save`]:
/// every mip level of array layer 0.
pub fn load(path: &Path, limits: &Limits) -> Result<Loaded> {
    let len = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
    if len > limits.max_alloc {
        return Err(Error::Limits(format!(
            "file is {} MiB, more than the {} MiB allowed (raise with --max-alloc)",
            len >> 20,
            limits.max_alloc >> 20
        )));
    }
    let file = std::fs::File::open(path).map_err(|e| Error::Io {
        path: path.to_path_buf(),
        action: "cannot open".into(),
        error: e,
    })?;
    let (w, h) = {
        // Check the declared size before ddsfile allocates the data.
        let mut head = [0u8; 20];
        use std::io::Read;
        (&file).read_exact(&mut head).map_err(decode_err)?;
        let h = u32::from_le_bytes([head[12], head[13], head[14], head[15]]);
        let w = u32::from_le_bytes([head[16], head[17], head[18], head[19]]);
        (w, h)
    };
    limits.check(w as u64, h as u64, len.saturating_mul(2))?;
    let file = std::fs::File::open(path).map_err(|e| Error::Io {
        path: path.to_path_buf(),
        action: "cannot open".into(),
        error: e,
    })?;
    let dds = Dds::read(std::io::BufReader::new(file)).map_err(decode_err)?;
    let dxgi = dds
        .get_dxgi_format()
        .ok_or_else(|| decode_err("only DDS files with a DX10 header are supported"))?;
    let (_, ch, ty, cs) = *TABLE.iter().find(|e| e.0 == dxgi).ok_or_else(|| {
        decode_err(format!(
            "DXGI format {dxgi:?} is not an uncompressed format parvo reads"
        ))
    })?;
    let mut format = Format::new(ch, ty, cs);
    if dds
        .header10
        .as_ref()
        .is_some_and(|h| h.alpha_mode == DdsAlpha::PreMultiplied)
    {
        format = format.with_alpha(AlphaMode::Premultiplied);
    }
    let (w, h) = (dds.get_width(), dds.get_height());
    let n = dds.get_num_mipmap_levels().max(1);
    let data = dds.get_data(0).map_err(decode_err)?;
    let mut levels = Vec::new();
    let mut at = 0usize;
    for k in 0..n.min(crate::mip::level_count(
        w.max(1),
        h.max(1),
        crate::mip::Rounding::Down,
        None,
    )) {
        let (lw, lh) = crate::mip::level_size(w, h, k, crate::mip::Rounding::Down);
        let need = lw as usize * lh as usize * format.texel_bytes();
        let bytes = data
            .get(at..at + need)
            .ok_or_else(|| decode_err(format!("file ends inside level {k}")))?;
        levels.push(Texture::from_texels(
            lw,
            lh,
            format,
            super::texels_from_le(ty, bytes),
        )?);
        at += need;
    }
    let mut info = SourceInfo::new(FileFormat::Dds, ch);
    info.own_mips = levels.len() > 1;
    info.attributes = vec![("dxgiFormat".into(), format!("{dxgi:?}"))];
    info.channel_names = ["R", "G", "B", "A"][..ch as usize]
        .iter()
        .map(|s| s.to_string())
        .collect();
    Ok(Loaded { levels, info })
}
