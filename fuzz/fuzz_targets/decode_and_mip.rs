//! The `decode_and_mip` fuzz target: the body is `fuzz/bodies/decode_and_mip.rs` (see there),
//! shared with the test that replays this target's seeds and artifacts.
#![no_main]

#[path = "../bodies/decode_and_mip.rs"]
mod body;

libfuzzer_sys::fuzz_target!(|data: &[u8]| body::run(data));
