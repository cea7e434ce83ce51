//! Issue 17: every DDS parvo wrote had pixel-format flags 0x44
//! (`DDPF_FOURCC | DDPF_RGB`) with fourCC `DX10` and zero masks, which
//! Pillow decodes with the masks and shows as an all-black image.
//!
//! The header of every format parvo writes is checked here field by field
//! against the DDS reference (offsets and constants written out below, not
//! taken from parvo's own header code): legacy headers where DirectXTex
//! writes one, with its flags, bit counts and masks; otherwise `DDPF_FOURCC`
//! alone, fourCC `DX10`, no masks, and a DX10 extension naming the DXGI
//! format and alpha mode. Then every file is read back.

use parvo::io::dds;
use parvo::mip::{self, MipOptions};
use parvo::{AlphaMode, ChannelType, ColorSpace, Format, Texels, Texture};

const DDPF_ALPHAPIXELS: u32 = 0x1;
const DDPF_FOURCC: u32 = 0x4;
const DDPF_RGB: u32 = 0x40;
const DDPF_LUMINANCE: u32 = 0x20000;
const DX10: u32 = u32::from_le_bytes(*b"DX10");

/// What the header must say: legacy (flags, bits, masks) or fourCC-only
/// (fourCC, optional DX10 format and alpha mode), and the bytes per stored
/// texel.
#[derive(Debug)]
enum Want {
    Legacy(u32, u32, [u32; 4], usize),
    FourCc(u32, usize),
    Dx10(u32, u32, usize),
}

fn word(b: &[u8], i: usize) -> u32 {
    u32::from_le_bytes(b[i * 4..i * 4 + 4].try_into().unwrap())
}

fn texture(w: u32, h: u32, f: Format, seed: u64) -> Texture {
    let n = (w * h) as usize * f.channels as usize;
    let mut s = seed;
    let mut next = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        s >> 33
    };
    let texels = match f.channel_type {
        ChannelType::U8 => Texels::U8((0..n).map(|_| next() as u8).collect()),
        ChannelType::U16 => Texels::U16((0..n).map(|_| next() as u16).collect()),
        ChannelType::F16 => Texels::F16(
            (0..n)
                .map(|_| half::f16::from_f32((next() % 1000) as f32 / 999.0))
                .collect(),
        ),
        ChannelType::F32 => Texels::F32(
            (0..n)
                .map(|_| (next() % 100_000) as f32 / 99_999.0)
                .collect(),
        ),
    };
    Texture::from_texels(w, h, f, texels).unwrap()
}

