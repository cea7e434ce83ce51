//! Reading DDS: legacy, DX10 and D3DX headers, masked, packed and block-
//! compressed texels, and the refusals that name what a file holds.

use super::*;

/// How the texels of a DDS file are stored, as parsed from its header.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Stored {
    /// Uncompressed values of `format`, `texel` bytes each, read with the
    /// masks of a legacy header when `masks` is set.
    Plain {
        format: Format,
        bytes: usize,
        masks: Option<Masked>,
        swap_rb: bool,
        drop_alpha: bool,
    },
    /// Block-compressed.
    Blocks {
        format: BlockFormat,
        srgb: bool,
        alpha: AlphaMode,
    },
}

/// A legacy masked layout: per output channel the mask (0 = constant).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Masked {
    masks: [u32; 4],
    channels: usize,
}

/// The DXGI formats parvo reads (uncompressed): format number, channels,
/// type, sRGB, R/B swapped (BGRA), 4th channel padding (BGRX), name.
/// `TYPELESS` formats are read as UNORM.
pub(super) const DXGI_PLAIN: [(u32, u8, ChannelType, bool, bool, bool, &str); 27] = {
    use ChannelType::*;
    [
        (2, 4, F32, false, false, false, "R32G32B32A32_FLOAT"),
        (6, 3, F32, false, false, false, "R32G32B32_FLOAT"),
        (10, 4, F16, false, false, false, "R16G16B16A16_FLOAT"),
        (11, 4, U16, false, false, false, "R16G16B16A16_UNORM"),
        (9, 4, U16, false, false, false, "R16G16B16A16_TYPELESS"),
        (16, 2, F32, false, false, false, "R32G32_FLOAT"),
        (27, 4, U8, false, false, false, "R8G8B8A8_TYPELESS"),
        (28, 4, U8, false, false, false, "R8G8B8A8_UNORM"),
        (29, 4, U8, true, false, false, "R8G8B8A8_UNORM_SRGB"),
        (34, 2, F16, false, false, false, "R16G16_FLOAT"),
        (35, 2, U16, false, false, false, "R16G16_UNORM"),
        (33, 2, U16, false, false, false, "R16G16_TYPELESS"),
        (41, 1, F32, false, false, false, "R32_FLOAT"),
        (49, 2, U8, false, false, false, "R8G8_UNORM"),
        (48, 2, U8, false, false, false, "R8G8_TYPELESS"),
        (54, 1, F16, false, false, false, "R16_FLOAT"),
        (56, 1, U16, false, false, false, "R16_UNORM"),
        (53, 1, U16, false, false, false, "R16_TYPELESS"),
        (61, 1, U8, false, false, false, "R8_UNORM"),
        (60, 1, U8, false, false, false, "R8_TYPELESS"),
        (65, 1, U8, false, false, false, "A8_UNORM"),
        (87, 4, U8, false, true, false, "B8G8R8A8_UNORM"),
        (88, 4, U8, false, true, true, "B8G8R8X8_UNORM"),
        (90, 4, U8, false, true, false, "B8G8R8A8_TYPELESS"),
        (92, 4, U8, false, true, true, "B8G8R8X8_TYPELESS"),
        (91, 4, U8, true, true, false, "B8G8R8A8_UNORM_SRGB"),
        (93, 4, U8, true, true, true, "B8G8R8X8_UNORM_SRGB"),
    ]
};

/// Block formats in DX10 files: DXGI number, format, sRGB.
pub(super) const DXGI_BLOCKS: [(u32, BlockFormat, bool); 21] = {
    use BlockFormat::*;
    [
        (70, Bc1, false),
        (71, Bc1, false),
        (72, Bc1, true),
        (73, Bc2, false),
        (74, Bc2, false),
        (75, Bc2, true),
        (76, Bc3, false),
        (77, Bc3, false),
        (78, Bc3, true),
        (79, Bc4 { signed: false }, false),
        (80, Bc4 { signed: false }, false),
        (81, Bc4 { signed: true }, false),
        (82, Bc5 { signed: false }, false),
        (83, Bc5 { signed: false }, false),
        (84, Bc5 { signed: true }, false),
        (94, Bc6h { signed: false }, false),
        (95, Bc6h { signed: false }, false),
        (96, Bc6h { signed: true }, false),
        (97, Bc7, false),
        (98, Bc7, false),
        (99, Bc7, true),
    ]
};

