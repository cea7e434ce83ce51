//! Issue 27 #3: `parvo mip photo.png -o v.ktx2 --compress bc3` wrote a file
//! that Khronos `ktx validate` rejects with error 6109: under the sRGB
//! transfer function the alpha sample of BC3 (and of BC2) must carry
//! `KHR_DF_SAMPLE_DATATYPE_LINEAR`, and parvo's did not.
//!
//! The checker below is an independent reading of the two specifications,
//! not parvo's DFD builder: each `vkFormat` parvo writes is described here
//! from the Khronos Data Format Specification (KDFS 1.3/1.4: section 5.6
//! "colorModel for compressed formats" with its example descriptors for
//! BC1A, BC2, BC3, BC4, BC5, BC6H and BC7; section 5.16 "sampleLower and
//! sampleUpper" for UNORM and float ranges), and the KTX 2.0
//! specification's rules are checked on top (section "Data Format
//! Descriptor", Restrictions, and section "typeSize"):
//! - the DFD matches the format's definition (texel block dimensions,
//!   bytesPlanes, every sample's offset, length, channel, qualifiers and
//!   range) except for the LINEAR qualifier;
//! - colour model RGBSDA for uncompressed formats, the format's own model
//!   for block formats;
//! - `_SRGB` formats have transfer sRGB; the non-sRGB variant of a format
//!   that has an sRGB one does not;
//! - with a non-linear transfer the alpha sample (channel 15) has LINEAR
//!   set; KDFS section 5.8 adds that no other sample has it then, and that
//!   with a linear transfer no sample has it (`ktx validate` 6108/6109);
//! - the premultiplied flag only where an alpha channel exists (KDFS 3.3:
//!   "fields which are irrelevant ... should be set to zero");
//! - `typeSize` 1 for `_BLOCK` formats, else the channel's byte size;
//!   `bytesPlane0` non-zero also when supercompressed (KTX 2.0.4).
//!
//! Every block format × sRGB/linear × alpha mode and every uncompressed
//! format parvo writes, plain, zstd and zlib, goes through the checker;
//! then the reported command itself.

use std::path::Path;

use parvo::compress::{BlockChain, BlockFormat};
use parvo::io::ktx2::Supercompression;
use parvo::io::{self, SaveOptions};
use parvo::{AlphaMode, ChannelType, ColorSpace, Format, Texels, Texture};

use super::util::{ok, parvo, s};

/// Sample qualifiers (KDFS 5.11).
const F: u32 = 0x80;
const S: u32 = 0x40;
const E: u32 = 0x20;
const L: u32 = 0x10;
/// RGBSDA and BC2/BC3 alpha channel id.
const ALPHA: u32 = 15;
const F32_ONE: u32 = 0x3F80_0000;
const F32_MINUS_ONE: u32 = 0xBF80_0000;

/// One expected sample: bit offset, bit length, channel id, qualifiers
/// other than LINEAR, sampleLower, sampleUpper.
type Sample = (u32, u32, u32, u32, u32, u32);

/// A format's definition as the specifications give it.
struct Def {
    name: &'static str,
    model: u32,
    /// texelBlockDimension0..3 as stored (size − 1).
    dims: [u8; 4],
    bytes_plane0: u32,
    samples: Vec<Sample>,
    /// Has alpha (premultiplication is meaningful).
    alpha: bool,
    /// One of the `_SRGB` formats.
    srgb: bool,
    /// A non-sRGB format with an sRGB variant.
    has_srgb_variant: bool,
    type_size: u32,
}

