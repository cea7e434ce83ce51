//! The `parsers` fuzz target: the body is `fuzz/bodies/parsers.rs` (see there),
//! shared with the test that replays this target's seeds and artifacts.
#![no_main]

#[path = "../bodies/parsers.rs"]
mod body;

libfuzzer_sys::fuzz_target!(|data: &[u8]| body::run(data));
