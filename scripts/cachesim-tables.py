#!/usr/bin/env python3
"""The README's cache tables, measured with `parvo cachesim` (run from the
repository root after `cargo build --release`):

    scripts/cachesim-tables.py [target/release/parvo]

1. plane 512x384, builtin:checker:4096: filters x layouts x three cache
   sizes (64-byte lines, 4-way LRU), hit rate and bytes per pixel;
2. rotate:30 1024x1024, builtin:checker:2048, bilinear, 4K:64:4: layouts x
   raster orders, bytes per pixel;
3. the lecture's question: level-0-only bilinear against trilinear.
"""
import csv
import json
import subprocess
import sys
import tempfile

parvo = sys.argv[1] if len(sys.argv) > 1 else "target/release/parvo"


def sim(*args):
    r = subprocess.run([parvo, "cachesim", *args, "--json"], capture_output=True, text=True, check=True)
    return json.loads(r.stdout)


layouts = ["linear", "tiled:4x4", "morton", "blocked:4x4:32x32"]
filters = ["bilinear", "trilinear", "aniso16", "sat"]
sizes = ["4K", "16K", "64K"]
with tempfile.TemporaryDirectory() as d:
    subprocess.run([parvo, "cachesim", "--sweep", "--scene", "plane", "--size", "512x384",
                    "--texture", "builtin:checker:4096", "--cache-sizes", ",".join(sizes),
                    "--lines", "64", "--ways", "4", "--layouts", ",".join(layouts),
                    "--filters", ",".join(filters), "--out", d], check=True, capture_output=True)
    rows = list(csv.DictReader(open(f"{d}/sweep.csv")))
print("Plane 512×384, `builtin:checker:4096` (RGBA8), scanline order, 64-byte lines, 4-way LRU: "
      "hit rate / bytes from memory per pixel.\n")
print("| filter | layout | " + " | ".join(sizes) + " |")
print("|---|---|" + "---|" * len(sizes))
for f in filters:
    for l in layouts:
        cells = []
        for s in sizes:
            r = next(r for r in rows if r["filter"] == f and r["layout"] == l and r["cache"].startswith(s + ":"))
            cells.append(f"{float(r['hit_rate']) * 100:.1f}% / {float(r['bytes_per_pixel']):.1f}")
        print(f"| {f} | {l} | " + " | ".join(cells) + " |")

orders = ["scanline", "tiled:8", "morton", "hilbert"]
print("\n`rotate:30` 1024×1024, `builtin:checker:2048`, bilinear, cache 4K:64:4: bytes from memory per pixel.\n")
print("| layout | " + " | ".join(orders) + " |")
print("|---|" + "---|" * len(orders))
for l in layouts:
    cells = [f"{sim('--scene', 'rotate:30', '--size', '1024x1024', '--texture', 'builtin:checker:2048', '--filter', 'bilinear', '--layout', l, '--order', o, '--cache', '4K:64:4')['bytes_per_pixel']:.2f}" for o in orders]
    print(f"| {l} | " + " | ".join(cells) + " |")

print("\nMipmapping (tiled:4x4, 16K:64:4, scanline): bytes from memory per pixel.\n")
print("| scene | bilinear, level 0 only | bilinear | trilinear |")
print("|---|---|---|---|")
for scene, size in [("plane", "512x384"), ("rotate:30:4", "512x512")]:
    cells = [f"{sim('--scene', scene, '--size', size, '--texture', 'builtin:checker:4096', '--filter', f, '--layout', 'tiled:4x4')['bytes_per_pixel']:.1f}" for f in ["bilinear-nomip", "bilinear", "trilinear"]]
    print(f"| {scene} {size} | " + " | ".join(cells) + " |")
