//! Issue 53: KTX2 files in the formats parvo has no texel type of its own
//! for (channels in another order, packed 4/5/6/10/12-bit fields, A8,
//! 8/16-bit UINT, SINT and SNORM) are read, converted the way KTX-Software's
//! `ktx extract` presents them; the formats still refused say so in one
//! line naming the vkFormat and what to convert it to.
//!
//! Each file is made here: random fields (fixed seed) packed into texels by
//! the Vulkan specification's bit layout for the format (written below as
//! the specification's text, `R15:11` for red in bits 15 to 11 of the
//! little-endian word), at sizes that are not multiples of anything, two
//! levels. The expected texels are computed from the same fields by the
//! rule each conversion follows, independently of parvo's tables.

use std::path::{Path, PathBuf};

use parvo::io::{self, Limits};
use parvo::texel::{AlphaMode, ChannelType, ColorSpace, Texels};

/// Deterministic pseudo-random 64-bit words (fixed seed).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        self.0 ^ (self.0 >> 29)
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    Unorm,
    Srgb,
    Uint,
    Sint,
    Snorm,
}

/// A format as the Vulkan specification describes it: its number, bytes
/// per texel, and each component's bits (`R15:11`), R, G, B, A order.
struct Spec {
    name: &'static str,
    vk: u32,
    bytes: usize,
    layout: &'static str,
    kind: Kind,
}

const fn f(name: &'static str, vk: u32, bytes: usize, layout: &'static str, kind: Kind) -> Spec {
    Spec {
        name,
        vk,
        bytes,
        layout,
        kind,
    }
}

use Kind::*;

/// Byte-ordered formats' components are given as bit ranges of the
/// little-endian texel too (byte 0 is bits 7:0).
const SPECS: &[Spec] = &[
    f("R4G4_UNORM_PACK8", 1, 1, "R7:4 G3:0", Unorm),
    f(
        "R4G4B4A4_UNORM_PACK16",
        2,
        2,
        "R15:12 G11:8 B7:4 A3:0",
        Unorm,
    ),
    f(
        "B4G4R4A4_UNORM_PACK16",
        3,
        2,
        "R7:4 G11:8 B15:12 A3:0",
        Unorm,
    ),
    f("R5G6B5_UNORM_PACK16", 4, 2, "R15:11 G10:5 B4:0", Unorm),
    f("B5G6R5_UNORM_PACK16", 5, 2, "R4:0 G10:5 B15:11", Unorm),
    f(
        "R5G5B5A1_UNORM_PACK16",
        6,
        2,
        "R15:11 G10:6 B5:1 A0:0",
        Unorm,
    ),
    f(
        "B5G5R5A1_UNORM_PACK16",
        7,
        2,
        "R5:1 G10:6 B15:11 A0:0",
        Unorm,
    ),
    f(
        "A1R5G5B5_UNORM_PACK16",
        8,
        2,
        "R14:10 G9:5 B4:0 A15:15",
        Unorm,
    ),
    f(
        "A1B5G5R5_UNORM_PACK16_KHR",
        1000470000,
        2,
        "R4:0 G9:5 B14:10 A15:15",
        Unorm,
    ),
    f(
        "A4R4G4B4_UNORM_PACK16",
        1000340000,
        2,
        "R11:8 G7:4 B3:0 A15:12",
        Unorm,
    ),
    f(
        "A4B4G4R4_UNORM_PACK16",
        1000340001,
        2,
        "R3:0 G7:4 B11:8 A15:12",
        Unorm,
    ),
    f("B8G8R8_UNORM", 30, 3, "R23:16 G15:8 B7:0", Unorm),
    f("B8G8R8_SRGB", 36, 3, "R23:16 G15:8 B7:0", Srgb),
    f("B8G8R8A8_UNORM", 44, 4, "R23:16 G15:8 B7:0 A31:24", Unorm),
    f("B8G8R8A8_SRGB", 50, 4, "R23:16 G15:8 B7:0 A31:24", Srgb),
    f(
        "A8B8G8R8_UNORM_PACK32",
        51,
        4,
        "R7:0 G15:8 B23:16 A31:24",
        Unorm,
    ),
    f(
        "A8B8G8R8_SRGB_PACK32",
        57,
        4,
        "R7:0 G15:8 B23:16 A31:24",
        Srgb,
    ),
    f(
        "A2R10G10B10_UNORM_PACK32",
        58,
        4,
        "R29:20 G19:10 B9:0 A31:30",
        Unorm,
    ),
    f(
        "A2B10G10R10_UNORM_PACK32",
        64,
        4,
        "R9:0 G19:10 B29:20 A31:30",
        Unorm,
    ),
    f("R10X6_UNORM_PACK16", 1000156007, 2, "R15:6", Unorm),
    f(
        "R10X6G10X6_UNORM_2PACK16",
        1000156008,
        4,
        "R15:6 G31:22",
        Unorm,
    ),
    f(
        "R12X4G12X4B12X4A12X4_UNORM_4PACK16",
        1000156019,
        8,
        "R15:4 G31:20 B47:36 A63:52",
        Unorm,
    ),
    f("R8_UINT", 13, 1, "R7:0", Uint),
    f("R8G8_SINT", 21, 2, "R7:0 G15:8", Sint),
    f("R8G8B8_UINT", 27, 3, "R7:0 G15:8 B23:16", Uint),
    f("R8G8B8A8_UINT", 41, 4, "R7:0 G15:8 B23:16 A31:24", Uint),
    f("R8G8B8A8_SINT", 42, 4, "R7:0 G15:8 B23:16 A31:24", Sint),
    f("B8G8R8A8_UINT", 48, 4, "R23:16 G15:8 B7:0 A31:24", Uint),
    f("B8G8R8_SINT", 35, 3, "R23:16 G15:8 B7:0", Sint),
    f("R16_SINT", 75, 2, "R15:0", Sint),
    f(
        "R16G16B16A16_UINT",
        95,
        8,
        "R15:0 G31:16 B47:32 A63:48",
        Uint,
    ),
    f("R16G16B16_SINT", 89, 6, "R15:0 G31:16 B47:32", Sint),
    f("R8_SNORM", 10, 1, "R7:0", Snorm),
    f("R8G8B8A8_SNORM", 38, 4, "R7:0 G15:8 B23:16 A31:24", Snorm),
    f("B8G8R8A8_SNORM", 45, 4, "R23:16 G15:8 B7:0 A31:24", Snorm),
    f("R16G16_SNORM", 78, 4, "R15:0 G31:16", Snorm),
];

