#!/usr/bin/env bash
# Interop checks against OpenImageIO: our tiled mip-mapped EXR as
# oiiotool sees it, our box levels against maketx's, and parvo reading
# maketx's output. Installs OpenImageIO into a venv under target/ with the
# project's own script (scripts/setup-interop.sh). Prints one line per check,
# exits non-zero on any failure.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV_BIN="$(scripts/setup-interop.sh)"
cargo build --release --quiet --bin parvo
PARVO="$PWD/target/release/parvo"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
echo "interop: OpenImageIO $("$VENV_BIN/oiiotool" --version)"
"$VENV_BIN/python" scripts/interop_check.py "$PARVO" "$VENV_BIN" "$WORK"
echo "interop: all checks passed"
