//! `parvo`'s DDS reader on files other tools write: every header below is
//! built byte by byte in the test, after the DDS reference, with the
//! texels it must decode to written out by hand.

use parvo::io::{self, Limits};
use parvo::{AlphaMode, ColorSpace, Texels};

const DDPF_ALPHAPIXELS: u32 = 0x1;
const DDPF_FOURCC: u32 = 0x4;
const DDPF_RGB: u32 = 0x40;
const DDPF_LUMINANCE: u32 = 0x20000;

/// Magic + 124-byte header; `mips` = (count, with the MIPMAPCOUNT flag).
fn header(w: u32, h: u32, mips: (u32, bool), pf: (u32, u32, u32, [u32; 4]), caps2: u32) -> Vec<u8> {
    let mut v: Vec<u32> = vec![u32::from_le_bytes(*b"DDS "), 124];
    let flags = 0x1 | 0x2 | 0x4 | 0x1000 | if mips.1 { 0x20000 } else { 0 };
    v.extend([flags, h, w, 0, 0, mips.0]);
    v.extend([0; 11]);
    v.extend([32, pf.0, pf.1, pf.2]);
    v.extend(pf.3);
    v.extend([0x1000, caps2, 0, 0, 0]);
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

fn dx10(dxgi: u32, misc: u32, array: u32, alpha_mode: u32) -> Vec<u8> {
    [dxgi, 3, misc, array, alpha_mode]
        .iter()
        .flat_map(|x| x.to_le_bytes())
        .collect()
}

fn load(bytes: &[u8]) -> parvo::Result<io::Loaded> {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("t.dds");
    std::fs::write(&p, bytes).unwrap();
    io::load(p.to_str().unwrap(), &Limits::default())
}

fn u8s(t: &parvo::Texture) -> Vec<u8> {
    match t.texels() {
        Texels::U8(v) => v.clone(),
        other => panic!("expected u8 texels, got {:?}", other.channel_type()),
    }
}

#[test]
fn pillow_l8_with_its_out_of_texel_mask_reads_as_grey() {
    // Pillow 13 writes L with masks ff000000 (outside the 8-bit texel).
    let mut b = header(
        3,
        1,
        (0, false),
        (
            DDPF_LUMINANCE,
            0,
            8,
            [0xff00_0000, 0xff00_0000, 0xff00_0000, 0],
        ),
        0,
    );
    b.extend([0, 128, 255]);
    let l = load(&b).unwrap();
    assert_eq!(l.base().channels(), 1);
    assert_eq!(u8s(l.base()), vec![0, 128, 255]);
}

#[test]
fn pillow_la_reads_as_grey_and_straight_alpha() {
    // Pillow writes LA with masks ff, ff, ff, ff000000 (alpha outside the
    // 16-bit texel); the bytes are L then A.
    let mut b = header(
        2,
        1,
        (0, false),
        (
            DDPF_LUMINANCE | DDPF_ALPHAPIXELS,
            0,
            16,
            [0xff, 0xff, 0xff, 0xff00_0000],
        ),
        0,
    );
    b.extend([10, 200, 20, 100]);
    let l = load(&b).unwrap();
    let f = l.base().format();
    assert_eq!(
        (f.channels, f.has_alpha(), f.alpha),
        (2, true, AlphaMode::Straight)
    );
    assert_eq!(u8s(l.base()), vec![10, 200, 20, 100]);
}

#[test]
fn bgr24_and_bgra32_masks_are_reordered_to_rgb() {
    // Pillow's RGB: 24-bit B, G, R in memory.
    let mut b = header(
        1,
        1,
        (1, true),
        (DDPF_RGB, 0, 24, [0xff0000, 0xff00, 0xff, 0]),
        0,
    );
    b.extend([3, 2, 1]);
    assert_eq!(u8s(load(&b).unwrap().base()), vec![1, 2, 3]);
    // D3DFMT_A8R8G8B8: B, G, R, A in memory.
    let mut b = header(
        1,
        1,
        (1, true),
        (
            DDPF_RGB | DDPF_ALPHAPIXELS,
            0,
            32,
            [0xff0000, 0xff00, 0xff, 0xff00_0000],
        ),
        0,
    );
    b.extend([3, 2, 1, 4]);
    assert_eq!(u8s(load(&b).unwrap().base()), vec![1, 2, 3, 4]);
}

#[test]
fn r5g6b5_channels_scale_to_eight_bits() {
    let mut b = header(
        2,
        1,
        (1, true),
        (DDPF_RGB, 0, 16, [0xf800, 0x07e0, 0x001f, 0]),
        0,
    );
    // (31, 63, 0) and (16, 32, 1): round(v · 255 / max).
    let px = |r: u16, g: u16, bl: u16| (r << 11 | g << 5 | bl).to_le_bytes();
    b.extend(px(31, 63, 0));
    b.extend(px(16, 32, 1));
    assert_eq!(
        u8s(load(&b).unwrap().base()),
        vec![255, 255, 0, 132, 130, 8]
    );
}

#[test]
fn dxt1_chain_decodes_every_level() {
    // 8x8 with 4 levels: 4 + 1 + 1 + 1 blocks of 8 bytes. Each block is a
    // solid colour: c0 = c1 = the level's 565 colour, indices 0.
    let mut b = header(
        8,
        8,
        (4, true),
        (DDPF_FOURCC, u32::from_le_bytes(*b"DXT1"), 0, [0; 4]),
        0,
    );
    let colours: [u16; 4] = [0xF800, 0x07E0, 0x001F, 0xFFFF];
    for (k, &c) in colours.iter().enumerate() {
        let blocks = if k == 0 { 4 } else { 1 };
        for _ in 0..blocks {
            b.extend(c.to_le_bytes());
            b.extend(c.to_le_bytes());
            b.extend([0u8; 4]);
        }
    }
    let l = load(&b).unwrap();
    assert_eq!(l.levels.len(), 4);
    let want = [
        [255, 0, 0, 255],
        [0, 255, 0, 255],
        [0, 0, 255, 255],
        [255, 255, 255, 255],
    ];
    for (k, lv) in l.levels.iter().enumerate() {
        assert_eq!(lv.width(), 8 >> k);
        let v = u8s(lv);
        assert!(
            v.chunks(4).all(|p| p == want[k]),
            "level {k}: {:?}",
            &v[..4]
        );
    }
    assert_eq!(l.info.attribute("dds:compression"), Some("BC1"));
}

#[test]
fn a_mip_count_without_its_flag_and_without_data_is_one_level() {
    let mut b = header(4, 4, (3, false), (DDPF_LUMINANCE, 0, 8, [0xff, 0, 0, 0]), 0);
    b.extend([7u8; 16]);
    assert_eq!(load(&b).unwrap().levels.len(), 1);
    // With the flag, the missing levels are an error that says where.
    let mut b = header(4, 4, (3, true), (DDPF_LUMINANCE, 0, 8, [0xff, 0, 0, 0]), 0);
    b.extend([7u8; 16]);
    let e = load(&b).unwrap_err().to_string();
    assert!(e.contains("ends inside level 1"), "{e}");
}

#[test]
fn dx10_bgra_srgb_and_d3dx_half_fourcc_read_their_values() {
    let mut b = header(
        1,
        1,
        (1, true),
        (DDPF_FOURCC, u32::from_le_bytes(*b"DX10"), 0, [0; 4]),
        0,
    );
    b.extend(dx10(91, 0, 1, 1)); // B8G8R8A8_UNORM_SRGB, straight
    b.extend([30, 20, 10, 40]);
    let l = load(&b).unwrap();
    assert_eq!(l.base().format().color_space, ColorSpace::Srgb);
    assert_eq!(u8s(l.base()), vec![10, 20, 30, 40]);
    // D3DFMT_A16B16G16R16F (fourCC 113).
    let mut b = header(1, 1, (1, true), (DDPF_FOURCC, 113, 0, [0; 4]), 0);
    for v in [0.5f32, -2.0, 1000.0, 1.0] {
        b.extend(half::f16::from_f32(v).to_le_bytes());
    }
    let l = load(&b).unwrap();
    assert_eq!(l.base().to_linear(), vec![0.5, -2.0, 1000.0, 1.0]);
    // An opaque DX10 RGBA comes back as RGB.
    let mut b = header(
        1,
        1,
        (1, true),
        (DDPF_FOURCC, u32::from_le_bytes(*b"DX10"), 0, [0; 4]),
        0,
    );
    b.extend(dx10(28, 0, 1, 3));
    b.extend([1, 2, 3, 255]);
    let l = load(&b).unwrap();
    assert_eq!(u8s(l.base()), vec![1, 2, 3]);
    // R8G8 with an unknown alpha mode is R, G data, not grey + alpha.
    let mut b = header(
        1,
        1,
        (1, true),
        (DDPF_FOURCC, u32::from_le_bytes(*b"DX10"), 0, [0; 4]),
        0,
    );
    b.extend(dx10(49, 0, 1, 0));
    b.extend([1, 2]);
    assert!(!load(&b).unwrap().base().format().has_alpha());
}

#[test]
fn what_parvo_cannot_read_is_named() {
    let cases: Vec<(Vec<u8>, &str)> = vec![
        (
            [
                header(
                    4,
                    4,
                    (1, true),
                    (DDPF_LUMINANCE, 0, 8, [0xff, 0, 0, 0]),
                    0x200 | 0xfc00,
                ),
                vec![0; 96],
            ]
            .concat(),
            "a cube map of six",
        ),
        (
            [
                header(
                    4,
                    4,
                    (1, true),
                    (DDPF_FOURCC, u32::from_le_bytes(*b"DX10"), 0, [0; 4]),
                    0,
                ),
                dx10(28, 0, 2, 0),
                vec![0; 128],
            ]
            .concat(),
            "a 2-D array of 2",
        ),
        (
            [
                header(
                    4,
                    4,
                    (1, true),
                    (DDPF_FOURCC, u32::from_le_bytes(*b"DX10"), 0, [0; 4]),
                    0,
                ),
                dx10(24, 0, 1, 0),
                vec![0; 64],
            ]
            .concat(),
            "DXGI format R10G10B10A2_UNORM (24)",
        ),
        (
            [
                header(
                    4,
                    4,
                    (1, true),
                    (DDPF_FOURCC, u32::from_le_bytes(*b"RXGB"), 0, [0; 4]),
                    0,
                ),
                vec![0; 16],
            ]
            .concat(),
            "fourCC `RXGB`",
        ),
        (
            [
                header(4, 4, (1, true), (DDPF_RGB, 0, 12, [0xf, 0xf0, 0xf00, 0]), 0),
                vec![0; 24],
            ]
            .concat(),
            "12 bits per texel",
        ),
        (
            header(
                4,
                4,
                (1, true),
                (DDPF_RGB, 0, 32, [0xff, 0xff00, 0xff0000, 0]),
                0,
            ),
            "ends inside level 0",
        ),
    ];
    for (bytes, want) in cases {
        let e = load(&bytes).unwrap_err().to_string();
        assert!(e.contains(want), "expected `{want}` in: {e}");
    }
}
