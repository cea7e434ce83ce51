//! `parvo mip` end to end: every output format round-trips (level count,
//! sizes, texel values within the output type's precision), sRGB inputs
//! become linear EXR, `--update`, `--dry-run` and `--json` behave.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use parvo::Texture;
use parvo::io::{self, Limits};
use parvo::mip::{self, MipOptions, Rounding};
use parvo::texel::{ChannelType, ColorSpace, Format};

fn parvo(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_parvo"))
        .args(args)
        .output()
        .expect("run parvo")
}

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

/// A 37x20 RGBA8 PNG of fixed-seed noise (odd sizes exercise the
/// polyphase box); returns its path and texels.
fn rgba8_png(dir: &Path) -> (PathBuf, Vec<u8>) {
    let (w, h) = (37u32, 20u32);
    let px = noise((w * h * 4) as usize, 42);
    let path = dir.join("src.png");
    image::save_buffer(&path, &px, w, h, image::ExtendedColorType::Rgba8).unwrap();
    (path, px)
}

fn load(path: &Path) -> io::Loaded {
    io::load(path.to_str().unwrap(), &Limits::default()).unwrap()
}

/// Largest difference in linear light; `premultiply` associates `b`'s
/// colour with its alpha first (EXR stores premultiplied colour).
fn max_diff(a: &Texture, b: &Texture, premultiply: bool) -> f32 {
    let mut want = b.to_linear();
    if premultiply {
        for px in want.chunks_exact_mut(4) {
            let a = px[3];
            px[..3].iter_mut().for_each(|c| *c *= a);
        }
    }
    a.to_linear()
        .iter()
        .zip(want)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f32::max)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn every_output_format_round_trips() {
    let dir = tempfile::tempdir().unwrap();
    let (src, px) = rgba8_png(dir.path());
    let base = Texture::from_u8(
        37,
        20,
        Format::new(4, ChannelType::U8, ColorSpace::Srgb),
        px,
    )
    .unwrap();
    let sizes = mip::level_sizes(37, 20, Rounding::Down, None);
    // Reference: built in linear f32 from level 0 (what the CLI does for a
    // type change) and in the source type (same type: no conversion).
    let f32_chain = mip::build(
        base.convert(Format::new(4, ChannelType::F32, ColorSpace::Linear))
            .unwrap(),
        &MipOptions::default(),
    )
    .unwrap();
    let u8_chain = mip::build(base.clone(), &MipOptions::default()).unwrap();

    // (output name, extra args, expected type, tolerance in linear units)
    let cases: [(&str, &[&str], ChannelType, f32); 6] = [
        ("h.exr", &[], ChannelType::F16, 1e-3),
        (
            "f.exr",
            &["--type", "f32", "--compression", "piz"],
            ChannelType::F32,
            1e-6,
        ),
        ("k.ktx2", &[], ChannelType::U8, 0.0),
        ("k16.ktx2", &["--type", "f16"], ChannelType::F16, 1e-3),
        ("d.dds", &[], ChannelType::U8, 0.0),
        ("p_{level}.png", &[], ChannelType::U8, 0.0),
    ];
    for (name, extra, ty, tol) in cases {
        let out = dir.path().join(name);
        let mut args = vec!["mip", s(&src), "-o", s(&out)];
        args.extend_from_slice(extra);
        let r = parvo(&args);
        assert!(
            r.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&r.stderr)
        );
        let levels: Vec<Texture> = if name.contains("{level}") {
            (0..sizes.len())
                .map(|k| load(&io::png_levels::level_path(&out, k)).into_base())
                .collect()
        } else {
            let l = load(&out);
            assert!(l.info.own_mips, "{name}");
            l.levels
        };
        assert_eq!(levels.len(), sizes.len(), "{name}: level count");
        let reference = if ty == ChannelType::U8 {
            &u8_chain
        } else {
            &f32_chain
        };
        for (k, (got, want)) in levels.iter().zip(reference.levels()).enumerate() {
            assert_eq!((got.width(), got.height()), sizes[k], "{name} level {k}");
            assert_eq!(got.channel_type(), ty, "{name} level {k}");
            let d = max_diff(got, want, name.ends_with(".exr"));
            if tol == 0.0 {
                assert_eq!(got.texels(), want.texels(), "{name} level {k}");
            } else {
                assert!(d <= tol, "{name} level {k}: max difference {d} > {tol}");
            }
        }
    }
}

