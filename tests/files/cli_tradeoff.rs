//! `parvo tradeoff` and `parvo render` end to end: a small default run
//! completes and writes every file it promises; `report.json` keeps its
//! schema (parsed back field by field); `built` shows that only what the
//! filters read was built; bad arguments are one-line usage errors;
//! `parvo render` writes frames of the requested size.

use crate::cli_common;
use cli_common::{ok, parvo};
use std::path::Path;

fn report(dir: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(dir.join("report.json")).unwrap()).unwrap()
}

fn png_size(p: &Path) -> (u32, u32) {
    let img = image::open(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    (img.width(), img.height())
}

const FILTERS: [&str; 9] = [
    "nearest",
    "bilinear",
    "trilinear",
    "aniso2",
    "aniso4",
    "aniso8",
    "aniso16",
    "ewa",
    "sat",
];

#[test]
fn a_small_default_run_writes_the_table_the_report_the_plot_and_the_images() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t");
    let stdout = ok(&parvo(&[
        "tradeoff",
        "--size",
        "64x48",
        "--runs",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]));
    for f in FILTERS {
        assert!(
            stdout
                .lines()
                .any(|l| l.split_whitespace().next() == Some(f)),
            "no table row for {f}:\n{stdout}"
        );
        assert_eq!(png_size(&out.join(format!("{f}.png"))), (64, 48));
        assert_eq!(png_size(&out.join(format!("{f}-error.png"))), (64, 48));
    }
    assert!(stdout.contains("16K:64:4") && stdout.contains("tiled:4x4"));
    assert_eq!(png_size(&out.join("reference.png")), (64, 48));
    for f in ["trilinear", "aniso16"] {
        assert_eq!(png_size(&out.join(format!("{f}-levels.png"))), (64, 48));
    }
    let svg = std::fs::read_to_string(out.join("tradeoff.svg")).unwrap();
    assert!(svg.starts_with("<svg") || svg.starts_with("<?xml"));
    for f in FILTERS {
        assert!(svg.contains(f), "the plot has no label {f}");
    }

    // report.json, field by field.
    let r = report(&out);
    assert_eq!(r["scene"], "plane");
    assert_eq!(r["frame"], "64x48");
    assert_eq!(r["texture"], "builtin:zoneplate:512");
    assert_eq!(r["texture_size"], serde_json::json!([512, 512]));
    assert_eq!(r["pixel_filter"], "gaussian");
    let pixels = r["pixels"].as_u64().unwrap();
    assert!(pixels > 0 && pixels <= 64 * 48);
    assert_eq!(r["cache"]["cache"], "16K:64:4");
    assert!(r["machine"]["logical_cpus"].as_u64().unwrap() >= 1);
    assert!(r["machine"]["cpu"].is_string());
    let built = &r["built"];
    assert_eq!(built["mip_levels"], 9);
    assert!(built["mip_bytes"].as_u64().unwrap() > 0);
    assert_eq!(built["sat"], true);
    assert!(built["sat_bytes"].as_u64().unwrap() >= 512 * 512 * 4);
    let filters = r["filters"].as_array().unwrap();
    let names: Vec<&str> = filters
        .iter()
        .map(|f| f["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, FILTERS);
    for f in filters {
        let n = |k: &str| {
            f[k].as_f64()
                .unwrap_or_else(|| panic!("{}: {k} is not a number", f["name"]))
        };
        assert!(n("ns_per_pixel") > 0.0);
        assert!(n("texels_per_pixel") >= 1.0);
        assert!(n("bytes_per_pixel") > 0.0);
        assert!(n("psnr_db") > 5.0 && n("psnr_db") < 100.0);
        assert!(n("rmse") > 0.0 && n("rmse") < 1.0);
        assert!(n("max_error") >= n("rmse") && n("max_error") <= 1.0);
        assert!(n("flicker").is_finite());
        // PSNR and RMSE describe the same error.
        let psnr = -20.0 * n("rmse").log10();
        assert!(
            (psnr - n("psnr_db")).abs() < 1e-6,
            "{psnr} vs {}",
            n("psnr_db")
        );
        let ws = f["working_set"].as_array().unwrap();
        assert!(!ws.is_empty());
        assert_eq!(ws[0]["level"], 0);
        for l in ws {
            let frac = l["fraction"].as_f64().unwrap();
            assert!((0.0..=1.0).contains(&frac));
            assert_eq!(l["touched"].as_bool().unwrap(), frac > 0.0);
        }
    }
    // Footprint assembly with more probes reads more texels.
    let texels = |name: &str| {
        filters.iter().find(|f| f["name"] == name).unwrap()["texels_per_pixel"]
            .as_f64()
            .unwrap()
    };
    assert!(texels("nearest") <= texels("bilinear"));
    assert!(texels("trilinear") <= texels("aniso4"));
    assert!(texels("aniso4") <= texels("aniso16"));
}

#[test]
fn only_what_the_filters_read_is_built() {
    let dir = tempfile::tempdir().unwrap();
    for (filters, mips, sat) in [
        ("trilinear", 9, false),
        ("sat", 0, true),
        ("bilinear-nomip,sat", 0, true),
    ] {
        let out = dir.path().join(filters.replace(',', "_"));
        ok(&parvo(&[
            "tradeoff",
            "--size",
            "32x24",
            "--runs",
            "1",
            "--filters",
            filters,
            "--out",
            out.to_str().unwrap(),
        ]));
        let r = report(&out);
        assert_eq!(r["built"]["mip_levels"], mips, "{filters}: {}", r["built"]);
        assert_eq!(r["built"]["sat"], sat, "{filters}: {}", r["built"]);
        assert_eq!(r["built"]["sat_bytes"].as_u64().unwrap() > 0, sat);
        assert_eq!(r["built"]["mip_bytes"].as_u64().unwrap() > 0, mips > 0);
    }
}

/// `--compress bc7` adds a row per filter for the compressed chain: the
/// same filter's texels per pixel, less traffic (a 16-byte block holds 16
/// texels where RGBA8 holds 4 per 16 bytes), accuracy close to the
/// uncompressed row's.
#[cfg(feature = "encode")]
#[test]
fn compressed_rows_count_whole_blocks() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("c");
    ok(&parvo(&[
        "tradeoff",
        "--size",
        "64x48",
        "--runs",
        "1",
        "--filters",
        "trilinear,aniso8",
        "--compress",
        "bc7",
        "--out",
        out.to_str().unwrap(),
    ]));
    let r = report(&out);
    let rows = r["filters"].as_array().unwrap();
    let row = |n: &str| rows.iter().find(|x| x["name"] == n).unwrap().clone();
    for f in ["trilinear", "aniso8"] {
        let (u, c) = (row(f), row(&format!("{f}+bc7")));
        assert_eq!(c["stored"], "BC7");
        assert_eq!(c["texels_per_pixel"], u["texels_per_pixel"], "{f}");
        let (bu, bc) = (
            u["bytes_per_pixel"].as_f64().unwrap(),
            c["bytes_per_pixel"].as_f64().unwrap(),
        );
        assert!(bc < bu, "{f}: {bc} bytes/px compressed, {bu} uncompressed");
        let (pu, pc) = (
            u["psnr_db"].as_f64().unwrap(),
            c["psnr_db"].as_f64().unwrap(),
        );
        assert!((pu - pc).abs() < 3.0, "{f}: {pu} dB vs {pc} dB");
        assert!(out.join(format!("{f}+bc7.png")).is_file());
    }
}

#[test]
fn bad_arguments_are_usage_errors() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x");
    let o = out.to_str().unwrap();
    for args in [
        vec!["tradeoff", "--filters", "blurry", "--out", o],
        vec!["tradeoff", "--runs", "0", "--out", o],
        vec!["tradeoff", "--spp", "0", "--out", o],
        vec!["tradeoff", "--scene", "cube", "--out", o],
        vec!["tradeoff", "--pixel-filter", "lanczos", "--out", o],
        vec!["tradeoff", "--size", "0x4", "--out", o],
    ] {
        let r = parvo(&args);
        assert_eq!(r.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert!(!out.join("report.json").exists());
    }
    let r = parvo(&["tradeoff", "--texture", "/nonexistent.png", "--out", o]);
    assert_eq!(r.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&r.stderr).contains("/nonexistent.png"));
}

#[test]
fn render_writes_the_requested_frame() {
    let dir = tempfile::tempdir().unwrap();
    for extra in [
        vec!["--filter", "ewa"],
        vec!["--filter", "reference", "--pixel-filter", "box"],
        vec!["--filter", "aniso8", "--show-levels"],
        vec!["--filter", "sat", "--scene", "rotate:30:4"],
    ] {
        let p = dir.path().join("r.png");
        let mut a = vec!["render", "--size", "50x30", "-o", p.to_str().unwrap()];
        a.extend(&extra);
        ok(&parvo(&a));
        assert_eq!(png_size(&p), (50, 30), "{extra:?}");
        std::fs::remove_file(&p).unwrap();
    }
    let p = dir.path().join("refused.png");
    let r = parvo(&[
        "render",
        "--filter",
        "reference",
        "--show-levels",
        "-o",
        p.to_str().unwrap(),
    ]);
    assert_eq!(
        r.status.code(),
        Some(2),
        "show-levels of the reference is refused"
    );
    assert!(!p.exists());
}
