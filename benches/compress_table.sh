#!/usr/bin/env bash
# Block compression on a 4096x4096 photo-like input (builtin:photo written
# as an sRGB RGB8 PNG; for BC6H the same image as half-float linear EXR): per format the
# level-0 PSNR of the decoded blocks against the uncompressed level, the
# file size (KTX2, full chain), the zstd-supercompressed size (--zstd 10),
# the encode time and the whole `parvo mip` wall time, beside the
# uncompressed file. Prints a Markdown table with the machine, for the
# README.
#
# Usage: benches/compress_table.sh [SIZE]   (default 4096; about 6 minutes:
# every row runs parvo mip three times: --json for the PSNR, --zstd 10 for
# the supercompressed size, and plain for the wall time)
set -euo pipefail
cd "$(dirname "$0")/.."
SIZE="${1:-4096}"
cargo build --quiet --release --bin parvo
PARVO="$PWD/target/release/parvo"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
"$PARVO" mip "builtin:photo:$SIZE" -o "$WORK/photo_{level}.png" --levels 1 >/dev/null
SRC="$WORK/photo_0.png"
"$PARVO" mip "$SRC" -o "$WORK/photo.exr" >/dev/null
field() { # JSON EXPR -> value
    python3 -c "import json,sys; d=json.loads(sys.argv[1]); print($2)" "$1"
}
row() { # LABEL INPUT ARGS... -> a table row
    local label="$1" input="$2"; shift 2
    local js zs
    js="$("$PARVO" mip "$input" -o "$WORK/t.ktx2" --json "$@" 2>/dev/null)"
    local size
    size=$(stat -c %s "$WORK/t.ktx2")
    "$PARVO" mip "$input" -o "$WORK/tz.ktx2" --zstd 10 "$@" >/dev/null 2>&1
    zs=$(stat -c %s "$WORK/tz.ktx2")
    # The wall time of a plain run (--json also decodes the blocks again
    # to measure PSNR, which is not part of the job).
    local t0 t1
    t0=$(date +%s.%N)
    "$PARVO" mip "$input" -o "$WORK/t.ktx2" "$@" >/dev/null 2>&1
    t1=$(date +%s.%N)
    local psnr enc total
    psnr=$(field "$js" "('%.2f' % d['compression']['levels'][0]['psnr_db']) if d.get('compression') else '-'")
    enc=$(field "$js" "('%.2f' % d['compression']['encode_seconds']) if d.get('compression') else '-'")
    total=$(printf '%.2f' "$(echo "$t1 - $t0" | bc -l)")
    printf '| %s | %s | %.1f | %.2f | %.1f | %s | %s |\n' "$label" "$psnr" \
        "$(echo "$size / 1048576" | bc -l)" "$(echo "$size * 8 / ($SIZE * $SIZE)" | bc -l)" \
        "$(echo "$zs / 1048576" | bc -l)" "$enc" "$total"
}
CPU=$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//')
echo "builtin:photo:$SIZE as a PNG, full mip chain in KTX2, box filter, $(nproc) threads; $CPU, $(date -u +%Y-%m-%d)"
echo
echo "| format | PSNR dB (level 0) | KTX2 MiB | bits per level-0 texel | with --zstd 10, MiB | encode s | parvo mip s |"
echo "|---|---:|---:|---:|---:|---:|---:|"
row "uncompressed RGB8 sRGB" "$SRC"
row "BC1 (normal)" "$SRC" --compress bc1
row "BC1 (slow)" "$SRC" --compress bc1 --quality slow
row "BC3 (normal)" "$SRC" --compress bc3
row "BC4 (R only)" "$SRC" --compress bc4
row "BC5 (R, G)" "$SRC" --compress bc5
row "BC7 (fast)" "$SRC" --compress bc7 --quality fast
row "BC7 (normal)" "$SRC" --compress bc7
row "BC7 (slow)" "$SRC" --compress bc7 --quality slow
row "uncompressed RGB f16 (EXR input)" "$WORK/photo.exr"
row "BC6H (normal, EXR input)" "$WORK/photo.exr" --compress bc6h
