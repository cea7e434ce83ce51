//! `parvo cachesim` end to end: the JSON counters and their identities,
//! `--trace-out` replayed with `--trace` gives the same counts, malformed
//! traces and impossible caches are one-line errors, and a sweep writes its
//! CSV (one row per configuration) and SVG.

use std::process::{Command, Output, Stdio};

fn parvo(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_parvo"))
        .args(args)
        .output()
        .expect("run parvo")
}

fn json(o: &Output) -> serde_json::Value {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

const SCENE: [&str; 8] = [
    "--scene",
    "plane",
    "--size",
    "96x64",
    "--texture",
    "builtin:checker:512",
    "--filter",
    "trilinear",
];

#[test]
fn json_counters_add_up_per_level_and_in_total() {
    let mut a = vec!["cachesim"];
    a.extend(SCENE);
    a.extend(["--cache", "4K:64:2", "--json"]);
    let v = json(&parvo(&a));
    let u = |k: &str| v[k].as_u64().unwrap();
    assert_eq!(u("hits") + u("misses"), u("accesses"));
    assert_eq!(
        u("cold_misses") + u("capacity_misses") + u("conflict_misses"),
        u("misses")
    );
    assert_eq!(u("bytes_from_memory"), u("misses") * 64);
    assert!(
        (v["texels_per_pixel"].as_f64().unwrap() - u("texel_reads") as f64 / u("pixels") as f64)
            .abs()
            < 1e-9
    );
    let levels = v["per_level"].as_array().unwrap();
    let sum = |k: &str| levels.iter().map(|l| l[k].as_u64().unwrap()).sum::<u64>();
    for k in [
        "accesses",
        "hits",
        "misses",
        "cold_misses",
        "capacity_misses",
        "conflict_misses",
        "bytes_from_memory",
        "working_set_bytes",
    ] {
        assert_eq!(sum(k), u(k), "{k}");
    }
    for k in ["hit_rate", "bytes_per_pixel", "pixels", "working_set_bytes"] {
        assert!(v.get(k).is_some(), "{k}");
    }
}

#[test]
fn a_written_trace_replays_to_the_same_counts() {
    let dir = tempfile::tempdir().unwrap();
    let t = dir.path().join("t.trace");
    let mut a = vec!["cachesim"];
    a.extend(SCENE);
    a.extend([
        "--cache",
        "2K:32:4:fifo",
        "--json",
        "--trace-out",
        t.to_str().unwrap(),
    ]);
    let scene = json(&parvo(&a));
    let replay = json(&parvo(&[
        "cachesim",
        "--trace",
        t.to_str().unwrap(),
        "--cache",
        "2K:32:4:fifo",
        "--access-bytes",
        "4",
        "--json",
    ]));
    for k in [
        "accesses",
        "hits",
        "misses",
        "cold_misses",
        "capacity_misses",
        "conflict_misses",
    ] {
        assert_eq!(scene[k], replay[k], "{k}");
    }
    // stdin and hex addresses work too.
    let mut child = Command::new(env!("CARGO_BIN_EXE_parvo"))
        .args(["cachesim", "--trace", "-", "--cache", "128:64:2", "--json"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    use std::io::Write;
    child
        .stdin
        .take()
        .unwrap()
        .write_all(b"# comment\n0x0\n64\n\n0x40 # again\n128\n0\n")
        .unwrap();
    let v = json(&child.wait_with_output().unwrap());
    // 0 miss, 64 miss, 64 hit, 128 miss (evicts 0), 0 miss.
    assert_eq!(
        (v["hits"].as_u64(), v["misses"].as_u64()),
        (Some(1), Some(4))
    );
}

#[test]
fn bad_traces_and_impossible_caches_are_one_line_errors() {
    let dir = tempfile::tempdir().unwrap();
    let t = dir.path().join("bad.trace");
    std::fs::write(&t, "12\n0x10\nfoo\n").unwrap();
    let r = parvo(&["cachesim", "--trace", t.to_str().unwrap()]);
    assert_eq!(r.status.code(), Some(1));
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(err.contains("line 3") && err.lines().count() == 1, "{err}");
    for (spec, rule) in [
        ("16K:48:4", "power of two"),
        ("16K:64:3", "multiple of line × ways"),
        ("0:64:1", "at least 1"),
    ] {
        let r = parvo(&["cachesim", "--cache", spec]);
        assert_eq!(r.status.code(), Some(2), "{spec}");
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(
            err.contains(rule) && err.lines().count() == 1,
            "{spec}: {err}"
        );
    }
}

#[test]
fn a_sweep_writes_one_csv_row_per_configuration_and_a_plot() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sweep");
    let mut a = vec!["cachesim", "--sweep"];
    a.extend(SCENE);
    a.extend([
        "--cache-sizes",
        "1K,4K",
        "--lines",
        "32,64",
        "--ways",
        "1,4",
        "--layouts",
        "linear,tiled:4x4",
        "--filters",
        "bilinear,sat",
        "--out",
        out.to_str().unwrap(),
    ]);
    let r = parvo(&a);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let csv = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().collect();
    assert_eq!(rows.len(), 1 + 2 * 2 * 2 * 2 * 2, "{csv}");
    assert!(rows[0].starts_with("filter,layout,cache,size,line,ways"));
    // sat reads its table entries: it has traffic too.
    assert!(
        rows.iter()
            .any(|r| r.starts_with("sat,") && !r.contains(",0,0,0,0,0,"))
    );
    let svg = std::fs::read_to_string(out.join("sweep.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("hit rate") && svg.contains("tiled:4x4"));
}

/// `parvo … | head`: a reader that has gone ends the run quietly with
/// status 141 (128 + SIGPIPE, as a shell reports a filter the signal
/// ended), not with a panic and a backtrace.
#[test]
fn a_closed_stdout_ends_the_run_quietly() {
    let mut a = vec!["cachesim"];
    a.extend(SCENE);
    a.extend(["--cache", "4K:64:2", "--json"]);
    let mut child = Command::new(env!("CARGO_BIN_EXE_parvo"))
        .args(&a)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run parvo");
    // The reader goes before parvo writes its report.
    drop(child.stdout.take());
    let o = child.wait_with_output().expect("wait for parvo");
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(o.status.code(), Some(141), "{stderr}");
}

/// The address side's AVX-512 lanes (plans and block addresses 8 at a
/// time, taken when the CPU has them) and the portable code
/// (`PARVO_NO_AVX=1`) print the same JSON, 3C counts included, under
/// several caches and raster orders. Without AVX-512 both runs take the
/// portable code and the test checks only that a run is reproducible.
#[test]
fn the_avx512_and_portable_address_sides_agree() {
    for (cache, order) in [
        ("4K:64:2", "scanline"),
        ("16K:64:4", "tiled:8"),
        ("2K:32:4:fifo", "hilbert"),
        ("1K:64:16", "scanline"),
    ] {
        let mut a = vec!["cachesim"];
        a.extend(SCENE);
        a.extend(["--cache", cache, "--order", order, "--json"]);
        let run = |no_avx: bool| {
            let mut c = Command::new(env!("CARGO_BIN_EXE_parvo"));
            c.args(&a);
            if no_avx {
                c.env("PARVO_NO_AVX", "1");
            } else {
                c.env_remove("PARVO_NO_AVX");
            }
            let o = c.output().expect("run parvo");
            json(&o);
            o.stdout
        };
        assert_eq!(run(false), run(true), "{cache} {order}");
    }
}
