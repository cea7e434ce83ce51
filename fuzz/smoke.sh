#!/usr/bin/env bash
# Fuzz smoke for CI (run by .ci/run): each target replays its seed corpus
# (fuzz/seeds/TARGET) and then runs a few thousand coverage-guided
# libFuzzer mutations, on stable Rust and without cargo-fuzz. The targets
# are built by build.sh as `cargo fuzz build -s none` builds them, with
# debug assertions and overflow checks on (fuzz/Cargo.toml), so arithmetic
# that overflows traps here as in a dependent crate's debug build. Long
# runs: fuzz/run.sh TARGET SECONDS (fuzz/README.md).
set -euo pipefail
cd "$(dirname "$0")"
bin="$(bash build.sh)"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
for t in decode_and_mip parsers compress sampler sat cachesim normal_roughness; do
    mkdir -p "$WORK/$t" "artifacts/$t"
    # New inputs go to the first (scratch) directory; the seeds stay as
    # they are. A crashing input is kept in artifacts/ (ignored by git).
    "$bin/$t" -runs=3000 -seed=16 -timeout=20 -rss_limit_mb=2048 \
        -artifact_prefix="artifacts/$t/" "$WORK/$t" "seeds/$t" >"$WORK/$t.log" 2>&1 || {
        tail -n 30 "$WORK/$t.log"
        echo "fuzz smoke: $t FAILED"
        exit 1
    }
    echo "fuzz smoke: $t ok ($(grep -c . "$WORK/$t.log") log lines, seeds $(ls "seeds/$t" | wc -l))"
done