#[test]
fn srgb_png_becomes_linear_half_exr_filtered_in_linear_light() {
    let dir = tempfile::tempdir().unwrap();
    // 2x2 grey: codes 0 and 255 in a checker; level 1 must be linear 0.5
    // (sRGB code 188 once encoded), never the code average 127.5.
    let src = dir.path().join("g.png");
    image::save_buffer(&src, &[0, 255, 255, 0], 2, 2, image::ExtendedColorType::L8).unwrap();
    let out = dir.path().join("g.exr");
    // A one-channel file that does not say it is sRGB is data by default
    // (issue 53): `--color srgb` says it is colour.
    let r = parvo(&["mip", s(&src), "--color", "srgb", "-o", s(&out)]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let l = load(&out);
    assert_eq!(
        l.base().format(),
        Format::new(1, ChannelType::F16, ColorSpace::Linear)
    );
    assert_eq!(l.info.channel_names, ["Y"]);
    assert_eq!(l.base().to_linear(), [0.0, 1.0, 1.0, 0.0]);
    assert_eq!(l.levels[1].to_linear(), [0.5]);
    // sRGB code 188 decodes to 0.5029 linear.
    image::save_buffer(&src, &[188], 1, 1, image::ExtendedColorType::L8).unwrap();
    assert!(
        parvo(&["mip", s(&src), "--color", "srgb", "-o", s(&out)])
            .status
            .success()
    );
    let v = load(&out).base().to_linear()[0];
    assert!((v - 0.50289).abs() < 5e-4, "{v}");
    // --color linear keeps the codes as linear values.
    assert!(
        parvo(&["mip", s(&src), "-o", s(&out), "--color", "linear"])
            .status
            .success()
    );
    let v = load(&out).base().to_linear()[0];
    assert!((v - 188.0 / 255.0).abs() < 5e-4, "{v}");
}

#[test]
fn exr_records_wrap_modes_rounding_tiles_and_fingerprint() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("c.exr");
    let r = parvo(&[
        "mip",
        "builtin:checker:40",
        "-o",
        s(&out),
        "--wrap",
        "clamp,mirror",
        "--rounding",
        "up",
        "--tile",
        "16x8",
        "--filter",
        "kaiser",
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let l = load(&out);
    assert_eq!(l.info.tile, Some((16, 8)));
    assert_eq!(l.info.rounding, Rounding::Up);
    assert_eq!(
        l.levels.len(),
        mip::level_sizes(40, 40, Rounding::Up, None).len()
    );
    assert_eq!(l.levels[1].width(), 20);
    assert_eq!(l.levels[3].width(), 5);
    assert_eq!(l.levels[4].width(), 3, "rounding up: ceil(40/16)");
    assert_eq!(l.info.attribute("wrapmodes"), Some("clamp,mirror"));
    assert_eq!(l.info.attribute("textureformat"), Some("Plain Texture"));
    assert_eq!(l.info.attribute("parvo:filter"), Some("kaiser"));
    assert_eq!(
        l.info.attribute("parvo:fingerprint").map(str::len),
        Some(32)
    );
}

#[test]
fn update_skips_unchanged_inputs_and_rebuilds_changed_options() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("u.exr");
    let run = |filter: &str| {
        let r = parvo(&[
            "mip",
            "builtin:zoneplate:64",
            "-o",
            s(&out),
            "--update",
            "--filter",
            filter,
        ]);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        String::from_utf8(r.stdout).unwrap()
    };
    assert!(!run("box").contains("up to date"));
    let before = std::fs::metadata(&out).unwrap().modified().unwrap();
    assert!(run("box").contains("up to date"));
    assert_eq!(std::fs::metadata(&out).unwrap().modified().unwrap(), before);
    assert!(
        !run("lanczos3").contains("up to date"),
        "a new filter rebuilds"
    );
}

#[test]
fn dry_run_writes_nothing_and_json_is_machine_readable() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("d.ktx2");
    let r = parvo(&[
        "mip",
        "builtin:checker:32",
        "-o",
        s(&out),
        "--dry-run",
        "--json",
    ]);
    assert!(r.status.success());
    assert!(!out.exists());
    let v: serde_json::Value = serde_json::from_slice(&r.stdout).unwrap();
    assert_eq!(v["status"], "dry run");
    assert_eq!(v["levels"].as_array().unwrap().len(), 6);
    let r = parvo(&[
        "mip",
        "builtin:checker:32",
        "-o",
        s(&out),
        "--json",
        "--stats",
    ]);
    assert!(r.status.success());
    let v: serde_json::Value = serde_json::from_slice(&r.stdout).unwrap();
    assert_eq!(v["status"], "written");
    assert_eq!(v["type"], "u8");
    assert!(v["seconds"]["build"].as_f64().unwrap() >= 0.0);
    assert!(out.exists());
}

