//! The uncompressed Vulkan formats parvo has no texel type of its own for,
//! unpacked on load into the nearest one the way libktx's `ktx extract`
//! presents them (KTX-Software, `tools/ktx/command_extract.cpp`):
//!
//! - channels stored in another order (`B8G8R8A8`, `B8G8R8`,
//!   `A8B8G8R8_PACK32`): RGBA or RGB u8 in R, G, B, A order, the
//!   vkFormat's transfer (`_SRGB` or linear) kept;
//! - packed UNORM fields (`R4G4_UNORM_PACK8`, `R5G6B5`, `B5G6R5`,
//!   `R4G4B4A4`, `B4G4R4A4`, `A4R4G4B4`, `A4B4G4R4`, `R5G5B5A1`,
//!   `B5G5R5A1`, `A1R5G5B5`, `A1B5G5R5_PACK16`): widened to u8 by left bit
//!   replication (`imageio::convertUNORM`: a 5-bit `v` becomes
//!   `v << 3 | v >> 2`, a 1-bit alpha 0 or 255), which is what `ktx
//!   extract` writes to PNG; the 10-bit `A2R10G10B10`/`A2B10G10R10` and
//!   the `R10X6…`/`R12X4…` formats likewise to u16 (PNG's 16 bits);
//! - `A8_UNORM`: grey + alpha with grey 0 (`ktx extract`'s grey-alpha PNG);
//! - `_UINT` 8/16-bit: the stored integers kept as u8/u16 codes (`n` is the
//!   value n/255 or n/65535), lossless; `ktx extract` writes the same
//!   numbers to EXR as floats, which parvo's pipeline would take as
//!   colour far above 1 (and as alpha far above opaque);
//! - `_SINT` 8/16-bit: the two's-complement integers as u8/u16 codes offset
//!   by half the range (−128 → 0, 0 → 128, 127 → 255), lossless and in the
//!   integers' order, since parvo's integer types are unsigned;
//! - `_SNORM` 8/16-bit: f32, `max(c / (2^(b−1) − 1), −1)` (the Vulkan
//!   conversion; signed BC4/BC5 decode to the same values). `ktx extract`
//!   has no PNG or EXR output for SNORM formats.
//!
//! Two channels are R, G data, four are RGBA with the DFD's alpha mode,
//! as for the formats parvo reads directly.

use crate::texel::{AlphaMode, ChannelType, ColorSpace, Format, Texels};

/// How a stored field becomes a channel value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Field {
    /// Unsigned normalised: widened by bit replication to the channel
    /// type's bits.
    Unorm,
    /// Unsigned integer: the code as is.
    Uint,
    /// Signed integer: the code with its sign bit flipped (offset binary).
    Sint,
    /// Signed normalised: f32 in [−1, 1].
    Snorm,
}

/// A stored texel layout and the texel format it unpacks to.
#[derive(Clone, Copy, Debug)]
pub(super) struct Packed {
    /// Bytes of one stored texel.
    pub bytes: u8,
    /// Per output channel (R, G, B, A order; grey first for `A8`): the
    /// bit offset and bit length of its field in the little-endian texel,
    /// or length 0 for a channel that is always 0.
    fields: [(u8, u8); 4],
    field: Field,
    /// What the levels decode to.
    pub format: Format,
}

/// The byte offsets of R, G, B (and A) of an 8-bit-per-channel format.
fn bytes8(order: &[u8], field: Field, cs: ColorSpace) -> Packed {
    let mut fields = [(0, 0); 4];
    for (f, &at) in fields.iter_mut().zip(order) {
        *f = (at * 8, 8);
    }
    let n = order.len() as u8;
    packed(n, fields, field, cs)
}

/// `n` channels of 16 bits, in R, G, B, A order.
fn words16(n: u8, field: Field) -> Packed {
    let mut fields = [(0, 0); 4];
    for (i, f) in fields.iter_mut().take(n as usize).enumerate() {
        *f = (i as u8 * 16, 16);
    }
    packed(n * 2, fields, field, ColorSpace::Linear)
}

/// `fields` (bit offset, length) of a texel of `bytes` bytes; the channel
/// count is the number of fields given.
fn packed(bytes: u8, fields: [(u8, u8); 4], field: Field, cs: ColorSpace) -> Packed {
    let channels = fields.iter().filter(|f| f.1 > 0).count() as u8;
    let widest = fields.iter().map(|f| f.1).max().unwrap_or(8);
    let ty = match field {
        Field::Snorm => ChannelType::F32,
        _ if widest > 8 => ChannelType::U16,
        _ => ChannelType::U8,
    };
    let mut format = Format::new(channels, ty, cs);
    if channels == 2 {
        format = format.with_alpha(AlphaMode::None);
    }
    Packed {
        bytes,
        fields,
        field,
        format,
    }
}

/// Unsigned normalised fields `(offset, length)` of a 16-bit (or 8-bit)
/// packed format, in R, G, B, A order.
fn unorm(bytes: u8, f: &[(u8, u8)]) -> Packed {
    let mut fields = [(0, 0); 4];
    fields[..f.len()].copy_from_slice(f);
    packed(bytes, fields, Field::Unorm, ColorSpace::Linear)
}

