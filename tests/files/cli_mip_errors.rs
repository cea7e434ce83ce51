//! Failures of `parvo mip`: one clear line per bad input naming the file,
//! exit code 1 while the other inputs are still written, exit code 2 for
//! usage errors, and never a partial file at a destination.

use std::path::Path;
use std::process::{Command, Output};

fn parvo(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_parvo"))
        .args(args)
        .output()
        .expect("run parvo")
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn stderr_lines(o: &Output) -> Vec<String> {
    String::from_utf8_lossy(&o.stderr)
        .lines()
        .map(str::to_string)
        .collect()
}

fn png(path: &Path, w: u32, h: u32) {
    let px: Vec<u8> = (0..w * h * 4).map(|i| (i * 7 % 251) as u8).collect();
    image::save_buffer(path, &px, w, h, image::ExtendedColorType::Rgba8).unwrap();
}

/// Files in `dir` whose name starts with `.parvo-` (temporary files).
fn leftovers(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".parvo-"))
        .collect()
}

/// Exactly one stderr line, starting with `parvo: INPUT:` and containing
/// `needle`; exit code 1.
fn assert_one_line_error(o: &Output, input: &str, needle: &str) {
    assert_eq!(o.status.code(), Some(1), "{o:?}");
    let lines = stderr_lines(o);
    assert_eq!(lines.len(), 1, "one line expected: {lines:?}");
    assert!(
        lines[0].starts_with(&format!("parvo: {input}: ")),
        "{lines:?}"
    );
    assert!(
        lines[0].to_lowercase().contains(needle),
        "`{needle}` not in {lines:?}"
    );
}

#[test]
fn batch_with_one_corrupt_input_exits_1_and_writes_the_others() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    let a = dir.path().join("a.png");
    let c = dir.path().join("c.png");
    let bad = dir.path().join("bad.png");
    png(&a, 16, 16);
    png(&c, 9, 5);
    png(&bad, 64, 64);
    let bytes = std::fs::read(&bad).unwrap();
    std::fs::write(&bad, &bytes[..bytes.len() / 2]).unwrap();
    // Colour stated, so that no note on the assumed colour space joins the
    // one error line.
    let o = parvo(&[
        "mip",
        s(&a),
        s(&bad),
        s(&c),
        "--out-dir",
        s(&out),
        "--color",
        "srgb",
    ]);
    assert_one_line_error(&o, s(&bad), "png");
    assert!(out.join("a.exr").exists());
    assert!(out.join("c.exr").exists());
    assert!(!out.join("bad.exr").exists(), "no file for the bad input");
    assert!(leftovers(&out).is_empty());
    // The summary names each written file once.
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(stdout.lines().count(), 2, "{stdout}");
}

#[test]
fn truncated_png_is_a_one_line_error() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("t.png");
    png(&p, 32, 32);
    let b = std::fs::read(&p).unwrap();
    std::fs::write(&p, &b[..40]).unwrap();
    let o = parvo(&["mip", s(&p), "-o", s(&dir.path().join("t.exr"))]);
    assert_one_line_error(&o, s(&p), "png");
    assert!(!dir.path().join("t.exr").exists());
}

#[test]
fn empty_file_is_a_one_line_error() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("e.png");
    std::fs::write(&p, b"").unwrap();
    let o = parvo(&["mip", s(&p), "-o", s(&dir.path().join("e.exr"))]);
    assert_one_line_error(&o, s(&p), "empty");
}