#[test]
fn stats_prints_phase_timings_and_peak_memory() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("s.dds");
    let r = parvo(&["mip", "builtin:checker:32", "-o", s(&out), "--stats"]);
    assert!(r.status.success());
    let stdout = String::from_utf8(r.stdout).unwrap();
    assert!(stdout.contains("stats: read"), "{stdout}");
    assert!(stdout.contains("peak memory"), "{stdout}");
}

#[test]
fn grey_and_rgb_sources_keep_their_channels_where_the_container_can() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("rgb.png");
    image::save_buffer(
        &src,
        &noise(16 * 8 * 3, 3),
        16,
        8,
        image::ExtendedColorType::Rgb8,
    )
    .unwrap();
    let exr = dir.path().join("rgb.exr");
    let dds = dir.path().join("rgb.dds");
    let ktx = dir.path().join("rgb.ktx2");
    for out in [&exr, &dds, &ktx] {
        assert!(parvo(&["mip", s(&src), "-o", s(out)]).status.success());
    }
    assert_eq!(load(&exr).base().channels(), 3);
    assert_eq!(load(&ktx).base().channels(), 3);
    // sRGB RGB8 has no DXGI format: stored as R8G8B8A8_UNORM_SRGB with
    // alpha 255 and the DX10 alpha mode "opaque", which reads back as RGB.
    let d = load(&dds);
    assert_eq!(d.base().channels(), 3);
    assert_eq!(d.info.attribute("dds:alphaMode"), Some("opaque"));
    let bytes = std::fs::read(&dds).unwrap();
    assert!(bytes[148..].chunks(4).all(|p| p[3] == 255));
}

#[test]
fn batch_names_outputs_after_inputs_and_refuses_duplicate_names() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.png");
    let a_jpg = dir.path().join("a.jpg");
    image::save_buffer(
        &a,
        &noise(8 * 8 * 3, 1),
        8,
        8,
        image::ExtendedColorType::Rgb8,
    )
    .unwrap();
    image::save_buffer(
        &a_jpg,
        &noise(8 * 8 * 3, 2),
        8,
        8,
        image::ExtendedColorType::Rgb8,
    )
    .unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    let r = parvo(&[
        "mip",
        s(&a),
        "builtin:checker:16",
        "--out-dir",
        s(&out),
        "--ext",
        "png",
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    for name in [
        "a_0.png",
        "a_3.png",
        "builtin-checker-16_0.png",
        "builtin-checker-16_4.png",
    ] {
        assert!(out.join(name).exists(), "{name}");
    }
    // a.png and a.jpg would both become a.ktx2: the second is refused.
    let r = parvo(&[
        "mip",
        s(&a),
        s(&a_jpg),
        "--out-dir",
        s(&out),
        "--ext",
        "ktx2",
    ]);
    assert_eq!(r.status.code(), Some(1));
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(err.contains("is also the output of"), "{err}");
    assert!(out.join("a.ktx2").exists());
}
