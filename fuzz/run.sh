#!/usr/bin/env bash
# A coverage-guided fuzz run on stable Rust without cargo-fuzz: builds
# TARGET instrumented (build.sh: as `cargo fuzz build -s none`, with debug
# assertions and overflow checks) and runs it on corpus/TARGET, seeded from
# seeds/TARGET, for SECONDS seconds on one job. Crashes go to
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
dir="$(bash build.sh "$t")"
mkdir -p "corpus/$t" "artifacts/$t"
exec "$dir/$t" -max_total_time="$secs" -timeout=20 -rss_limit_mb=2048 \
    -artifact_prefix="artifacts/$t/" "$@" "corpus/$t" "seeds/$t"
