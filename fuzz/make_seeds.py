#!/usr/bin/env python3
"""Seeds of the sat, cachesim and normal_roughness targets: small inputs
laid out as each target reads its bytes (header bytes, then texels, then
rectangles or accesses), from a fixed seed. Run from fuzz/:
`python3 make_seeds.py` rewrites seeds/{sat,cachesim,normal_roughness}."""
import os
import random
import struct

rng = random.Random(16)


def write(target, name, data):
    os.makedirs(f"seeds/{target}", exist_ok=True)
    with open(f"seeds/{target}/{name}", "wb") as f:
        f.write(bytes(data))


# sat: w-1, h-1, channels-1, flags (1 sRGB, 2 16-bit), accumulator (0 auto,
# k+1 = AccumulatorKind::ALL[k]), wrap u, wrap v, unused; texels; then
# rectangles of four little-endian f64.
for i, (w, h, ch, flags, acc, wu, wv) in enumerate(
    [(5, 7, 3, 0, 0, 0, 1), (16, 3, 1, 2, 2, 3, 4), (1, 1, 2, 1, 5, 2, 2), (9, 11, 3, 3, 6, 1, 0)]
):
    n = w * h * ch * (2 if flags & 2 else 1)
    d = [w - 1, h - 1, ch - 1, flags, acc, wu, wv, 0] + [rng.randrange(256) for _ in range(n)]
    for _ in range(6):
        x0, y0 = rng.uniform(-2 * w, 2 * w), rng.uniform(-2 * h, 2 * h)
        d += struct.pack("<4d", x0, y0, x0 + rng.uniform(0.5, 3 * w), y0 + rng.uniform(0.5, 3 * h))
    d += struct.pack("<4d", float("nan"), 1e300, float("-inf"), 2.5)
    write("sat", f"s{i}", d)

# cachesim: log2(line)-1, log2(size)-6, ways-1, policy, sector, seed,
# layout kind, tile w-1, tile h-1, texel bytes-1 / super-tile, chain w-1,
# chain h-1; then accesses of three bytes (address LE16, size code).
for i, hdr in enumerate(
    [[5, 6, 3, 0, 0, 1, 1, 3, 3, 3, 63, 40], [3, 4, 0, 1, 1, 2, 4, 1, 3, 11, 8, 5],
     [6, 7, 15, 2, 2, 3, 3, 7, 1, 15, 36, 36], [1, 0, 7, 0, 0, 4, 0, 0, 0, 0, 0, 0]]
):
    d = list(hdr)
    pos = 0
    for _ in range(600):
        pos = (pos + rng.randrange(-40, 41)) % 65536 if rng.random() < 0.9 else rng.randrange(65536)
        d += list(struct.pack("<H", pos)) + [rng.randrange(8)]
    write("cachesim", f"s{i}", d)

# normal_roughness: w-1, h-1, channels-2, type (U8, U16, F16, F32), mip
# filter, NaN policy, base roughness f32 LE, mode bits, unused; texels.
for i, (w, h, ch, ty, filt, nan, base, mode) in enumerate(
    [(8, 8, 3, 0, 0, 0, 0.3, 0), (5, 3, 2, 1, 2, 1, 0.7, 1), (7, 9, 3, 3, 3, 2, 0.0, 2),
     (4, 4, 4, 2, 4, 1, 16.0, 8), (1, 1, 3, 3, 0, 0, -1.0, 4)]
):
    size = [1, 2, 2, 4][ty]
    d = [w - 1, h - 1, ch - 2, ty, filt, nan] + list(struct.pack("<f", base)) + [mode, 0]
    texels = []
    for _ in range(w * h):
        v = [rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(0, 1), rng.uniform(0, 1)][:ch]
        for c in v:
            if ty == 0:
                texels += [int((c + 1) / 2 * 255)]
            elif ty == 1:
                texels += list(struct.pack("<H", int((c + 1) / 2 * 65535)))
            elif ty == 2:
                texels += list(struct.pack("<e", c))
            else:
                texels += list(struct.pack("<f", c))
    if ty == 3 and texels:
        texels[0:4] = list(struct.pack("<f", float("nan")))
    write("normal_roughness", f"s{i}", d + texels)
