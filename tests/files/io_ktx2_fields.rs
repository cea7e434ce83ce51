//! Our hand-written KTX2 writer, read back by the `ktx2` crate and checked
//! field by field against the KTX 2.0 specification (header, level index
//! and alignment, Data Format Descriptor, key/value data).

use parvo::io::{self, SaveOptions};
use parvo::mip::{self, MipOptions};
use parvo::texel::{AlphaMode, ChannelType, ColorSpace, Format};
use parvo::{Texture, Wrap, WrapMode};

/// Deterministic pseudo-random bytes (fixed seed).
fn noise(n: usize, seed: u64) -> Vec<u8> {
    let mut s = seed;
    (0..n)
        .map(|_| {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 56) as u8
        })
        .collect()
}

fn chain_of(format: Format, w: u32, h: u32) -> Vec<Texture> {
    let base8 = Texture::from_u8(
        w,
        h,
        Format::new(format.channels, ChannelType::U8, format.color_space),
        noise((w * h) as usize * format.channels as usize, 7),
    )
    .unwrap();
    let base = base8.convert(format).unwrap();
    mip::build(base, &MipOptions::default())
        .unwrap()
        .into_levels()
}

fn write(levels: &[Texture], opts: &SaveOptions) -> Vec<u8> {
    let mut out = Vec::new();
    io::ktx2::write_to(levels, opts, &mut out).unwrap();
    out
}

#[test]
fn ktx2_header_level_index_and_dfd_match_the_specification() {
    use ChannelType::*;
    use ColorSpace::*;
    let cases = [
        (1, U8, Linear, 9u32),
        (2, U8, Linear, 16),
        (3, U8, Srgb, 29),
        (4, U8, Srgb, 43),
        (4, U8, Linear, 37),
        (1, U16, Linear, 70),
        (4, U16, Linear, 91),
        (3, F16, Linear, 90),
        (4, F16, Linear, 97),
        (1, F32, Linear, 100),
        (4, F32, Linear, 109),
    ];
    for (ch, ty, cs, vk) in cases {
        // Two channels are R, G data: Vulkan has no grey + alpha format.
        let format = if ch == 2 {
            Format::new(ch, ty, cs).with_alpha(AlphaMode::None)
        } else {
            Format::new(ch, ty, cs)
        };
        let levels = chain_of(format, 37, 20);
        let opts = SaveOptions {
            wrap: Wrap {
                u: WrapMode::Repeat,
                v: WrapMode::ClampToEdge,
            },
            fingerprint: Some("0123abcd".into()),
            ..SaveOptions::default()
        };
        let bytes = write(&levels, &opts);
        let r = ktx2::Reader::new(bytes.as_slice()).expect("ktx2 crate accepts our file");
        let h = r.header();
        let what = format!("{format}");
        assert_eq!(h.format.map(|f| f.value()), Some(vk), "{what}");
        assert_eq!(h.type_size, ty.bytes() as u32, "{what}");
        assert_eq!((h.pixel_width, h.pixel_height), (37, 20), "{what}");
        assert_eq!(
            (h.pixel_depth, h.layer_count, h.face_count),
            (0, 0, 1),
            "{what}"
        );
        assert_eq!(h.level_count as usize, levels.len(), "{what}");
        assert_eq!(h.level_count, 6, "37x20 has 6 levels down to 1x1");
        assert!(h.supercompression_scheme.is_none());
        assert_eq!((h.index.sgd_byte_offset, h.index.sgd_byte_length), (0, 0));

        // Level index: level 0 first, data smallest level first, each
        // level aligned to lcm(texel size, 4), lengths exact.
        let texel = format.texel_bytes() as u64;
        let align = (1..=texel * 4)
            .find(|m| m.is_multiple_of(texel) && m.is_multiple_of(4))
            .unwrap();
        let mut prev_offset = u64::MAX;
        for (k, lvl) in levels.iter().enumerate() {
            let at = 80 + 24 * k;
            let word = |i: usize| {
                u64::from_le_bytes(bytes[at + 8 * i..at + 8 * i + 8].try_into().unwrap())
            };
            let (off, len, ulen) = (word(0), word(1), word(2));
            assert_eq!(
                off % align,
                0,
                "{what} level {k} offset {off} not aligned to {align}"
            );
            assert_eq!(len, lvl.byte_len() as u64);
            assert_eq!(ulen, len);
            assert!(off < prev_offset, "levels are stored smallest first");
            prev_offset = off;
        }
        // Texels round-trip exactly.
        for (k, (data, lvl)) in r.levels().zip(&levels).enumerate() {
            assert_eq!(data.data, &*io::le_bytes(lvl.texels()), "{what} level {k}");
        }

        // DFD: identical to the one the ktx2 crate generates for the format.
        let dfd_at = h.index.dfd_byte_offset as usize;
        let dfd_len = h.index.dfd_byte_length as usize;
        assert_eq!(dfd_at, 80 + 24 * levels.len());
        let total = u32::from_le_bytes(bytes[dfd_at..dfd_at + 4].try_into().unwrap()) as usize;
        assert_eq!(total, dfd_len);
        let (basic, _) = ktx2::dfd::Basic::from_format(h.format.unwrap()).unwrap();
        let reference = ktx2::dfd::Block::Basic(basic).to_vec();
        assert_eq!(
            &bytes[dfd_at + 4..dfd_at + dfd_len],
            reference.as_slice(),
            "{what} DFD"
        );
        let b = r.basic_dfd().expect("basic DFD block");
        assert_eq!(b.sample_information.len(), ch as usize);
        assert_eq!(
            r.transfer_function(),
            Some(if cs == Srgb {
                ktx2::TransferFunction::SRGB
            } else {
                ktx2::TransferFunction::Linear
            })
        );

        // Key/value data: sorted, with orientation, writer and fingerprint.
        let kv: Vec<(String, Vec<u8>)> = r
            .key_value_data()
            .map(|(k, v)| (k.to_string(), v.to_vec()))
            .collect();
        let keys: Vec<&str> = kv.iter().map(|(k, _)| k.as_str()).collect();
        let mut sorted = keys.clone();
        sorted.sort();
        assert_eq!(keys, sorted, "keys must be sorted");
        let get = |key: &str| kv.iter().find(|(k, _)| k == key).map(|(_, v)| v.clone());
        assert_eq!(get("KTXorientation").unwrap(), b"rd\0");
        assert!(r.writer().unwrap().starts_with("parvo"));
        assert_eq!(get("parvo:fingerprint").unwrap(), b"0123abcd\0");
        assert_eq!(get("parvo:wrapmodes").unwrap(), b"periodic,clamp\0");
    }
}

