//! Writing KTX2: texels and blocks of every image kind, the level index,
//! DFD and key/value data, levels supercompressed on all threads.

use super::*;

/// Serialise `levels` (level 0 first, sizes rounding down) as KTX2 bytes
/// written to `out`.
pub fn write_to(levels: &[Texture], opts: &SaveOptions, out: &mut impl Write) -> Result<()> {
    write_images_to(&[levels], ImageKind::Plain, opts, out)
}

/// The header's layer and face counts for `kind` holding `images` 2-D
/// images (KTX 2.0 section 3.4), or why it cannot.
pub(super) fn layer_face_counts(kind: ImageKind, images: usize) -> Result<(u32, u32)> {
    if kind.images() != images {
        return Err(encode_err(format!(
            "a {} holds {} images, got {images}",
            kind.describe(),
            kind.images()
        )));
    }
    Ok(match kind {
        ImageKind::Plain | ImageKind::LatLong => (0, 1),
        ImageKind::Array { layers } => (layers, 1),
        ImageKind::Cube => (0, 6),
        ImageKind::CubeArray { cubes } => (cubes, 6),
    })
}

/// Serialise a cube map, an array or a 2-D texture of `kind`: `images`
/// holds each face or layer's levels (level 0 first, sizes rounding
/// down, every image the same size, format and level count), in the
/// order of [`crate::io::Loaded::images`]; each KTX2 level holds level k of
/// every image, one after the other.
pub fn write_images_to(
    images: &[&[Texture]],
    kind: ImageKind,
    opts: &SaveOptions,
    out: &mut impl Write,
) -> Result<()> {
    let (layers, faces) = layer_face_counts(kind, images.len())?;
    let levels = *images
        .first()
        .ok_or_else(|| encode_err("nothing to write: no images"))?;
    let first = levels
        .first()
        .ok_or_else(|| encode_err("nothing to write: no levels"))?;
    for (i, image) in images.iter().enumerate() {
        let same = image.len() == levels.len()
            && image.iter().zip(levels).all(|(a, b)| {
                (a.width(), a.height(), a.format()) == (b.width(), b.height(), b.format())
            });
        if !same {
            return Err(encode_err(format!(
                "image {i} of the {} differs from the first in size, format or level count",
                kind.describe()
            )));
        }
    }
    if faces == 6 && first.width() != first.height() {
        return Err(encode_err(format!(
            "a cube map's faces must be square, got {}x{}",
            first.width(),
            first.height()
        )));
    }
    let f = first.format();
    let vk = vk_format(&f).ok_or_else(|| {
        encode_err(format!(
            "Vulkan has no format for {f} (convert the levels to ktx2::storable's format first)"
        ))
    })?;
    let desc = Desc {
        vk,
        type_size: f.channel_type.bytes() as u32,
        dfd: dfd(&f),
        block_bytes: f.texel_bytes() as u64,
    };
    let payloads: Vec<std::borrow::Cow<[u8]>> = if images.len() == 1 {
        levels
            .iter()
            .map(|l| crate::io::le_bytes(l.texels()))
            .collect()
    } else {
        (0..levels.len())
            .map(|k| {
                let mut level = Vec::new();
                for image in images {
                    level.extend_from_slice(&crate::io::le_bytes(image[k].texels()));
                }
                std::borrow::Cow::Owned(level)
            })
            .collect()
    };
    let shape = Shape {
        width: first.width(),
        height: first.height(),
        layers,
        faces,
    };
    write_payloads(shape, &desc, &payloads, opts, out)
}

/// The header's image dimensions.
pub(super) struct Shape {
    width: u32,
    height: u32,
    /// `layerCount` (0: not an array).
    layers: u32,
    /// `faceCount` (6 for a cube map).
    faces: u32,
}

/// Serialise a block-compressed chain as KTX2 bytes written to `out`.
pub fn write_blocks_to(chain: &BlockChain, opts: &SaveOptions, out: &mut impl Write) -> Result<()> {
    write_block_images_to(std::slice::from_ref(chain), ImageKind::Plain, opts, out)
}

