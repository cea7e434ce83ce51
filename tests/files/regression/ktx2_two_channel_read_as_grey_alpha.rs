//! Issue 27 #5: two-channel KTX2 files (`R8G8_UNORM`, `R16G16_UNORM`,
//! plain and zstd: KTX-Software-CTS's `valid_R8G8_UNORM_2D.ktx2`,
//! `valid_R16G16_UNORM_2D.ktx2`, `large_R8G8_UNORM_2D_ZSTD.ktx2`) were read
//! as grey + alpha: `parvo info` showed channel 0's mean as R×G (0.2469
//! for a mean of 0.498), and DDS output was written `LUMINANCE|ALPHAPIXELS`.
//! Vulkan's two-channel formats are R, G data. The other way round, grey +
//! alpha must stay grey + alpha through KTX2, which has no such format.
//!
//! The expected values are the files' own bytes, read here from the level
//! index at the offsets KTX 2.0 gives (zstd levels inflated with the `zstd`
//! crate), not through parvo.

use std::path::{Path, PathBuf};

use parvo::io::{self, Limits};

use super::util::{ok, parvo, parvo_stdin, s};

fn peer(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/peer")
        .join(name)
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap())
}

fn u64_at(b: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(b[at..at + 8].try_into().unwrap())
}

/// Level 0 of a KTX2 file as normalised channel values, from its bytes:
/// (width, height, values R,G,R,G,…).
fn level0_from_bytes(path: &Path, bytes_per_channel: usize) -> (u32, u32, Vec<f64>) {
    let b = std::fs::read(path).unwrap();
    let (w, h) = (u32_at(&b, 20), u32_at(&b, 24));
    let scheme = u32_at(&b, 44);
    let (off, len, ulen) = (u64_at(&b, 80), u64_at(&b, 88), u64_at(&b, 96));
    let stored = &b[off as usize..(off + len) as usize];
    let raw = match scheme {
        0 => stored.to_vec(),
        2 => zstd::bulk::decompress(stored, ulen as usize).unwrap(),
        s => panic!("scheme {s}"),
    };
    let vals = match bytes_per_channel {
        1 => raw.iter().map(|&v| v as f64 / 255.0).collect(),
        _ => raw
            .chunks_exact(2)
            .map(|c| u16::from_le_bytes([c[0], c[1]]) as f64 / 65535.0)
            .collect(),
    };
    (w, h, vals)
}

const FILES: [(&str, usize, u32); 3] = [
    ("cts_valid_R8G8_UNORM_2D.ktx2", 1, 16),
    ("cts_valid_R16G16_UNORM_2D.ktx2", 2, 77),
    ("cts_large_R8G8_UNORM_2D_ZSTD.ktx2", 1, 16),
];

#[test]
fn two_channel_ktx2_is_read_as_r_g_data() {
    for (name, bpc, _) in FILES {
        let path = peer(name);
        let (w, h, want) = level0_from_bytes(&path, bpc);
        let l = io::load(s(&path), &Limits::default()).unwrap();
        let f = l.levels[0].format();
        assert_eq!(f.channels, 2, "{name}");
        assert!(!f.has_alpha(), "{name}: read as grey + alpha ({f})");
        assert_eq!(l.info.channel_names, ["R", "G"], "{name}");
        let got = l.levels[0].to_linear();
        assert_eq!(got.len(), (w * h * 2) as usize);
        for (i, (g, e)) in got.iter().zip(&want).enumerate() {
            assert!((*g as f64 - e).abs() < 1e-6, "{name} value {i}: {g} != {e}");
        }
        // `parvo info`: the means of R and G are the files' own.
        let info: serde_json::Value =
            serde_json::from_str(&ok(&parvo(&["info", "--json", s(&path)]))).unwrap();
        let mean = &info["levels"][0]["mean"];
        for c in 0..2 {
            let m: f64 = want.iter().skip(c).step_by(2).sum::<f64>() / (w * h) as f64;
            let got = mean[c].as_f64().unwrap();
            assert!((got - m).abs() < 1e-3, "{name} mean {c}: {got} != {m}");
        }
        // `parvo sample`, nearest, at each texel centre of level 0 of row 0.
        let queries: String = (0..w)
            .map(|x| {
                format!(
                    "{} {} 0 0 0 0\n",
                    (x as f64 + 0.5) / w as f64,
                    0.5 / h as f64
                )
            })
            .collect();
        let out = ok(&parvo_stdin(
            &["sample", s(&path), "--filter", "nearest"],
            &queries,
        ));
        for (x, line) in out.lines().enumerate() {
            let v: Vec<f64> = line
                .split_whitespace()
                .map(|t| t.parse().unwrap())
                .collect();
            assert_eq!(v.len(), 2, "{name}: {line}");
            for c in 0..2 {
                let e = want[x * 2 + c];
                assert!((v[c] - e).abs() < 1e-6, "{name} sample x={x} c={c}: {line}");
            }
        }
    }
}

