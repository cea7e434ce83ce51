//! Writing DDS: the header each format gets (see the parent's table),
//! texels and blocks, cube maps and arrays.

use super::*;

/// The closest format DDS can store `f` in without widening: sRGB is kept
/// only for 8-bit data (DXGI has no other uncompressed sRGB format), so
/// sRGB u16 and float data are converted to linear values first.
pub fn storable(f: Format) -> Format {
    let mut out = f;
    if f.color_space == ColorSpace::Srgb && f.channel_type != ChannelType::U8 {
        out.color_space = ColorSpace::Linear;
    }
    out
}

/// The stored layout of `f` (see the module docs), or `None` for formats
/// [`storable`] would change (sRGB u16 and floats).
pub fn layout(f: &Format) -> Option<Layout> {
    use ChannelType::*;
    use alpha_mode::*;
    let srgb = f.color_space == ColorSpace::Srgb;
    if srgb && f.channel_type != U8 {
        return None;
    }
    let alpha = match (f.has_alpha(), f.alpha) {
        (true, AlphaMode::Premultiplied) => PREMULTIPLIED,
        (true, _) => STRAIGHT,
        (false, _) if f.channels == 4 => CUSTOM,
        (false, _) => OPAQUE,
    };
    let dx = |dxgi: u32, stored: u8, name: &'static str, mode: u32| Layout {
        pixel_format: fourcc_only(DX10),
        dx10: Some((dxgi, mode)),
        stored_channels: stored,
        name,
    };
    let leg = |pf: PixelFormat, stored: u8, name: &'static str| Layout {
        pixel_format: pf,
        dx10: None,
        stored_channels: stored,
        name,
    };
    let straight = alpha == STRAIGHT;
    Some(match (f.channel_type, f.channels, srgb) {
        (U8, _, true) => dx(29, 4, "R8G8B8A8_UNORM_SRGB", alpha),
        (U8, 1, _) => leg(legacy(ddpf::LUMINANCE, 8, [0xff, 0, 0, 0]), 1, "L8"),
        (U8, 2, _) if straight => leg(
            legacy(
                ddpf::LUMINANCE | ddpf::ALPHAPIXELS,
                16,
                [0xff, 0, 0, 0xff00],
            ),
            2,
            "A8L8",
        ),
        (U8, 2, _) => dx(49, 2, "R8G8_UNORM", alpha),
        (U8, 3, _) => leg(
            legacy(ddpf::RGB, 32, [0xff, 0xff00, 0xff_0000, 0]),
            4,
            "X8B8G8R8",
        ),
        (U8, _, _) if straight => leg(
            legacy(
                ddpf::RGB | ddpf::ALPHAPIXELS,
                32,
                [0xff, 0xff00, 0xff_0000, 0xff00_0000],
            ),
            4,
            "A8B8G8R8",
        ),
        (U8, _, _) => dx(28, 4, "R8G8B8A8_UNORM", alpha),
        (U16, 1, _) => leg(legacy(ddpf::LUMINANCE, 16, [0xffff, 0, 0, 0]), 1, "L16"),
        (U16, 2, _) if alpha == OPAQUE => leg(
            legacy(ddpf::RGB, 32, [0xffff, 0xffff_0000, 0, 0]),
            2,
            "G16R16",
        ),
        (U16, 2, _) => dx(35, 2, "R16G16_UNORM", alpha),
        (U16, 3, _) => dx(11, 4, "R16G16B16A16_UNORM", alpha),
        (U16, _, _) if straight => leg(fourcc_only(36), 4, "A16B16G16R16"),
        (U16, _, _) => dx(11, 4, "R16G16B16A16_UNORM", alpha),
        (F16, 1, _) => dx(54, 1, "R16_FLOAT", alpha),
        (F16, 2, _) => dx(34, 2, "R16G16_FLOAT", alpha),
        (F16, _, _) => dx(10, 4, "R16G16B16A16_FLOAT", alpha),
        (F32, 1, _) => dx(41, 1, "R32_FLOAT", alpha),
        (F32, 2, _) => dx(16, 2, "R32G32_FLOAT", alpha),
        (F32, 3, _) => dx(6, 3, "R32G32B32_FLOAT", alpha),
        (F32, _, _) => dx(2, 4, "R32G32B32A32_FLOAT", alpha),
    })
}