/// Serialise block-compressed chains of an image of `kind` (one chain per
/// face or layer, in [`crate::io::Loaded::images`]'s order, all of one format,
/// size and level count) as KTX2 bytes: each KTX2 level holds level k of
/// every image, one after the other.
pub fn write_block_images_to(
    chains: &[BlockChain],
    kind: ImageKind,
    opts: &SaveOptions,
    out: &mut impl Write,
) -> Result<()> {
    let (layers, faces) = layer_face_counts(kind, chains.len())?;
    let chain = &chains[0];
    for c in chains {
        c.validate()?;
        if (c.format, c.srgb, c.alpha, c.width, c.height, c.levels.len())
            != (
                chain.format,
                chain.srgb,
                chain.alpha,
                chain.width,
                chain.height,
                chain.levels.len(),
            )
        {
            return Err(encode_err(format!(
                "the images of the {} differ in size, format or level count",
                kind.describe()
            )));
        }
    }
    let alpha = chain.alpha != AlphaMode::None;
    let desc = Desc {
        vk: vk_block_format(chain.format, chain.srgb, alpha),
        // Block-compressed formats have typeSize 1 (KTX 2.0 section 3.2).
        type_size: 1,
        dfd: dfd_block(
            chain.format,
            chain.srgb,
            chain.alpha == AlphaMode::Premultiplied,
            alpha,
        ),
        block_bytes: chain.format.block_bytes() as u64,
    };
    let payloads: Vec<std::borrow::Cow<[u8]>> = if chains.len() == 1 {
        chain
            .levels
            .iter()
            .map(|l| std::borrow::Cow::Borrowed(l.as_slice()))
            .collect()
    } else {
        (0..chain.levels.len())
            .map(|k| {
                std::borrow::Cow::Owned(
                    chains
                        .iter()
                        .flat_map(|c| c.levels[k].iter().copied())
                        .collect(),
                )
            })
            .collect()
    };
    let shape = Shape {
        width: chain.width,
        height: chain.height,
        layers,
        faces,
    };
    write_payloads(shape, &desc, &payloads, opts, out)
}

