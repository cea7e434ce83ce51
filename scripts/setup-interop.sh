#!/usr/bin/env bash
# Install the interop reference tools (OpenImageIO's oiiotool, maketx and
# Python bindings, plus numpy) into a venv under target/, so the interop
# checks in .ci/interop.sh and benches/cli_vs_maketx.sh run on any machine
# of the project without anything installed by hand.
#
# Usage: scripts/setup-interop.sh            (idempotent; prints the venv bin dir)
set -euo pipefail
cd "$(dirname "$0")/.."
VENV="${PARVO_INTEROP_VENV:-target/interop-venv}"
if [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV" >&2
fi
if ! "$VENV/bin/python" -c 'import OpenImageIO, numpy' 2>/dev/null \
    || [ ! -x "$VENV/bin/oiiotool" ] || [ ! -x "$VENV/bin/maketx" ]; then
    "$VENV/bin/pip" install --quiet --disable-pip-version-check OpenImageIO numpy >&2
fi
for tool in oiiotool maketx; do
    if [ ! -x "$VENV/bin/$tool" ]; then
        echo "setup-interop: $VENV/bin/$tool missing after pip install OpenImageIO" >&2
        exit 1
    fi
done
echo "$VENV/bin"