/// The definitions of the `vkFormat`s parvo may write (Vulkan numbers
/// from the Vulkan specification's `VkFormat` enumeration).
fn definition(vk: u32) -> Option<Def> {
    // Uncompressed: channels R, G, B, A in order at consecutive offsets.
    let plain = |name, ch: u32, bits: u32, kind: &str, srgb: bool| {
        let ids = [0, 1, 2, ALPHA];
        let (quals, lower, upper) = match kind {
            "UNORM" => (0, 0, ((1u64 << bits) - 1) as u32),
            "SFLOAT" => (F | S, F32_MINUS_ONE, F32_ONE),
            _ => unreachable!(),
        };
        Def {
            name,
            model: 1,
            dims: [0; 4],
            bytes_plane0: ch * bits / 8,
            samples: (0..ch)
                .map(|i| (i * bits, bits, ids[i as usize], quals, lower, upper))
                .collect(),
            alpha: ch == 4,
            srgb,
            has_srgb_variant: !srgb && bits == 8,
            type_size: bits / 8,
        }
    };
    // Block formats: 4×4 texels, KDFS section 5.6's example descriptors.
    let unsigned = (0, 0, u32::MAX);
    let block = |name, model, bytes, samples: Vec<Sample>, alpha, srgb, variant| Def {
        name,
        model,
        dims: [3, 3, 0, 0],
        bytes_plane0: bytes,
        samples,
        alpha,
        srgb,
        has_srgb_variant: variant,
        type_size: 1,
    };
    let (q0, lo, hi) = unsigned;
    let snorm = (S, 0x8000_0000, 0x7FFF_FFFF);
    Some(match vk {
        9 => plain("R8_UNORM", 1, 8, "UNORM", false),
        15 => plain("R8_SRGB", 1, 8, "UNORM", true),
        16 => plain("R8G8_UNORM", 2, 8, "UNORM", false),
        22 => plain("R8G8_SRGB", 2, 8, "UNORM", true),
        23 => plain("R8G8B8_UNORM", 3, 8, "UNORM", false),
        29 => plain("R8G8B8_SRGB", 3, 8, "UNORM", true),
        37 => plain("R8G8B8A8_UNORM", 4, 8, "UNORM", false),
        43 => plain("R8G8B8A8_SRGB", 4, 8, "UNORM", true),
        70 => plain("R16_UNORM", 1, 16, "UNORM", false),
        77 => plain("R16G16_UNORM", 2, 16, "UNORM", false),
        84 => plain("R16G16B16_UNORM", 3, 16, "UNORM", false),
        91 => plain("R16G16B16A16_UNORM", 4, 16, "UNORM", false),
        76 => plain("R16_SFLOAT", 1, 16, "SFLOAT", false),
        83 => plain("R16G16_SFLOAT", 2, 16, "SFLOAT", false),
        90 => plain("R16G16B16_SFLOAT", 3, 16, "SFLOAT", false),
        97 => plain("R16G16B16A16_SFLOAT", 4, 16, "SFLOAT", false),
        100 => plain("R32_SFLOAT", 1, 32, "SFLOAT", false),
        103 => plain("R32G32_SFLOAT", 2, 32, "SFLOAT", false),
        106 => plain("R32G32B32_SFLOAT", 3, 32, "SFLOAT", false),
        109 => plain("R32G32B32A32_SFLOAT", 4, 32, "SFLOAT", false),
        // BC1A: one 64-bit sample, channel 0 (colour) or 1 (alpha present).
        131 | 132 => block(
            ["BC1_RGB_UNORM_BLOCK", "BC1_RGB_SRGB_BLOCK"][vk as usize - 131],
            128,
            8,
            vec![(0, 64, 0, q0, lo, hi)],
            false,
            vk == 132,
            vk == 131,
        ),
        133 | 134 => block(
            ["BC1_RGBA_UNORM_BLOCK", "BC1_RGBA_SRGB_BLOCK"][vk as usize - 133],
            128,
            8,
            vec![(0, 64, 1, q0, lo, hi)],
            true,
            vk == 134,
            vk == 133,
        ),
        // BC2, BC3: alpha (channel 15) at bit 0, colour at bit 64.
        135..=138 => block(
            [
                "BC2_UNORM_BLOCK",
                "BC2_SRGB_BLOCK",
                "BC3_UNORM_BLOCK",
                "BC3_SRGB_BLOCK",
            ][vk as usize - 135],
            if vk < 137 { 129 } else { 130 },
            16,
            vec![(0, 64, ALPHA, q0, lo, hi), (64, 64, 0, q0, lo, hi)],
            true,
            vk.is_multiple_of(2),
            !vk.is_multiple_of(2),
        ),
        139 => block(
            "BC4_UNORM_BLOCK",
            131,
            8,
            vec![(0, 64, 0, q0, lo, hi)],
            false,
            false,
            false,
        ),
        140 => block(
            "BC4_SNORM_BLOCK",
            131,
            8,
            vec![(0, 64, 0, snorm.0, snorm.1, snorm.2)],
            false,
            false,
            false,
        ),
        141 => block(
            "BC5_UNORM_BLOCK",
            132,
            16,
            vec![(0, 64, 0, q0, lo, hi), (64, 64, 1, q0, lo, hi)],
            false,
            false,
            false,
        ),
        142 => block(
            "BC5_SNORM_BLOCK",
            132,
            16,
            vec![
                (0, 64, 0, snorm.0, snorm.1, snorm.2),
                (64, 64, 1, snorm.0, snorm.1, snorm.2),
            ],
            false,
            false,
            false,
        ),
        143 => block(
            "BC6H_UFLOAT_BLOCK",
            133,
            16,
            vec![(0, 128, 0, F, 0, F32_ONE)],
            false,
            false,
            false,
        ),
        144 => block(
            "BC6H_SFLOAT_BLOCK",
            133,
            16,
            vec![(0, 128, 0, F | S, F32_MINUS_ONE, F32_ONE)],
            false,
            false,
            false,
        ),
        145 | 146 => block(
            ["BC7_UNORM_BLOCK", "BC7_SRGB_BLOCK"][vk as usize - 145],
            134,
            16,
            vec![(0, 128, 0, q0, lo, hi)],
            true,
            vk == 146,
            vk == 145,
        ),
        _ => return None,
    })
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap())
}

