#!/usr/bin/env bash
# Fuzz smoke for CI (run by .ci/run): each target replays its seed corpus
# (fuzz/seeds/TARGET) and then runs a few thousand libFuzzer mutations, on
# stable Rust and without cargo-fuzz (the targets are plain binaries with
# libFuzzer's main; without coverage instrumentation the mutations are
# blind, so this is a smoke test: the real runs are
# `cargo fuzz run -s none TARGET`, see fuzz/README.md).
set -euo pipefail
cd "$(dirname "$0")"
cargo build --release --quiet --bins
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
for t in decode_and_mip parsers compress sampler sat cachesim normal_roughness; do
    mkdir -p "$WORK/$t"
    # New inputs go to the first (scratch) directory; the seeds stay as
    # they are.
    ./target/release/"$t" -runs=3000 -seed=16 -timeout=20 -rss_limit_mb=2048 \
        "$WORK/$t" "seeds/$t" >"$WORK/$t.log" 2>&1 || {
        tail -n 30 "$WORK/$t.log"
        echo "fuzz smoke: $t FAILED"
        exit 1
    }
    echo "fuzz smoke: $t ok ($(grep -c . "$WORK/$t.log") log lines, seeds $(ls "seeds/$t" | wc -l))"
done
