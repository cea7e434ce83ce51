//! Block compression: every format round-trips through its encoder and an
//! independent decoder (`bcdec_rs`, a port of bcdec, which shares no code
//! with Intel's ISPC kernels or libsquish) above a PSNR floor per format
//! and input; odd sizes with partial blocks; BC5 normal maps; KTX2 block
//! and supercompressed files field by field against the KTX 2.0
//! specification (and read back by the `ktx2` crate); DDS DX10 headers per
//! DXGI format.
//!
//! PSNR is computed here from the raw values (not with
//! `parvo::compress::psnr`): 8-bit codes scaled to 0..1, BC6H's halves with
//! the level's largest value as the peak.
#![cfg(feature = "encode")]

use parvo::compress::encode::encode;
use parvo::compress::{BlockChain, BlockFormat, Quality, decode, input_format, prepare};
use parvo::io::ktx2::{self, Supercompression};
use parvo::io::{SaveOptions, dds};
use parvo::texel::{AlphaMode, ChannelType, ColorSpace, Format, Texels};
use parvo::texture::Texture;

const FORMATS: [BlockFormat; 6] = [
    BlockFormat::Bc1,
    BlockFormat::Bc3,
    BlockFormat::Bc4 { signed: false },
    BlockFormat::Bc5 { signed: false },
    BlockFormat::Bc7,
    BlockFormat::Bc6h { signed: false },
];

fn values(t: &Texture) -> Vec<f64> {
    match t.texels() {
        Texels::U8(v) => v.iter().map(|&x| x as f64 / 255.0).collect(),
        Texels::U16(v) => v.iter().map(|&x| x as f64 / 65535.0).collect(),
        Texels::F16(v) => v.iter().map(|x| x.to_f64()).collect(),
        Texels::F32(v) => v.iter().map(|&x| x as f64).collect(),
    }
}

/// PSNR over the first `ch` channels, peak 1 (or the largest value of a
/// float reference).
fn psnr(reference: &Texture, got: &Texture, ch: usize) -> f64 {
    assert_eq!(
        (reference.width(), reference.height()),
        (got.width(), got.height())
    );
    let n = reference.channels();
    assert_eq!(n, got.channels());
    let (a, b) = (values(reference), values(got));
    let peak = if reference.channel_type().is_float() {
        a.iter().fold(1.0f64, |m, x| m.max(*x))
    } else {
        1.0
    };
    let mut se = 0.0;
    for (pa, pb) in a.chunks_exact(n).zip(b.chunks_exact(n)) {
        for c in 0..ch {
            se += (pa[c] - pb[c]).powi(2);
        }
    }
    let mse = se / (a.len() / n * ch) as f64;
    if mse == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (peak * peak / mse).log10()
    }
}

/// Channels a format's PSNR is scored on (an opaque BC1/BC3/BC7: RGB).
fn scored(f: BlockFormat, has_alpha: bool) -> usize {
    match f {
        BlockFormat::Bc4 { .. } => 1,
        BlockFormat::Bc5 { .. } => 2,
        BlockFormat::Bc6h { .. } => 3,
        _ if has_alpha => 4,
        _ => 3,
    }
}

/// The input in the format's encoder format: sRGB photo-like or synthetic
/// 8-bit data; for BC6H the same scaled to an HDR range (peak 4) in f16.
fn input(name: &str, f: BlockFormat) -> Texture {
    let t = parvo::builtin::load(name).unwrap();
    if let BlockFormat::Bc6h { .. } = f {
        let lin = t
            .convert(Format::new(
                t.format().channels,
                ChannelType::F32,
                ColorSpace::Linear,
            ))
            .unwrap();
        let Texels::F32(v) = lin.texels() else {
            unreachable!()
        };
        let hdr: Vec<f32> = v.iter().map(|x| x * 4.0).collect();
        let hdr = Texture::from_f32(t.width(), t.height(), lin.format(), hdr).unwrap();
        let want = input_format(f, ColorSpace::Linear, None);
        return prepare(&hdr, f, want).unwrap();
    }
    let fmt = t.format();
    let want = input_format(f, fmt.color_space, fmt.has_alpha().then_some(fmt.alpha));
    prepare(&t, f, want).unwrap()
}

