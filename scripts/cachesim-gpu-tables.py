#!/usr/bin/env python3
"""The README's quad and prefetch tables, measured with `parvo cachesim`
(run from the repository root after `cargo build --release`):

    scripts/cachesim-gpu-tables.py [target/release/parvo]

1. per-texel requests against 2x2 quads (`--quads`): the 1920x1080 plane,
   builtin:checker:4096, tiled:8 raster order, 16K and 64K caches of
   64-byte lines, 4-way LRU, every layout and three filters: line requests
   per pixel, hit rate, bytes from memory per pixel, and the layout that
   moves the fewest bytes;
2. the prefetching unit (`--prefetch`): trilinear, tiled:4x4, 16K:64:4, per
   pixel and per quad, FIFO depths against memory latencies: the share of
   the unit's peak rate reached, against the same unit with a zero-latency
   memory, and the share of a blocking cache's lost cycles recovered;
3. the same for the linear layout, where more misses reach the FIFO.
"""
import csv
import json
import subprocess
import sys
import tempfile

parvo = sys.argv[1] if len(sys.argv) > 1 else "target/release/parvo"
frame = ["--scene", "plane", "--size", "1920x1080", "--texture", "builtin:checker:4096",
         "--order", "tiled:8"]
layouts = ["linear", "tiled:4x4", "morton", "blocked:4x4:32x32"]
filters = ["bilinear", "trilinear", "aniso16"]
sizes = ["16K", "64K"]


def sweep(*extra):
    with tempfile.TemporaryDirectory() as d:
        subprocess.run([parvo, "cachesim", "--sweep", *frame, "--cache-sizes", ",".join(sizes),
                        "--lines", "64", "--ways", "4", "--layouts", ",".join(layouts),
                        "--filters", ",".join(filters), "--out", d, *extra],
                       check=True, capture_output=True)
        return list(csv.DictReader(open(f"{d}/sweep.csv")))


texel, quad = sweep(), sweep("--quads")
print("Plane 1920×1080, `builtin:checker:4096` (RGBA8), tiled:8 order, 64-byte lines, 4-way LRU: "
      "line requests per pixel, hit rate, bytes from memory per pixel, per texel read and per "
      "2×2 quad.\n")
print("| filter | layout | cache | requests/px texel → quad | hit rate texel → quad "
      "| bytes/px texel → quad |")
print("|---|---|---|---|---|---|")
best = {}
for f in filters:
    for s in sizes:
        for model, rows in (("texel", texel), ("quad", quad)):
            sel = [r for r in rows if r["filter"] == f and r["cache"].startswith(s + ":")]
            win = min(sel, key=lambda r: float(r["bytes_per_pixel"]))
            best[(f, s, model)] = win["layout"]
    for l in layouts:
        for s in sizes:
            a, b = (next(r for r in rows if r["filter"] == f and r["layout"] == l
                         and r["cache"].startswith(s + ":")) for rows in (texel, quad))
            req = lambda r: int(r["accesses"]) / int(r["pixels"])
            print(f"| {f} | {l} | {s} | {req(a):.2f} → {req(b):.2f} "
                  f"| {float(a['hit_rate']) * 100:.1f}% → {float(b['hit_rate']) * 100:.1f}% "
                  f"| {float(a['bytes_per_pixel']):.2f} → {float(b['bytes_per_pixel']):.2f} |")
print("\nFewest bytes per pixel: " + "; ".join(
    f"{f} {s}: {best[(f, s, 'texel')]} per texel, {best[(f, s, 'quad')]} per quad"
    for f in filters for s in sizes) + ".")

depths = [0, 4, 16, 64, 256, 1024]
latencies = [50, 200, 1000]


def prefetch(layout, quads, latency):
    r = subprocess.run([parvo, "cachesim", *frame, "--filter", "trilinear", "--layout", layout,
                        "--cache", "16K:64:4", "--prefetch", ",".join(map(str, depths)),
                        "--latency", str(latency), "--json", *(["--quads"] if quads else [])],
                       check=True, capture_output=True, text=True)
    return json.loads(r.stdout)["prefetch"]


for layout in ["tiled:4x4", "linear"]:
    print(f"\nPrefetching unit, trilinear, {layout}, 16K:64:4, a line request per cycle: share of "
          "the peak rate (one fragment per cycle) / of the zero-latency rate / of the blocking "
          "cache's lost cycles recovered.\n")
    print("| fragments | latency | " + " | ".join(f"FIFO {d}" for d in depths) + " |")
    print("|---|---|" + "---|" * len(depths))
    for quads in (False, True):
        zero = prefetch(layout, quads, 0)
        for latency in latencies:
            rows = prefetch(layout, quads, latency)
            cells = [f"{p['efficiency'] * 100:.1f}% / {z['cycles'] / p['cycles'] * 100:.1f}% / "
                     f"{p['latency_hidden'] * 100:.0f}%" for p, z in zip(rows, zero)]
            kind = "quads" if quads else "pixels"
            print(f"| {kind} | {latency} | " + " | ".join(cells) + " |")
    p = prefetch(layout, False, 200)[0]
    print(f"\n({p['fragments']} pixels, {p['line_requests']} line requests, {p['line_fetches']} "
          f"fetched; stall-free hit rate at FIFO 0 {p['stall_free_hit_rate'] * 100:.2f}%.)")
