//! The fuzz targets that need no file or codec, replayed over their seeds,
//! kept artifacts and fixed mutations (`tests/common/replay.rs`), in this
//! build's overflow checks. `tests/files/fuzz_replay.rs` replays the rest.

use crate::common::replay::replay;

#[path = "../../fuzz/bodies/cachesim.rs"]
mod cachesim;
#[path = "../../fuzz/bodies/normal_roughness.rs"]
mod normal_roughness;
#[path = "../../fuzz/bodies/parsers.rs"]
mod parsers;
#[path = "../../fuzz/bodies/sampler.rs"]
mod sampler;
#[path = "../../fuzz/bodies/sat.rs"]
mod sat;

#[test]
fn fuzz_cachesim_seeds_artifacts_and_mutations_pass() {
    assert!(replay("cachesim", cachesim::run) > 0);
}

#[test]
fn fuzz_normal_roughness_seeds_artifacts_and_mutations_pass() {
    assert!(replay("normal_roughness", normal_roughness::run) > 0);
}

#[test]
fn fuzz_parsers_seeds_artifacts_and_mutations_pass() {
    assert!(replay("parsers", parsers::run) > 0);
}

#[test]
fn fuzz_sampler_seeds_artifacts_and_mutations_pass() {
    assert!(replay("sampler", sampler::run) > 0);
}

#[test]
fn fuzz_sat_seeds_artifacts_and_mutations_pass() {
    assert!(replay("sat", sat::run) > 0);
}