/// Microsoft's `DXGI_FORMAT_*` enumerants without the prefix, by value
/// (every value DXGI defines; the gaps 116-129 and 133-188 are unused).
pub(super) const DXGI_NAMES: [(u32, &str); 121] = [
    (0, "UNKNOWN"),
    (1, "R32G32B32A32_TYPELESS"),
    (2, "R32G32B32A32_FLOAT"),
    (3, "R32G32B32A32_UINT"),
    (4, "R32G32B32A32_SINT"),
    (5, "R32G32B32_TYPELESS"),
    (6, "R32G32B32_FLOAT"),
    (7, "R32G32B32_UINT"),
    (8, "R32G32B32_SINT"),
    (9, "R16G16B16A16_TYPELESS"),
    (10, "R16G16B16A16_FLOAT"),
    (11, "R16G16B16A16_UNORM"),
    (12, "R16G16B16A16_UINT"),
    (13, "R16G16B16A16_SNORM"),
    (14, "R16G16B16A16_SINT"),
    (15, "R32G32_TYPELESS"),
    (16, "R32G32_FLOAT"),
    (17, "R32G32_UINT"),
    (18, "R32G32_SINT"),
    (19, "R32G8X24_TYPELESS"),
    (20, "D32_FLOAT_S8X24_UINT"),
    (21, "R32_FLOAT_X8X24_TYPELESS"),
    (22, "X32_TYPELESS_G8X24_UINT"),
    (23, "R10G10B10A2_TYPELESS"),
    (24, "R10G10B10A2_UNORM"),
    (25, "R10G10B10A2_UINT"),
    (26, "R11G11B10_FLOAT"),
    (27, "R8G8B8A8_TYPELESS"),
    (28, "R8G8B8A8_UNORM"),
    (29, "R8G8B8A8_UNORM_SRGB"),
    (30, "R8G8B8A8_UINT"),
    (31, "R8G8B8A8_SNORM"),
    (32, "R8G8B8A8_SINT"),
    (33, "R16G16_TYPELESS"),
    (34, "R16G16_FLOAT"),
    (35, "R16G16_UNORM"),
    (36, "R16G16_UINT"),
    (37, "R16G16_SNORM"),
    (38, "R16G16_SINT"),
    (39, "R32_TYPELESS"),
    (40, "D32_FLOAT"),
    (41, "R32_FLOAT"),
    (42, "R32_UINT"),
    (43, "R32_SINT"),
    (44, "R24G8_TYPELESS"),
    (45, "D24_UNORM_S8_UINT"),
    (46, "R24_UNORM_X8_TYPELESS"),
    (47, "X24_TYPELESS_G8_UINT"),
    (48, "R8G8_TYPELESS"),
    (49, "R8G8_UNORM"),
    (50, "R8G8_UINT"),
    (51, "R8G8_SNORM"),
    (52, "R8G8_SINT"),
    (53, "R16_TYPELESS"),
    (54, "R16_FLOAT"),
    (55, "D16_UNORM"),
    (56, "R16_UNORM"),
    (57, "R16_UINT"),
    (58, "R16_SNORM"),
    (59, "R16_SINT"),
    (60, "R8_TYPELESS"),
    (61, "R8_UNORM"),
    (62, "R8_UINT"),
    (63, "R8_SNORM"),
    (64, "R8_SINT"),
    (65, "A8_UNORM"),
    (66, "R1_UNORM"),
    (67, "R9G9B9E5_SHAREDEXP"),
    (68, "R8G8_B8G8_UNORM"),
    (69, "G8R8_G8B8_UNORM"),
    (70, "BC1_TYPELESS"),
    (71, "BC1_UNORM"),
    (72, "BC1_UNORM_SRGB"),
    (73, "BC2_TYPELESS"),
    (74, "BC2_UNORM"),
    (75, "BC2_UNORM_SRGB"),
    (76, "BC3_TYPELESS"),
    (77, "BC3_UNORM"),
    (78, "BC3_UNORM_SRGB"),
    (79, "BC4_TYPELESS"),
    (80, "BC4_UNORM"),
    (81, "BC4_SNORM"),
    (82, "BC5_TYPELESS"),
    (83, "BC5_UNORM"),
    (84, "BC5_SNORM"),
    (85, "B5G6R5_UNORM"),
    (86, "B5G5R5A1_UNORM"),
    (87, "B8G8R8A8_UNORM"),
    (88, "B8G8R8X8_UNORM"),
    (89, "R10G10B10_XR_BIAS_A2_UNORM"),
    (90, "B8G8R8A8_TYPELESS"),
    (91, "B8G8R8A8_UNORM_SRGB"),
    (92, "B8G8R8X8_TYPELESS"),
    (93, "B8G8R8X8_UNORM_SRGB"),
    (94, "BC6H_TYPELESS"),
    (95, "BC6H_UF16"),
    (96, "BC6H_SF16"),
    (97, "BC7_TYPELESS"),
    (98, "BC7_UNORM"),
    (99, "BC7_UNORM_SRGB"),
    (100, "AYUV"),
    (101, "Y410"),
    (102, "Y416"),
    (103, "NV12"),
    (104, "P010"),
    (105, "P016"),
    (106, "OPAQUE_420"),
    (107, "YUY2"),
    (108, "Y210"),
    (109, "Y216"),
    (110, "NV11"),
    (111, "AI44"),
    (112, "IA44"),
    (113, "P8"),
    (114, "A8P8"),
    (115, "B4G4R4A4_UNORM"),
    (130, "P208"),
    (131, "V208"),
    (132, "V408"),
    (189, "SAMPLER_FEEDBACK_MIN_MIP_OPAQUE"),
    (190, "SAMPLER_FEEDBACK_MIP_REGION_USED_OPAQUE"),
];

