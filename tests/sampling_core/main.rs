//! The samplers' heavier integration tests (SPEC.md formula by formula,
//! storage formats, SIMD paths, extremes, properties) as one test binary.
//!
//! Why one binary: in an optimised build every test binary instantiates the
//! library's generic samplers anew, and these five files did so five times
//! (about 630 CPU-seconds of `cargo test --release`'s compile on the 2-core
//! CI machine). Each file is still a module with its own references;
//! `cargo test --release --test sampling_core MODULE::` runs one of them.
//! `tests/cache_report` does the same for the cache model and the report.

#[path = "../common/mod.rs"]
mod common;

mod sample_extremes;
mod sample_props;
mod sample_simd;
mod sample_spec;
mod sample_storage;
