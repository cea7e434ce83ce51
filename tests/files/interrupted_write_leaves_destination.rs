//! A failure while writing leaves an existing destination untouched, for
//! every file parvo writes: `parvo mip`'s EXR, KTX2, DDS, `{level}.png`
//! levels and roughness chain, `cachesim`'s `--trace-out`, `--sweep` CSV
//! and SVG, `tradeoff`'s PNGs, JSON and SVG, and `render`'s PNG.
//!
//! The `parvo` binary runs under `ulimit -f N` (RLIMIT_FSIZE), with N
//! chosen from a first, unlimited run so that the targeted file is cut
//! short and every file written before it fits. Each destination already
//! exists with known bytes. Two ways to fail:
//! - SIGXFSZ (the limit's default action) kills the process mid-write,
//!   like a crash or SIGKILL: no cleanup runs, so the temporary file of
//!   the cut write is left behind under a `.parvo-*.tmp` name (observed:
//!   exactly one, for every target); the destination keeps its bytes;
//! - with SIGXFSZ ignored, the write fails with EFBIG ("File too large",
//!   as a full disk fails with ENOSPC): parvo exits 1 naming the error,
//!   the destination keeps its bytes and no temporary file is left.
//!
//! Files written after the target are never reached and keep their bytes
//! too. Files written before it are complete new files: the roughness
//! case shows that a normal map and its roughness chain are two files
//! replaced one after the other, not together.
#![cfg(target_os = "linux")]

use std::collections::BTreeSet;
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// How the cut write fails.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Failure {
    /// SIGXFSZ kills the process.
    Killed,
    /// SIGXFSZ ignored: write(2) fails with EFBIG.
    Efbig,
}

struct Case {
    name: &'static str,
    /// parvo's arguments, run in the case's directory.
    args: Vec<String>,
    /// The files parvo writes, relative to that directory, in the order
    /// it writes them.
    outputs: Vec<String>,
    /// The output whose write is cut short.
    target: usize,
}

fn case(name: &'static str, args: &[&str], outputs: &[&str], target: &str) -> Case {
    let outputs: Vec<String> = outputs.iter().map(|s| s.to_string()).collect();
    let target = outputs
        .iter()
        .position(|o| o == target)
        .unwrap_or_else(|| panic!("{name}: {target} is not an output"));
    Case {
        name,
        args: args.iter().map(|s| s.to_string()).collect(),
        outputs,
        target,
    }
}

