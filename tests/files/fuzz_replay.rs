//! The fuzz targets that read files or encode blocks, replayed over their
//! seeds, kept artifacts and fixed mutations (`tests/common/replay.rs`),
//! in this build's overflow checks. `tests/core/fuzz_replay.rs` replays the
//! rest.

use crate::common::replay::replay;

#[cfg(feature = "encode")]
#[path = "../../fuzz/bodies/compress.rs"]
mod compress;
#[path = "../../fuzz/bodies/decode_and_mip.rs"]
mod decode_and_mip;

#[cfg(feature = "encode")]
#[test]
fn fuzz_compress_seeds_artifacts_and_mutations_pass() {
    assert!(replay("compress", compress::run) > 0);
}

#[test]
fn fuzz_decode_and_mip_seeds_artifacts_and_mutations_pass() {
    assert!(replay("decode_and_mip", decode_and_mip::run) > 0);
}
