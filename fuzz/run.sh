#!/usr/bin/env bash
# A coverage-guided fuzz run on stable Rust without cargo-fuzz: builds
# TARGET with the instrumentation `cargo fuzz build -s none` adds
# (SanitizerCoverage edges, inline 8-bit counters, the PC table, compare
# tracing, `--cfg fuzzing`) on top of this crate's release profile (which
# has debug assertions and overflow checks on), then runs it on
# corpus/TARGET seeded from seeds/TARGET for SECONDS seconds. Crashes go to
# artifacts/TARGET/. Extra arguments are passed to libFuzzer.
#
#   fuzz/run.sh sampler 600
#   fuzz/run.sh sat 180 -max_len=4096
set -euo pipefail
cd "$(dirname "$0")"
if [ $# -lt 2 ]; then
    echo "usage: fuzz/run.sh TARGET SECONDS [libFuzzer options...]" >&2
    exit 2
fi
t="$1"
secs="$2"
shift 2
flags=(
    -Cpasses=sancov-module
    -Cllvm-args=-sanitizer-coverage-level=4
    -Cllvm-args=-sanitizer-coverage-inline-8bit-counters
    -Cllvm-args=-sanitizer-coverage-pc-table
    -Cllvm-args=-sanitizer-coverage-trace-compares
    --cfg fuzzing
)
# Own target directory: the smoke's uninstrumented build stays valid.
export CARGO_TARGET_DIR="$PWD/target/coverage"
RUSTFLAGS="${flags[*]}" cargo build --release --quiet --bin "$t"
mkdir -p "corpus/$t" "artifacts/$t"
exec "$CARGO_TARGET_DIR/release/$t" -max_total_time="$secs" -timeout=20 \
    -rss_limit_mb=2048 -artifact_prefix="artifacts/$t/" "$@" "corpus/$t" "seeds/$t"