/// (low bit, bit count) of each component of a layout.
fn fields(layout: &str) -> Vec<(u32, u32)> {
    layout
        .split(' ')
        .map(|c| {
            let (hi, lo) = c[1..].split_once(':').unwrap();
            let (hi, lo): (u32, u32) = (hi.parse().unwrap(), lo.parse().unwrap());
            (lo, hi - lo + 1)
        })
        .collect()
}

/// A `bits`-bit field widened to `to` bits by repeating its binary digits
/// from the top (KTX-Software's `convertUNORM`, which `ktx extract`
/// applies before writing PNG): 0b10110 to 8 bits is 0b10110_101.
fn widened(v: u64, bits: u32, to: u32) -> u64 {
    let digits = format!("{v:0w$b}", w = bits as usize);
    let long = digits.repeat((to / bits + 1) as usize);
    u64::from_str_radix(&long[..to as usize], 2).unwrap()
}

/// A basic Data Format Descriptor for `spec`: RGBSDA, BT.709, one sample
/// per component (alpha is channel 15).
fn dfd(spec: &Spec) -> Vec<u8> {
    let fl = fields(spec.layout);
    let block = 24 + 16 * fl.len() as u32;
    let transfer = if spec.kind == Srgb { 2 } else { 1 };
    let mut w = vec![
        4 + block,
        0,
        2 | (block << 16),
        1 | (1 << 8) | (transfer << 16),
        0,
        spec.bytes as u32,
        0,
    ];
    for (i, &(lo, bits)) in fl.iter().enumerate() {
        let id = if i == 3 || spec.name.starts_with("A8_") {
            15
        } else {
            i as u32
        };
        let signed = matches!(spec.kind, Sint | Snorm);
        let q = if signed { 0x40 } else { 0 }
            | if spec.kind == Srgb && id == 15 {
                0x10
            } else {
                0
            };
        w.push(lo | ((bits - 1) << 16) | ((id | q) << 24));
        w.push(0);
        let top = (1u64 << bits) - 1;
        let (lower, upper) = match spec.kind {
            Uint | Sint => (0, 1),
            Snorm => ((1u32 << 31).wrapping_neg() | 1, (1u32 << 31) - 1),
            _ => (0, top as u32),
        };
        w.push(lower);
        w.push(upper);
    }
    w.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// A KTX2 file of `levels` (each `(width, height, stored bytes)`), laid
/// out as KTX 2.0 section 3 says: header, index, level index, DFD, levels.
fn ktx2(vk: u32, type_size: u32, dfd: &[u8], levels: &[(u32, u32, Vec<u8>)]) -> Vec<u8> {
    let n = levels.len();
    let dfd_at = 80 + 24 * n;
    let mut at = (dfd_at + dfd.len()).next_multiple_of(8);
    let mut index = Vec::new();
    for (_, _, data) in levels {
        index.push((at, data.len()));
        at = (at + data.len()).next_multiple_of(8);
    }
    let mut b = vec![
        0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A,
    ];
    for v in [
        vk,
        type_size,
        levels[0].0,
        levels[0].1,
        0,
        0,
        1,
        n as u32,
        0,
    ] {
        b.extend(v.to_le_bytes());
    }
    for v in [dfd_at as u32, dfd.len() as u32, 0, 0] {
        b.extend(v.to_le_bytes());
    }
    b.extend([0u8; 16]);
    for &(off, len) in &index {
        for v in [off as u64, len as u64, len as u64] {
            b.extend(v.to_le_bytes());
        }
    }
    b.extend(dfd);
    for ((_, _, data), (off, _)) in levels.iter().zip(&index) {
        b.resize(*off, 0);
        b.extend(data);
    }
    b
}

/// What parvo should give for the components `codes` of one texel, as
/// f64 code values (u8/u16 codes, or SNORM values), and the channel type.
fn expected(spec: &Spec, codes: &[u64]) -> (Vec<f64>, ChannelType) {
    let fl = fields(spec.layout);
    let widest = fl.iter().map(|f| f.1).max().unwrap();
    let to = if widest > 8 { 16 } else { 8 };
    let ty = match (spec.kind, to) {
        (Snorm, _) => ChannelType::F32,
        (_, 16) => ChannelType::U16,
        _ => ChannelType::U8,
    };
    let out = codes
        .iter()
        .zip(&fl)
        .map(|(&c, &(_, bits))| {
            // The two's-complement value of a signed field.
            let signed = c as i64 - if c >> (bits - 1) == 1 { 1 << bits } else { 0 };
            match spec.kind {
                Unorm | Srgb => widened(c, bits, to) as f64,
                Uint => c as f64,
                Sint => (signed + (1 << (bits - 1))) as f64,
                // Vulkan's conversion, in f32 as parvo stores it.
                Snorm => f64::from((signed as f32 / ((1i64 << (bits - 1)) - 1) as f32).max(-1.0)),
            }
        })
        .collect();
    (out, ty)
}

fn values(t: &Texels) -> Vec<f64> {
    match t {
        Texels::U8(v) => v.iter().map(|&x| x as f64).collect(),
        Texels::U16(v) => v.iter().map(|&x| x as f64).collect(),
        Texels::F16(v) => v.iter().map(|&x| x.to_f64()).collect(),
        Texels::F32(v) => v.iter().map(|&x| x as f64).collect(),
    }
}

/// A directory of this test's own (the tests run at once, and each
/// removes its directory at the end).
fn dir(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("parvo-ktx2-{test}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn load(path: &Path) -> parvo::Result<io::Loaded> {
    io::load(path.to_str().unwrap(), &Limits::default())
}

#[test]
fn packed_swizzled_and_integer_formats_read_as_ktx_extract_presents_them() {
    let d = dir("packed");
    let mut rng = Rng(53);
    for spec in SPECS {
        let fl = fields(spec.layout);
        let mut levels = Vec::new();
        let mut want = Vec::new();
        for (w, h) in [(13u32, 7u32), (6, 3)] {
            let mut data = Vec::new();
            let mut exp = Vec::new();
            for _ in 0..w * h {
                let mut word = 0u64;
                let mut codes = Vec::new();
                for &(lo, bits) in &fl {
                    let c = rng.next() & ((1u64 << bits) - 1);
                    word |= c << lo;
                    codes.push(c);
                }
                data.extend(&word.to_le_bytes()[..spec.bytes]);
                let (e, ty) = expected(spec, &codes);
                exp.push((e, ty));
            }
            levels.push((w, h, data));
            want.push(exp);
        }
        // typeSize: the packed word's size, or one component's.
        let type_size = if spec.name.contains("PACK32") {
            4
        } else if spec.name.contains("PACK16") || fl[0].1 == 16 {
            2
        } else {
            1
        };
        let path = d.join(format!("{}.ktx2", spec.name));
        std::fs::write(&path, ktx2(spec.vk, type_size, &dfd(spec), &levels)).unwrap();
        let loaded = load(&path).unwrap_or_else(|e| panic!("{}: {e}", spec.name));
        assert_eq!(loaded.levels.len(), 2, "{}", spec.name);
        for (k, (level, exp)) in loaded.levels.iter().zip(&want).enumerate() {
            let what = format!("{} level {k}", spec.name);
            let fmt = level.format();
            assert_eq!(fmt.channels as usize, fl.len(), "{what}");
            assert_eq!(fmt.channel_type, exp[0].1, "{what}");
            let cs = if spec.kind == Srgb {
                ColorSpace::Srgb
            } else {
                ColorSpace::Linear
            };
            assert_eq!(fmt.color_space, cs, "{what}");
            match fl.len() {
                2 => assert_eq!(fmt.alpha, AlphaMode::None, "{what}: R, G data"),
                4 => assert_eq!(fmt.alpha, AlphaMode::Straight, "{what}"),
                _ => {}
            }
            let got = values(level.texels());
            let flat: Vec<f64> = exp.iter().flat_map(|e| e.0.clone()).collect();
            assert_eq!(got.len(), flat.len(), "{what}");
            for (i, (g, e)) in got.iter().zip(&flat).enumerate() {
                assert_eq!(g, e, "{what}: value {i} (texel {})", i / fl.len());
            }
        }
        let notes = loaded.info.notes.join("\n");
        match spec.kind {
            Uint | Sint => assert!(
                notes.contains(&format!("VK_FORMAT_{}", spec.name)) && notes.contains("codes"),
                "{}: notes {notes}",
                spec.name
            ),
            _ => assert!(!notes.contains("codes"), "{}: {notes}", spec.name),
        }
    }
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn widened_fields_are_within_a_code_of_the_exact_value_and_keep_the_ends() {
    // Bit replication is not rounding (a 5-bit 4 is 33, 4·255/31 = 32.9),
    // but it is never more than a code off, and 0 and all ones map to 0
    // and 255 (opaque stays opaque).
    for bits in [1u32, 2, 4, 5, 6] {
        for v in 0..1u64 << bits {
            let exact = v as f64 * 255.0 / ((1u64 << bits) - 1) as f64;
            let w = widened(v, bits, 8) as f64;
            assert!((w - exact).abs() < 1.0, "{bits}-bit {v}: {w} vs {exact}");
        }
        assert_eq!(widened(0, bits, 8), 0);
        assert_eq!(widened((1 << bits) - 1, bits, 8), 255);
    }
}

#[test]
fn a8_unorm_reads_as_grey_zero_and_alpha() {
    let d = dir("a8");
    let spec = f("A8_UNORM_KHR", 1000470001, 1, "A7:0", Unorm);
    let (w, h) = (11u32, 5u32);
    let data: Vec<u8> = (0..w * h).map(|i| (i * 37 % 256) as u8).collect();
    let path = d.join("a8.ktx2");
    std::fs::write(
        &path,
        ktx2(spec.vk, 1, &dfd(&spec), &[(w, h, data.clone())]),
    )
    .unwrap();
    let loaded = load(&path).unwrap();
    let t = &loaded.levels[0];
    // `ktx extract` writes a grey + alpha PNG with grey 0.
    assert_eq!(t.format().channels, 2);
    assert!(t.format().has_alpha());
    let want: Vec<f64> = data.iter().flat_map(|&a| [0.0, a as f64]).collect();
    assert_eq!(values(t.texels()), want);
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn formats_still_refused_say_what_to_convert_to_in_one_line() {
    let d = dir("refused");
    for (vk, name, bytes, words) in [
        (126u32, "VK_FORMAT_D32_SFLOAT", 4usize, "depth/stencil"),
        (124, "VK_FORMAT_D16_UNORM", 2, "R16_UNORM or R32_SFLOAT"),
        (157, "VK_FORMAT_ASTC_4x4_UNORM_BLOCK", 1, "R8G8B8A8"),
        (
            147,
            "VK_FORMAT_ETC2_R8G8B8_UNORM_BLOCK",
            1,
            "block-compressed",
        ),
        (
            123,
            "VK_FORMAT_E5B9G9R9_UFLOAT_PACK32",
            4,
            "R16G16B16A16_SFLOAT",
        ),
        (39, "VK_FORMAT_R8G8B8A8_USCALED", 4, "R8G8B8A8_UNORM"),
        (98, "VK_FORMAT_R32_UINT", 4, "R32G32B32A32_SFLOAT"),
        (127, "VK_FORMAT_S8_UINT", 1, "stencil"),
        (
            67,
            "VK_FORMAT_A2B10G10R10_SSCALED_PACK32",
            4,
            "R16G16B16A16_UNORM",
        ),
        (1000156000, "VK_FORMAT_G8B8G8R8_422_UNORM", 4, "4:2:2"),
    ] {
        let spec = f("X", vk, bytes, "R7:0", Unorm);
        let path = d.join(format!("{vk}.ktx2"));
        let data = vec![0u8; 16 * 16 * bytes];
        std::fs::write(&path, ktx2(vk, 1, &dfd(&spec), &[(8, 8, data)])).unwrap();
        let e = match load(&path) {
            Ok(_) => panic!("{name} was read"),
            Err(e) => e.to_string(),
        };
        assert!(e.contains(&format!("{name} ({vk})")), "{e}");
        assert!(e.contains(words) && e.contains("first"), "{e}");
        assert!(!e.contains('\n'), "{e}");
    }
    std::fs::remove_dir_all(&d).ok();
}
