//! Issue 27, finding 13: README.md said "Not built yet: … of the fuzzing
//! work, the `sat`, `cachesim` and `normal_roughness` targets" when all
//! seven targets existed. The README's "Not built yet" paragraph must not
//! name anything `fuzz/fuzz_targets/` has, and every target there must be
//! named in the README and replayed by the tests CI runs (its seeds, kept
//! artifacts and mutations: `tests/core/fuzz_replay.rs`,
//! `tests/files/fuzz_replay.rs`).

use std::path::Path;

#[test]
fn readme_names_every_fuzz_target_and_calls_none_missing() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let replays = ["tests/core/fuzz_replay.rs", "tests/files/fuzz_replay.rs"]
        .map(|p| std::fs::read_to_string(root.join(p)).unwrap())
        .concat();
    let mut targets: Vec<String> = std::fs::read_dir(root.join("fuzz/fuzz_targets"))
        .unwrap()
        .filter_map(|e| {
            let p = e.unwrap().path();
            (p.extension()? == "rs").then(|| p.file_stem().unwrap().to_string_lossy().into_owned())
        })
        .collect();
    targets.sort();
    assert!(targets.len() >= 7, "fuzz targets: {targets:?}");
    // The paragraph that starts "Not built yet" (up to the blank line).
    let missing = readme
        .split("\n\n")
        .find(|p| p.trim_start().starts_with("Not built yet"))
        .unwrap_or("");
    for t in &targets {
        let quoted = format!("`{t}`");
        assert!(
            readme.contains(&quoted),
            "README does not name the fuzz target {t}"
        );
        assert!(
            !missing.contains(&quoted),
            "README lists the fuzz target {t} as not built: {missing}"
        );
        assert!(
            replays.contains(&format!("replay(\"{t}\", {t}::run)")),
            "no test replays the fuzz target {t}"
        );
    }
}
