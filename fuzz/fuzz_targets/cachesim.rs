//! The `cachesim` fuzz target: the body is `fuzz/bodies/cachesim.rs` (see there),
//! shared with the test that replays this target's seeds and artifacts.
#![no_main]

#[path = "../bodies/cachesim.rs"]
mod body;

libfuzzer_sys::fuzz_target!(|data: &[u8]| body::run(data));