fn crc32(data: &[u8]) -> u32 {
    let mut c = !0u32;
    for &b in data {
        c ^= b as u32;
        for _ in 0..8 {
            c = if c & 1 != 0 {
                0xEDB8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
        }
    }
    !c
}

fn chunk(kind: &[u8; 4], data: &[u8]) -> Vec<u8> {
    let mut out = (data.len() as u32).to_be_bytes().to_vec();
    out.extend_from_slice(kind);
    out.extend_from_slice(data);
    let mut crc_in = kind.to_vec();
    crc_in.extend_from_slice(data);
    out.extend_from_slice(&crc32(&crc_in).to_be_bytes());
    out
}

#[test]
fn png_declaring_100000_squared_is_refused_by_the_limits() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("bomb.png");
    let mut ihdr = Vec::new();
    ihdr.extend_from_slice(&100_000u32.to_be_bytes());
    ihdr.extend_from_slice(&100_000u32.to_be_bytes());
    ihdr.extend_from_slice(&[8, 6, 0, 0, 0]); // RGBA8
    let mut f = b"\x89PNG\r\n\x1a\n".to_vec();
    f.extend(chunk(b"IHDR", &ihdr));
    f.extend(chunk(
        b"IDAT",
        &[0x78, 0x9c, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01],
    ));
    f.extend(chunk(b"IEND", &[]));
    std::fs::write(&p, f).unwrap();
    let out = dir.path().join("bomb.exr");
    let o = parvo(&["mip", s(&p), "-o", s(&out)]);
    assert_one_line_error(&o, s(&p), "limit");
    assert!(!out.exists());
    // Raising the limits gets past the check (then the data is missing).
    let o = parvo(&[
        "mip",
        s(&p),
        "-o",
        s(&out),
        "--max-width",
        "100000",
        "--max-height",
        "100000",
        "--max-alloc",
        "64", // bytes: still refused, by the allocation limit
    ]);
    assert_one_line_error(&o, s(&p), "limit");
}

#[test]
fn directory_without_images_is_a_one_line_usage_error() {
    // A directory input stands for the images in it; none is a usage
    // error that says so (exit 2), before anything is read.
    let dir = tempfile::tempdir().unwrap();
    let o = parvo(&["mip", s(dir.path()), "-o", s(&dir.path().join("x.exr"))]);
    assert_eq!(o.status.code(), Some(2), "{o:?}");
    let lines = stderr_lines(&o);
    assert_eq!(lines.len(), 1, "{lines:?}");
    assert!(lines[0].contains("holds no image"), "{lines:?}");
}

#[test]
fn missing_input_is_a_one_line_error() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("nope.png");
    let o = parvo(&["mip", s(&p), "-o", s(&dir.path().join("x.exr"))]);
    assert_one_line_error(&o, s(&p), "no such file");
}

#[test]
fn unwritable_output_directory_is_a_one_line_error() {
    let dir = tempfile::tempdir().unwrap();
    // A regular file where the output directory should be: not writable
    // even for root (unlike a chmod 555 directory).
    let not_dir = dir.path().join("file");
    std::fs::write(&not_dir, b"x").unwrap();
    let o = parvo(&[
        "mip",
        "builtin:checker:16",
        "-o",
        s(&not_dir.join("out.exr")),
    ]);
    assert_one_line_error(&o, "builtin:checker:16", "cannot create a file in");
    let missing = dir.path().join("missing/out.exr");
    let o = parvo(&["mip", "builtin:checker:16", "-o", s(&missing)]);
    assert_one_line_error(&o, "builtin:checker:16", "no such file");
}

#[test]
fn exr_with_nan_is_an_error_unless_fixnan_says_otherwise() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("nan.exr");
    // A scanline RGBA float EXR (not a texture), NaN at texel (3, 2).
    exr::prelude::write_rgba_file(&p, 8, 4, |x, y| {
        let v = if (x, y) == (3, 2) { f32::NAN } else { 0.25 };
        (v, v, v, 1.0f32)
    })
    .unwrap();
    let out = dir.path().join("nan_out.exr");
    let o = parvo(&["mip", s(&p), "-o", s(&out)]);
    assert_one_line_error(&o, s(&p), "non-finite value nan at texel (3, 2)");
    assert!(!out.exists());
    let o = parvo(&["mip", s(&p), "-o", s(&out), "--fixnan", "neighbors"]);
    assert!(o.status.success(), "{o:?}");
    let l = parvo::io::load(s(&out), &parvo::io::Limits::default()).unwrap();
    assert!(l.base().to_linear().iter().all(|v| v.is_finite()));
    assert!((l.levels[1].to_linear()[4] - 0.25).abs() < 1e-3);
}

#[test]
fn a_failing_level_leaves_no_partial_png_set() {
    let dir = tempfile::tempdir().unwrap();
    // Level 2's name is taken by a directory: levels 0 and 1 must not
    // appear either.
    std::fs::create_dir(dir.path().join("p_2.png")).unwrap();
    let tpl = dir.path().join("p_{level}.png");
    let o = parvo(&["mip", "builtin:checker:16", "-o", s(&tpl)]);
    assert_one_line_error(&o, "builtin:checker:16", "directory");
    assert!(!dir.path().join("p_0.png").exists());
    assert!(!dir.path().join("p_1.png").exists());
    assert!(leftovers(dir.path()).is_empty());
}