/// The name of a `DXGI_FORMAT` value (Microsoft's `DXGI_FORMAT_*`
/// enumerants without the prefix), `None` for values it does not define.
pub fn dxgi_name(v: u32) -> Option<&'static str> {
    DXGI_NAMES.iter().find(|e| e.0 == v).map(|e| e.1)
}

/// `NAME (n)`, or the number alone when DXGI defines no such format.
pub(super) fn dxgi_describe(v: u32) -> String {
    match dxgi_name(v) {
        Some(n) => format!("{n} ({v})"),
        None => format!("{v} (not a DXGI format)"),
    }
}

/// The meaning a `_TYPELESS` DXGI format is read with, as Pillow reads
/// them (OpenImageIO 3.2 refuses them): UNORM (`UF16` for BC6H), or `None`
/// when `v` is not typeless.
pub(super) fn typeless_reading(v: u32) -> Option<String> {
    let name = dxgi_name(v)?.strip_suffix("_TYPELESS")?;
    Some(if name == "BC6H" {
        "BC6H_UF16".to_string()
    } else {
        format!("{name}_UNORM")
    })
}

pub(super) fn fourcc_text(v: u32) -> String {
    let d3d = match v {
        36 => "D3DFMT_A16B16G16R16",
        110 => "D3DFMT_Q16W16V16U16",
        111 => "D3DFMT_R16F",
        112 => "D3DFMT_G16R16F",
        113 => "D3DFMT_A16B16G16R16F",
        114 => "D3DFMT_R32F",
        115 => "D3DFMT_G32R32F",
        116 => "D3DFMT_A32B32G32R32F",
        _ => "",
    };
    if !d3d.is_empty() {
        return format!("{v} ({d3d})");
    }
    let b = v.to_le_bytes();
    if v > 255
        && b.iter()
            .all(|c| c.is_ascii_graphic() || *c == b' ' || *c == 0)
    {
        format!("`{}`", String::from_utf8_lossy(&b).trim_end_matches('\0'))
    } else {
        format!("{v}")
    }
}

/// DirectDraw's palette flags (ddraw.h `DDPF_PALETTEINDEXED*`) and the
/// index width each names: texels are indices into a palette stored after
/// the header.
pub(super) const PALETTE_FLAGS: [(u32, &str); 5] = [
    (0x800, "1-bit"),
    (0x1000, "2-bit"),
    (0x8, "4-bit"),
    (0x20, "8-bit"),
    (0x10, ""),
];

/// Block formats named by a fourCC: code, format, alpha (`DXT2` and `DXT4`
/// are the premultiplied `DXT3` and `DXT5`).
pub(super) const FOURCC_BLOCKS: [(&[u8; 4], BlockFormat, AlphaMode); 11] = {
    use AlphaMode::{Premultiplied, Straight};
    use BlockFormat::*;
    [
        (b"DXT1", Bc1, Straight),
        (b"DXT2", Bc2, Premultiplied),
        (b"DXT3", Bc2, Straight),
        (b"DXT4", Bc3, Premultiplied),
        (b"DXT5", Bc3, Straight),
        (b"ATI1", Bc4 { signed: false }, Straight),
        (b"BC4U", Bc4 { signed: false }, Straight),
        (b"BC4S", Bc4 { signed: true }, Straight),
        (b"ATI2", Bc5 { signed: false }, Straight),
        (b"BC5U", Bc5 { signed: false }, Straight),
        (b"BC5S", Bc5 { signed: true }, Straight),
    ]
};