/// The container around the levels' bytes: header, level index, DFD,
/// key/value data, then the levels smallest first, supercompressed (on
/// all threads) when `opts` asks.
pub(super) fn write_payloads(
    shape: Shape,
    desc: &Desc,
    payloads: &[std::borrow::Cow<[u8]>],
    opts: &SaveOptions,
    out: &mut impl Write,
) -> Result<()> {
    use rayon::prelude::*;
    let n = payloads.len() as u64;
    // A 1-D texture has pixelHeight 0 and a one-letter orientation (KTX
    // 2.0 sections 3.4 and 5.4).
    let one_d = opts.one_d && shape.height == 1;
    let mut kv = Vec::new();
    let mut entries: Vec<(String, String)> = vec![
        (
            "KTXorientation".into(),
            if one_d { "r" } else { "rd" }.into(),
        ),
        (
            "KTXwriter".into(),
            concat!("parvo ", env!("CARGO_PKG_VERSION")).into(),
        ),
        (
            "parvo:wrapmodes".into(),
            format!("{},{}", opts.wrap.u.oiio_name(), opts.wrap.v.oiio_name()),
        ),
    ];
    if let Some(fp) = &opts.fingerprint {
        entries.push((FINGERPRINT_KEY.into(), fp.clone()));
    }
    entries.extend(opts.attributes.iter().cloned());
    entries.sort();
    entries.dedup_by(|a, b| a.0 == b.0);
    for (k, v) in &entries {
        kv.extend(kv_entry(k, v));
    }
    // Supercompressed levels: compressed in parallel, written in order.
    let packed: Option<Vec<Vec<u8>>> = match opts.ktx2.supercompression {
        Some(sc) => Some(
            payloads
                .par_iter()
                .map(|p| sc.compress(p))
                .collect::<Result<Vec<_>>>()?,
        ),
        None => None,
    };
    let stored: Vec<&[u8]> = match &packed {
        Some(v) => v.iter().map(|x| x.as_slice()).collect(),
        None => payloads.iter().map(|p| p.as_ref()).collect(),
    };
    let level_index_at = 80u64;
    let dfd_at = level_index_at + 24 * n;
    let kvd_at = dfd_at + desc.dfd.len() as u64;
    // Section 3.10: levels are aligned to lcm(texel block size, 4), or to
    // 1 byte when supercompressed.
    let align = if packed.is_some() {
        1
    } else {
        lcm(desc.block_bytes, 4)
    };
    let mut at = (kvd_at + kv.len() as u64).next_multiple_of(align);
    let data_start = at;
    // Offsets, smallest level first in the file.
    let mut offsets = vec![0u64; payloads.len()];
    for k in (0..payloads.len()).rev() {
        at = at.next_multiple_of(align);
        offsets[k] = at;
        at += stored[k].len() as u64;
    }
    let mut head = Vec::with_capacity(data_start as usize);
    head.extend_from_slice(&IDENTIFIER);
    for v in [
        desc.vk,
        desc.type_size,
        shape.width,
        if one_d { 0 } else { shape.height },
        0,
        shape.layers,
        shape.faces,
        n as u32,
        opts.ktx2.supercompression.map_or(0, |s| s.scheme()),
    ] {
        head.extend_from_slice(&v.to_le_bytes());
    }
    head.extend_from_slice(&(dfd_at as u32).to_le_bytes());
    head.extend_from_slice(&(desc.dfd.len() as u32).to_le_bytes());
    head.extend_from_slice(&(kvd_at as u32).to_le_bytes());
    head.extend_from_slice(&(kv.len() as u32).to_le_bytes());
    head.extend_from_slice(&0u64.to_le_bytes());
    head.extend_from_slice(&0u64.to_le_bytes());
    for k in 0..payloads.len() {
        for v in [offsets[k], stored[k].len() as u64, payloads[k].len() as u64] {
            head.extend_from_slice(&v.to_le_bytes());
        }
    }
    head.extend_from_slice(&desc.dfd);
    head.extend_from_slice(&kv);
    head.resize(data_start as usize, 0);
    let io = |e: std::io::Error| encode_err(e.to_string());
    out.write_all(&head).map_err(io)?;
    let mut pos = data_start;
    for k in (0..payloads.len()).rev() {
        let pad = (offsets[k] - pos) as usize;
        out.write_all(&vec![0u8; pad]).map_err(io)?;
        out.write_all(stored[k]).map_err(io)?;
        pos = offsets[k] + stored[k].len() as u64;
    }
    Ok(())
}

/// Write a block-compressed chain to a `.ktx2` file atomically.
pub fn save_blocks(chain: &BlockChain, path: &Path, opts: &SaveOptions) -> Result<()> {
    save_block_images(std::slice::from_ref(chain), ImageKind::Plain, path, opts)
}

/// Write block-compressed chains of an image of `kind` to a `.ktx2` file
/// atomically (see [`write_block_images_to`]).
pub fn save_block_images(
    chains: &[BlockChain],
    kind: ImageKind,
    path: &Path,
    opts: &SaveOptions,
) -> Result<()> {
    for c in chains {
        c.validate()?;
    }
    atomic::write(path, |w| write_block_images_to(chains, kind, opts, w))
}

/// Write `levels` to a `.ktx2` file atomically.
pub fn save(levels: &[Texture], path: &Path, opts: &SaveOptions) -> Result<()> {
    atomic::write(path, |w| write_to(levels, opts, w))
}

/// Write a cube map, an array or a 2-D texture (see [`write_images_to`])
/// to a `.ktx2` file atomically.
pub fn save_images(
    images: &[&[Texture]],
    kind: ImageKind,
    path: &Path,
    opts: &SaveOptions,
) -> Result<()> {
    atomic::write(path, |w| write_images_to(images, kind, opts, w))
}
