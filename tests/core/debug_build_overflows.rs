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

/// `.ci/run` runs every test with overflow checks on (it sets
/// `CARGO_PROFILE_RELEASE_OVERFLOW_CHECKS` for the README's `cargo test
/// --release`); under CI (`CI` set) this fails if the build it runs in
/// lost them, so the modules above cannot silently stop trapping.
#[test]
fn ci_runs_the_tests_with_overflow_checks_on() {
    if std::env::var_os("CI").is_none() {
        return;
    }
    let wrapped =
        std::panic::catch_unwind(|| std::hint::black_box(u8::MAX) + std::hint::black_box(1u8));
    assert!(
        wrapped.is_err(),
        "u8::MAX + 1 did not trap: this build has no overflow checks (run the tests as .ci/run does)"
    );
}