/// Every rule the file breaks (empty when it is valid); `scheme` is the
/// supercompression the writer was asked for.
fn dfd_violations(bytes: &[u8], scheme: u32) -> Vec<String> {
    let mut bad = Vec::new();
    let vk = u32_at(bytes, 12);
    let Some(def) = definition(vk) else {
        return vec![format!("vkFormat {vk} is not one this checker describes")];
    };
    let mut fail = |what: String| bad.push(format!("{}: {what}", def.name));
    if u32_at(bytes, 16) != def.type_size {
        fail(format!(
            "typeSize {} (must be {})",
            u32_at(bytes, 16),
            def.type_size
        ));
    }
    if u32_at(bytes, 44) != scheme {
        fail(format!("supercompressionScheme {}", u32_at(bytes, 44)));
    }
    let (at, len) = (u32_at(bytes, 48) as usize, u32_at(bytes, 52) as usize);
    let d = &bytes[at..at + len];
    let w = |i: usize| u32_at(d, 4 * i);
    if w(0) as usize != len {
        fail(format!("dfdTotalSize {} != dfdByteLength {len}", w(0)));
    }
    if w(1) != 0 {
        fail(format!(
            "first block is not a Khronos basic block ({:#x})",
            w(1)
        ));
    }
    let (version, block_size) = (w(2) & 0xffff, w(2) >> 16);
    if version != 2 {
        fail(format!("versionNumber {version} (KDFS 1.3 is 2)"));
    }
    let n = def.samples.len();
    if block_size as usize != 24 + 16 * n || len != 4 + block_size as usize {
        fail(format!(
            "descriptorBlockSize {block_size} for {n} samples in a {len}-byte DFD"
        ));
        return bad;
    }
    let (model, primaries, transfer, flags) = (
        w(3) & 0xff,
        (w(3) >> 8) & 0xff,
        (w(3) >> 16) & 0xff,
        w(3) >> 24,
    );
    if model != def.model {
        fail(format!("colorModel {model} (must be {})", def.model));
    }
    if primaries == 0 || primaries > 11 {
        fail(format!("colorPrimaries {primaries} is not a defined value"));
    }
    if def.srgb && transfer != 2 {
        fail(format!("an _SRGB format with transferFunction {transfer}"));
    }
    if def.has_srgb_variant && transfer == 2 {
        fail("a non-sRGB format with an sRGB variant has transfer sRGB".into());
    }
    if transfer > 19 {
        fail(format!(
            "transferFunction {transfer} is not a defined value"
        ));
    }
    if flags & 1 != 0 && !def.alpha {
        fail("premultiplied flag on a format without alpha".into());
    }
    if flags & !1 != 0 {
        fail(format!("undefined flags {flags:#x}"));
    }
    let dims = w(4).to_le_bytes();
    if dims != def.dims {
        fail(format!(
            "texelBlockDimensions {dims:?}, must be {:?}",
            def.dims
        ));
    }
    if w(5) != def.bytes_plane0 || w(6) != 0 {
        fail(format!(
            "bytesPlanes {:#x} {:#x}, must be {} then zeros",
            w(5),
            w(6),
            def.bytes_plane0
        ));
    }
    let nonlinear = !matches!(transfer, 0 | 1);
    for (i, want) in def.samples.iter().enumerate() {
        let s = |j: usize| w(7 + 4 * i + j);
        let (offset, length, ty) = (s(0) & 0xffff, ((s(0) >> 16) & 0xff) + 1, s(0) >> 24);
        let (id, quals) = (ty & 0xf, ty & 0xf0);
        let got = (offset, length, id, quals & !L, s(2), s(3));
        if got != *want {
            fail(format!(
                "sample {i} (offset, length, channel, qualifiers, lower, upper) = {got:?}, the \
                 format defines {want:?}"
            ));
        }
        if s(1) != 0 {
            fail(format!("sample {i} position {:#x}", s(1)));
        }
        if quals & E != 0 {
            fail(format!("sample {i} has the EXPONENT qualifier"));
        }
        let linear = quals & L != 0;
        if nonlinear && id == ALPHA && !linear {
            fail(format!(
                "sample {i} is alpha under transfer {transfer} without the LINEAR qualifier \
                 (ktx validate 6109)"
            ));
        }
        if nonlinear && id != ALPHA && linear {
            fail(format!(
                "sample {i} is not alpha but has LINEAR under transfer {transfer} (6109)"
            ));
        }
        if !nonlinear && linear {
            fail(format!(
                "sample {i} has LINEAR under a linear transfer (6108)"
            ));
        }
    }
    bad
}

