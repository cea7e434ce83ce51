//! The cache model's fast paths, its quad and prefetch models, and the
//! trade-off report and cache sweep as library calls, as one test binary.
//!
//! Why one binary: in an optimised build every test binary instantiates the
//! library's generic samplers and cache runs anew, and these three files
//! did so three times (about 520 CPU-seconds of `cargo test --release`'s
//! compile on the 2-core CI machine). Each file is still a module with its
//! own references; `cargo test --release --test cache_report MODULE::`
//! runs one of them. `tests/sampling_core` does the same for the samplers.

mod cache_fast_paths;
mod cache_quads_prefetch;
mod report_library;