/// The layout of a `VkFormat` parvo unpacks (Vulkan specification,
/// "Formats": a `_PACKn` format's first component is in the most
/// significant bits of its little-endian word; other formats store their
/// components in byte order).
pub(super) fn packed_of_vk(vk: u32) -> Option<Packed> {
    use ColorSpace::{Linear, Srgb};
    use Field::*;
    // The 8-bit formats in groups of (UNORM, SNORM, USCALED, SSCALED, UINT,
    // SINT, SRGB): base value and byte order of R, G, B, A.
    let group8: [(u32, &[u8]); 6] = [
        (9, &[0]),
        (16, &[0, 1]),
        (23, &[0, 1, 2]),
        (30, &[2, 1, 0]),
        (37, &[0, 1, 2, 3]),
        (44, &[2, 1, 0, 3]),
    ];
    for (base, order) in group8 {
        let field = match vk.checked_sub(base) {
            Some(0) if base == 30 || base == 44 => Some((Unorm, Linear)),
            Some(6) if base == 30 || base == 44 => Some((Unorm, Srgb)),
            Some(1) => Some((Snorm, Linear)),
            Some(4) => Some((Uint, Linear)),
            Some(5) => Some((Sint, Linear)),
            _ => None,
        };
        if let Some((field, cs)) = field {
            return Some(bytes8(order, field, cs));
        }
    }
    // A8B8G8R8_*_PACK32 (51-57): A in bits 31..24 ... R in 7..0, the bytes
    // of R8G8B8A8.
    let abgr = |field, cs| bytes8(&[0, 1, 2, 3], field, cs);
    Some(match vk {
        51 => abgr(Unorm, Linear),
        52 => abgr(Snorm, Linear),
        55 => abgr(Uint, Linear),
        56 => abgr(Sint, Linear),
        57 => abgr(Unorm, Srgb),
        // R16 … R16G16B16A16 in groups of (UNORM, SNORM, USCALED, SSCALED,
        // UINT, SINT, SFLOAT) from 70.
        71 | 78 | 85 | 92 => words16((vk - 71) as u8 / 7 + 1, Snorm),
        74 | 81 | 88 | 95 => words16((vk - 74) as u8 / 7 + 1, Uint),
        75 | 82 | 89 | 96 => words16((vk - 75) as u8 / 7 + 1, Sint),
        1 => unorm(1, &[(4, 4), (0, 4)]),
        2 => unorm(2, &[(12, 4), (8, 4), (4, 4), (0, 4)]),
        3 => unorm(2, &[(4, 4), (8, 4), (12, 4), (0, 4)]),
        4 => unorm(2, &[(11, 5), (5, 6), (0, 5)]),
        5 => unorm(2, &[(0, 5), (5, 6), (11, 5)]),
        6 => unorm(2, &[(11, 5), (6, 5), (1, 5), (0, 1)]),
        7 => unorm(2, &[(1, 5), (6, 5), (11, 5), (0, 1)]),
        8 => unorm(2, &[(10, 5), (5, 5), (0, 5), (15, 1)]),
        58 => unorm(4, &[(20, 10), (10, 10), (0, 10), (30, 2)]),
        64 => unorm(4, &[(0, 10), (10, 10), (20, 10), (30, 2)]),
        // VK_KHR_maintenance5 / VK_EXT_4444_formats.
        1000470000 => unorm(2, &[(0, 5), (5, 5), (10, 5), (15, 1)]),
        1000340000 => unorm(2, &[(8, 4), (4, 4), (0, 4), (12, 4)]),
        1000340001 => unorm(2, &[(0, 4), (4, 4), (8, 4), (12, 4)]),
        // A8_UNORM_KHR: grey 0 and alpha, as `ktx extract` writes it.
        1000470001 => Packed {
            bytes: 1,
            fields: [(0, 0), (0, 8), (0, 0), (0, 0)],
            field: Unorm,
            format: Format::new(2, ChannelType::U8, Linear),
        },
        // R10X6… and R12X4… (VK_KHR_sampler_ycbcr_conversion): the value
        // in the high bits of each 16-bit word.
        1000156007 => unorm(2, &[(6, 10)]),
        1000156008 => unorm(4, &[(6, 10), (22, 10)]),
        1000156009 => unorm(8, &[(6, 10), (22, 10), (38, 10), (54, 10)]),
        1000156017 => unorm(2, &[(4, 12)]),
        1000156018 => unorm(4, &[(4, 12), (20, 12)]),
        1000156019 => unorm(8, &[(4, 12), (20, 12), (36, 12), (52, 12)]),
        _ => return None,
    })
}

/// `v`, `from` bits wide, widened to `to` bits by left bit replication
/// (KTX-Software's `convertUNORM`): the field repeated from the top bit
/// down, so 0 stays 0 and all ones stays all ones.
pub(super) fn replicate(v: u32, from: u32, to: u32) -> u32 {
    let mut out = 0u64;
    let mut i = 0;
    while i < to {
        out |= (u64::from(v) << (to - i)) >> from;
        i += from;
    }
    out as u32
}