/// Uncompressed formats named by a D3DX fourCC number (`D3DFMT_*`, see
/// [`fourcc_text`]): code, channels, type; linear, two channels are R, G
/// data.
pub(super) const FOURCC_PLAIN: [(u32, u8, ChannelType); 7] = {
    use ChannelType::*;
    [
        (36, 4, U16),
        (111, 1, F16),
        (112, 2, F16),
        (113, 4, F16),
        (114, 1, F32),
        (115, 2, F32),
        (116, 4, F32),
    ]
};

/// What the header says is stored, and a description for `parvo info`.
pub(super) fn stored_of(h: &Header) -> Result<(Stored, String)> {
    let pf = &h.pixel_format;
    if let Some(d) = &h.dx10 {
        return stored_of_dx10(d);
    }
    refuse_palette(pf)?;
    if pf.flags & ddpf::FOURCC != 0 {
        return stored_of_fourcc(pf.fourcc);
    }
    if pf.flags & (ddpf::YUV | ddpf::BUMPDUDV) != 0 {
        return Err(decode_err(
            "YUV and signed bump-map (DUDV) pixel formats are not supported",
        ));
    }
    stored_of_masks(pf)
}

/// What a DX10 header's DXGI format and alpha mode say is stored.
pub(super) fn stored_of_dx10(d: &Dx10) -> Result<(Stored, String)> {
    let mode = d.misc_flags2 & 7;
    if let Some(&(_, bf, srgb)) = DXGI_BLOCKS.iter().find(|e| e.0 == d.dxgi_format) {
        let alpha = match mode {
            alpha_mode::PREMULTIPLIED => AlphaMode::Premultiplied,
            alpha_mode::OPAQUE => AlphaMode::None,
            _ => AlphaMode::Straight,
        };
        return Ok((
            Stored::Blocks {
                format: bf,
                srgb,
                alpha,
            },
            format!(
                "DX10 {}",
                dxgi_name(d.dxgi_format).unwrap_or(if srgb { "sRGB" } else { "" })
            ),
        ));
    }
    let &(_, ch, ty, srgb, swap, padded, name) = DXGI_PLAIN
        .iter()
        .find(|e| e.0 == d.dxgi_format)
        .ok_or_else(|| {
        decode_err(format!(
            "DXGI format {} is not one parvo reads (it reads the uncompressed UNORM 8-bit \
                 and 16-bit, half and float R/RG/RGB/RGBA/BGRA formats and BC1-BC7)",
            dxgi_describe(d.dxgi_format)
        ))
    })?;
    let cs = if srgb {
        ColorSpace::Srgb
    } else {
        ColorSpace::Linear
    };
    let mut format = Format::new(ch, ty, cs);
    let mut drop_alpha = padded;
    match (ch, mode) {
        (2, alpha_mode::STRAIGHT) => {}
        (2, alpha_mode::PREMULTIPLIED) | (4, alpha_mode::PREMULTIPLIED) => {
            format = format.with_alpha(AlphaMode::Premultiplied)
        }
        (2, _) => format = format.with_alpha(AlphaMode::None),
        (4, alpha_mode::OPAQUE) => drop_alpha = true,
        (4, alpha_mode::CUSTOM) => format = format.with_alpha(AlphaMode::None),
        _ => {}
    }
    let bytes = ch as usize * ty.bytes();
    if drop_alpha {
        format.channels = 3;
    }
    Ok((
        Stored::Plain {
            format,
            bytes,
            masks: None,
            swap_rb: swap,
            drop_alpha,
        },
        format!("DX10 {name}"),
    ))
}

/// Refuse a palettised pixel format ([`PALETTE_FLAGS`]).
pub(super) fn refuse_palette(pf: &PixelFormat) -> Result<()> {
    let Some((_, bits)) = PALETTE_FLAGS.iter().find(|(flag, _)| pf.flags & flag != 0) else {
        return Ok(());
    };
    Err(decode_err(format!(
        "this is a palettised DDS ({}palette indices, pixel format flags {:#x}), which parvo \
         does not read",
        if bits.is_empty() {
            String::new()
        } else {
            format!("{bits} ")
        },
        pf.flags
    )))
}

