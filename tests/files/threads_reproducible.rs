//! Output bytes do not depend on the number of threads: every container
//! (EXR with its parallel tile compression, KTX2 with parallel zstd, DDS,
//! PNG levels) and the block encoders (bands encoded in parallel), written
//! by `parvo mip --threads 1` and `--threads 2`, are byte for byte equal.

use std::path::Path;
use std::process::Command;

fn mip(input: &str, out: &Path, threads: &str, extra: &[&str]) {
    let o = Command::new(env!("CARGO_BIN_EXE_parvo"))
        .args(["mip", input, "-o"])
        .arg(out)
        .args(["--threads", threads])
        .args(extra)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn one_and_two_threads_write_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let mut cases: Vec<(&str, &str, Vec<&str>)> = vec![
        // Odd size: partial tiles, odd levels; kaiser reads across bands.
        ("builtin:photo:333", "exr", vec!["--filter", "kaiser"]),
        ("builtin:photo:333", "exr", vec!["--compression", "piz"]),
        // Even size, box: level 0 built, compressed and written a group of
        // rows at a time (the fused EXR path), with a tile height that is
        // not the group's.
        ("builtin:photo:512", "exr", vec!["--tile", "32x16"]),
        ("builtin:checker:300", "ktx2", vec!["--zstd", "5"]),
        ("builtin:zoneplate:257", "dds", vec![]),
        ("builtin:photo:129", "png", vec!["--filter", "lanczos3"]),
    ];
    if cfg!(feature = "encode") {
        cases.push((
            "builtin:photo:333",
            "ktx2",
            vec!["--compress", "bc7", "--quality", "fast"],
        ));
        cases.push(("builtin:photo:333", "dds", vec!["--compress", "bc1"]));
    }
    for (i, (input, ext, extra)) in cases.iter().enumerate() {
        let name = |t: &str| {
            if *ext == "png" {
                dir.path().join(format!("c{i}_{t}_{{level}}.png"))
            } else {
                dir.path().join(format!("c{i}_{t}.{ext}"))
            }
        };
        let (a, b) = (name("1"), name("2"));
        mip(input, &a, "1", extra);
        mip(input, &b, "2", extra);
        let files = |p: &Path| -> Vec<Vec<u8>> {
            if *ext == "png" {
                (0..)
                    .map(|k| p.to_str().unwrap().replace("{level}", &k.to_string()))
                    .take_while(|f| Path::new(f).exists())
                    .map(|f| std::fs::read(f).unwrap())
                    .collect()
            } else {
                vec![std::fs::read(p).unwrap()]
            }
        };
        let (fa, fb) = (files(&a), files(&b));
        assert!(!fa.is_empty());
        assert!(
            fa == fb,
            "{input} -> .{ext} {extra:?}: bytes differ between 1 and 2 threads"
        );
    }
}