#[test]
fn every_written_header_has_the_flags_and_masks_readers_expect() {
    use AlphaMode::{None as Data, Premultiplied as Pm, Straight as St};
    use ChannelType::*;
    use ColorSpace::{Linear as Lin, Srgb};
    // DirectXTex's DDSPF_* constants (DDS.h) and DXGI_FORMAT numbers.
    let l8 = Want::Legacy(DDPF_LUMINANCE, 8, [0xff, 0, 0, 0], 1);
    let a8l8 = Want::Legacy(
        DDPF_LUMINANCE | DDPF_ALPHAPIXELS,
        16,
        [0xff, 0, 0, 0xff00],
        2,
    );
    let x8b8g8r8 = Want::Legacy(DDPF_RGB, 32, [0xff, 0xff00, 0xff0000, 0], 4);
    let a8b8g8r8 = Want::Legacy(
        DDPF_RGB | DDPF_ALPHAPIXELS,
        32,
        [0xff, 0xff00, 0xff0000, 0xff000000],
        4,
    );
    let l16 = Want::Legacy(DDPF_LUMINANCE, 16, [0xffff, 0, 0, 0], 2);
    let g16r16 = Want::Legacy(DDPF_RGB, 32, [0xffff, 0xffff0000, 0, 0], 4);
    // DX10 alpha modes: 1 straight, 2 premultiplied, 3 opaque, 4 custom.
    let cases: Vec<(u8, ChannelType, ColorSpace, AlphaMode, Want)> = vec![
        (1, U8, Lin, St, l8),
        (2, U8, Lin, St, a8l8),
        (2, U8, Lin, Pm, Want::Dx10(49, 2, 2)),
        (2, U8, Lin, Data, Want::Dx10(49, 3, 2)),
        (3, U8, Lin, St, x8b8g8r8),
        (4, U8, Lin, St, a8b8g8r8),
        (4, U8, Lin, Pm, Want::Dx10(28, 2, 4)),
        (4, U8, Lin, Data, Want::Dx10(28, 4, 4)),
        (1, U8, Srgb, St, Want::Dx10(29, 3, 4)),
        (2, U8, Srgb, St, Want::Dx10(29, 1, 4)),
        (3, U8, Srgb, St, Want::Dx10(29, 3, 4)),
        (4, U8, Srgb, St, Want::Dx10(29, 1, 4)),
        (4, U8, Srgb, Pm, Want::Dx10(29, 2, 4)),
        (1, U16, Lin, St, l16),
        (2, U16, Lin, St, Want::Dx10(35, 1, 4)),
        (2, U16, Lin, Data, g16r16),
        (3, U16, Lin, St, Want::Dx10(11, 3, 8)),
        (4, U16, Lin, St, Want::FourCc(36, 8)),
        (4, U16, Lin, Pm, Want::Dx10(11, 2, 8)),
        (1, F16, Lin, St, Want::Dx10(54, 3, 2)),
        (2, F16, Lin, St, Want::Dx10(34, 1, 4)),
        (3, F16, Lin, St, Want::Dx10(10, 3, 8)),
        (4, F16, Lin, St, Want::Dx10(10, 1, 8)),
        (1, F32, Lin, St, Want::Dx10(41, 3, 4)),
        (2, F32, Lin, Data, Want::Dx10(16, 3, 8)),
        (3, F32, Lin, St, Want::Dx10(6, 3, 12)),
        (4, F32, Lin, Pm, Want::Dx10(2, 2, 16)),
    ];
    let (w, h) = (13u32, 6u32);
    for (i, (ch, ty, cs, alpha, want)) in cases.into_iter().enumerate() {
        let f = Format::new(ch, ty, cs).with_alpha(alpha);
        let chain = mip::build(texture(w, h, f, i as u64), &MipOptions::default()).unwrap();
        let mut b = Vec::new();
        dds::write_to(chain.levels(), &mut b).unwrap();
        let what = format!("{f}");
        assert_eq!(&b[0..4], b"DDS ", "{what}");
        assert_eq!(word(&b, 1), 124, "{what}: header size");
        // CAPS | HEIGHT | WIDTH | PITCH | PIXELFORMAT | MIPMAPCOUNT
        assert_eq!(
            word(&b, 2),
            0x1 | 0x2 | 0x4 | 0x8 | 0x1000 | 0x20000,
            "{what}: flags"
        );
        assert_eq!((word(&b, 3), word(&b, 4)), (h, w), "{what}: height, width");
        assert_eq!(word(&b, 7), 4, "{what}: mip count (13x6 → 6x3, 3x1, 1x1)");
        // TEXTURE | COMPLEX | MIPMAP
        assert_eq!(word(&b, 27), 0x1000 | 0x8 | 0x400000, "{what}: caps");
        assert_eq!(word(&b, 28), 0, "{what}: caps2");
        assert_eq!(word(&b, 19), 32, "{what}: pixel format size");
        let (pf_flags, fourcc, bits, masks) = (
            word(&b, 20),
            word(&b, 21),
            word(&b, 22),
            [word(&b, 23), word(&b, 24), word(&b, 25), word(&b, 26)],
        );
        let (texel, data_at) = match want {
            Want::Legacy(flags, wbits, wmasks, texel) => {
                assert_eq!(pf_flags, flags, "{what}: pixel format flags");
                assert_eq!(fourcc, 0, "{what}: fourCC");
                assert_eq!(bits, wbits, "{what}: bit count");
                assert_eq!(masks, wmasks, "{what}: masks");
                (texel, 128)
            }
            Want::FourCc(code, texel) => {
                assert_eq!(pf_flags, DDPF_FOURCC, "{what}: FOURCC alone");
                assert_eq!(fourcc, code, "{what}: fourCC");
                assert_eq!((bits, masks), (0, [0; 4]), "{what}: no bit count or masks");
                (texel, 128)
            }
            Want::Dx10(dxgi, mode, texel) => {
                assert_eq!(
                    pf_flags, DDPF_FOURCC,
                    "{what}: FOURCC alone, never RGB with DX10"
                );
                assert_eq!(fourcc, DX10, "{what}: fourCC");
                assert_eq!((bits, masks), (0, [0; 4]), "{what}: no bit count or masks");
                assert_eq!(word(&b, 32), dxgi, "{what}: DXGI format");
                assert_eq!(word(&b, 33), 3, "{what}: resource dimension (2-D)");
                assert_eq!(word(&b, 34), 0, "{what}: misc flag");
                assert_eq!(word(&b, 35), 1, "{what}: array size");
                assert_eq!(word(&b, 36), mode, "{what}: alpha mode");
                (texel, 148)
            }
        };
        assert_eq!(word(&b, 5) as usize, w as usize * texel, "{what}: pitch");
        let data: usize = chain.levels().iter().map(|l| l.texel_count() * texel).sum();
        assert_eq!(b.len(), data_at + data, "{what}: file size");
    }
}

#[test]
fn every_written_format_reads_back_with_its_texels() {
    let dir = tempfile::tempdir().unwrap();
    let mut i = 0;
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
                    if cs == ColorSpace::Srgb && ty != ChannelType::U8 {
                        continue; // not storable as is: converted to linear first
                    }
                    i += 1;
                    let f = Format::new(ch, ty, cs).with_alpha(alpha);
                    let chain = mip::build(texture(9, 5, f, i), &MipOptions::default()).unwrap();
                    let path = dir.path().join(format!("{i}.dds"));
                    dds::save(chain.levels(), &path).unwrap();
                    let back = dds::load(&path, &parvo::io::Limits::default()).unwrap();
                    assert_eq!(back.levels.len(), chain.len(), "{f}");
                    for (k, (a, b)) in chain.levels().iter().zip(&back.levels).enumerate() {
                        // sRGB grey, grey + alpha and RGB come back as the
                        // RGBA/RGB they were widened to; compare texels in
                        // the source's channels.
                        let bf = b.format();
                        assert_eq!(bf.channel_type, ty, "{f} level {k}");
                        assert_eq!(bf.color_space, cs, "{f} level {k}");
                        if f.has_alpha() {
                            assert_eq!(bf.alpha, f.alpha, "{f} level {k}");
                        }
                        let (la, lb) = (a.to_linear(), b.to_linear());
                        let (ca, cb) = (a.channels(), b.channels());
                        for (pa, pb) in la.chunks(ca).zip(lb.chunks(cb)) {
                            let expect: Vec<f32> = match (ca, cb, f.has_alpha()) {
                                (x, y, _) if x == y => pa.to_vec(),
                                (1, _, _) => vec![pa[0]; 3],
                                (2, _, true) => vec![pa[0], pa[0], pa[0], pa[1]],
                                (2, _, false) => vec![pa[0], pa[1], 0.0],
                                _ => pa.to_vec(),
                            };
                            assert_eq!(&pb[..expect.len()], &expect[..], "{f} level {k}");
                        }
                    }
                }
            }
        }
    }
}