#[test]
fn two_channel_ktx2_stays_two_data_channels_in_every_output() {
    let dir = tempfile::tempdir().unwrap();
    for (name, bpc, vk) in FILES {
        let path = peer(name);
        let (w, h, want) = level0_from_bytes(&path, bpc);
        let n = (w * h) as usize;
        // DDS: the DX10 R8G8_UNORM (49) or the legacy G16R16 (DDPF_RGB,
        // masks ffff / ffff0000), never LUMINANCE|ALPHAPIXELS.
        let dds = dir.path().join("o.dds");
        ok(&parvo(&["mip", s(&path), "-o", s(&dds)]));
        let b = std::fs::read(&dds).unwrap();
        let flags = u32_at(&b, 80);
        assert_eq!(
            flags & 0x20000,
            0,
            "{name}: DDS flags {flags:#x} say luminance"
        );
        assert_eq!(flags & 0x1, 0, "{name}: DDS flags {flags:#x} say alpha");
        let data_at = if bpc == 1 {
            assert_eq!(&b[84..88], b"DX10", "{name}");
            assert_eq!(u32_at(&b, 128), 49, "{name}: DXGI format");
            148
        } else {
            assert_eq!(flags, 0x40, "{name}: DDPF_RGB");
            assert_eq!(
                [
                    u32_at(&b, 92),
                    u32_at(&b, 96),
                    u32_at(&b, 100),
                    u32_at(&b, 104)
                ],
                [0xffff, 0xffff_0000, 0, 0],
                "{name}: G16R16 masks"
            );
            128
        };
        let raw = &b[data_at..data_at + n * 2 * bpc];
        let (_, _, again) = {
            let vals: Vec<f64> = if bpc == 1 {
                raw.iter().map(|&v| v as f64 / 255.0).collect()
            } else {
                raw.chunks_exact(2)
                    .map(|c| u16::from_le_bytes([c[0], c[1]]) as f64 / 65535.0)
                    .collect()
            };
            (w, h, vals)
        };
        assert_eq!(again, want, "{name}: DDS level 0");

        // KTX2: the same vkFormat and bytes.
        let k = dir.path().join("o.ktx2");
        ok(&parvo(&["mip", s(&path), "-o", s(&k)]));
        assert_eq!(u32_at(&std::fs::read(&k).unwrap(), 12), vk, "{name}");
        assert_eq!(level0_from_bytes(&k, bpc).2, want, "{name}: KTX2 level 0");

        // EXR: channels R and G (read with the exr crate).
        let e = dir.path().join("o.exr");
        ok(&parvo(&["mip", s(&path), "-o", s(&e)]));
        let img = exr::prelude::read_all_flat_layers_from_file(&e).unwrap();
        let names: Vec<String> = img.layer_data[0]
            .channel_data
            .list
            .iter()
            .map(|c| c.name.to_string())
            .collect();
        assert_eq!(names, ["G", "R"], "{name}: EXR channels (sorted)");

        // PNG levels: RGB with B = 0 and R, G the source's codes.
        let tpl = dir.path().join("l_{level}.png");
        ok(&parvo(&["mip", s(&path), "-o", s(&tpl)]));
        let png = image::open(dir.path().join("l_0.png")).unwrap();
        assert_eq!(png.color().channel_count(), 3, "{name}: PNG");
        let rgb = png.to_rgb16();
        for (i, px) in rgb.pixels().enumerate() {
            for c in 0..2 {
                let e = want[i * 2 + c];
                let tol = if bpc == 1 { 0.5 / 255.0 } else { 0.5 / 65535.0 };
                assert!(
                    (px[c] as f64 / 65535.0 - e).abs() <= tol + 1e-9,
                    "{name}: PNG texel {i} channel {c}"
                );
            }
            assert_eq!(px[2], 0, "{name}: PNG blue");
        }
    }
}