#[test]
fn premultiplied_alpha_sets_the_dfd_flag_and_reads_back() {
    let f =
        Format::new(4, ChannelType::U8, ColorSpace::Linear).with_alpha(AlphaMode::Premultiplied);
    let levels = chain_of(f, 8, 8);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("p.ktx2");
    io::save(
        &levels,
        parvo::Rounding::Down,
        &path,
        io::OutputKind::KTX2,
        &SaveOptions::default(),
    )
    .unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let r = ktx2::Reader::new(bytes.as_slice()).unwrap();
    assert_eq!(r.is_alpha_premultiplied(), Some(true));
    let back = io::load(path.to_str().unwrap(), &io::Limits::default()).unwrap();
    assert_eq!(back.levels, levels);
}

/// A 1-D texture (KTX2 `pixelHeight` 0) is said as 1-D and stays 1-D:
/// `parvo mip` of it writes `pixelHeight` 0 and a one-letter
/// `KTXorientation` (KTX 2.0 sections 3.4 and 5.4), every level one row
/// (issue 53: it was read as a 2-D texture of height 1 and written so).
#[test]
fn one_d_textures_stay_one_d() {
    let dir = tempfile::tempdir().unwrap();
    let w = 37u32;
    let row = Texture::from_u8(
        w,
        1,
        Format::new(4, ChannelType::U8, ColorSpace::Srgb),
        noise(w as usize * 4, 0x1d),
    )
    .unwrap();
    let mut bytes = write(&[row], &SaveOptions::default());
    // pixelHeight (bytes 24..28) 0: the same level sizes, a 1-D texture.
    assert_eq!(u32::from_le_bytes(bytes[24..28].try_into().unwrap()), 1);
    bytes[24..28].copy_from_slice(&0u32.to_le_bytes());
    let src = dir.path().join("row.ktx2");
    std::fs::write(&src, &bytes).unwrap();
    let loaded = parvo::io::load(src.to_str().unwrap(), &Default::default()).unwrap();
    assert!(loaded.info.one_d);
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_parvo"))
        .args(["info", src.to_str().unwrap()])
        .output()
        .unwrap();
    let info = String::from_utf8_lossy(&o.stdout);
    assert!(info.contains("kind:       1-D"), "{info}");
    let out = dir.path().join("out.ktx2");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_parvo"))
        .args(["mip", src.to_str().unwrap(), "-o", out.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let b = std::fs::read(&out).unwrap();
    let r = ktx2::Reader::new(&b[..]).unwrap();
    let h = r.header();
    assert_eq!((h.pixel_width, h.pixel_height), (w, 0));
    // 37 → 18 → 9 → 4 → 2 → 1: six levels, each one row.
    assert_eq!(h.level_count, 6);
    for (k, level) in r.levels().enumerate() {
        let lw = (w >> k).max(1) as usize;
        assert_eq!(level.data.len(), lw * 4, "level {k}");
    }
    let orientation = r
        .key_value_data()
        .find(|(k, _)| *k == "KTXorientation")
        .map(|(_, v)| {
            String::from_utf8_lossy(v)
                .trim_end_matches('\0')
                .to_string()
        });
    assert_eq!(orientation.as_deref(), Some("r"));
    let back = parvo::io::load(out.to_str().unwrap(), &Default::default()).unwrap();
    assert!(back.info.one_d);
}
