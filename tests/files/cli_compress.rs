//! `parvo mip --compress`, `--zstd`/`--zlib` and `--resize-to` end to end:
//! what is written is what `info` and `sample` read back, usage errors are
//! refused before any work, `--json` reports every level.
#![cfg(feature = "encode")]

use std::io::Write;
use std::path::Path;
use std::process::{Command, Output, Stdio};

fn parvo(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_parvo"))
        .args(args)
        .output()
        .unwrap()
}

fn ok(o: &Output) -> String {
    assert!(
        o.status.success(),
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn p(path: &Path) -> &str {
    path.to_str().unwrap()
}

#[test]
fn compressed_and_supercompressed_outputs_read_back() {
    let dir = tempfile::tempdir().unwrap();
    let plain = dir.path().join("plain.ktx2");
    let bc7 = dir.path().join("bc7.ktx2");
    let bc7z = dir.path().join("bc7z.ktx2");
    let zl = dir.path().join("zl.ktx2");
    let dds = dir.path().join("bc7.dds");
    let src = "builtin:photo:96";
    ok(&parvo(&["mip", src, "-o", p(&plain)]));
    ok(&parvo(&["mip", src, "-o", p(&bc7), "--compress", "bc7"]));
    ok(&parvo(&[
        "mip",
        src,
        "-o",
        p(&bc7z),
        "--compress",
        "bc7",
        "--zstd",
        "9",
    ]));
    ok(&parvo(&["mip", src, "-o", p(&zl), "--zlib", "6"]));
    ok(&parvo(&["mip", src, "-o", p(&dds), "--compress", "bc7"]));
    let limits = parvo::io::Limits::default();
    let load = |f: &Path| parvo::io::load(p(f), &limits).unwrap();
    // Supercompression is lossless: the same texels as without it.
    let (a, z) = (load(&plain), load(&zl));
    assert_eq!(a.levels.len(), z.levels.len());
    for (x, y) in a.levels.iter().zip(&z.levels) {
        assert_eq!(x.texels(), y.texels());
    }
    assert!(std::fs::metadata(&zl).unwrap().len() < std::fs::metadata(&plain).unwrap().len());
    // BC7 with and without zstd, in KTX2 and DDS: the same blocks (the
    // DDS is marked opaque, so its alpha reads as 1 where ISPC's opaque
    // modes decode 254: RGB compared there).
    let (b, bz, bd) = (load(&bc7), load(&bc7z), load(&dds));
    assert_eq!(b.levels.len(), a.levels.len());
    for ((x, y), w) in b.levels.iter().zip(&bz.levels).zip(&bd.levels) {
        assert!(x.texels() == y.texels(), "zstd changed the texels");
        let rgb = |t: &parvo::texture::Texture| -> Vec<u8> {
            let parvo::texel::Texels::U8(v) = t.texels() else {
                panic!("BC7 decodes to u8")
            };
            v.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect()
        };
        assert!(rgb(x) == rgb(w), "KTX2 and DDS differ");
        let parvo::texel::Texels::U8(dv) = w.texels() else {
            unreachable!()
        };
        assert!(dv.chunks_exact(4).all(|p| p[3] == 255), "opaque DDS alpha");
    }
    // info names the stored format and the scheme.
    let info = ok(&parvo(&["info", p(&bc7z)]));
    assert!(info.contains("stored: BC7_SRGB"), "{info}");
    assert!(info.contains("supercompression: zstd"), "{info}");
    // sample reads the compressed file: close to the uncompressed one.
    let sample = |f: &Path| -> Vec<Vec<f32>> {
        let mut c = Command::new(env!("CARGO_BIN_EXE_parvo"))
            .args(["sample", p(f), "--filter", "trilinear"])
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .unwrap();
        c.stdin
            .take()
            .unwrap()
            .write_all(b"0.3 0.6 0.01 0 0 0.01\n0.7 0.2 0.05 0 0 0.05\n")
            .unwrap();
        let o = c.wait_with_output().unwrap();
        String::from_utf8(o.stdout)
            .unwrap()
            .lines()
            .map(|l| l.split_whitespace().map(|t| t.parse().unwrap()).collect())
            .collect()
    };
    // RGB (3 values per line) against BC7's RGBA (4).
    let (u, c) = (sample(&plain), sample(&bc7z));
    assert_eq!(u.len(), 2);
    assert_eq!(c.len(), 2);
    for (x, y) in u.iter().zip(&c) {
        assert_eq!((x.len(), y.len()), (3, 4));
        for k in 0..3 {
            assert!((x[k] - y[k]).abs() < 0.03, "{u:?} vs {c:?}");
        }
    }
}

#[test]
fn json_reports_every_level() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.dds");
    let o = ok(&parvo(&[
        "mip",
        "builtin:photo:40",
        "-o",
        p(&out),
        "--compress",
        "bc1",
        "--json",
    ]));
    let v: serde_json::Value = serde_json::from_str(o.trim()).unwrap();
    let c = &v["compression"];
    assert_eq!(c["format"], "BC1_SRGB");
    let levels = c["levels"].as_array().unwrap();
    // 40, 20, 10, 5, 2, 1.
    assert_eq!(levels.len(), 6);
    let sizes: Vec<u64> = levels
        .iter()
        .map(|l| l["bytes"].as_u64().unwrap())
        .collect();
    // Whole 8-byte blocks: 10x10, 5x5, 3x3, 2x2, 1, 1.
    assert_eq!(sizes, vec![800, 200, 72, 32, 8, 8]);
    assert_eq!(levels[0]["bytes_per_texel"].as_f64().unwrap(), 0.5);
    for l in &levels[..4] {
        let p = l["psnr_db"].as_f64().unwrap();
        // A 40² photo-like image is all detail: BC1 measured 24.9 dB at
        // level 0; this checks a real PSNR is reported.
        assert!(p > 15.0 && p < 80.0, "{l}");
    }
    assert_eq!(
        c["bytes"].as_u64().unwrap() + 148,
        std::fs::metadata(&out).unwrap().len()
    );
    // A cube map's bytes are its six faces', per texel of the six.
    let cube = dir.path().join("c.ktx2");
    let o = ok(&parvo(&[
        "mip",
        "tests/data/peer/openexr-images/WavyLinesCube.exr",
        "-o",
        p(&cube),
        "--levels",
        "2",
        "--compress",
        "bc6h",
        "--json",
    ]));
    let v: serde_json::Value = serde_json::from_str(o.trim()).unwrap();
    let l0 = &v["compression"]["levels"][0];
    assert_eq!(l0["bytes"].as_u64().unwrap(), 6 * 256 * 256);
    assert_eq!(l0["bytes_per_texel"].as_f64().unwrap(), 1.0);
    // WebGL takes this chain (level 0 a multiple of 4; WEBGL_compressed_
    // texture_s3tc revision 6): nothing said. A 42² level 0 is not whole
    // blocks: said on stderr.
    let e = parvo(&[
        "mip",
        "builtin:photo:40",
        "-o",
        p(&out),
        "--compress",
        "bc1",
    ]);
    assert!(!String::from_utf8_lossy(&e.stderr).contains("WebGL"));
    let e = parvo(&[
        "mip",
        "builtin:photo:42",
        "-o",
        p(&out),
        "--compress",
        "bc1",
    ]);
    assert!(String::from_utf8_lossy(&e.stderr).contains("level 0 is 42x42"));
}

#[test]
fn resize_to_gives_block_friendly_sizes() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r.ktx2");
    for (rule, src, want) in [
        ("pow2", "builtin:photo:1000", 1024),
        ("pow2", "builtin:photo:700", 512),
        ("multiple-of-4", "builtin:photo:101", 104),
    ] {
        let o = parvo(&[
            "mip",
            src,
            "-o",
            p(&out),
            "--compress",
            "bc7",
            "--quality",
            "fast",
            "--resize-to",
            rule,
        ]);
        ok(&o);
        let l = parvo::io::load(p(&out), &parvo::io::Limits::default()).unwrap();
        assert_eq!((l.levels[0].width(), l.levels[0].height()), (want, want));
        assert!(String::from_utf8_lossy(&o.stderr).contains("resized"));
    }
}

