#!/usr/bin/env python3
"""BC1/BC3/BC7 encoders side by side on four scikit-image photos.

Run by benches/bc_peers.sh (which installs the peers into a venv under
target/ and builds parvo); prints a Markdown table for the README.

Every encoder gets the same 8-bit RGB texels (the photos as skimage.data
returns them, written as PNGs without colour chunks: parvo reads those as
sRGB and writes the _SRGB formats; the blocks are the same as for UNORM).
Every file is decoded by one independent decoder, texture2ddecoder
(Perfare's Texture2DDecoder, a port of the DirectX reference decoders),
and PSNR is over R, G, B of the visible texels against the input codes,
peak 255: 10 * log10(255^2 / MSE).

Time: the median of --reps runs, as wall time and as CPU time (user +
system, all threads; the figure that other jobs on a shared machine
disturb least). The command-line tools (parvo, nvcompress) are timed as
whole processes (read the PNG, encode, write the DDS); the Python
libraries (quicktex, etcpak) by the encode call alone, on input already
padded to whole blocks.
"""

import argparse
import os
import platform
import resource
import shutil
import statistics
import subprocess
import sys
import time

import numpy as np
from PIL import Image
import skimage
import skimage.data
import texture2ddecoder
import etcpak
import quicktex
from quicktex.s3tc.bc1 import BC1Encoder
from quicktex.s3tc.bc3 import BC3Encoder

PHOTOS = ["astronaut", "chelsea", "coffee", "rocket"]
BLOCK_BYTES = {"bc1": 8, "bc3": 16, "bc7": 16}