/// What a fourCC says is stored ([`FOURCC_BLOCKS`], [`FOURCC_PLAIN`]).
pub(super) fn stored_of_fourcc(code: u32) -> Result<(Stored, String)> {
    if code == 0 {
        return Err(decode_err(
            "the pixel format says a fourCC names the format, but the fourCC is empty (0)",
        ));
    }
    let blocks = FOURCC_BLOCKS
        .iter()
        .find(|e| e.0 == &code.to_le_bytes())
        .map(|&(_, format, alpha)| Stored::Blocks {
            format,
            srgb: false,
            alpha,
        });
    let plain = || {
        FOURCC_PLAIN
            .iter()
            .find(|e| e.0 == code)
            .map(|&(_, ch, ty)| {
                let mut format = Format::new(ch, ty, ColorSpace::Linear);
                if ch == 2 {
                    format = format.with_alpha(AlphaMode::None);
                }
                Stored::Plain {
                    format,
                    bytes: ch as usize * ty.bytes(),
                    masks: None,
                    swap_rb: false,
                    drop_alpha: false,
                }
            })
    };
    let st = blocks.or_else(plain).ok_or_else(|| {
        decode_err(format!(
            "fourCC {} is not a format parvo reads (it reads DXT1-DXT5, ATI1/ATI2, \
             BC4U/BC4S/BC5U/BC5S, DX10 and the D3DX codes 36 and 111-116)",
            fourcc_text(code)
        ))
    })?;
    Ok((st, format!("fourCC {}", fourcc_text(code))))
}

/// What a legacy pixel format's bit count, masks and RGB / LUMINANCE /
/// ALPHA flags say is stored.
pub(super) fn stored_of_masks(pf: &PixelFormat) -> Result<(Stored, String)> {
    let lin = ColorSpace::Linear;
    let bits = pf.rgb_bit_count;
    if !matches!(bits, 8 | 16 | 24 | 32) {
        return Err(decode_err(format!(
            "legacy pixel format with {bits} bits per texel (8, 16, 24 or 32 are read)"
        )));
    }
    let bytes = bits as usize / 8;
    let fits = |m: u32| bits == 32 || m >> bits == 0;
    let [mut r, g, b, mut a] = pf.masks;
    let has_a = pf.flags & ddpf::ALPHAPIXELS != 0;
    let (channels, masks) = if pf.flags & ddpf::LUMINANCE != 0 {
        // Pillow writes L8 with mask ff000000 and A8L8 with alpha mask
        // ff000000, outside the texel; it reads them as plain L / LA bytes.
        if !fits(r) || r == 0 {
            r = if bits == 16 && !has_a { 0xffff } else { 0xff };
        }
        if has_a {
            if !fits(a) || a == 0 {
                a = 0xff00;
            }
            (2, [r, a, 0, 0])
        } else {
            (1, [r, 0, 0, 0])
        }
    } else if pf.flags & ddpf::RGB != 0 {
        if bits == 32 && r == 0xffff_ffff && g == 0 && b == 0 {
            // D3DX's alternative R32F (DirectXTex reads it as R32_FLOAT).
            return Ok((
                Stored::Plain {
                    format: Format::new(1, ChannelType::F32, lin),
                    bytes: 4,
                    masks: None,
                    swap_rb: false,
                    drop_alpha: false,
                },
                "legacy R32F (RGB mask ffffffff)".into(),
            ));
        }
        if has_a && a != 0 {
            (4, [r, g, b, a])
        } else if b == 0 && g != 0 {
            (2, [r, g, 0, 0])
        } else {
            (3, [r, g, b, 0])
        }
    } else if pf.flags & ddpf::ALPHA != 0 {
        (1, [a, 0, 0, 0])
    } else {
        return Err(decode_err(format!(
            "the pixel format flags ({:#x}) set none of RGB, LUMINANCE, ALPHA or FOURCC, so they \
             name no texel layout",
            pf.flags
        )));
    };
    let widest = masks[..channels]
        .iter()
        .map(|m| m.count_ones())
        .max()
        .unwrap_or(0);
    if widest == 0 || widest > 16 || masks[..channels].iter().any(|&m| !fits(m)) {
        return Err(decode_err(format!(
            "legacy masks {:#x} {:#x} {:#x} {:#x} do not describe a {bits}-bit texel parvo reads",
            pf.masks[0], pf.masks[1], pf.masks[2], pf.masks[3]
        )));
    }
    let ty = if widest <= 8 {
        ChannelType::U8
    } else {
        ChannelType::U16
    };
    let mut format = Format::new(channels as u8, ty, lin);
    if channels == 2 && !has_a {
        format = format.with_alpha(AlphaMode::None);
    }
    let desc = format!(
        "legacy {}{} {bits}-bit, masks {:#x} {:#x} {:#x} {:#x}",
        if pf.flags & ddpf::LUMINANCE != 0 {
            "LUMINANCE"
        } else if pf.flags & ddpf::RGB != 0 {
            "RGB"
        } else {
            "ALPHA"
        },
        if has_a { "|ALPHAPIXELS" } else { "" },
        pf.masks[0],
        pf.masks[1],
        pf.masks[2],
        pf.masks[3]
    );
    Ok((
        Stored::Plain {
            format,
            bytes,
            masks: Some(Masked { masks, channels }),
            swap_rb: false,
            drop_alpha: false,
        },
        desc,
    ))
}