const SCHEMES: [(Option<Supercompression>, u32); 3] = [
    (None, 0),
    (Some(Supercompression::Zstd(3)), 2),
    (Some(Supercompression::Zlib(6)), 3),
];

/// With `PARVO_KTX2_DFD_DUMP=DIR`, every file checked is also written to
/// DIR, to run Khronos `ktx validate` over them by hand.
fn dump(name: &str, bytes: &[u8]) {
    if let Some(dir) = std::env::var_os("PARVO_KTX2_DFD_DUMP") {
        let name: String = name
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
            .collect();
        std::fs::write(Path::new(&dir).join(format!("{name}.ktx2")), bytes).unwrap();
    }
}

fn opts(sc: Option<Supercompression>) -> SaveOptions {
    SaveOptions {
        ktx2: parvo::io::ktx2::Ktx2Options {
            supercompression: sc,
        },
        ..SaveOptions::default()
    }
}

#[test]
fn every_block_format_dfd_follows_the_ktx2_and_data_format_rules() {
    use BlockFormat::*;
    let formats = [
        Bc1,
        Bc2,
        Bc3,
        Bc4 { signed: false },
        Bc4 { signed: true },
        Bc5 { signed: false },
        Bc5 { signed: true },
        Bc6h { signed: false },
        Bc6h { signed: true },
        Bc7,
    ];
    let mut bad = Vec::new();
    let mut checked = 0;
    for format in formats {
        for srgb in [false, true] {
            for alpha in [
                AlphaMode::None,
                AlphaMode::Straight,
                AlphaMode::Premultiplied,
            ] {
                // 9×6: partial blocks, two levels' worth of whole blocks.
                let (w, h) = (9u32, 6u32);
                let levels = (0..4)
                    .map(|k| {
                        let (lw, lh) = ((w >> k).max(1), (h >> k).max(1));
                        vec![0x5Au8; format.level_bytes(lw, lh) as usize]
                    })
                    .collect();
                let chain = BlockChain {
                    format,
                    srgb,
                    alpha,
                    width: w,
                    height: h,
                    levels,
                };
                for (sc, scheme) in SCHEMES {
                    let mut out = Vec::new();
                    io::ktx2::write_blocks_to(&chain, &opts(sc), &mut out).unwrap();
                    dump(&format!("{format}_srgb{srgb}_{alpha}_sc{scheme}"), &out);
                    let v = dfd_violations(&out, scheme);
                    checked += 1;
                    bad.extend(v.into_iter().map(|m| {
                        format!("{format} srgb={srgb} alpha={alpha} scheme={scheme}: {m}")
                    }));
                }
            }
        }
    }
    assert_eq!(checked, 10 * 2 * 3 * 3);
    assert!(
        bad.is_empty(),
        "{} violations:\n{}",
        bad.len(),
        bad.join("\n")
    );
}

#[test]
fn bc3_and_bc2_srgb_files_mark_their_alpha_sample_linear() {
    // The reported case, spelled out: the vkFormat and the alpha sample's
    // LINEAR bit, read from the bytes at the offsets KTX 2.0 gives.
    for (format, vk) in [(BlockFormat::Bc3, 138), (BlockFormat::Bc2, 136)] {
        let chain = BlockChain {
            format,
            srgb: true,
            alpha: AlphaMode::Straight,
            width: 4,
            height: 4,
            levels: vec![vec![0; 16], vec![0; 16], vec![0; 16]],
        };
        let mut out = Vec::new();
        io::ktx2::write_blocks_to(&chain, &SaveOptions::default(), &mut out).unwrap();
        assert_eq!(u32_at(&out, 12), vk);
        let dfd = u32_at(&out, 48) as usize;
        let transfer = (u32_at(&out, dfd + 12) >> 16) & 0xff;
        assert_eq!(transfer, 2, "sRGB transfer");
        // Sample 0 of the basic block is the alpha block at bit 0.
        let alpha_sample = u32_at(&out, dfd + 28) >> 24;
        assert_eq!(alpha_sample & 0xf, ALPHA);
        assert_eq!(alpha_sample & L, L, "{format}: alpha sample without LINEAR");
        let colour_sample = u32_at(&out, dfd + 44) >> 24;
        assert_eq!(colour_sample, 0, "{format}: colour sample");
    }
}

