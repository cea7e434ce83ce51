#!/usr/bin/env bash
# Hash what `parvo tradeoff` and `parvo cachesim` print and write for a
# fixed set of runs, timings left out, one line per output: the
# before/after check of a change that must not move any of their bytes
# (`diff` two runs' stdout). Complements scripts/output-hashes.sh, which
# covers `mip`, `sample`, `info` and one cachesim table.
#
#   scripts/report-hashes.sh PARVO_BINARY WORKDIR > hashes.txt
#
# Left out as timings: tradeoff's ns/pixel column and seconds per
# reference frame, report.json's `ns_per_pixel` and `reference.seconds`,
# and tradeoff.svg (its x axis is ns per pixel).
set -euo pipefail
bin=$(realpath "$1")
work=$2
rm -rf "$work"
mkdir -p "$work"
cd "$work"
h() { sha256sum | cut -c1-16; }

tradeoff() { # tradeoff NAME ARGS...
    local name=$1
    shift
    "$bin" tradeoff --out "$name" "$@" >"$name.txt"
    # The table without the ns/pixel column and the reference's time.
    echo "$name table $(sed -E 's/\([0-9.]+ s per frame\)//' "$name.txt" |
        awk 'NF == 8 && $2 ~ /^[0-9.]+$/ { $2 = "" } { print }' | h)"
    echo "$name report.json $(python3 -c '
import json, sys
r = json.load(open(sys.argv[1]))
del r["reference"]["seconds"]
for f in r["filters"]:
    del f["ns_per_pixel"]
print(json.dumps(r, sort_keys=True))' "$name/report.json" | h)"
    for f in $(cd "$name" && ls | grep -v -e report.json -e tradeoff.svg | sort); do
        echo "$name $f $(h <"$name/$f")"
    done
}
tradeoff default --runs 1
tradeoff small --runs 1 --scene tunnel --size 97x61 --texture builtin:checker:100 \
    --filters sat,ewa,trilinear,aniso16,bilinear-nomip --pixel-filter box --spp 2
tradeoff bc1 --runs 1 --scene rotate:30:2 --size 64x48 --texture builtin:photo:128 \
    --filters nearest,trilinear,aniso8 --compress bc1 --quality fast

cachesim() { # cachesim NAME ARGS...
    local name=$1
    shift
    echo "$name $("$bin" cachesim "$@" | h)"
}
cachesim cs-default --size 160x120 --texture builtin:checker:256
cachesim cs-json --size 160x120 --texture builtin:checker:256 --json
cachesim cs-l2 --scene tunnel --size 128x96 --texture builtin:zoneplate:200 --filter aniso \
    --max-aniso 4 --cache 4K:32:2:fifo --l2 64K:64:8 --sector 16 --order hilbert --layout morton
cachesim cs-sat --size 100x80 --texture builtin:checker:128 --filter sat --json
cachesim cs-trace-out --size 64x48 --texture builtin:checker:64 --filter ewa --trace-out t.txt
echo "cs-trace-file $(h <t.txt)"
cachesim cs-trace --trace t.txt --cache 2K:64:full:random --access-bytes 8
cachesim cs-trace-json --trace t.txt --json

sweep() { # sweep NAME ARGS...
    local name=$1
    shift
    echo "$name stdout $("$bin" cachesim --sweep --out "$name" "$@" | sed "s#$work/##g" | h)"
    for f in sweep.csv sweep.svg; do
        echo "$name $f $(h <"$name/$f")"
    done
}
sweep sw-default --size 96x72 --texture builtin:checker:256
sweep sw-grid --scene rotate:20 --size 80x60 --texture builtin:zoneplate:128 --order tiled:8 \
    --cache-sizes 2K,8K,24K --lines 32,128 --ways 1,2,8 --layouts linear,morton:8x8 \
    --filters sat,ewa,aniso4,nearest --sector 16