fn round_trip(f: BlockFormat, q: Quality, t: &Texture) -> (Texture, Vec<u8>) {
    let blocks = encode(f, q, t).unwrap();
    assert_eq!(
        blocks.len() as u64,
        f.level_bytes(t.width(), t.height()),
        "{f}: block bytes"
    );
    let fmt = t.format();
    let d = decode(
        f,
        fmt.color_space == ColorSpace::Srgb,
        fmt.alpha,
        t.width(),
        t.height(),
        &blocks,
    )
    .unwrap();
    (d, blocks)
}

/// PSNR floors per format and input (quality normal, 256² inputs), 1.5 dB
/// under what was measured on the 2-core Zen 4 VM (in the comments); 90
/// where the round trip was exact.
#[test]
fn every_format_round_trips_above_its_psnr_floor() {
    let cases: [(BlockFormat, [f64; 3]); 6] = [
        // photo 256², checker 256², zone plate 256²
        // Measured: BC1 34.82 / 54.15 / 25.15; BC3 34.82 / 49.38 / 24.53;
        // BC4 43.93 / exact / 29.02; BC5 44.10 / exact / 29.02; BC7 42.25 /
        // exact / 37.91; BC6H 39.14 / 68.89 / 23.90 (the zone plate reaches
        // the Nyquist limit at its border: the hardest input for 4×4
        // blocks; the checker's flat squares are exact where the format
        // has enough endpoints).
        (BlockFormat::Bc1, [33.3, 52.5, 23.6]),
        (BlockFormat::Bc3, [33.3, 47.8, 23.0]),
        (BlockFormat::Bc4 { signed: false }, [42.4, 90.0, 27.5]),
        (BlockFormat::Bc5 { signed: false }, [42.6, 90.0, 27.5]),
        (BlockFormat::Bc7, [40.7, 90.0, 36.4]),
        (BlockFormat::Bc6h { signed: false }, [37.6, 67.3, 22.4]),
    ];
    let inputs = [
        "builtin:photo:256",
        "builtin:checker:256",
        "builtin:zoneplate:256",
    ];
    let mut report = String::new();
    let mut failures = Vec::new();
    for (f, floors) in cases {
        for (name, floor) in inputs.iter().zip(floors) {
            let t = input(name, f);
            let (d, _) = round_trip(f, Quality::Normal, &t);
            let p = psnr(&t, &d, scored(f, t.format().has_alpha()));
            report.push_str(&format!("{f} {name}: {p:.2} dB (floor {floor})\n"));
            if p < floor {
                failures.push(format!("{f} {name}: {p:.2} dB < {floor}"));
            }
        }
    }
    println!("{report}");
    assert!(failures.is_empty(), "{failures:?}\n{report}");
}

/// More effort never costs more than a rounding's worth of PSNR, and
/// `fast` is a different (cheaper) encoding for BC7 and BC6H.
#[test]
fn quality_levels_order_by_psnr() {
    for f in [BlockFormat::Bc7, BlockFormat::Bc6h { signed: false }] {
        let t = input("builtin:photo:128", f);
        let ch = scored(f, false);
        let p: Vec<f64> = [Quality::Fast, Quality::Normal, Quality::Slow]
            .iter()
            .map(|&q| psnr(&t, &round_trip(f, q, &t).0, ch))
            .collect();
        assert!(p[0] < p[1], "{f}: fast {:.2} !< normal {:.2}", p[0], p[1]);
        assert!(
            p[2] > p[1] - 0.05,
            "{f}: slow {:.2} < normal {:.2}",
            p[2],
            p[1]
        );
    }
}