#[test]
fn usage_errors_are_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let d = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    for (args, says) in [
        (
            vec!["--compress", "bc7", "-o", &d("a.exr")],
            "use .ktx2 or .dds",
        ),
        (
            vec!["--compress", "bc7", "--type", "u8", "-o", &d("a.ktx2")],
            "fixes what is stored",
        ),
        (vec!["--zstd", "5", "-o", &d("a.dds")], "KTX2 feature"),
        (vec!["--zstd", "0", "-o", &d("a.ktx2")], "from 1 to 22"),
        (vec!["--zlib", "13", "-o", &d("a.ktx2")], "from 1 to 12"),
        (vec!["--quality", "slow", "-o", &d("a.ktx2")], "--compress"),
    ] {
        let mut all = vec!["mip", "builtin:photo:16"];
        all.extend(args.iter().copied());
        let o = parvo(&all);
        assert_eq!(o.status.code(), Some(2), "{all:?}");
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(e.contains(says), "{all:?}: {e}");
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

/// `parvo cachesim` on a block-compressed file counts whole blocks: the
/// same accesses as the uncompressed file, a fraction of its bytes.
#[test]
fn cachesim_counts_blocks_of_compressed_files() {
    let dir = tempfile::tempdir().unwrap();
    let plain = dir.path().join("c.ktx2");
    let bc7 = dir.path().join("c7.dds");
    ok(&parvo(&["mip", "builtin:checker:256", "-o", p(&plain)]));
    ok(&parvo(&[
        "mip",
        "builtin:checker:256",
        "-o",
        p(&bc7),
        "--compress",
        "bc7",
        "--quality",
        "fast",
    ]));
    let bytes = |f: &Path| -> (u64, String) {
        let o = ok(&parvo(&["cachesim", "--texture", p(f), "--size", "128x96"]));
        let line = o
            .lines()
            .find(|l| l.starts_with("bytes from memory"))
            .unwrap()
            .to_string();
        let n = line.split_whitespace().nth(3).unwrap().parse().unwrap();
        (n, o)
    };
    let ((bu, _), (bc, text)) = (bytes(&plain), bytes(&bc7));
    assert!(
        text.contains("BC7 blocks, 16 bytes per 4x4 block"),
        "{text}"
    );
    assert!(bc * 2 < bu, "BC7 {bc} bytes, RGBA8 {bu}");
}

/// A grey PNG that says nothing of its colour, written with the `png`
/// crate alone (no sRGB, gAMA or iCCP chunk): smooth with some noise,
/// like a height or roughness map.
fn untagged_grey_png(path: &Path, w: u32, h: u32) -> Vec<u8> {
    let mut s = 0x2545_f491_4f6c_dd1du64;
    let codes: Vec<u8> = (0..w * h)
        .map(|i| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let (x, y) = ((i % w) as f64, (i / w) as f64);
            let v = 128.0 + 90.0 * (x / 9.0).sin() * (y / 13.0).cos() + (s % 17) as f64 - 8.0;
            v.clamp(0.0, 255.0) as u8
        })
        .collect();
    let file = std::fs::File::create(path).unwrap();
    let mut enc = png::Encoder::new(std::io::BufWriter::new(file), w, h);
    enc.set_color(png::ColorType::Grayscale);
    enc.set_depth(png::BitDepth::Eight);
    let mut wr = enc.write_header().unwrap();
    wr.write_image_data(&codes).unwrap();
    wr.finish().unwrap();
    codes
}