impl Packed {
    /// The levels' texels from stored bytes (a whole number of texels).
    pub(super) fn unpack(&self, data: &[u8]) -> Texels {
        let n = self.format.channels as usize;
        let words = data.chunks_exact(self.bytes as usize).map(|t| {
            let mut b = [0u8; 8];
            b[..t.len()].copy_from_slice(t);
            u64::from_le_bytes(b)
        });
        let fields = &self.fields[..n];
        let codes = words.flat_map(|w| {
            fields.iter().map(move |&(at, len)| {
                if len == 0 {
                    0
                } else {
                    ((w >> at) & ((1u64 << len) - 1)) as u32
                }
            })
        });
        let to = self.format.channel_type.bytes() as u32 * 8;
        let lens: Vec<u32> = fields.iter().map(|f| u32::from(f.1)).collect();
        let len_of = |i: usize| lens[i % n];
        match (self.field, self.format.channel_type) {
            (Field::Snorm, _) => Texels::F32(
                codes
                    .enumerate()
                    .map(|(i, c)| {
                        let bits = len_of(i);
                        let signed = ((c << (32 - bits)) as i32) >> (32 - bits);
                        (signed as f32 / ((1u32 << (bits - 1)) - 1) as f32).max(-1.0)
                    })
                    .collect(),
            ),
            (field, ty) => {
                let code = |(i, c): (usize, u32)| {
                    let bits = len_of(i);
                    match field {
                        _ if bits == 0 => 0,
                        Field::Sint => c ^ (1 << (bits - 1)),
                        Field::Unorm => replicate(c, bits, to),
                        _ => c,
                    }
                };
                if ty == ChannelType::U16 {
                    Texels::U16(codes.enumerate().map(|x| code(x) as u16).collect())
                } else {
                    Texels::U8(codes.enumerate().map(|x| code(x) as u8).collect())
                }
            }
        }
    }

    /// What reading `name` (the vkFormat's Vulkan name) changes, for
    /// `parvo info` and stderr: integers become codes.
    pub(super) fn note(&self, name: &str) -> Option<String> {
        let bits = self.format.channel_type.bytes() * 8;
        match self.field {
            Field::Uint => Some(format!(
                "the integers of {name} are read as {bits}-bit codes (n as n/{})",
                (1u32 << bits) - 1
            )),
            Field::Sint => Some(format!(
                "the signed integers of {name} are read as {bits}-bit codes offset by {h} \
                 (-{h} as 0, 0 as {h}, {} as {})",
                (1u32 << (bits - 1)) - 1,
                (1u32 << bits) - 1,
                h = 1u32 << (bits - 1)
            )),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replication_is_ktx_softwares() {
        // convertUNORM's loop, by hand: 5 -> 8 is v << 3 | v >> 2.
        for v in 0..32 {
            assert_eq!(replicate(v, 5, 8), (v << 3) | (v >> 2));
        }
        for v in 0..64 {
            assert_eq!(replicate(v, 6, 8), (v << 2) | (v >> 4));
        }
        for v in 0..16 {
            assert_eq!(replicate(v, 4, 8), v * 17);
            assert_eq!(replicate(v, 4, 16), v * 0x1111);
        }
        assert_eq!(replicate(1, 1, 8), 255);
        assert_eq!(replicate(0b10, 2, 16), 0xAAAA);
        assert_eq!(replicate(0x3FF, 10, 16), 0xFFFF);
        assert_eq!(replicate(0x200, 10, 16), 0x8020);
        assert_eq!(replicate(200, 8, 8), 200);
    }

    #[test]
    fn every_layout_fills_its_texel() {
        for vk in (1..=130).chain([
            1000470000, 1000470001, 1000340000, 1000340001, 1000156007, 1000156008, 1000156009,
            1000156017, 1000156018, 1000156019,
        ]) {
            let Some(p) = packed_of_vk(vk) else { continue };
            let n = p.format.channels as usize;
            let bits: u32 = p.fields[..n].iter().map(|f| u32::from(f.1)).sum();
            assert!(bits <= p.bytes as u32 * 8, "{vk}");
            for &(at, len) in &p.fields[..n] {
                assert!(u32::from(at) + u32::from(len) <= p.bytes as u32 * 8, "{vk}");
            }
            // No field overlaps another.
            let mut used = 0u64;
            for &(at, len) in &p.fields[..n] {
                let m = if len == 0 {
                    0
                } else {
                    ((1u64 << len) - 1) << at
                };
                assert_eq!(used & m, 0, "{vk}");
                used |= m;
            }
        }
        // 9, 15, 16, 22, ... are read directly, not unpacked.
        for vk in [9, 15, 16, 22, 23, 29, 37, 43, 70, 77, 84, 91] {
            assert!(packed_of_vk(vk).is_none(), "{vk}");
        }
    }
}