/// Partial blocks: 1×1, 3×5 and 257×129 levels encode to whole blocks and
/// decode to the level's texels (the outside ones dropped) close to the
/// input; a constant level decodes (nearly) exactly.
#[test]
fn odd_sizes_encode_whole_blocks() {
    for f in FORMATS {
        for (w, h) in [(1, 1), (3, 5), (257, 129), (2, 7)] {
            let full = input("builtin:photo:257", f);
            // Crop the top-left w×h.
            let fmt = full.format();
            let bpt = fmt.texel_bytes();
            let le = parvo::io::le_bytes(full.texels());
            let mut bytes = Vec::new();
            for y in 0..h as usize {
                bytes.extend_from_slice(&le[y * 257 * bpt..(y * 257 + w as usize) * bpt]);
            }
            let t = Texture::from_texels(
                w,
                h,
                fmt,
                parvo::io::texels_from_le(fmt.channel_type, &bytes),
            )
            .unwrap();
            let (d, blocks) = round_trip(f, Quality::Normal, &t);
            assert_eq!(
                blocks.len(),
                w.div_ceil(4) as usize * h.div_ceil(4) as usize * f.block_bytes()
            );
            assert_eq!((d.width(), d.height()), (w, h));
            let p = psnr(&t, &d, scored(f, fmt.has_alpha()));
            let floor = if (w, h) == (1, 1) { 40.0 } else { 28.0 };
            assert!(p >= floor, "{f} {w}x{h}: {p:.2} dB");
        }
    }
}

/// BC1 keeps one-bit alpha: texels below half alpha decode transparent
/// (alpha 0), the others opaque.
#[test]
fn bc1_alpha_is_one_bit() {
    let (w, h) = (16u32, 12u32);
    let mut v = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let a = if (x / 3 + y / 2) % 2 == 0 { 255 } else { 10 };
            v.extend_from_slice(&[(x * 15) as u8, (y * 20) as u8, 128, a]);
        }
    }
    let t = Texture::from_u8(
        w,
        h,
        Format::new(4, ChannelType::U8, ColorSpace::Srgb),
        v.clone(),
    )
    .unwrap();
    let (d, _) = round_trip(BlockFormat::Bc1, Quality::Normal, &t);
    let Texels::U8(out) = d.texels() else {
        unreachable!()
    };
    for (i, (o, s)) in out.chunks_exact(4).zip(v.chunks_exact(4)).enumerate() {
        assert_eq!(o[3], if s[3] >= 128 { 255 } else { 0 }, "texel {i}");
    }
}

/// BC5 normal maps: the two stored channels give back a unit normal (x² +
/// y² ≤ 1 within BC5's rounding, z rebuilt), each channel within BC5's
/// error (a block interpolates 8 values between its endpoints, so a texel
/// is at most range/14 plus rounding from the value it encodes), and the
/// normals stay close to the uncompressed chain's on every level.
#[test]
fn bc5_normal_maps_keep_unit_length_after_z_reconstruction() {
    let dir = tempfile::tempdir().unwrap();
    let plain = dir.path().join("n.ktx2");
    let bc5 = dir.path().join("n5.ktx2");
    let run = |out: &std::path::Path, extra: &[&str]| {
        let st = std::process::Command::new(env!("CARGO_BIN_EXE_parvo"))
            .args(["mip", "builtin:bumps:256", "--normal-map", "-o"])
            .arg(out)
            .args(extra)
            .output()
            .unwrap();
        assert!(st.status.success(), "{st:?}");
    };
    run(&plain, &[]);
    run(&bc5, &["--compress", "bc5"]);
    let limits = parvo::io::Limits::default();
    let a = ktx2::load(&plain, &limits).unwrap().levels;
    let b = ktx2::load(&bc5, &limits).unwrap().levels;
    assert_eq!(a.len(), b.len());
    for (k, (la, lb)) in a.iter().zip(&b).enumerate() {
        let (va, vb) = (values(la), values(lb));
        let (na, nb) = (la.channels(), lb.channels());
        assert_eq!(nb, 2, "BC5 decodes to two channels");
        let (w, h) = (la.width() as usize, la.height() as usize);
        // Per block and channel: the range of the encoded values.
        let mut range = vec![[0f64; 2]; w.div_ceil(4) * h.div_ceil(4)];
        for by in 0..h.div_ceil(4) {
            for bx in 0..w.div_ceil(4) {
                for c in 0..2 {
                    let (mut lo, mut hi) = (1f64, 0f64);
                    for y in by * 4..(by * 4 + 4).min(h) {
                        for x in bx * 4..(bx * 4 + 4).min(w) {
                            let v = va[(y * w + x) * na + c];
                            lo = lo.min(v);
                            hi = hi.max(v);
                        }
                    }
                    range[by * w.div_ceil(4) + bx][c] = hi - lo;
                }
            }
        }
        let mut sum = 0f64;
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                let rng = range[(y / 4) * w.div_ceil(4) + x / 4];
                for c in 0..2 {
                    let err = (vb[i * nb + c] - va[i * na + c]).abs();
                    assert!(
                        err <= rng[c] / 14.0 + 2.0 / 255.0,
                        "level {k} texel ({x},{y}) channel {c}: error {err:.4}, block range {:.4}",
                        rng[c]
                    );
                }
                let r: Vec<f64> = (0..3).map(|c| 2.0 * va[i * na + c] - 1.0).collect();
                let (nx, ny) = (2.0 * vb[i * nb] - 1.0, 2.0 * vb[i * nb + 1] - 1.0);
                let nz = (1.0 - nx * nx - ny * ny).max(0.0).sqrt();
                let len = (nx * nx + ny * ny + nz * nz).sqrt();
                assert!((len - 1.0).abs() < 2e-3, "level {k}: |n| = {len}");
                let rl = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
                let cos = (nx * r[0] + ny * r[1] + nz * r[2]) / (len * rl);
                sum += cos.clamp(-1.0, 1.0).acos().to_degrees();
            }
        }
        // Measured: at most 3.0 degrees on average (levels 1 and 2, where
        // the bumps are sharpest per block), 0 on the 2×2 and 1×1 levels.
        let mean = sum / (w * h) as f64;
        assert!(mean < 4.0, "level {k}: mean angle {mean:.3} deg");
    }
}