#[test]
fn grey_alpha_stays_grey_alpha_through_ktx2() {
    // A linear grey + alpha source (an EXR with Y and A, written with the
    // exr crate): KTX2 has no grey + alpha format, so it is stored RGBA
    // (grey in R, G, B) and reads back with its alpha.
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (5usize, 3usize);
    let y: Vec<f32> = (0..w * h).map(|i| i as f32 / 20.0).collect();
    let a: Vec<f32> = (0..w * h).map(|i| 1.0 - i as f32 / 16.0).collect();
    let src = dir.path().join("ya.exr");
    super::util::write_exr(&src, &[("Y", y.clone()), ("A", a.clone())], w, h);
    let k = dir.path().join("ya.ktx2");
    ok(&parvo(&["mip", s(&src), "-o", s(&k), "--type", "f32"]));
    let b = std::fs::read(&k).unwrap();
    assert_eq!(u32_at(&b, 12), 109, "R32G32B32A32_SFLOAT");
    let off = u64_at(&b, 80) as usize;
    for i in 0..w * h {
        let px: Vec<f32> = (0..4)
            .map(|c| f32::from_le_bytes(b[off + 16 * i + 4 * c..][..4].try_into().unwrap()))
            .collect();
        // OpenEXR's colour is premultiplied; KTX2 keeps it so (DFD flag).
        assert_eq!([px[0], px[1], px[2]], [y[i]; 3], "texel {i}");
        assert_eq!(px[3], a[i], "texel {i} alpha");
    }
    let back = io::load(s(&k), &Limits::default()).unwrap();
    assert!(back.levels[0].format().has_alpha());
    assert_eq!(
        back.levels[0].format().alpha,
        parvo::AlphaMode::Premultiplied
    );
}

#[test]
fn ktxswizzle_rrrg_is_luminance_alpha() {
    // KTX 2.0's own luminance + alpha: R8G8_UNORM with KTXswizzle `rrrg`
    // (section "KTXswizzle", Common Mappings). The CTS file's bytes with
    // the key added, written here by hand.
    let src = std::fs::read(peer("cts_valid_R8G8_UNORM_2D.ktx2")).unwrap();
    let kvd_at = u32_at(&src, 56) as usize;
    let kvd_len = u32_at(&src, 60) as usize;
    assert_eq!(u64_at(&src, 64), 0, "no supercompression global data");
    // The key/value data again with `KTXswizzle` added, sorted by key and
    // each entry padded to 4 bytes (KTX 2.0 section "Key/Value Data").
    let mut pairs: Vec<(Vec<u8>, Vec<u8>)> = ktx2::Reader::new(src.as_slice())
        .unwrap()
        .key_value_data()
        .map(|(k, v)| (k.as_bytes().to_vec(), v.to_vec()))
        .collect();
    pairs.push((b"KTXswizzle".to_vec(), b"rrrg\0".to_vec()));
    pairs.sort();
    let mut kvd = Vec::new();
    for (k, v) in &pairs {
        let len = k.len() + 1 + v.len();
        kvd.extend_from_slice(&(len as u32).to_le_bytes());
        kvd.extend_from_slice(k);
        kvd.push(0);
        kvd.extend_from_slice(v);
        while kvd.len() % 4 != 0 {
            kvd.push(0);
        }
    }
    // The levels follow the key/value data and move by the difference (a
    // multiple of 4, so they stay aligned for R8G8).
    let shift = kvd.len() as i64 - kvd_len as i64;
    assert_eq!(shift % 4, 0);
    let mut out = src[..kvd_at].to_vec();
    out.extend_from_slice(&kvd);
    out.extend_from_slice(&src[kvd_at + kvd_len..]);
    out[60..64].copy_from_slice(&(kvd.len() as u32).to_le_bytes());
    let levels = u32_at(&src, 40).max(1) as usize;
    for k in 0..levels {
        let at = 80 + 24 * k;
        let off = (u64_at(&src, at) as i64 + shift) as u64;
        out[at..at + 8].copy_from_slice(&off.to_le_bytes());
    }
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("la.ktx2");
    std::fs::write(&p, &out).unwrap();
    // The ktx2 crate reads the edited file and finds the key.
    let r = ktx2::Reader::new(out.as_slice()).unwrap();
    assert!(
        r.key_value_data()
            .any(|(k, v)| k == "KTXswizzle" && v == b"rrrg\0")
    );
    let l = io::load(s(&p), &Limits::default()).unwrap();
    let f = l.levels[0].format();
    assert_eq!(f.channels, 2);
    assert!(f.has_alpha(), "rrrg is grey + alpha: {f}");
    let (_, _, want) = level0_from_bytes(&peer("cts_valid_R8G8_UNORM_2D.ktx2"), 1);
    let got: Vec<f64> = match l.levels[0].texels() {
        parvo::Texels::U8(v) => v.iter().map(|&x| x as f64 / 255.0).collect(),
        t => panic!("{:?}", t.channel_type()),
    };
    assert_eq!(got, want);
}