/// The header parvo writes for `levels` (level 0 first, rounding down).
pub fn header_for(levels: &[Texture]) -> Result<(Header, Layout)> {
    let first = levels
        .first()
        .ok_or_else(|| encode_err("nothing to write: no levels"))?;
    let f = first.format();
    let lay = layout(&f).ok_or_else(|| {
        encode_err(format!(
            "DDS has no format for {f} (convert it with dds::storable)"
        ))
    })?;
    let (w, h) = (first.width(), first.height());
    let n = levels.len() as u32;
    let full = crate::mip::level_count(w, h, crate::mip::Rounding::Down, None);
    if n > full {
        return Err(encode_err(format!(
            "{n} levels, a {w}x{h} chain has {full}"
        )));
    }
    for (k, l) in levels.iter().enumerate() {
        let want = crate::mip::level_size(w, h, k as u32, crate::mip::Rounding::Down);
        if (l.width(), l.height()) != want {
            return Err(encode_err(format!(
                "level {k} is {}x{}; DDS level sizes round down, so it must be {}x{}",
                l.width(),
                l.height(),
                want.0,
                want.1
            )));
        }
    }
    let texel = lay.stored_channels as u64 * f.channel_type.bytes() as u64;
    let pitch = u32::try_from(w as u64 * texel)
        .map_err(|_| encode_err(format!("a row of {w} texels is too long for DDS")))?;
    let header = Header {
        flags: ddsd::CAPS
            | ddsd::HEIGHT
            | ddsd::WIDTH
            | ddsd::PITCH
            | ddsd::PIXELFORMAT
            | ddsd::MIPMAPCOUNT,
        height: h,
        width: w,
        pitch_or_linear_size: pitch,
        depth: 0,
        mip_map_count: n,
        pixel_format: lay.pixel_format,
        caps: caps::TEXTURE
            | if n > 1 {
                caps::COMPLEX | caps::MIPMAP
            } else {
                0
            },
        caps2: 0,
        dx10: lay.dx10.map(|(dxgi, mode)| Dx10 {
            dxgi_format: dxgi,
            resource_dimension: D3D10_RESOURCE_DIMENSION_TEXTURE2D,
            misc_flag: 0,
            array_size: 1,
            misc_flags2: mode,
        }),
    };
    Ok((header, lay))
}

/// Serialise `levels` (level 0 first, sizes rounding down) as DDS bytes.
pub fn write_to(levels: &[Texture], out: &mut impl Write) -> Result<()> {
    let (header, lay) = header_for(levels)?;
    out.write_all(&header.to_bytes()).map_err(encode_err)?;
    write_levels(levels, &lay, out)
}

/// The DXGI format of a layout written with a legacy header, for the
/// DX10 header an array needs (`None` for luminance + alpha, which DXGI
/// has no format for).
pub(super) fn dx10_of_legacy(lay: &Layout) -> Option<(u32, u32)> {
    use alpha_mode::*;
    Some(match lay.name {
        "L8" => (61, OPAQUE),
        "X8B8G8R8" => (28, OPAQUE),
        "A8B8G8R8" => (28, STRAIGHT),
        "L16" => (56, OPAQUE),
        "G16R16" => (35, OPAQUE),
        "A16B16G16R16" => (11, STRAIGHT),
        _ => return None,
    })
}

/// The caps of an image of `kind` set in `header` (complex; the cube
/// flags of a cube map), and its DX10 `arraySize` (cubes or layers);
/// `None` for one 2-D image, whose header stays as it is.
pub(super) fn mark_images(header: &mut Header, kind: ImageKind) -> Option<u32> {
    let count = match kind {
        ImageKind::Plain | ImageKind::LatLong => return None,
        ImageKind::Cube => 1,
        ImageKind::CubeArray { cubes } => cubes,
        ImageKind::Array { layers } => layers,
    };
    header.caps |= caps::COMPLEX;
    if kind.is_cube() {
        header.caps2 = caps::CUBEMAP | caps::ALL_FACES;
    }
    Some(count)
}

