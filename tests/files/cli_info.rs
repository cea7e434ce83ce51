//! `parvo info`: describes our outputs and other writers' files (a plain
//! single-level EXR from the `exr` crate), every level, and fails with one line
//! per unreadable file.

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

#[test]
fn info_lists_every_level_tiling_wrap_modes_and_metadata() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("z.exr");
    let o = parvo(&[
        "mip",
        "builtin:zoneplate:48",
        "-o",
        s(&exr),
        "--wrap",
        "clamp",
        "--tile",
        "32",
    ]);
    assert!(o.status.success());
    let o = parvo(&["info", s(&exr)]);
    assert!(o.status.success());
    let text = String::from_utf8(o.stdout).unwrap();
    for needle in [
        "OpenEXR, tiled 32x32, mip-mapped (rounding down)",
        "size:       48x48",
        "levels:     6",
        " 0: 48x48",
        " 5: 1x1",
        "wrap modes: clamp,clamp",
        "textureformat: Plain Texture",
        "parvo:fingerprint:",
    ] {
        assert!(text.contains(needle), "`{needle}` missing from:\n{text}");
    }
    let o = parvo(&["info", "--json", s(&exr)]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let sizes: Vec<u64> = v["levels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l["width"].as_u64().unwrap())
        .collect();
    assert_eq!(sizes, [48, 24, 12, 6, 3, 1]);
    assert_eq!(v["tile"], serde_json::json!([32, 32]));
    assert_eq!(v["type"], "f16");
}

#[test]
fn info_reads_a_single_level_exr_from_another_writer() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("scan.exr");
    exr::prelude::write_rgb_file(&p, 5, 3, |x, y| (x as f32, y as f32, 0.5f32)).unwrap();
    let o = parvo(&["info", "--json", s(&p)]);
    assert!(o.status.success(), "{o:?}");
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["levels"].as_array().unwrap().len(), 1);
    assert_eq!(v["channels"], 3);
    assert_eq!(v["type"], "f32");
    let mean = v["levels"][0]["mean"].as_array().unwrap();
    assert!((mean[0].as_f64().unwrap() - 2.0).abs() < 1e-9, "{mean:?}");
    assert!((mean[1].as_f64().unwrap() - 1.0).abs() < 1e-9, "{mean:?}");
}

#[test]
fn unreadable_files_fail_with_one_line_each_and_the_rest_are_described() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.exr");
    std::fs::write(&bad, [0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0, 1]).unwrap();
    let o = parvo(&["info", s(&bad), "builtin:checker:8"]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8(o.stderr).unwrap();
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with(&format!("parvo: {}: cannot decode OpenEXR", s(&bad))),
        "{err}"
    );
    assert!(
        String::from_utf8(o.stdout)
            .unwrap()
            .contains("builtin:checker:8")
    );
}
