#!/usr/bin/env python3
"""How far an 8-bit chain written by parvo is from the exact chain.

Usage: drift-table.py PARVO_BIN IMAGE [PARVO_BIN_2 ...]

For the box and Kaiser filters, in sRGB and in linear colour (`--color`),
runs `parvo mip IMAGE -o 'DIR/t_{level}.png'` and compares every level with
round(the exact chain): level 0 decoded to linear light in float64, each
level filtered from the *unrounded* level before it with SPEC.md's weights
(box: area weights, polyphase for odd sizes; Kaiser width 3, alpha 4,
stretched by the reduction, normalised; repeat wrap), encoded and rounded
once. Prints, per binary, filter, colour and level, the share of values
off by at least one code and the bias (mean of parvo's code minus the
reference code), both without the values whose exact result is a tie
(x.5 codes), which either rounding gets right. Needs numpy and Pillow (scripts/setup-interop.sh).
"""
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image


def srgb_decode(c):
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def srgb_encode(l):
    l = np.clip(l, 0.0, 1.0)
    return np.where(l <= 0.0031308, l * 12.92, 1.055 * l ** (1 / 2.4) - 0.055)


def kaiser(x, width=3.0, alpha=4.0):
    t = np.clip(1 - (x / width) ** 2, 0, None)
    v = np.sinc(x) * np.i0(alpha * np.sqrt(t)) / np.i0(alpha)
    return np.where(np.abs(x) < width, v, 0.0)


def axis_weights(filt, src, dst):
    """dst × src matrix of normalised weights (repeat wrap)."""
    m = np.zeros((dst, src))
    s = src / dst
    for x in range(dst):
        if src == dst:
            m[x, x] = 1
            continue
        if filt == "box":
            lo, hi = x * s, (x + 1) * s
            for i in range(int(np.floor(lo)), int(np.ceil(hi))):
                m[x, i % src] += max(0.0, min(hi, i + 1) - max(lo, i)) / s
        else:
            c = (x + 0.5) * s
            r = 3 * s
            for i in range(int(np.floor(c - r)) - 1, int(np.ceil(c + r)) + 1):
                m[x, i % src] += kaiser((i + 0.5 - c) / s)
            m[x] /= m[x].sum()
    return m


def reference(lin, filt, srgb):
    h, w, _ = lin.shape
    levels = [lin]
    k = 1
    while max(w >> (k - 1), h >> (k - 1)) > 1:
        sw, sh = max(1, w >> (k - 1)), max(1, h >> (k - 1))
        dw, dh = max(1, w >> k), max(1, h >> k)
        wx, wy = axis_weights(filt, sw, dw), axis_weights(filt, sh, dh)
        prev = levels[-1]
        tmp = np.tensordot(wy, prev, axes=(1, 0))  # dh × sw × c
        levels.append(np.tensordot(tmp, wx, axes=(1, 1)).transpose(0, 2, 1))
        k += 1
    enc = (lambda l: srgb_encode(l)) if srgb else (lambda l: np.clip(l, 0, 1))
    return [enc(l) * 255 for l in levels]


def main():
    bins, image = [sys.argv[1]] + sys.argv[3:], sys.argv[2]
    codes = np.asarray(Image.open(image).convert("RGB"), dtype=np.float64) / 255
    print(f"image {image}: {codes.shape[1]}x{codes.shape[0]}")
    refs = {}
    for filt in ["box", "kaiser"]:
        for color in ["srgb", "linear"]:
            lin = srgb_decode(codes) if color == "srgb" else codes
            refs[filt, color] = reference(lin, filt, color == "srgb")
    with tempfile.TemporaryDirectory() as d:
        for b in bins:
            print(f"\nparvo: {b}")
            print("| filter | colour | level | size | values off | bias (codes) | exact ties |")
            print("|---|---|---:|---|---:|---:|---:|")
            for (filt, color), ref in refs.items():
                tag = f"{filt}_{color}"
                subprocess.run([b, "mip", image, "-o", f"{d}/{tag}_{{level}}.png",
                                "--filter", filt, "--color", color], check=True,
                               capture_output=True)
                for k, r in enumerate(ref):
                    got = np.asarray(Image.open(f"{d}/{tag}_{k}.png").convert("RGB"),
                                     dtype=np.float64)
                    # An exact tie (an average of codes ending in .5, common
                    # in linear and in sRGB's linear toe) is right either
                    # way: it is left out of both figures.
                    tie = np.abs(r - np.floor(r) - 0.5) < 1e-6
                    diff = (got - np.floor(r + 0.5))[~tie]
                    off = np.mean(diff != 0) * 100
                    print(f"| {filt} | {color} | {k} | {r.shape[1]}x{r.shape[0]} | "
                          f"{off:.2f} % | {diff.mean():+.3f} | {tie.mean() * 100:.1f} % |")


if __name__ == "__main__":
    main()
