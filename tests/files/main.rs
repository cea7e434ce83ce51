//! The tests that read or write files or run the command-line tool (the
//! default features), as one test binary: the containers and codecs, the
//! pipeline, every subcommand, the regression tests named after their
//! findings and the file-reading fuzz targets' bodies replayed.
//!
//! Why one binary: see `tests/core/main.rs`. `cargo test --release --test
//! files MODULE::` runs one module.

#[path = "../cli_common/mod.rs"]
mod cli_common;
#[path = "../common/mod.rs"]
mod common;

mod cli_cachesim;
mod cli_compress;
mod cli_cube_inputs_and_layers;
mod cli_env_scenes;
mod cli_info;
mod cli_mip_errors;
mod cli_mip_roundtrip;
mod cli_roughness;
mod cli_tradeoff;
#[cfg(feature = "encode")]
mod compress;
mod env_containers;
mod env_openexr_conventions;
mod error_words;
mod fuzz_replay;
mod interrupted_write_leaves_destination;
mod io_corrupt_inputs;
mod io_dds_read;
mod io_exr_read;
mod io_image_inputs;
mod io_ktx2_fields;
mod io_ktx2_packed;
mod mip_flags_by_kind;
mod mip_separable_fast;
mod mip_streamed;
mod pipeline;
#[cfg(feature = "encode")]
mod regression;
mod sample_accuracy;
mod sample_cli;
mod scene_reference;
mod threads_reproducible;
