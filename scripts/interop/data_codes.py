#!/usr/bin/env python3
"""BC4 and BC5 hold data (issue 53): an untagged grey PNG and an untagged
RG PNG (RGB with B = 0: PNG has no two-channel colour) go into BC4 and BC5
as their stored codes, with no flag, as every peer keeps them.

For each, parvo's block file (`parvo mip IN --compress bc4|bc5 -o X.dds
--levels 1`) and quicktex's encoder (the peer, same codes in) are decoded
as the D3D functional specification defines BC4/BC5 UNORM (the palette
interpolated in float: what a GPU's fetch returns), by a decoder written
here, and scored against the input's codes: parvo's PSNR must be within
0.1 dB of quicktex's or above it. Printed beside it: the same blocks
through texture2ddecoder (an independent decoder that truncates the
palette to 8 bits, which favours encoders fitted to truncation, as
quicktex's is) and the file read as sRGB colour (`--color srgb`, what
parvo did by default before).
"""
import math
import struct

import numpy as np
import quicktex
import quicktex.s3tc.bc4 as bc4
import quicktex.s3tc.bc5 as bc5
import texture2ddecoder
from PIL import Image

from common import args, check, finish, run

parvo, _venv, work = args()
SIZE = 512


def photo_rgb():
    """parvo's built-in photo-like image as 8-bit RGB codes."""
    out = f"{work}/photo_{{level}}.png"
    r = run(parvo, "mip", f"builtin:photo:{SIZE}", "-o", out, "--levels", "1")
    assert r.returncode == 0, r.stderr
    with Image.open(out.replace("{level}", "0")) as im:
        return np.array(im.convert("RGB"))


def dds_level0(path, w, h, block_bytes):
    """Level 0's blocks of a DDS (legacy or DX10 header)."""
    data = open(path, "rb").read()
    fourcc = data[84:88]
    start = 4 + 124 + (20 if fourcc == b"DX10" else 0)
    n = ((w + 3) // 4) * ((h + 3) // 4) * block_bytes
    return data[start:start + n]


def decode(blocks, fmt, w, h):
    """texture2ddecoder's decode: BGRA bytes as an H x W x 4 array (RGBA)."""
    raw = (texture2ddecoder.decode_bc4 if fmt == "bc4" else texture2ddecoder.decode_bc5)(blocks, w, h)
    bgra = np.frombuffer(raw, dtype=np.uint8).reshape(h, w, 4)
    return bgra[:, :, [2, 1, 0, 3]]


def spec_bc4(b, w, h):
    """BC4 UNORM blocks (N x 8 bytes) as the D3D specification decodes them:
    a0 > a1: a0, a1 and (k·a0 + (7 - k)·a1)/7; else a0, a1, (k·a0 + (5 - k)·a1)/5,
    0 and 255; the index of texel i in bits 16 + 3i. Float, 0..255."""
    a0, a1 = b[:, 0].astype(np.float64), b[:, 1].astype(np.float64)
    bits = np.zeros(len(b), np.uint64)
    for k in range(6):
        bits |= b[:, 2 + k].astype(np.uint64) << np.uint64(8 * k)
    idx = np.stack([((bits >> np.uint64(3 * i)) & np.uint64(7)).astype(np.int64) for i in range(16)], 1)
    eight = a0 > a1
    pal = np.zeros((len(b), 8))
    pal[:, 0], pal[:, 1] = a0, a1
    for i in range(1, 7):
        pal[:, 1 + i] = ((7 - i) * a0 + i * a1) / 7
    for i in range(1, 5):
        pal[~eight, 1 + i] = (((5 - i) * a0 + i * a1) / 5)[~eight]
    pal[~eight, 6], pal[~eight, 7] = 0, 255
    vals = np.take_along_axis(pal, idx, 1)
    bw, bh = (w + 3) // 4, (h + 3) // 4
    return vals.reshape(bh, bw, 4, 4).transpose(0, 2, 1, 3).reshape(bh * 4, bw * 4)[:h, :w]


def spec_decode(blocks, fmt, w, h):
    """BC4 (R) or BC5 (R block, then G block) per the specification:
    H x W x channels, float."""
    per = 8 if fmt == "bc4" else 16
    b = np.frombuffer(blocks, np.uint8).reshape(-1, per)
    return np.stack([spec_bc4(np.ascontiguousarray(b[:, c:c + 8]), w, h) for c in range(0, per, 8)], -1)


def psnr(a, b):
    mse = np.mean((a.astype(np.float64) - b.astype(np.float64)) ** 2)
    return math.inf if mse == 0 else 10 * math.log10(255.0 ** 2 / mse)


def quicktex_blocks(codes, fmt):
    """quicktex's BC4 (from R) or BC5 (R, G) of `codes` (H x W x C)."""
    h, w = codes.shape[:2]
    rgba = np.zeros((h, w, 4), dtype=np.uint8)
    rgba[:, :, :codes.shape[2]] = codes
    rgba[:, :, 3] = 255
    raw = quicktex.RawTexture.frombytes(rgba.tobytes(), w, h)
    enc = bc4.BC4Encoder(0) if fmt == "bc4" else bc5.BC5Encoder(0, 1)
    return bytes(enc.encode(raw).tobytes())


def main():
    rgb = photo_rgb()
    grey = (0.299 * rgb[:, :, 0] + 0.587 * rgb[:, :, 1] + 0.114 * rgb[:, :, 2]).round().astype(np.uint8)
    rg = rgb.copy()
    rg[:, :, 2] = 0
    cases = [("bc4", "grey", grey[:, :, None], 1), ("bc5", "RG", rg, 2)]
    for fmt, what, codes, ch in cases:
        src = f"{work}/untagged_{what}.png"
        # Pillow writes no sRGB, gAMA or iCCP chunk: the file says nothing.
        Image.fromarray(codes[:, :, 0] if codes.shape[2] == 1 else codes).save(src)
        h, w = codes.shape[:2]
        block = 8 if fmt == "bc4" else 16
        scores = {}
        for name, extra in [("no flag", []), ("--color srgb", ["--color", "srgb"])]:
            out = f"{work}/{what}_{fmt}_{len(extra)}.dds"
            r = run(parvo, "mip", src, "--compress", fmt, "--levels", "1", "-o", out, *extra)
            if not check(r.returncode == 0, f"parvo writes {fmt} from an untagged {what} PNG ({name})"):
                continue
            blocks = dds_level0(out, w, h, block)
            scores[name] = (psnr(spec_decode(blocks, fmt, w, h), codes[:, :, :ch]),
                            psnr(decode(blocks, fmt, w, h)[:, :, :ch], codes[:, :, :ch]))
        qt = quicktex_blocks(codes, fmt)
        peer = (psnr(spec_decode(qt, fmt, w, h), codes[:, :, :ch]),
                psnr(decode(qt, fmt, w, h)[:, :, :ch], codes[:, :, :ch]))
        if "no flag" in scores:
            ours = scores["no flag"]
            srgb = scores.get("--color srgb", (float("nan"),) * 2)
            check(ours[0] >= peer[0] - 0.1,
                  f"{fmt} from an untagged {what} PNG keeps the codes: parvo within 0.1 dB of quicktex",
                  f"{w}x{h}, decoded as specified: parvo {ours[0]:.2f} dB, quicktex {peer[0]:.2f} dB, "
                  f"read as sRGB colour {srgb[0]:.2f} dB; through texture2ddecoder: {ours[1]:.2f}, "
                  f"{peer[1]:.2f}, {srgb[1]:.2f} dB")
    finish()


main()