/// The header of a cube map, an array or a cube-map array of `kind`
/// whose images each hold `levels`' sizes and format: the legacy cube
/// flags for one cube map, a DX10 header with `arraySize` for arrays.
pub fn header_for_images(levels: &[Texture], kind: ImageKind) -> Result<(Header, Layout)> {
    let (mut header, mut lay) = header_for(levels)?;
    let Some(count) = mark_images(&mut header, kind) else {
        return Ok((header, lay));
    };
    if count > 1 && header.dx10.is_none() {
        let (dxgi, mode) = dx10_of_legacy(&lay).ok_or_else(|| {
            encode_err(format!(
                "a DDS array needs a DX10 format and DXGI has none for {} (write it to KTX2)",
                lay.name
            ))
        })?;
        header.pixel_format = fourcc_only(DX10);
        header.dx10 = Some(Dx10 {
            dxgi_format: dxgi,
            resource_dimension: D3D10_RESOURCE_DIMENSION_TEXTURE2D,
            misc_flag: 0,
            array_size: 1,
            misc_flags2: mode,
        });
        lay.dx10 = Some((dxgi, mode));
    }
    if let Some(d) = &mut header.dx10 {
        d.array_size = count;
        if kind.is_cube() {
            d.misc_flag |= D3D11_RESOURCE_MISC_TEXTURECUBE;
        }
    }
    Ok((header, lay))
}

/// Serialise a cube map or an array (`images` in
/// [`crate::io::Loaded::images`]'s order, each its levels) as DDS bytes:
/// image after image, each with all its levels.
pub fn write_images_to(images: &[&[Texture]], kind: ImageKind, out: &mut impl Write) -> Result<()> {
    let first = images
        .first()
        .ok_or_else(|| encode_err("nothing to write: no images"))?;
    let (header, lay) = header_for_images(first, kind)?;
    out.write_all(&header.to_bytes()).map_err(encode_err)?;
    for levels in images {
        write_levels(levels, &lay, out)?;
    }
    Ok(())
}

/// Write a cube map or an array atomically (see [`write_images_to`]).
pub fn save_images(images: &[&[Texture]], kind: ImageKind, path: &Path) -> Result<()> {
    if let Some(first) = images.first() {
        header_for_images(first, kind)?;
    }
    atomic::write(path, |w| write_images_to(images, kind, w))
}

/// One image's levels in `lay`'s stored channels.
pub(super) fn write_levels(levels: &[Texture], lay: &Layout, out: &mut impl Write) -> Result<()> {
    let io = |e: std::io::Error| encode_err(e);
    for l in levels {
        if lay.stored_channels as usize == l.channels() {
            out.write_all(&crate::io::le_bytes(l.texels()))
                .map_err(io)?;
        } else {
            let wide = l.expand_channels(lay.stored_channels)?;
            out.write_all(&crate::io::le_bytes(wide.texels()))
                .map_err(io)?;
        }
    }
    Ok(())
}

/// Write `levels` (level 0 first, rounding down) as a DDS file atomically.
pub fn save(levels: &[Texture], path: &Path) -> Result<()> {
    header_for(levels)?;
    atomic::write(path, |w| write_to(levels, w))
}

/// The DXGI format of a block format (`_UNORM_SRGB` when `srgb`).
pub fn dxgi_block_format(f: BlockFormat, srgb: bool) -> u32 {
    let s = u32::from(srgb);
    match f {
        BlockFormat::Bc1 => 71 + s,
        BlockFormat::Bc2 => 74 + s,
        BlockFormat::Bc3 => 77 + s,
        BlockFormat::Bc4 { signed } => 80 + u32::from(signed),
        BlockFormat::Bc5 { signed } => 83 + u32::from(signed),
        BlockFormat::Bc6h { signed } => 95 + u32::from(signed),
        BlockFormat::Bc7 => 98 + s,
    }
}

