#!/usr/bin/env bash
# Hash what `parvo` writes for a fixed set of inputs and options, one line
# per output file: the before/after check of a restructuring that must not
# change any byte (`diff` two runs' stdout). Every container, the fused
# and banded EXR paths, every filter, compression, roughness, resize,
# alpha and the text outputs of sample, info, tradeoff and cachesim.
#
#   scripts/output-hashes.sh PARVO_BINARY WORKDIR > hashes.txt
#
# Timings and peak memory are not outputs: --stats/--json are not used,
# tradeoff runs with its timing columns removed.
set -euo pipefail
bin=$(realpath "$1")
work=$2
here=$(cd "$(dirname "$0")/.." && pwd)
peer=$here/tests/data/peer
rm -rf "$work"
mkdir -p "$work"
cd "$work"

n=0
mip() { # mip NAME ARGS...: write out/NAME.* and record every file it wrote
    local name=$1
    shift
    n=$((n + 1))
    mkdir -p "o$n"
    local rc=0
    (cd "o$n" && "$bin" mip "$@" >/dev/null 2>"../o$n.err") || rc=$?
    if [ "$rc" != 0 ]; then
        # Paths inside the checkout are printed relative to it, so two
        # checkouts' runs compare.
        echo "$name: exit $rc $(tr '\n' ' ' <"o$n.err" | sed "s#$here/##g")"
    fi
    find "o$n" -type f | sort | while read -r f; do
        echo "$name ${f#o$n/} $(sha256sum "$f" | cut -c1-16)"
    done
}

# EXR: box (fused and banded), every other filter, types, tiles, rounding.
mip exr-box-photo builtin:photo:512 -o a.exr
mip exr-box-odd builtin:photo:333 -o a.exr
mip exr-box-f32 builtin:photo:256 -o a.exr --type f32 --compression piz
mip exr-kaiser builtin:photo:300 -o a.exr --filter kaiser
mip exr-lanczos builtin:zoneplate:257 -o a.exr --filter lanczos3 --rounding up
mip exr-mitchell builtin:checker:128 -o a.exr --filter mitchell --tile 32x16
mip ktx2-triangle builtin:photo:200 -o a.ktx2 --filter triangle --levels 3 --wrap clamp
mip exr-resize builtin:photo:300 -o a.exr --resize-to pow2
mip exr-png16 "$peer/image-png/basn6a16.png" -o a.exr
mip exr-grey "$peer/image-png/basn0g08.png" -o a.exr --filter kaiser
mip exr-from-exr "$peer/openexr-images/$(ls "$peer/openexr-images" | grep -m1 '\.exr$')" -o a.exr --fixnan black
# KTX2 and DDS: plain, zstd, block formats, sRGB and linear.
mip ktx2-rgba8 builtin:photo:300 -o a.ktx2
mip ktx2-kaiser builtin:photo:300 -o a.ktx2 --filter kaiser
mip ktx2-zstd builtin:photo:256 -o a.ktx2 --zstd 5
mip ktx2-bc7 builtin:photo:128 -o a.ktx2 --compress bc7
mip ktx2-bc1 builtin:photo:128 -o a.ktx2 --compress bc1 --quality slow
mip ktx2-bc5 builtin:bumps:128 -o a.ktx2 --compress bc5 --normal-map
mip ktx2-rg "$peer/cts_valid_R8G8_UNORM_2D.ktx2" -o a.ktx2
mip ktx2-u16 "$peer/image-png/basn2c16.png" -o a.ktx2 --filter lanczos3
mip dds-rgba8 builtin:photo:200 -o a.dds
mip dds-bc3 builtin:photo:128 -o a.dds --compress bc3
mip dds-bc4 "$peer/image-png/basn0g08.png" -o a.dds --compress bc4
mip dds-bc6h builtin:photo:64 -o a.dds --compress bc6h
mip dds-from-dds "$peer/pillow_bc1.dds" -o a.dds
# PNG levels, TIFF inputs, alpha, normal maps and roughness.
mip png-levels builtin:photo:100 -o 'a_{level}.png'
mip png-u16 "$peer/tiff_strip_planar_16bit_RGB.tiff" -o 'a_{level}.png'
mip png-alpha "$peer/image-png/basn6a08.png" -o 'a_{level}.png' --alpha-coverage 0.5
mip png-alpha-none "$peer/image-png/basn6a08.png" -o a.ktx2 --alpha none --filter kaiser
mip tiff-tiled "$peer/tiff_tiled_planar_16bit_RGB.tiff" -o a.exr
mip normal-rough builtin:bumps:128 -o n.exr --normal-map --roughness 0.3 --roughness-out r.exr
mip normal-pack builtin:bumps:128 -o n.ktx2 --normal-map --roughness 0.2 --pack-roughness A
mip batch-exr builtin:photo:64 builtin:photo:96 --out-dir out --filter kaiser
mip batch builtin:photo:64 builtin:checker:64 builtin:zoneplate:65 --out-dir out --ext ktx2

# Usage errors: their words must survive the move of flag names to the CLI.
mip err-levels-exr builtin:photo:64 -o a.exr --levels 3
mip err-type-compress builtin:photo:64 -o a.dds --compress bc1 --type f16
mip err-up-ktx2 builtin:photo:64 -o a.ktx2 --rounding up
mip err-png-f32 builtin:photo:64 -o 'a_{level}.png' --type f32
mip err-compress-exr builtin:photo:64 -o a.exr --compress bc7
mip err-rough-no-normal builtin:photo:64 -o a.exr --roughness 0.3
mip err-nan "$peer/openexr-images/AllHalfValues.exr" -o a.exr
mip err-ext builtin:photo:64 -o a.jpg
mip err-tile builtin:photo:64 -o a.exr --tile 0

# Text outputs.
q=$(printf '0.3 0.7 0.01 0 0 0.01\n-12.25 3.5 0.002 0.001 -0.001 0.003\n0.5 0.5 0 0 0 0\n')
for f in nearest bilinear trilinear aniso ewa sat supersample; do
    echo "sample-$f $(printf '%s\n' "$q" | "$bin" sample o1/a.exr --filter "$f" 2>&1 | sha256sum | cut -c1-16)"
done
echo "sample-gather $(printf '%s\n' "$q" | "$bin" sample o12/a.ktx2 --gather 1 | sha256sum | cut -c1-16)"
echo "info $("$bin" info o1/a.exr o12/a.ktx2 o20/a.dds | sha256sum | cut -c1-16)"
echo "cachesim $("$bin" cachesim --scene plane --size 160x120 --texture builtin:checker:256 --filter trilinear --layout tiled:4x4 --cache 16K:64:4 | sha256sum | cut -c1-16)"
