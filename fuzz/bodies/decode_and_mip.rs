//! Arbitrary bytes as each input format parvo reads (the first byte picks
//! it) → load under tight limits → mips → every output container written
//! to a temporary directory. Any outcome but a panic is fine: errors are
//! the expected answer to most inputs.
//!
//! The body of `fuzz/fuzz_targets/decode_and_mip.rs`, shared with the replay test
//! (`tests/core/fuzz_replay.rs` or `tests/cli/fuzz_replay.rs`), which runs it
//! over `fuzz/seeds/decode_and_mip` and every kept artifact in the checks-on test build.

use parvo::io::{self, Limits, SaveOptions};
use parvo::mip::{self, MipOptions, Rounding};

const EXTS: [&str; 7] = ["png", "jpg", "tif", "hdr", "exr", "ktx2", "dds"];

/// One input of the `decode_and_mip` target: any outcome but a panic (or a failed
/// assertion below) is a pass.
pub fn run(data: &[u8]) {
    let Some((&pick, bytes)) = data.split_first() else {
        return;
    };
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir
        .path()
        .join(format!("in.{}", EXTS[pick as usize % EXTS.len()]));
    std::fs::write(&path, bytes).expect("write input");
    let limits = Limits {
        max_width: 512,
        max_height: 512,
        max_alloc: 16 << 20,
    };
    let Ok(loaded) = io::load(path.to_str().expect("utf-8 path"), &limits) else {
        return;
    };
    let base = loaded.into_base();
    let Ok(chain) = mip::build(base, &MipOptions::default()) else {
        return;
    };
    let levels = chain.into_levels();
    let f = levels[0].format();
    let opts = SaveOptions::default();
    // Every output container of the table, in the format `parvo mip`
    // would write for this source.
    for kind in io::container::outputs() {
        let name = kind.batch_path(dir.path(), "o");
        let Ok(out_f) = parvo::pipeline::output_format(f, kind, &Default::default()) else {
            continue;
        };
        let conv: Vec<_> = levels
            .iter()
            .filter_map(|l| l.convert(out_f).ok())
            .collect();
        if conv.len() == levels.len() {
            let _ = io::save(&conv, Rounding::Down, &name, kind, &opts);
        }
    }
}