/// The header parvo writes for a block-compressed chain: the DX10
/// extension with the block format's DXGI number and alpha mode,
/// `DDSD_LINEARSIZE` with level 0's byte size (DirectXTex's layout for
/// compressed textures).
pub fn header_for_blocks(chain: &BlockChain) -> Result<Header> {
    chain.validate()?;
    let n = chain.levels.len() as u32;
    let full = crate::mip::level_count(chain.width, chain.height, crate::mip::Rounding::Down, None);
    if n > full {
        return Err(encode_err(format!(
            "{n} levels, a {}x{} chain has {full}",
            chain.width, chain.height
        )));
    }
    let linear = u32::try_from(chain.levels[0].len())
        .map_err(|_| encode_err("level 0 is too large for a DDS header (4 GiB)"))?;
    let mode = match chain.alpha {
        AlphaMode::Premultiplied => alpha_mode::PREMULTIPLIED,
        AlphaMode::Straight => alpha_mode::STRAIGHT,
        AlphaMode::None => alpha_mode::OPAQUE,
    };
    Ok(Header {
        flags: ddsd::CAPS
            | ddsd::HEIGHT
            | ddsd::WIDTH
            | ddsd::LINEARSIZE
            | ddsd::PIXELFORMAT
            | ddsd::MIPMAPCOUNT,
        height: chain.height,
        width: chain.width,
        pitch_or_linear_size: linear,
        depth: 0,
        mip_map_count: n,
        pixel_format: fourcc_only(DX10),
        caps: caps::TEXTURE
            | if n > 1 {
                caps::COMPLEX | caps::MIPMAP
            } else {
                0
            },
        caps2: 0,
        dx10: Some(Dx10 {
            dxgi_format: dxgi_block_format(chain.format, chain.srgb),
            resource_dimension: D3D10_RESOURCE_DIMENSION_TEXTURE2D,
            misc_flag: 0,
            array_size: 1,
            misc_flags2: mode,
        }),
    })
}

/// Serialise a block-compressed chain as DDS bytes.
pub fn write_blocks_to(chain: &BlockChain, out: &mut impl Write) -> Result<()> {
    write_block_images_to(std::slice::from_ref(chain), ImageKind::Plain, out)
}

/// The header of block-compressed chains of an image of `kind` (one chain
/// per face or layer): [`header_for_blocks`] with the cube flags and the
/// DX10 `arraySize` (cubes or layers).
pub fn header_for_block_images(chains: &[BlockChain], kind: ImageKind) -> Result<Header> {
    let first = chains
        .first()
        .ok_or_else(|| encode_err("nothing to write: no images"))?;
    let mut header = header_for_blocks(first)?;
    let Some(count) = mark_images(&mut header, kind) else {
        return Ok(header);
    };
    if let Some(d) = &mut header.dx10 {
        d.array_size = count;
        if kind.is_cube() {
            d.misc_flag |= D3D11_RESOURCE_MISC_TEXTURECUBE;
        }
    }
    Ok(header)
}

/// Serialise block-compressed chains of an image of `kind` as DDS bytes:
/// image after image, each with all its levels (as
/// [`write_images_to`] orders uncompressed ones).
pub fn write_block_images_to(
    chains: &[BlockChain],
    kind: ImageKind,
    out: &mut impl Write,
) -> Result<()> {
    let header = header_for_block_images(chains, kind)?;
    let io = |e: std::io::Error| encode_err(e);
    out.write_all(&header.to_bytes()).map_err(io)?;
    for chain in chains {
        for l in &chain.levels {
            out.write_all(l).map_err(io)?;
        }
    }
    Ok(())
}

/// Write a block-compressed chain as a DDS file atomically.
pub fn save_blocks(chain: &BlockChain, path: &Path) -> Result<()> {
    save_block_images(std::slice::from_ref(chain), ImageKind::Plain, path)
}

/// Write block-compressed chains of an image of `kind` as a DDS file
/// atomically (see [`write_block_images_to`]).
pub fn save_block_images(chains: &[BlockChain], kind: ImageKind, path: &Path) -> Result<()> {
    header_for_block_images(chains, kind)?;
    atomic::write(path, |w| write_block_images_to(chains, kind, w))
}
