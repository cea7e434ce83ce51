#!/usr/bin/env bash
# Install Mesa's software OpenGL (llvmpipe behind EGL, no display needed)
# for the GPU-semantics interop check scripts/interop/gl_sampling.py. The
# Python side (moderngl, glcontext) is pinned in
# scripts/interop-requirements.txt and installed by scripts/setup-interop.sh;
# this script adds the system libraries pip cannot bring: Debian's glvnd
# loaders (libEGL.so.1, libGL.so.1) and Mesa's EGL vendor library and
# Gallium drivers (libEGL_mesa.so.0, swrast_dri.so with llvmpipe).
#
# Usage: scripts/setup-gl.sh     (idempotent: a no-op when all are present)
# Exit 0: the libraries are there (one "gl: ..." line on stderr).
# Exit 3: they are missing and cannot be installed here (not root, no
#         apt-get, or apt-get failed); the reason is printed as a "skip:"
#         line on stdout so the caller can pass it on.
set -uo pipefail

PACKAGES=(libegl1 libgl1 libegl-mesa0 libgl1-mesa-dri)

missing() {
    local p out=()
    for p in "${PACKAGES[@]}"; do
        dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || out+=("$p")
    done
    echo "${out[@]:-}"
}

if ! command -v dpkg-query >/dev/null 2>&1; then
    # Not Debian: trust the dynamic loader instead of the package database.
    if ldconfig -p 2>/dev/null | grep -q 'libEGL_mesa.so.0' && ldconfig -p | grep -q 'libGL.so.1'; then
        echo "gl: Mesa EGL found by the dynamic loader (no dpkg here)" >&2
        exit 0
    fi
    echo "skip: Mesa EGL/llvmpipe not found and this is no Debian system (no dpkg-query): install Mesa's EGL and DRI drivers"
    exit 3
fi

need="$(missing)"
if [ -z "$need" ]; then
    echo "gl: Mesa EGL/llvmpipe present (${PACKAGES[*]})" >&2
    exit 0
fi
if [ "$(id -u)" != 0 ] || ! command -v apt-get >/dev/null 2>&1; then
    echo "skip: Debian packages $need are missing and cannot be installed (needs root and apt-get)"
    exit 3
fi
echo "gl: installing $need with apt-get" >&2
export DEBIAN_FRONTEND=noninteractive
# A fresh machine has no package lists yet; update only when the install
# cannot find the packages with the lists it has.
# shellcheck disable=SC2086
if ! apt-get install -y -qq --no-install-recommends $need >&2 2>/dev/null; then
    apt-get update -qq >&2 || true
    # shellcheck disable=SC2086
    if ! apt-get install -y -qq --no-install-recommends $need >&2; then
        echo "skip: apt-get could not install $need"
        exit 3
    fi
fi
need="$(missing)"
if [ -n "$need" ]; then
    echo "skip: $need still missing after apt-get install"
    exit 3
fi
echo "gl: Mesa EGL/llvmpipe installed" >&2
exit 0
