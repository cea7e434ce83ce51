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
# The binary `cargo test --release` builds (target/release/parvo), not
# `cargo build --release --bin parvo`'s: the dev-dependencies turn on
# features of shared crates (image's rayon, among others), so that build
# compiled the library a second time, about 10 of CI's minutes. After the
# README's test command this is a no-op.
cargo test --release --no-run --quiet
PARVO="$PWD/target/release/parvo"
echo "interop: the venv and the release binary ready after $SECONDS s"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
echo "interop: OpenImageIO $("$VENV_BIN/oiiotool" --version), Pillow $("$VENV_BIN/python" -c 'import PIL; print(PIL.__version__)')"
status=0
for script in scripts/interop/[a-z]*.py; do
    [ "$(basename "$script")" = common.py ] && continue
    echo "== interop: $(basename "$script" .py)"
    mkdir -p "$WORK/$(basename "$script" .py)"
    started=$SECONDS
    "$VENV_BIN/python" "$script" "$PARVO" "$VENV_BIN" "$WORK/$(basename "$script" .py)" || status=1
    echo "== interop: $(basename "$script" .py) took $((SECONDS - started)) s"
done
[ "$status" = 0 ] && echo "interop: all checks passed"
exit "$status"