fn run_limited(dir: &Path, args: &[String], blocks: Option<u64>, failure: Failure) -> Output {
    // `exec` keeps the limit and the ignored signal; `ulimit -c 0` keeps
    // the killed process from dumping core into the directory.
    let script = match (blocks, failure) {
        (None, _) => "exec \"$0\" \"$@\"".to_string(),
        (Some(n), Failure::Killed) => format!("ulimit -c 0; ulimit -f {n}; exec \"$0\" \"$@\""),
        (Some(n), Failure::Efbig) => {
            format!("ulimit -c 0; ulimit -f {n}; trap '' XFSZ; exec \"$0\" \"$@\"")
        }
    };
    Command::new("sh")
        .arg("-c")
        .arg(script)
        .arg(env!("CARGO_BIN_EXE_parvo"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run sh")
}

/// Bytes per `ulimit -f` block of this `sh` (512 in POSIX; measured, so a
/// shell counting 1024 does not make the limits twice as loose).
fn block_bytes() -> u64 {
    let dir = tempfile::tempdir().unwrap();
    let o = Command::new("sh")
        .arg("-c")
        .arg("ulimit -f 2; trap '' XFSZ; head -c 8192 /dev/zero > f")
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(!o.status.success(), "head wrote 8 KiB under ulimit -f 2");
    let n = std::fs::metadata(dir.path().join("f")).unwrap().len();
    assert!(n == 1024 || n == 2048, "ulimit -f 2 let {n} bytes through");
    n / 2
}

fn old_bytes(name: &str) -> Vec<u8> {
    format!("the existing {name}, which a failed write must not touch\n")
        .repeat(20)
        .into_bytes()
}

/// A flat RGB8 normal map: its roughness chain is constant, so a
/// zstd-supercompressed normal output is far smaller than an uncompressed
/// EXR roughness chain, and the roughness file can be the one cut short.
fn write_inputs(dir: &Path) {
    let n = 128u32;
    let codes: Vec<u8> = (0..n * n).flat_map(|_| [128u8, 128, 255]).collect();
    image::RgbImage::from_raw(n, n, codes)
        .unwrap()
        .save(dir.join("normal.png"))
        .unwrap();
}

/// Files in the directories that hold `outputs`, relative to `dir`.
fn listing(dir: &Path, outputs: &[String]) -> BTreeSet<String> {
    let parents: BTreeSet<PathBuf> = outputs
        .iter()
        .map(|o| dir.join(o).parent().unwrap().to_path_buf())
        .collect();
    let mut out = BTreeSet::new();
    for p in parents {
        for e in std::fs::read_dir(&p).unwrap() {
            let path = e.unwrap().path();
            if path.is_file() {
                let rel = path.strip_prefix(dir).unwrap();
                out.insert(rel.to_string_lossy().into_owned());
            }
        }
    }
    out
}

fn is_temporary(rel: &str) -> bool {
    let name = Path::new(rel).file_name().unwrap().to_string_lossy();
    name.starts_with(".parvo-") && name.ends_with(".tmp")
}

/// Runs `c` once unlimited to size its outputs, then once per failure
/// over existing destinations; returns the temporary files left after
/// the kill.
fn check(c: &Case, block: u64) -> usize {
    let sizes: Vec<u64> = {
        let dir = tempfile::tempdir().unwrap();
        write_inputs(dir.path());
        for o in &c.outputs {
            if let Some(p) = dir.path().join(o).parent() {
                std::fs::create_dir_all(p).unwrap();
            }
        }
        let o = run_limited(dir.path(), &c.args, None, Failure::Killed);
        assert!(
            o.status.success(),
            "{}: the unlimited run failed: {}",
            c.name,
            String::from_utf8_lossy(&o.stderr)
        );
        c.outputs
            .iter()
            .map(|f| {
                std::fs::metadata(dir.path().join(f))
                    .unwrap_or_else(|e| panic!("{}: {f} not written: {e}", c.name))
                    .len()
            })
            .collect()
    };
    let before = sizes[..c.target].iter().copied().max().unwrap_or(0);
    let size = sizes[c.target];
    let blocks = (before + size) / 2 / block;
    assert!(
        blocks * block >= before && blocks * block < size,
        "{}: no limit fits {} ({size} bytes) after files of up to {before} bytes",
        c.name,
        c.outputs[c.target]
    );
    let mut left = 0;
    for failure in [Failure::Killed, Failure::Efbig] {
        let what = format!(
            "{} {failure:?} ({} cut at {} of {size} bytes)",
            c.name,
            c.outputs[c.target],
            blocks * block
        );
        let dir = tempfile::tempdir().unwrap();
        write_inputs(dir.path());
        for o in &c.outputs {
            let p = dir.path().join(o);
            std::fs::create_dir_all(p.parent().unwrap()).unwrap();
            std::fs::write(&p, old_bytes(o)).unwrap();
        }
        let existing = listing(dir.path(), &c.outputs);
        let o = run_limited(dir.path(), &c.args, Some(blocks), failure);
        let stderr = String::from_utf8_lossy(&o.stderr);
        match failure {
            Failure::Killed => assert_eq!(
                o.status.signal(),
                Some(libc::SIGXFSZ),
                "{what}: {:?} {stderr}",
                o.status
            ),
            Failure::Efbig => {
                assert_eq!(o.status.code(), Some(1), "{what}: {stderr}");
                assert!(stderr.contains("File too large"), "{what}: {stderr}");
            }
        }
        eprintln!(
            "{what}: {:?}, {}",
            o.status,
            stderr.lines().next().unwrap_or("(no message)")
        );
        // The cut file and the ones after it keep their bytes.
        for f in &c.outputs[c.target..] {
            let got = std::fs::read(dir.path().join(f)).unwrap();
            assert!(got == old_bytes(f), "{what}: {f} changed");
        }
        // Nothing else appears but the killed write's temporary file.
        let extra: Vec<String> = listing(dir.path(), &c.outputs)
            .difference(&existing)
            .cloned()
            .collect();
        eprintln!("{what}: new files {extra:?}");
        match failure {
            Failure::Killed => {
                assert!(extra.iter().all(|f| is_temporary(f)), "{what}: {extra:?}");
                left = extra.len();
            }
            Failure::Efbig => assert!(extra.is_empty(), "{what}: left {extra:?}"),
        }
    }
    left
}

fn cases() -> Vec<Case> {
    let photo = "builtin:photo:128";
    let levels: Vec<String> = (0..8).map(|k| format!("photo_{k}.png")).collect();
    let levels: Vec<&str> = levels.iter().map(String::as_str).collect();
    let sweep = [
        "cachesim",
        "--sweep",
        "--out",
        "sweep",
        "--size",
        "32x24",
        "--texture",
        "builtin:checker:64",
        "--cache-sizes",
        "1K,2K,4K,8K,16K,32K",
        "--lines",
        "32,64",
        "--ways",
        "1,2",
        "--layouts",
        "linear",
        "--filters",
        "bilinear",
    ];
    let sweep_out = ["sweep/sweep.csv", "sweep/sweep.svg"];
    let tradeoff = [
        "tradeoff",
        "--out",
        "t",
        "--size",
        "32x24",
        "--texture",
        "builtin:checker:64",
        "--filters",
        "trilinear",
        "--runs",
        "1",
    ];
    let tradeoff_out = [
        "t/reference.png",
        "t/trilinear.png",
        "t/trilinear-error.png",
        "t/trilinear-levels.png",
        "t/report.json",
        "t/tradeoff.svg",
    ];
    let rough = [
        "mip",
        "normal.png",
        "--normal-map",
        "--roughness",
        "0.25",
        "-o",
        "normal.ktx2",
        "--zstd",
        "19",
        "--roughness-out",
        "rough.exr",
        "--compression",
        "none",
    ];
    vec![
        case(
            "mip exr",
            &["mip", photo, "-o", "photo.exr", "--compression", "none"],
            &["photo.exr"],
            "photo.exr",
        ),
        case(
            "mip ktx2",
            &["mip", photo, "-o", "photo.ktx2"],
            &["photo.ktx2"],
            "photo.ktx2",
        ),
        case(
            "mip dds",
            &["mip", photo, "-o", "photo.dds"],
            &["photo.dds"],
            "photo.dds",
        ),
        // Every level is staged before any is renamed: level 0, written
        // first and largest, is cut and no level is replaced.
        case(
            "mip png levels",
            &["mip", photo, "-o", "photo_{level}.png"],
            &levels,
            "photo_0.png",
        ),
        case(
            "mip roughness exr",
            &rough,
            &["normal.ktx2", "rough.exr"],
            "rough.exr",
        ),
        case(
            "cachesim trace",
            &[
                "cachesim",
                "--size",
                "64x48",
                "--texture",
                "builtin:checker:128",
                "--trace-out",
                "trace.txt",
            ],
            &["trace.txt"],
            "trace.txt",
        ),
        case("cachesim sweep csv", &sweep, &sweep_out, "sweep/sweep.csv"),
        case("cachesim sweep svg", &sweep, &sweep_out, "sweep/sweep.svg"),
        case("tradeoff png", &tradeoff, &tradeoff_out, "t/reference.png"),
        case("tradeoff json", &tradeoff, &tradeoff_out, "t/report.json"),
        case("tradeoff svg", &tradeoff, &tradeoff_out, "t/tradeoff.svg"),
        case(
            "render png",
            &[
                "render",
                "--size",
                "32x24",
                "--texture",
                "builtin:checker:64",
                "-o",
                "render.png",
            ],
            &["render.png"],
            "render.png",
        ),
    ]
}

#[test]
fn a_write_cut_short_leaves_every_existing_destination_untouched() {
    let block = block_bytes();
    for c in cases() {
        let left = check(&c, block);
        // The killed write's own temporary file, and nothing else.
        assert_eq!(left, 1, "{}: {left} temporary files after the kill", c.name);
    }
}

/// The roughness chain is written after the normal map, as a second
/// atomic write: when only the roughness write fails, the normal output
/// is already the new file (complete, readable), the roughness file the
/// old one. `--update` rebuilds both (it skips only when both carry the
/// run's fingerprint).
#[test]
fn a_failed_roughness_write_leaves_the_new_normal_map_complete() {
    let block = block_bytes();
    let c = cases()
        .into_iter()
        .find(|c| c.name == "mip roughness exr")
        .unwrap();
    let dir = tempfile::tempdir().unwrap();
    write_inputs(dir.path());
    std::fs::write(dir.path().join("normal.ktx2"), old_bytes("normal.ktx2")).unwrap();
    std::fs::write(dir.path().join("rough.exr"), old_bytes("rough.exr")).unwrap();
    // Large enough for the supercompressed normal map, far below the
    // uncompressed 128² roughness chain (about 44 KB).
    let o = run_limited(dir.path(), &c.args, Some(16 * 1024 / block), Failure::Efbig);
    assert_eq!(o.status.code(), Some(1));
    let rough = std::fs::read(dir.path().join("rough.exr")).unwrap();
    assert!(rough == old_bytes("rough.exr"), "rough.exr changed");
    let normal = parvo::io::load(
        dir.path().join("normal.ktx2").to_str().unwrap(),
        &parvo::io::Limits::default(),
    )
    .unwrap();
    assert_eq!(normal.levels.len(), 8);
}