fn noise_texture(w: u32, h: u32, f: Format, seed: u64) -> Texture {
    let n = (w * h) as usize * f.channels as usize;
    let mut s = seed;
    let mut next = move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 40) as u32
    };
    let texels = match f.channel_type {
        ChannelType::U8 => Texels::U8((0..n).map(|_| next() as u8).collect()),
        ChannelType::U16 => Texels::U16((0..n).map(|_| next() as u16).collect()),
        ChannelType::F16 => Texels::F16(
            (0..n)
                .map(|_| half::f16::from_f32((next() % 1000) as f32 / 999.0))
                .collect(),
        ),
        ChannelType::F32 => Texels::F32((0..n).map(|_| (next() % 1000) as f32 / 999.0).collect()),
    };
    Texture::from_texels(w, h, f, texels).unwrap()
}

#[test]
fn every_uncompressed_format_parvo_writes_follows_the_rules() {
    let mut bad = Vec::new();
    let mut seen = std::collections::BTreeSet::new();
    for ch in 1..=4u8 {
        for ty in [
            ChannelType::U8,
            ChannelType::U16,
            ChannelType::F16,
            ChannelType::F32,
        ] {
            for cs in [ColorSpace::Linear, ColorSpace::Srgb] {
                for alpha in [
                    AlphaMode::Straight,
                    AlphaMode::Premultiplied,
                    AlphaMode::None,
                ] {
                    let f = io::ktx2::storable(Format::new(ch, ty, cs).with_alpha(alpha));
                    let base = noise_texture(7, 5, f, 11);
                    let levels = parvo::mip::build(base, &parvo::MipOptions::default())
                        .unwrap()
                        .into_levels();
                    for (sc, scheme) in SCHEMES {
                        let mut out = Vec::new();
                        io::ktx2::write_to(&levels, &opts(sc), &mut out).unwrap();
                        dump(&format!("{f}_sc{scheme}"), &out);
                        seen.insert(u32_at(&out, 12));
                        bad.extend(
                            dfd_violations(&out, scheme)
                                .into_iter()
                                .map(|m| format!("{f} scheme={scheme}: {m}")),
                        );
                    }
                }
            }
        }
    }
    // Every uncompressed vkFormat of the issue is among those written.
    let want: std::collections::BTreeSet<u32> = [
        9, 15, 16, 22, 23, 29, 37, 43, 70, 77, 84, 91, 76, 83, 90, 97, 100, 103, 106, 109,
    ]
    .into_iter()
    .collect();
    assert_eq!(seen, want, "vkFormats written");
    assert!(
        bad.is_empty(),
        "{} violations:\n{}",
        bad.len(),
        bad.join("\n")
    );
}

#[test]
fn the_reported_command_writes_valid_dfds() {
    // A photo with alpha, as the user had: RGBA8 PNG (sRGB by default).
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("photo.png");
    let (w, h) = (37u32, 22u32);
    let img = image::RgbaImage::from_fn(w, h, |x, y| {
        image::Rgba([
            (x * 7) as u8,
            (y * 11) as u8,
            ((x + y) * 5) as u8,
            ((x * y) % 256) as u8,
        ])
    });
    img.save(&png).unwrap();
    for (args, scheme) in [
        (vec!["--compress", "bc3"], 0),
        (vec!["--compress", "bc3", "--zstd", "5"], 2),
        (vec!["--compress", "bc1"], 0),
        (vec!["--compress", "bc7", "--zlib", "6"], 3),
        (vec![], 0),
    ] {
        let out = dir.path().join("v.ktx2");
        let mut a = vec!["mip", s(&png), "-o", s(&out)];
        a.extend(args.iter().copied());
        ok(&parvo(&a));
        let bytes = std::fs::read(&out).unwrap();
        let v = dfd_violations(&bytes, scheme);
        assert!(v.is_empty(), "{args:?}:\n{}", v.join("\n"));
    }
}