/// BC4 holds data: an untagged grey PNG goes in as its stored codes with
/// no flag (as nvcompress, etcpak and quicktex keep them), said once on
/// stderr; `--color srgb` still decodes it (the old default, far off the
/// codes). The blocks are decoded by `bcdec_rs`, not by parvo.
#[test]
fn bc4_keeps_the_stored_codes_of_an_untagged_grey_png() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (61, 37);
    let src = dir.path().join("height.png");
    let codes = untagged_grey_png(&src, w, h);
    let psnr = |extra: &[&str]| {
        let out = dir.path().join(format!("bc4_{}.dds", extra.len()));
        let mut args = vec!["mip", p(&src), "--compress", "bc4", "--levels", "1"];
        args.extend_from_slice(extra);
        args.extend(["-o", p(&out)]);
        let o = parvo(&args);
        ok(&o);
        let data = std::fs::read(&out).unwrap();
        let start = 4 + 124 + if &data[84..88] == b"DX10" { 20 } else { 0 };
        let (bw, bh) = (w.div_ceil(4) as usize, h.div_ceil(4) as usize);
        let mut se = 0.0f64;
        for by in 0..bh {
            for bx in 0..bw {
                let off = start + (by * bw + bx) * 8;
                let mut texels = [0u8; 16];
                bcdec_rs::bc4(&data[off..off + 8], &mut texels, 4, false);
                for j in 0..4 {
                    for i in 0..4 {
                        let (x, y) = (bx * 4 + i, by * 4 + j);
                        if x < w as usize && y < h as usize {
                            let d = texels[j * 4 + i] as f64 - codes[y * w as usize + x] as f64;
                            se += d * d;
                        }
                    }
                }
            }
        }
        let mse = se / (w * h) as f64;
        (
            10.0 * (255.0f64 * 255.0 / mse.max(1e-12)).log10(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    let (kept, said) = psnr(&[]);
    let (decoded, _) = psnr(&["--color", "srgb"]);
    eprintln!("BC4 of an untagged grey PNG: {kept:.2} dB; read as sRGB colour {decoded:.2} dB");
    assert!(kept > 40.0 && decoded < 25.0, "{kept} / {decoded}");
    assert_eq!(said.matches("holds data").count(), 1, "{said}");
}

/// A batch says each distinct note once, for the first input it concerns,
/// and at the end how many inputs it concerned: three untagged grey PNGs
/// give the colour note once (to BC4, the note that the codes are kept).
#[test]
fn a_batch_says_each_note_once_with_its_count() {
    let dir = tempfile::tempdir().unwrap();
    let inputs: Vec<String> = (0..3)
        .map(|i| {
            let path = dir.path().join(format!("g{i}.png"));
            untagged_grey_png(&path, 20 + i, 12);
            p(&path).to_string()
        })
        .collect();
    for (extra, phrase) in [
        (vec![], "a one-channel output holds data"),
        (vec!["--compress", "bc4"], "holds data"),
    ] {
        let out = dir.path().join(format!("out{}", extra.len()));
        let mut args: Vec<&str> = vec!["mip"];
        args.extend(inputs.iter().map(String::as_str));
        args.extend(extra.iter().copied());
        args.extend(["--out-dir", p(&out), "--ext", "ktx2"]);
        let o = parvo(&args);
        ok(&o);
        let err = String::from_utf8_lossy(&o.stderr);
        let said = err
            .lines()
            .filter(|l| l.contains(phrase) && !l.contains("concerns"))
            .count();
        assert_eq!(said, 1, "{err}");
        let counted = err
            .lines()
            .filter(|l| l.contains("concerns 3 inputs in all"));
        assert_eq!(counted.count(), 1, "{err}");
    }
}

/// Not BC4 only: any one-channel output without `--color` holds data
/// (roughness, height, masks), so an untagged grey PNG's codes reach an
/// OpenEXR level 0 as code / 255, not decoded from sRGB, said once; and a
/// batch of such files says it once with the count (issue 53).
#[test]
fn one_channel_outputs_keep_the_stored_codes_said_once() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n);
    let codes = untagged_grey_png(&p("g.png"), 37, 23);
    let o = parvo(&[
        "mip",
        p("g.png").to_str().unwrap(),
        "-o",
        p("g.exr").to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&ok_output(&o)).to_string();
    assert_eq!(
        err.matches("a one-channel output holds data").count(),
        1,
        "{err}"
    );
    let loaded = parvo::io::load(p("g.exr").to_str().unwrap(), &Default::default()).unwrap();
    let got = loaded.base().to_linear();
    assert_eq!(got.len(), codes.len());
    for (g, c) in got.iter().zip(&codes) {
        // f16 holds code / 255 within half a unit in its last place.
        assert!((g - *c as f32 / 255.0).abs() <= 5e-4, "{g} vs code {c}");
    }
    // `--color srgb` still decodes (a mid grey code is far below 0.5).
    ok(&parvo(&[
        "mip",
        p("g.png").to_str().unwrap(),
        "--color",
        "srgb",
        "-o",
        p("s.exr").to_str().unwrap(),
    ]));
    let s = parvo::io::load(p("s.exr").to_str().unwrap(), &Default::default()).unwrap();
    let diff = (s.base().to_linear().iter().zip(&got)).fold(0f32, |m, (a, b)| m.max((a - b).abs()));
    assert!(diff > 0.1, "--color srgb decodes the codes: {diff}");
    // A batch of three: the note once, with its count.
    for n in ["b1.png", "b2.png", "b3.png"] {
        untagged_grey_png(&p(n), 9, 7);
    }
    std::fs::create_dir(p("out")).unwrap();
    let o = parvo(&[
        "mip",
        p("b1.png").to_str().unwrap(),
        p("b2.png").to_str().unwrap(),
        p("b3.png").to_str().unwrap(),
        "--out-dir",
        p("out").to_str().unwrap(),
        "--ext",
        "exr",
    ]);
    let err = String::from_utf8_lossy(&ok_output(&o)).to_string();
    // The note, and the line that counts the inputs it concerns.
    assert_eq!(
        err.matches("a one-channel output holds data").count(),
        2,
        "{err}"
    );
    assert!(err.contains("concerns 3 inputs in all"), "{err}");
}

/// The stderr of a run that must have succeeded.
fn ok_output(o: &Output) -> Vec<u8> {
    ok(o);
    o.stderr.clone()
}
