#!/usr/bin/env bash
# BC1, BC3 and BC7 per quality step (fast, normal, slow) beside nvcompress
# -fast (NVIDIA Texture Tools 2.0.8, Debian's libnvtt-bin), quicktex and
# etcpak, on four scikit-image photos (astronaut, chelsea, coffee, rocket):
# PSNR over R, G, B decoded by texture2ddecoder (an independent decoder),
# wall and CPU time in the same run. Prints a Markdown table with the
# machine, for the README's block-compression section.
#
# Installs what it needs: the Python peers, the photos (scikit-image) and
# the decoder into target/bc-peers-venv (pinned in
# benches/bc-peers-requirements.txt), and nvcompress with
# `apt-get install -y libnvtt-bin` when it is missing and apt-get can run
# (root); without it the nvcompress rows are left out. A benchmark, not a
# CI check.
#
# Usage: benches/bc_peers.sh [REPS]   (default 5; about 7 minutes at 5 on
# the shared 2-core VM)
set -euo pipefail
cd "$(dirname "$0")/.."
REPS="${1:-5}"
VENV="${PARVO_BC_PEERS_VENV:-target/bc-peers-venv}"
REQ=benches/bc-peers-requirements.txt
if [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV" >&2
fi
if ! cmp -s "$REQ" "$VENV/.requirements"; then
    "$VENV/bin/pip" install --quiet --disable-pip-version-check -r "$REQ" >&2
    cp "$REQ" "$VENV/.requirements"
fi
if ! command -v nvcompress >/dev/null 2>&1; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
        echo "bc_peers: installing nvcompress (libnvtt-bin)" >&2
        { apt-get install -y -qq libnvtt-bin >/dev/null 2>&1 \
            || { apt-get update -qq >/dev/null 2>&1 && apt-get install -y -qq libnvtt-bin >/dev/null 2>&1; }; } \
            || echo "bc_peers: libnvtt-bin could not be installed; nvcompress rows left out" >&2
    else
        echo "bc_peers: nvcompress missing and apt-get unavailable; nvcompress rows left out" >&2
    fi
fi
cargo build --quiet --release --bin parvo
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
"$VENV/bin/python" benches/bc_peers.py --parvo "$PWD/target/release/parvo" \
    --work "$WORK" --reps "$REPS" --threads "$(nproc)"