def padded_rgba(rgb):
    """RGB uint8 (h, w, 3) -> RGBA padded to whole 4x4 blocks by repeating
    the last row and column (as parvo and nvtt pad)."""
    h, w, _ = rgb.shape
    ph, pw = -(-h // 4) * 4, -(-w // 4) * 4
    rgba = np.empty((h, w, 4), np.uint8)
    rgba[..., :3] = rgb
    rgba[..., 3] = 255
    return np.pad(rgba, ((0, ph - h), (0, pw - w), (0, 0)), mode="edge")


def decode(fmt, blocks, w, h):
    """Blocks (row-major, whole blocks) -> RGB uint8 (h, w, 3), decoded by
    texture2ddecoder (which returns BGRA)."""
    pw, ph = -(-w // 4) * 4, -(-h // 4) * 4
    need = (pw // 4) * (ph // 4) * BLOCK_BYTES[fmt]
    if len(blocks) < need:
        raise ValueError(f"{fmt}: {len(blocks)} bytes of blocks, {need} needed")
    dec = {"bc1": texture2ddecoder.decode_bc1, "bc3": texture2ddecoder.decode_bc3,
           "bc7": texture2ddecoder.decode_bc7}[fmt]
    bgra = np.frombuffer(dec(bytes(blocks[:need]), pw, ph), np.uint8).reshape(ph, pw, 4)
    return bgra[:h, :w, 2::-1]


def psnr(ref, got):
    d = ref.astype(np.float64) - got.astype(np.float64)
    mse = float(np.mean(d * d))
    return float("inf") if mse == 0 else 10 * np.log10(255.0 ** 2 / mse)


def dds_blocks(path):
    """The level-0 payload of a DDS file (DX9 or DX10 header)."""
    data = open(path, "rb").read()
    if data[:4] != b"DDS ":
        raise ValueError(f"{path}: not a DDS file")
    four_cc = data[84:88]
    return data[148:] if four_cc == b"DX10" else data[128:]


def timed(fn, reps):
    """Run fn reps times: its last result, the median wall and CPU seconds
    (this process and the children it waited for)."""
    walls, cpus, out = [], [], None
    for _ in range(reps):
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        c0, t0 = time.process_time(), time.perf_counter()
        out = fn()
        t1, c1 = time.perf_counter(), time.process_time()
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        walls.append(t1 - t0)
        cpus.append((c1 - c0) + (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime))
    return out, statistics.median(walls), statistics.median(cpus)


def run(cmd):
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def parvo_encoder(parvo, fmt, quality, threads):
    def enc(png, work, reps):
        out = os.path.join(work, f"parvo_{fmt}_{quality}.dds")
        cmd = [parvo, "mip", png, "-o", out, "--levels", "1", "--compress", fmt,
               "--quality", quality, "--threads", str(threads)]
        _, t, c = timed(lambda: run(cmd), reps)
        return dds_blocks(out), t, c
    return enc


def nvcompress_encoder(fmt, fast):
    def enc(png, work, reps):
        out = os.path.join(work, f"nvcompress_{fmt}_{int(fast)}.dds")
        cmd = ["nvcompress"] + (["-fast"] if fast else []) + ["-nocuda", f"-{fmt}", "-nomips", png, out]
        _, t, c = timed(lambda: run(cmd), reps)
        return dds_blocks(out), t, c
    return enc


def quicktex_encoder(fmt, level):
    def enc(png, work, reps, rgba=None):
        h, w, _ = rgba.shape
        raw = quicktex.RawTexture.frombytes(rgba.tobytes(), w, h)
        e = BC1Encoder(level) if fmt == "bc1" else BC3Encoder(level)
        out, t, c = timed(lambda: e.encode(raw).tobytes(), reps)
        return out, t, c
    enc.wants_rgba = True
    return enc


def etcpak_encoder(fmt, params=None):
    def enc(png, work, reps, rgba=None):
        h, w, _ = rgba.shape
        data = rgba.tobytes()
        if fmt == "bc1":
            fn = lambda: etcpak.compress_bc1(data, w, h)
        elif fmt == "bc3":
            fn = lambda: etcpak.compress_bc3(data, w, h)
        else:
            fn = lambda: etcpak.compress_bc7(data, w, h, params)
        out, t, c = timed(fn, reps)
        return out, t, c
    enc.wants_rgba = True
    return enc


def version(cmd):
    try:
        return subprocess.run(cmd, capture_output=True, text=True).stdout.strip()
    except OSError:
        return "?"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--parvo", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--threads", type=int, default=os.cpu_count())
    args = ap.parse_args()
    os.makedirs(args.work, exist_ok=True)
    have_nv = shutil.which("nvcompress") is not None
    if not have_nv:
        print("bc_peers: nvcompress not found, its rows are left out", file=sys.stderr)

    photos = {}
    for name in PHOTOS:
        rgb = getattr(skimage.data, name)()
        png = os.path.join(args.work, f"{name}.png")
        Image.fromarray(rgb).save(png)
        photos[name] = (rgb, png, padded_rgba(rgb))

    # (format, label, threads, encoder)
    rows = []
    # etcpak's BC7 is bc7enc: its defaults weigh the channels perceptually;
    # the second row asks for uniform weights (what PSNR measures) and the
    # highest effort.
    bc7_slow = etcpak.BC7CompressBlockParams()
    bc7_slow.init_linear_weights()
    bc7_slow.m_uber_level = 4
    bc7_slow.m_max_partitions = 64
    for fmt in ["bc1", "bc3", "bc7"]:
        for q in ["fast", "normal", "slow"]:
            default = " (default)" if q == "normal" else ""
            rows.append((fmt, f"parvo {q}{default}", args.threads,
                         parvo_encoder(args.parvo, fmt, q, args.threads)))
        if fmt != "bc7":
            rows.append((fmt, f"parvo normal, 1 thread", 1,
                         parvo_encoder(args.parvo, fmt, "normal", 1)))
            if have_nv:
                rows.append((fmt, "nvcompress -fast", 1, nvcompress_encoder(fmt, True)))
                rows.append((fmt, "nvcompress (no -fast)", 1, nvcompress_encoder(fmt, False)))
            rows.append((fmt, "quicktex level 5 (default)", 1, quicktex_encoder(fmt, 5)))
            rows.append((fmt, "quicktex level 18", 1, quicktex_encoder(fmt, 18)))
            rows.append((fmt, "etcpak", 1, etcpak_encoder(fmt)))
        else:
            rows.append((fmt, "etcpak (default params)", 1, etcpak_encoder(fmt, None)))
            rows.append((fmt, "etcpak (uniform weights, uber 4)", 1, etcpak_encoder(fmt, bc7_slow)))

    cpu = "?"
    for line in open("/proc/cpuinfo"):
        if line.startswith("model name"):
            cpu = line.split(":", 1)[1].strip()
            break
    nv = "NVIDIA Texture Tools 2.0.8 (Debian libnvtt-bin)" if have_nv else "nvcompress absent"
    print(f"Four scikit-image {skimage.__version__} photos; {os.cpu_count()} cores, {cpu}; "
          f"{nv}, quicktex {quicktex.__version__}, etcpak {etcpak.__version__}, "
          f"decoded by texture2ddecoder; Python {platform.python_version()}; "
          f"median of {args.reps} runs; {time.strftime('%Y-%m-%d', time.gmtime())}")
    print()
    head = " | ".join(f"{n} dB" for n in PHOTOS)
    print(f"| format | encoder | threads | {head} | mean dB | wall ms | CPU ms |")
    print("|---|---|---:|" + "---:|" * len(PHOTOS) + "---:|---:|---:|")
    for fmt, label, threads, enc in rows:
        ps, wall, cpu = [], 0.0, 0.0
        for name in PHOTOS:
            rgb, png, rgba = photos[name]
            if getattr(enc, "wants_rgba", False):
                blocks, t, c = enc(png, args.work, args.reps, rgba=rgba)
            else:
                blocks, t, c = enc(png, args.work, args.reps)
            h, w, _ = rgb.shape
            ps.append(psnr(rgb, decode(fmt, blocks, w, h)))
            wall += t
            cpu += c
        cells = " | ".join(f"{p:.2f}" for p in ps)
        print(f"| {fmt.upper()} | {label} | {threads} | {cells} | {statistics.mean(ps):.2f} | "
              f"{wall * 1e3:.0f} | {cpu * 1e3:.0f} |", flush=True)


if __name__ == "__main__":
    main()