#[test]
fn failed_rebuild_keeps_the_previous_output() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("keep.exr");
    assert!(
        parvo(&["mip", "builtin:checker:16", "-o", s(&out)])
            .status
            .success()
    );
    let before = std::fs::read(&out).unwrap();
    let bad = dir.path().join("bad.png");
    std::fs::write(&bad, b"\x89PNG\r\n\x1a\nnot really").unwrap();
    let o = parvo(&["mip", s(&bad), "-o", s(&out)]);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(std::fs::read(&out).unwrap(), before);
}

#[test]
fn usage_errors_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.exr");
    for args in [
        vec![
            "mip",
            "builtin:checker:8",
            "builtin:checker:16",
            "-o",
            s(&out),
        ],
        vec!["mip", "builtin:checker:8", "-o", "x.bmp"],
        vec!["mip", "builtin:checker:8"],
        vec![
            "mip",
            "builtin:checker:8",
            "-o",
            s(&out),
            "--filter",
            "gauss",
        ],
        vec![
            "mip",
            "builtin:checker:8",
            "-o",
            s(&out),
            "--wrap",
            "sideways",
        ],
        vec!["mip", "builtin:checker:8", "-o", s(&out), "--tile", "0"],
        vec!["mip", "builtin:checker:8", "-o", s(&out), "--levels", "0"],
    ] {
        let o = parvo(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {o:?}");
        assert!(!stderr_lines(&o).is_empty());
    }
    assert!(!out.exists());
}

#[test]
fn impossible_type_is_a_usage_error_and_a_short_exr_chain_a_per_file_error() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.exr");
    // Known from the arguments alone: exit 2 before any input is read.
    let o = parvo(&["mip", "builtin:checker:8", "-o", s(&out), "--type", "u8"]);
    assert_eq!(o.status.code(), Some(2), "{o:?}");
    assert!(String::from_utf8_lossy(&o.stderr).contains("cannot store u8"));
    let o = parvo(&["mip", "builtin:checker:8", "-o", s(&out), "--levels", "2"]);
    assert_one_line_error(&o, "builtin:checker:8", "full chain");
}

#[test]
fn killing_parvo_mid_write_leaves_the_old_output_or_a_complete_new_one() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("big.exr");
    std::fs::write(&out, b"old").unwrap();
    for delay_ms in [50u64, 400, 1200] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_parvo"))
            .args([
                "mip",
                "builtin:zoneplate:2048",
                "-o",
                s(&out),
                "--compression",
                "zip",
            ])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_millis(delay_ms));
        let _ = child.kill();
        let _ = child.wait();
        let bytes = std::fs::read(&out).unwrap();
        if bytes != b"old" {
            // The run finished before the kill: the file must be whole.
            let l = parvo::io::load(s(&out), &parvo::io::Limits::default())
                .expect("a complete EXR at the destination");
            assert_eq!(l.levels.len(), 12, "delay {delay_ms} ms");
            std::fs::write(&out, b"old").unwrap();
        }
    }
}

#[test]
fn ctrl_c_removes_temporary_files_and_keeps_the_old_output() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("big.exr");
    std::fs::write(&out, b"old").unwrap();
    let child = Command::new(env!("CARGO_BIN_EXE_parvo"))
        .args(["mip", "builtin:zoneplate:2048", "-o", s(&out)])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Wait until the temporary file exists (the write phase), then SIGINT.
    let t0 = std::time::Instant::now();
    while leftovers(dir.path()).is_empty() && t0.elapsed().as_secs() < 60 {
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    let interrupted = !leftovers(dir.path()).is_empty();
    Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    let o = child.wait_with_output().unwrap();
    if interrupted && o.status.code() == Some(130) {
        assert!(String::from_utf8_lossy(&o.stderr).contains("interrupted"));
        assert_eq!(std::fs::read(&out).unwrap(), b"old");
        assert!(leftovers(dir.path()).is_empty(), "temporary files removed");
    } else {
        // Finished before the signal arrived: the new file is complete.
        assert!(parvo::io::load(s(&out), &parvo::io::Limits::default()).is_ok());
    }
}