fn word(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap())
}

fn qword(b: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(b[at..at + 8].try_into().unwrap())
}

fn chain_of(f: BlockFormat, size: u32, srgb: bool) -> (BlockChain, Vec<Texture>) {
    let base = input(&format!("builtin:photo:{size}"), f);
    let opts = parvo::MipOptions::default();
    let levels = parvo::mip::build(base, &opts).unwrap().into_levels();
    let fmt = levels[0].format();
    let data = levels
        .iter()
        .map(|l| encode(f, Quality::Fast, l).unwrap())
        .collect();
    (
        BlockChain {
            format: f,
            srgb,
            alpha: fmt.alpha,
            width: size,
            height: size,
            levels: data,
        },
        levels,
    )
}

/// Each block format's KTX2 file, field by field (KTX 2.0 sections 3.1 to
/// 3.9; DFD per the Khronos Data Format Specification's BC models), with
/// and without supercompression; then read back by the `ktx2` crate and
/// by parvo.
#[test]
fn ktx2_block_files_follow_the_specification() {
    let vk = |f: BlockFormat, srgb: bool| ktx2::vk_block_format(f, srgb, false);
    // Vulkan's numbers (VkFormat enum).
    assert_eq!(vk(BlockFormat::Bc1, false), 131);
    assert_eq!(ktx2::vk_block_format(BlockFormat::Bc1, true, true), 134);
    assert_eq!(vk(BlockFormat::Bc3, true), 138);
    assert_eq!(vk(BlockFormat::Bc4 { signed: false }, false), 139);
    assert_eq!(vk(BlockFormat::Bc5 { signed: false }, false), 141);
    assert_eq!(vk(BlockFormat::Bc6h { signed: false }, false), 143);
    assert_eq!(vk(BlockFormat::Bc7, false), 145);
    assert_eq!(vk(BlockFormat::Bc7, true), 146);
    for f in FORMATS {
        for sc in [
            None,
            Some(Supercompression::Zstd(5)),
            Some(Supercompression::Zlib(6)),
        ] {
            let srgb = matches!(f, BlockFormat::Bc1 | BlockFormat::Bc3 | BlockFormat::Bc7);
            let (chain, levels) = chain_of(f, 20, srgb);
            let opts = SaveOptions {
                ktx2: parvo::io::ktx2::Ktx2Options {
                    supercompression: sc,
                },
                ..SaveOptions::default()
            };
            let mut b = Vec::new();
            ktx2::write_blocks_to(&chain, &opts, &mut b).unwrap();
            let what = format!("{f} {sc:?}");
            assert_eq!(&b[..12], &ktx2::IDENTIFIER, "{what}");
            let alpha = chain.alpha != AlphaMode::None;
            assert_eq!(
                word(&b, 12),
                ktx2::vk_block_format(f, srgb, alpha),
                "{what}"
            );
            assert_eq!(word(&b, 16), 1, "{what}: typeSize of a block format");
            assert_eq!((word(&b, 20), word(&b, 24)), (20, 20), "{what}");
            assert_eq!(word(&b, 28), 0, "{what}: pixelDepth");
            assert_eq!(word(&b, 32), 0, "{what}: layerCount");
            assert_eq!(word(&b, 36), 1, "{what}: faceCount");
            let n = word(&b, 40) as usize;
            assert_eq!(n, 5, "{what}: 20, 10, 5, 2, 1");
            assert_eq!(word(&b, 44), sc.map_or(0, |s| s.scheme()), "{what}");
            let (dfd_at, dfd_len) = (word(&b, 48) as usize, word(&b, 52) as usize);
            assert_eq!(dfd_at, 80 + 24 * n, "{what}: DFD after the level index");
            assert_eq!((qword(&b, 64), qword(&b, 72)), (0, 0), "{what}: no sgd");
            // DFD: total size, one basic block.
            let d = &b[dfd_at..dfd_at + dfd_len];
            assert_eq!(word(d, 0) as usize, dfd_len);
            assert_eq!(word(d, 4), 0, "Khronos vendor, basic descriptor");
            let samples = match f {
                BlockFormat::Bc1
                | BlockFormat::Bc4 { .. }
                | BlockFormat::Bc6h { .. }
                | BlockFormat::Bc7 => 1,
                _ => 2,
            };
            assert_eq!(
                word(d, 8),
                2 | ((24 + 16 * samples) << 16),
                "{what}: version 2"
            );
            let model = match f {
                BlockFormat::Bc1 => 128,
                BlockFormat::Bc2 => 129,
                BlockFormat::Bc3 => 130,
                BlockFormat::Bc4 { .. } => 131,
                BlockFormat::Bc5 { .. } => 132,
                BlockFormat::Bc6h { .. } => 133,
                BlockFormat::Bc7 => 134,
            };
            let w3 = word(d, 12);
            assert_eq!(w3 & 0xff, model, "{what}: colour model");
            assert_eq!((w3 >> 8) & 0xff, 1, "{what}: BT.709 primaries");
            assert_eq!(
                (w3 >> 16) & 0xff,
                if srgb { 2 } else { 1 },
                "{what}: transfer"
            );
            assert_eq!(word(d, 16), 3 | (3 << 8), "{what}: 4x4 texel block");
            assert_eq!(word(d, 20), f.block_bytes() as u32, "{what}: bytesPlane0");
            let bits = if f.block_bytes() == 16 && samples == 1 {
                127
            } else {
                63
            };
            assert_eq!(
                (word(d, 28) >> 16) & 0xff,
                bits,
                "{what}: sample bit length"
            );
            // Level index: level 0 first, offsets aligned (8/16 bytes, or
            // 1 when supercompressed), lengths as the levels need, and the
            // data inside the file; smallest level stored first.
            let mut prev_end = None;
            for k in (0..n).rev() {
                let at = 80 + 24 * k;
                let (off, len, ulen) = (qword(&b, at), qword(&b, at + 8), qword(&b, at + 16));
                let (w, h) = (levels[k].width(), levels[k].height());
                assert_eq!(ulen, f.level_bytes(w, h), "{what}: level {k} uncompressed");
                if sc.is_none() {
                    assert_eq!(len, ulen, "{what}: level {k}");
                    assert_eq!(off % f.block_bytes() as u64, 0, "{what}: level {k} aligned");
                }
                if let Some(p) = prev_end {
                    assert!(off >= p, "{what}: levels overlap");
                }
                prev_end = Some(off + len);
                let payload = &b[off as usize..(off + len) as usize];
                let raw = match sc {
                    None => payload.to_vec(),
                    Some(Supercompression::Zstd(_)) => {
                        zstd::bulk::decompress(payload, ulen as usize).unwrap()
                    }
                    Some(Supercompression::Zlib(_)) => {
                        let mut out = vec![0u8; ulen as usize];
                        let m = libdeflater::Decompressor::new()
                            .zlib_decompress(payload, &mut out)
                            .unwrap();
                        out.truncate(m);
                        out
                    }
                };
                assert_eq!(
                    raw.len() as u64,
                    ulen,
                    "{what}: level {k} decompresses to its length"
                );
                assert_eq!(raw, chain.levels[k], "{what}: level {k} bytes");
            }
            assert_eq!(
                prev_end,
                Some(b.len() as u64),
                "{what}: level 0 ends the file"
            );
            // The ktx2 crate reads it.
            let r = ::ktx2::Reader::new(b.as_slice()).unwrap();
            assert_eq!(r.header().format.map(|v| v.value()), Some(word(&b, 12)));
            assert_eq!(r.levels().count(), n);
            // parvo reads it back to the decoded chain.
            let dir = tempfile::tempdir().unwrap();
            let p = dir.path().join("t.ktx2");
            std::fs::write(&p, &b).unwrap();
            let loaded = ktx2::load(&p, &parvo::io::Limits::default()).unwrap();
            let decoded = chain.decode().unwrap();
            assert_eq!(loaded.levels.len(), n);
            for (l, d) in loaded.levels.iter().zip(&decoded) {
                assert_eq!(l.texels(), d.texels(), "{what}");
            }
        }
    }
}

