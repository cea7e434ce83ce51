#!/usr/bin/env bash
# Builds fuzz targets (all, or the ones named) as `cargo fuzz build -s none`
# does, on stable Rust and without cargo-fuzz: SanitizerCoverage edges,
# inline 8-bit counters, the PC table and compare tracing (so libFuzzer's
# mutations are coverage-guided), `--cfg fuzzing`, on top of this crate's
# release profile, which has debug assertions and overflow checks on.
# `--target` keeps the instrumentation out of build scripts and proc
# macros (they do not link libFuzzer). Prints the directory of the
# binaries.
#
#   fuzz/build.sh                  # every target
#   fuzz/build.sh sampler sat      # these
set -euo pipefail
cd "$(dirname "$0")"
host="$(rustc -vV | sed -n 's/^host: //p')"
flags=(
    -Cpasses=sancov-module
    -Cllvm-args=-sanitizer-coverage-level=4
    -Cllvm-args=-sanitizer-coverage-inline-8bit-counters
    -Cllvm-args=-sanitizer-coverage-pc-table
    -Cllvm-args=-sanitizer-coverage-trace-compares
    --cfg fuzzing
)
bins=()
for t in "$@"; do
    bins+=(--bin "$t")
done
[ ${#bins[@]} -gt 0 ] || bins=(--bins)
RUSTFLAGS="${flags[*]}" cargo build --release --quiet --target "$host" "${bins[@]}" >&2
echo "$PWD/target/$host/release"
