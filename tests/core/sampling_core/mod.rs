//! The samplers' heavier integration tests (SPEC.md formula by formula,
//! storage formats, SIMD paths, extremes, properties), modules of the
//! `core` test binary (see `tests/core/main.rs` for why one binary);
//! `cargo test --release --test core sampling_core::MODULE::` runs one.

mod sample_extremes;
mod sample_props;
mod sample_simd;
mod sample_spec;
mod sample_storage;
