#!/usr/bin/env bash
# Large textures: `parvo mip IN.png -o OUT.exr` (RGBA8 PNG -> tiled half
# EXR, box, zip) and maketx on the same file at 4096², 8192² and 16384²,
# printing each parvo phase (read, build, write: `--stats`), the wall time
# and the peak memory of both tools, and the per-texel time of each phase
# relative to 4096² (the linear-cost goal of issue 19: at most 1.25x).
# parvo's figures are the median of three runs per size, maketx's one run.
#
# Usage: benches/large_textures.sh [SIZES...]   (default: 4096 8192 16384)
# Inputs are generated once into target/bench-large-SIZE.png (deterministic
# gradients, a zone plate, noise and an alpha disc, as cli_vs_maketx.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -gt 0 ]; then SIZES=("$@"); else SIZES=(4096 8192 16384); fi
THREADS="$(nproc)"
VENV_BIN="$(scripts/setup-interop.sh)"
cargo build --quiet --release --bin parvo
PARVO="$PWD/target/release/parvo"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
gen() { # SIZE PATH: written in strips, so generating needs little memory
    "$VENV_BIN/python" - "$1" "$2" <<'PY'
import sys
import numpy as np
import OpenImageIO as oiio
n, path = int(sys.argv[1]), sys.argv[2]
out = oiio.ImageOutput.create(path)
assert out.open(path, oiio.ImageSpec(n, n, 4, "uint8"))
rng = np.random.default_rng(n)
strip = 256
c = n / 2
for y0 in range(0, n, strip):
    y, x = np.mgrid[y0:y0 + strip, 0:n].astype(np.float32)
    r, g = x / n, y / n
    b = 0.5 + 0.5 * np.cos(np.pi * ((x - c) ** 2 + (y - c) ** 2) / (4 * n))
    a = np.where((x - c) ** 2 + (y - c) ** 2 < (0.4 * n) ** 2, 1.0, 0.5)
    img = np.stack([r, g, b, a], axis=-1) * 255 + rng.normal(0, 2, (strip, n, 4))
    img = np.clip(np.round(img), 0, 255).astype(np.uint8)
    assert out.write_scanlines(y0, y0 + strip, 0, img)
out.close()
PY
}
measure() { # NAME CMD... -> "wall_seconds peak_rss_kib"
    local name="$1"; shift
    /usr/bin/time -v "$@" >"$WORK/$name.out" 2>"$WORK/$name.time"
    local wall rss
    wall=$(awk -F': ' '/Elapsed \(wall clock\)/ {n=split($2,t,":"); s=0; for(i=1;i<=n;i++) s=s*60+t[i]; print s}' "$WORK/$name.time")
    rss=$(awk -F': ' '/Maximum resident set size/ {print $2}' "$WORK/$name.time")
    echo "$wall $rss"
}
echo "Machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(free -g | awk '/Mem:/ {print $2}') GiB; $(date -u +%Y-%m-%d)"
echo "RGBA8 PNG -> tiled 64x64 half EXR, box, zip, $THREADS threads; per-texel ratios against the first size"
echo
echo "| size | read s | build s | write s | parvo wall s | parvo peak MiB | per-texel read / build / write vs first | maketx wall s | maketx peak MiB |"
echo "|---|---:|---:|---:|---:|---:|---|---:|---:|"
base=""
for n in "${SIZES[@]}"; do
    src="$PWD/target/bench-large-$n.png"
    [ -f "$src" ] || gen "$n" "$src"
    # parvo three times: the median of each column (a phase of 0.1-0.2 s
    # at 4096² moves by half between runs on this host, and every ratio
    # below divides by it).
    runs=()
    for _ in 1 2 3; do
        read -r pw prss < <(measure parvo "$PARVO" mip "$src" -o "$WORK/p.exr" --filter box \
            --compression zip --type f16 --threads "$THREADS" --stats)
        stats=$(grep 'stats:' "$WORK/parvo.out")
        runs+=("$(echo "$stats" | sed -E 's/.*read ([0-9.]+) s, build ([0-9.]+) s, write ([0-9.]+) s.*/\1 \2 \3/') $pw $prss")
        rm -f "$WORK/p.exr"
    done
    median() { printf '%s\n' "${runs[@]}" | awk -v c="$1" '{print $c}' | sort -g | sed -n 2p; }
    rd=$(median 1) bd=$(median 2) wr=$(median 3) pw=$(median 4) prss=$(median 5)
    rm -f "$WORK/p.exr"
    read -r mw mrss < <(measure maketx "$VENV_BIN/maketx" "$src" -o "$WORK/m.exr" --filter box \
        -d half --compression zip --threads "$THREADS")
    rm -f "$WORK/m.exr"
    texels=$((n * n))
    if [ -z "$base" ]; then
        base="$rd $bd $wr $texels"
    fi
    read -r brd bbd bwr btex <<<"$base"
    ratio() { echo "($1 / $texels) / ($2 / $btex)" | bc -l; }
    printf "| %d² | %.2f | %.2f | %.2f | %.2f | %.0f | %.2f / %.2f / %.2f | %.2f | %.0f |\n" \
        "$n" "$rd" "$bd" "$wr" "$pw" "$(echo "$prss/1024" | bc -l)" \
        "$(ratio "$rd" "$brd")" "$(ratio "$bd" "$bbd")" "$(ratio "$wr" "$bwr")" \
        "$mw" "$(echo "$mrss/1024" | bc -l)"
done
