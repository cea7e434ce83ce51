#!/usr/bin/env bash
# parvo mip against maketx (OpenImageIO) on the same 4096x4096 RGBA8 PNG:
# half EXR, box filter, zip compression, same thread count. Runs each tool
# once under /usr/bin/time -v and prints a Markdown table (wall time, peak
# RSS) with the machine and versions, for the README.
#
# Usage: benches/cli_vs_maketx.sh [THREADS]   (default: all cores)
set -euo pipefail
cd "$(dirname "$0")/.."
THREADS="${1:-$(nproc)}"
VENV_BIN="$(scripts/setup-interop.sh)"
cargo build --quiet --release --bin parvo
PARVO="$PWD/target/release/parvo"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
SRC="$PWD/target/bench-src4096.png" # kept between runs
# Deterministic test image: gradients, a zone plate, mild noise and an alpha
# disc, so that neither compression nor filtering sees a trivial image.
[ -f "$SRC" ] || "$VENV_BIN/python" - "$SRC" <<'PY'
import sys
import numpy as np
import OpenImageIO as oiio
n = 4096
y, x = np.mgrid[0:n, 0:n].astype(np.float32)
rng = np.random.default_rng(4096)
r = x / n
g = y / n
c = n / 2
b = 0.5 + 0.5 * np.cos(np.pi * ((x - c) ** 2 + (y - c) ** 2) / (4 * n))
a = np.where((x - c) ** 2 + (y - c) ** 2 < (0.4 * n) ** 2, 1.0, 0.5)
img = np.stack([r, g, b, a], axis=-1)
img = img * 255 + rng.normal(0, 2, img.shape)
img = np.clip(np.round(img), 0, 255).astype(np.uint8)
out = oiio.ImageOutput.create(sys.argv[1])
assert out.open(sys.argv[1], oiio.ImageSpec(n, n, 4, "uint8"))
assert out.write_image(img)
out.close()
PY
measure() { # NAME CMD... -> "wall_seconds peak_rss_kib cpu_seconds"
    local name="$1"; shift
    /usr/bin/time -v "$@" >"$WORK/$name.out" 2>"$WORK/$name.time"
    local wall rss
    wall=$(awk -F': ' '/Elapsed \(wall clock\)/ {n=split($2,t,":"); s=0; for(i=1;i<=n;i++) s=s*60+t[i]; print s}' "$WORK/$name.time")
    rss=$(awk -F': ' '/Maximum resident set size/ {print $2}' "$WORK/$name.time")
    cpu=$(awk -F': ' '/User time|System time/ {s+=$2} END {print s}' "$WORK/$name.time")
    echo "$wall $rss $cpu"
}
PARVO_CMD=("$PARVO" mip "$SRC" -o "$WORK/parvo.exr" --filter box --compression zip --type f16 --threads "$THREADS")
MAKETX_CMD=("$VENV_BIN/maketx" "$SRC" -o "$WORK/maketx.exr" --filter box -d half --compression zip --threads "$THREADS")
read -r P_WALL P_RSS P_CPU < <(measure parvo "${PARVO_CMD[@]}")
read -r M_WALL M_RSS M_CPU < <(measure maketx "${MAKETX_CMD[@]}")
LOAD="$(cut -d' ' -f1-3 /proc/loadavg)"
P_SIZE=$(stat -c %s "$WORK/parvo.exr")
M_SIZE=$(stat -c %s "$WORK/maketx.exr")
echo
echo "Machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(free -g | awk '/Mem:/ {print $2}') GiB; $(uname -sr)"
echo "Versions: $("$PARVO" --version), maketx $("$VENV_BIN/oiiotool" --version) (pip install OpenImageIO)"
echo "Input: 4096x4096 RGBA8 PNG; output: tiled 64x64 half EXR, 13 levels, box, zip; threads: $THREADS; load average after the runs: $LOAD"
echo
echo "| tool | wall time (s) | CPU time, user+sys (s) | peak RSS (MiB) | output size (MiB) |"
echo "| --- | ---: | ---: | ---: | ---: |"
printf "| parvo mip | %.2f | %.2f | %.0f | %.1f |\n" "$P_WALL" "$P_CPU" "$(echo "$P_RSS/1024" | bc -l)" "$(echo "$P_SIZE/1048576" | bc -l)"
printf "| maketx | %.2f | %.2f | %.0f | %.1f |\n" "$M_WALL" "$M_CPU" "$(echo "$M_RSS/1024" | bc -l)" "$(echo "$M_SIZE/1048576" | bc -l)"
printf "\nparvo speed-up: wall %.2fx, CPU %.2fx; peak memory ratio parvo/maketx: %.2f\n" \
    "$(echo "$M_WALL/$P_WALL" | bc -l)" "$(echo "$M_CPU/$P_CPU" | bc -l)" "$(echo "$P_RSS/$M_RSS" | bc -l)"
echo
echo "Commands:"
echo "  ${PARVO_CMD[*]}" | sed "s#$WORK#\$WORK#g; s#$PWD/##g"
echo "  ${MAKETX_CMD[*]}" | sed "s#$WORK#\$WORK#g; s#$PWD/##g"
