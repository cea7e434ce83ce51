//! The debug-build findings that need no file (issue 28), as a test target
//! of their own: `.ci/run` runs it with `--no-default-features` in the
//! `ci-debug` profile (release speed, debug assertions and overflow checks
//! on), where integer overflow traps as in a dependent crate's debug
//! build. The same files are modules of the `regression` target too.

#[path = "regression/debug_build_floor_fast_overflow.rs"]
mod debug_build_floor_fast_overflow;
#[path = "regression/debug_build_sample_bias_nan_overflow.rs"]
mod debug_build_sample_bias_nan_overflow;