/// The DDS header of each block format: DX10 extension with the DXGI
/// number (and `_UNORM_SRGB` for sRGB), `DDSD_LINEARSIZE` with level 0's
/// byte size, the mip count and caps, the alpha mode.
#[test]
fn dds_block_headers_per_dxgi_format() {
    let cases = [
        (BlockFormat::Bc1, false, 71),
        (BlockFormat::Bc1, true, 72),
        (BlockFormat::Bc3, false, 77),
        (BlockFormat::Bc3, true, 78),
        (BlockFormat::Bc4 { signed: false }, false, 80),
        (BlockFormat::Bc5 { signed: false }, false, 83),
        (BlockFormat::Bc6h { signed: false }, false, 95),
        (BlockFormat::Bc7, false, 98),
        (BlockFormat::Bc7, true, 99),
    ];
    for (f, srgb, dxgi) in cases {
        let (chain, levels) = chain_of(f, 36, srgb);
        let h = dds::header_for_blocks(&chain).unwrap();
        let what = format!("{f} srgb={srgb}");
        assert_eq!(
            h.flags,
            0x1 | 0x2 | 0x4 | 0x1000 | 0x20000 | 0x80000,
            "{what}"
        );
        assert_eq!((h.width, h.height), (36, 36));
        assert_eq!(
            h.pitch_or_linear_size as u64,
            f.level_bytes(36, 36),
            "{what}"
        );
        assert_eq!(h.mip_map_count as usize, levels.len());
        assert_eq!(h.pixel_format.flags, 0x4, "{what}: DDPF_FOURCC only");
        assert_eq!(h.pixel_format.fourcc, u32::from_le_bytes(*b"DX10"));
        assert_eq!(
            h.caps,
            0x1000 | 0x8 | 0x400000,
            "{what}: texture, complex, mipmap"
        );
        let d = h.dx10.unwrap();
        assert_eq!(d.dxgi_format, dxgi, "{what}");
        assert_eq!((d.resource_dimension, d.array_size, d.misc_flag), (3, 1, 0));
        let mode = match chain.alpha {
            AlphaMode::Straight => 1,
            AlphaMode::Premultiplied => 2,
            AlphaMode::None => 3,
        };
        assert_eq!(d.misc_flags2, mode, "{what}: alpha mode");
        // The file: header, then every level's blocks in order.
        let mut b = Vec::new();
        dds::write_blocks_to(&chain, &mut b).unwrap();
        let total: usize = chain.levels.iter().map(Vec::len).sum();
        assert_eq!(b.len(), 148 + total, "{what}");
        assert_eq!(dds::Header::parse(&b).unwrap(), h);
    }
}
