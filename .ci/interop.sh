#!/usr/bin/env bash
# Interop checks: parvo's files as other programs read them, and other
# programs' files as parvo reads them (scripts/interop/*.py: OpenEXR via
# OpenImageIO and maketx, DDS via Pillow and OpenImageIO, other projects'
# test files in tests/data/peer/ via peer.py, ...). Installs
# the pinned readers into a venv under target/ with the project's own script
# (scripts/setup-interop.sh). Prints one line per check, exits non-zero on
# any failure.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV_BIN="$(scripts/setup-interop.sh)"
cargo build --release --quiet --bin parvo
PARVO="$PWD/target/release/parvo"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
echo "interop: OpenImageIO $("$VENV_BIN/oiiotool" --version), Pillow $("$VENV_BIN/python" -c 'import PIL; print(PIL.__version__)')"
status=0
for script in scripts/interop/[a-z]*.py; do
    [ "$(basename "$script")" = common.py ] && continue
    echo "== interop: $(basename "$script" .py)"
    mkdir -p "$WORK/$(basename "$script" .py)"
    "$VENV_BIN/python" "$script" "$PARVO" "$VENV_BIN" "$WORK/$(basename "$script" .py)" || status=1
done
[ "$status" = 0 ] && echo "interop: all checks passed"
exit "$status"