/// Bytes of level `k` (`w × h`) as stored.
pub(super) fn stored_len(st: &Stored, w: u32, h: u32) -> u64 {
    match st {
        Stored::Plain { bytes, .. } => w as u64 * h as u64 * *bytes as u64,
        Stored::Blocks { format, .. } => format.level_bytes(w, h),
    }
}

/// Texels of one level from its stored bytes.
pub(super) fn decode_level(st: &Stored, w: u32, h: u32, data: &[u8]) -> Result<Texture> {
    match *st {
        Stored::Blocks {
            format,
            srgb,
            alpha,
        } => crate::compress::decode(format, srgb, alpha, w, h, data),
        Stored::Plain {
            format,
            bytes,
            masks: Some(m),
            ..
        } => {
            let n = w as usize * h as usize;
            let shifts: Vec<(u32, u32, u32)> = m.masks[..m.channels]
                .iter()
                .map(|&mask| (mask, mask.trailing_zeros() % 32, mask.count_ones()))
                .collect();
            let get = |px: &[u8]| {
                let mut b = [0u8; 4];
                b[..bytes].copy_from_slice(px);
                u32::from_le_bytes(b)
            };
            let scale = |v: u32, bits: u32, to: u32| -> u32 {
                if bits == 0 {
                    return 0;
                }
                let max_in = (1u64 << bits) - 1;
                let max_out = (1u64 << to) - 1;
                ((v as u64 * max_out * 2 + max_in) / (2 * max_in)) as u32
            };
            let texels = match format.channel_type {
                ChannelType::U8 => {
                    let mut out = Vec::with_capacity(n * m.channels);
                    for px in data.chunks_exact(bytes).take(n) {
                        let v = get(px);
                        for &(mask, sh, bits) in &shifts {
                            out.push(scale((v & mask) >> sh, bits, 8) as u8);
                        }
                    }
                    Texels::U8(out)
                }
                _ => {
                    let mut out = Vec::with_capacity(n * m.channels);
                    for px in data.chunks_exact(bytes).take(n) {
                        let v = get(px);
                        for &(mask, sh, bits) in &shifts {
                            out.push(scale((v & mask) >> sh, bits, 16) as u16);
                        }
                    }
                    Texels::U16(out)
                }
            };
            Texture::from_texels(w, h, format, texels)
        }
        Stored::Plain {
            format,
            bytes,
            masks: None,
            swap_rb,
            drop_alpha,
        } => {
            let ty = format.channel_type;
            let stored_ch = bytes / ty.bytes();
            let mut texels = crate::io::texels_from_le(ty, data);
            fn fix<T: Copy>(v: Vec<T>, ch: usize, swap: bool, drop: bool) -> Vec<T> {
                if !swap && !drop {
                    return v;
                }
                let keep = if drop { 3 } else { ch };
                let mut out = Vec::with_capacity(v.len() / ch * keep);
                for px in v.chunks_exact(ch) {
                    let mut p = [px[0], px[1 % ch], px[2 % ch], px[3 % ch]];
                    if swap {
                        p.swap(0, 2);
                    }
                    out.extend_from_slice(&p[..keep]);
                }
                out
            }
            texels = match texels {
                Texels::U8(v) => Texels::U8(fix(v, stored_ch, swap_rb, drop_alpha)),
                Texels::U16(v) => Texels::U16(fix(v, stored_ch, swap_rb, drop_alpha)),
                Texels::F16(v) => Texels::F16(fix(v, stored_ch, swap_rb, drop_alpha)),
                Texels::F32(v) => Texels::F32(fix(v, stored_ch, swap_rb, drop_alpha)),
            };
            Texture::from_texels(w, h, format, texels)
        }
    }
}

/// Read and check the header of the DDS file at `path` (for `parvo info`
/// and tests).
pub fn read_header(path: &Path) -> Result<Header> {
    use std::io::Read;
    let mut head = Vec::with_capacity(HEADER_BYTES + DX10_BYTES);
    std::fs::File::open(path)
        .and_then(|f| {
            f.take((HEADER_BYTES + DX10_BYTES) as u64)
                .read_to_end(&mut head)
        })
        .map_err(|e| Error::Io {
            path: path.to_path_buf(),
            action: "cannot read".into(),
            error: e,
        })?;
    Header::parse(&head)
}

