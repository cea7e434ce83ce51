#!/usr/bin/env bash
# Install the interop reference tools (OpenImageIO's oiiotool, maketx and
# Python bindings, Pillow, numpy, moderngl; pinned in scripts/interop-requirements.txt)
# into a venv under target/, so the interop checks in .ci/interop.sh and
# benches/cli_vs_maketx.sh run on any machine of the project without
# anything installed by hand.
#
# Usage: scripts/setup-interop.sh            (idempotent; prints the venv bin dir)
set -euo pipefail
cd "$(dirname "$0")/.."
VENV="${PARVO_INTEROP_VENV:-target/interop-venv}"
REQ=scripts/interop-requirements.txt
if [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV" >&2
fi
# Reinstall when the pinned set changes (the stamp is a copy of it).
if ! cmp -s "$REQ" "$VENV/.requirements" \
    || [ ! -x "$VENV/bin/oiiotool" ] || [ ! -x "$VENV/bin/maketx" ]; then
    # `python -m pip`, not bin/pip: a venv copied from another checkout keeps
    # bin/pip's #! line pointing at the original venv.
    "$VENV/bin/python" -m pip install --quiet --disable-pip-version-check -r "$REQ" >&2
    cp "$REQ" "$VENV/.requirements"
fi
for tool in oiiotool maketx; do
    if [ ! -x "$VENV/bin/$tool" ]; then
        echo "setup-interop: $VENV/bin/$tool missing after pip install OpenImageIO" >&2
        exit 1
    fi
done
echo "$VENV/bin"
