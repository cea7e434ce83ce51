//! The tests of the sampling core (no default features): texels, mips,
//! summed-area tables, samplers, scenes, environments, the cache model
//! and the fuzz targets' bodies replayed, as one test binary.
//!
//! Why one binary: in an optimised build every test binary instantiates
//! the library's generic samplers and cache runs anew and links on its
//! own; 22 binaries did that 22 times. Each file is still a module with
//! its own references; `cargo test --release --test core MODULE::` runs
//! one of them. The light build (`--no-default-features`) runs this
//! binary too. `tests/files` holds the tests that read or write files or
//! run the command-line tool.

#[path = "../common/mod.rs"]
mod common;

mod cache_literature;
mod cache_model;
mod cache_report;
mod cube_layouts;
mod debug_build_overflows;
mod env_cube;
mod env_prefilter;
mod fuzz_replay;
mod mip_extremes;
mod mip_fast_paths_match_plain;
mod mip_filters_match_reference;
mod mip_properties;
mod normal_roughness;
mod sample_ewa_fast;
mod sample_one;
mod sampling_core;
mod sat_brute_force;
mod sat_exactness;
mod sat_precision;
mod sat_sampler;
mod sat_wrap;
mod scene_env;
mod scene_view;