/// The kind of image a file starting with `head` (its header) holds;
/// a plain 2-D image when it cannot tell.
pub(crate) fn peek_kind(head: &[u8]) -> ImageKind {
    Header::parse(head)
        .ok()
        .and_then(|h| dds_kind(&h).ok())
        .unwrap_or(ImageKind::Plain)
}

/// The kind of image a header describes: a cube map (the legacy cube
/// flag with all six faces, or DX10's `TEXTURECUBE` with `arraySize`
/// cubes), an array (DX10 `arraySize` > 1) or one 2-D image.
pub(super) fn dds_kind(header: &Header) -> Result<ImageKind> {
    let dx_cube = header
        .dx10
        .is_some_and(|d| d.misc_flag & D3D11_RESOURCE_MISC_TEXTURECUBE != 0);
    // An array size of 0 is read as 1, as Pillow and OpenImageIO read it
    // (they ignore the field; Pillow's own `bc1.dds` has 0).
    let count = header.dx10.map_or(1, |d| d.array_size.max(1));
    if dx_cube || header.caps2 & caps::CUBEMAP != 0 {
        if !dx_cube && header.caps2 & caps::ALL_FACES != caps::ALL_FACES {
            return Err(decode_err(format!(
                "a cube map with only {} of its six faces (parvo reads whole cube maps)",
                (header.caps2 & caps::ALL_FACES).count_ones()
            )));
        }
        if header.width != header.height {
            return Err(decode_err(format!(
                "a cube map's faces must be square, the header gives {}x{}",
                header.width, header.height
            )));
        }
        return Ok(if count == 1 {
            ImageKind::Cube
        } else {
            ImageKind::CubeArray { cubes: count }
        });
    }
    Ok(if count == 1 {
        ImageKind::Plain
    } else {
        ImageKind::Array { layers: count }
    })
}

/// The refusal of a volume (3-D) texture.
const VOLUME: &str = "volume (3-D) textures are not supported (parvo reads 2-D textures, arrays \
     and cube maps): store its depth slices as the layers of a 2-D array texture first";

/// The kinds of DDS file parvo does not read (volumes, buffers), refused
/// in words before any texel is read.
pub(super) fn refuse_unsupported(header: &Header) -> Result<()> {
    let h = header.height;
    if header.caps2 & caps::VOLUME != 0 || (header.flags & ddsd::DEPTH != 0 && header.depth > 1) {
        return Err(decode_err(VOLUME));
    }
    if let Some(d) = &header.dx10 {
        match d.resource_dimension {
            D3D10_RESOURCE_DIMENSION_TEXTURE2D => {}
            // Unknown: Pillow and OpenImageIO do not read the field and take
            // the header's width and height (Pillow's own `bc1.dds` has 0).
            0 => {}
            // A 1-D texture is a row of texels.
            2 if h == 1 => {}
            2 => {
                return Err(decode_err(format!(
                    "the DX10 header says a 1-D texture, but the height is {h}"
                )));
            }
            4 => {
                return Err(decode_err(VOLUME));
            }
            1 => {
                return Err(decode_err(
                    "the DX10 header describes a buffer, not a texture",
                ));
            }
            n => {
                return Err(decode_err(format!(
                    "the DX10 header's resource dimension is {n}; it defines 2 (1-D), 3 (2-D) \
                     and 4 (3-D texture)"
                )));
            }
        }
    }
    Ok(())
}

/// Load a DDS file: every mip level of a 2-D texture (see the module docs
/// for the formats read); a cube map or an array is refused (see
/// [`load_with`]).
pub fn load(path: &Path, limits: &Limits) -> Result<Loaded> {
    load_with(path, limits, &crate::io::LoadOptions::default())
}

