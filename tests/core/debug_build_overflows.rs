//! The debug-build findings that need no file (issue 28), in the `core`
//! test binary so the light build's tests (`--no-default-features`, which
//! leaves out `tests/files`) run them too, with debug assertions and
//! overflow checks on, where integer overflow traps as in a dependent
//! crate's debug build. The same files are modules of `files`'s
//! `regression` too.

#[path = "../files/regression/debug_build_floor_fast_overflow.rs"]
mod debug_build_floor_fast_overflow;
#[path = "../files/regression/debug_build_sample_bias_nan_overflow.rs"]
mod debug_build_sample_bias_nan_overflow;