/// [`load`] with [`crate::io::LoadOptions`]: cube maps and arrays are read
/// whole (every face and layer, each with its levels) when `options`
/// accept them.
pub fn load_with(path: &Path, limits: &Limits, options: &crate::io::LoadOptions) -> Result<Loaded> {
    let header = read_header(path)?;
    let (w, h) = (header.width, header.height);
    if w == 0 || h == 0 {
        return Err(decode_err(format!("the header declares a {w}x{h} texture")));
    }
    refuse_unsupported(&header)?;
    let kind = dds_kind(&header)?;
    crate::io::layered_image("DDS", kind, (w, h), options)?;
    let images = kind.images();
    let (stored, desc) = stored_of(&header)?;
    let full = crate::mip::level_count(w, h, crate::mip::Rounding::Down, None);
    let declared = header.mip_map_count.max(1);
    if declared > full {
        return Err(decode_err(format!(
            "the header declares {declared} mip levels, a {w}x{h} chain has {full}"
        )));
    }
    let sizes: Vec<(u32, u32)> = (0..declared)
        .map(|k| crate::mip::level_size(w, h, k, crate::mip::Rounding::Down))
        .collect();
    let decoded_bytes: u64 = {
        let f = match stored {
            Stored::Plain { format, .. } => format,
            Stored::Blocks { format, srgb, .. } => format.decoded_format(srgb),
        };
        sizes
            .iter()
            .map(|&(a, b)| a as u64 * b as u64 * f.texel_bytes() as u64)
            .sum::<u64>()
            .saturating_mul(images as u64)
    };
    let file_len = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
    limits.check(w as u64, h as u64, decoded_bytes.saturating_add(file_len))?;
    let bytes = std::fs::read(path).map_err(|e| Error::Io {
        path: path.to_path_buf(),
        action: "cannot read".into(),
        error: e,
    })?;
    // Image by image (face or layer), each with all its levels.
    let mut at = header.data_offset();
    let mut all: Vec<Vec<Texture>> = Vec::with_capacity(images);
    for image in 0..images {
        all.push(
            read_levels(&bytes, &mut at, &stored, &sizes, &header, images > 1).map_err(
                |e| match e {
                    Error::Decode { format, reason } if images > 1 => Error::Decode {
                        format,
                        reason: format!("image {image} of {images}: {reason}"),
                    },
                    e => e,
                },
            )?,
        );
    }
    let mut all = all.into_iter();
    let Some(levels) = all.next() else {
        return Err(decode_err("no image"));
    };
    let base = &levels[0];
    let format = base.format();
    let mut info = SourceInfo::new(FileFormat::Dds, &format);
    info.own_mips = levels.len() > 1;
    info.channel_names = match (format.channels, format.has_alpha()) {
        (1, _) => vec!["R".into()],
        (2, true) => vec!["Y".into(), "A".into()],
        (2, false) => vec!["R".into(), "G".into()],
        (3, _) => vec!["R".into(), "G".into(), "B".into()],
        _ => vec!["R".into(), "G".into(), "B".into(), "A".into()],
    };
    info.attributes = vec![("dds:format".into(), desc)];
    if let Some(d) = &header.dx10
        && let Some(meaning) = typeless_reading(d.dxgi_format)
    {
        info.notes.push(format!(
            "DXGI format {} says no type; read as {meaning}, as Pillow reads it",
            dxgi_name(d.dxgi_format).unwrap_or_default()
        ));
    }
    if let Stored::Blocks { format: bf, .. } = stored {
        info.attributes
            .push(("dds:compression".into(), bf.name().to_string()));
        info.blocks = Some(bf);
    }
    if let Some(d) = &header.dx10 {
        let mode = match d.misc_flags2 & 7 {
            alpha_mode::STRAIGHT => "straight",
            alpha_mode::PREMULTIPLIED => "premultiplied",
            alpha_mode::OPAQUE => "opaque",
            alpha_mode::CUSTOM => "custom",
            _ => "unknown",
        };
        info.attributes.push(("dds:alphaMode".into(), mode.into()));
    }
    info.attributes.sort();
    info.kind = kind;
    // DX10's TEXTURE1D (2): one row, said as 1-D.
    info.one_d = header.dx10.is_some_and(|d| d.resource_dimension == 2);
    Ok(Loaded {
        levels,
        info,
        images: all.collect(),
    })
}

/// The levels of one image from `bytes` at `*at` (moved past them).
pub(super) fn read_levels(
    bytes: &[u8],
    at: &mut usize,
    stored: &Stored,
    sizes: &[(u32, u32)],
    header: &Header,
    layered: bool,
) -> Result<Vec<Texture>> {
    let mut levels = Vec::with_capacity(sizes.len());
    for (k, &(lw, lh)) in sizes.iter().enumerate() {
        let need = stored_len(stored, lw, lh) as usize;
        let Some(data) = bytes.get(*at..*at + need) else {
            if k > 0 && !layered && header.flags & ddsd::MIPMAPCOUNT == 0 {
                // A mip count without its flag, and no data for it: the
                // file holds one level (DirectXTex would refuse it).
                break;
            }
            return Err(decode_err(format!(
                "the file ends inside level {k} ({lw}x{lh}, {need} bytes from offset {at}; the file has {})",
                bytes.len()
            )));
        };
        levels.push(decode_level(stored, lw, lh, data)?);
        *at += need;
    }
    Ok(levels)
}
