#!/usr/bin/env python3
"""Print criterion results as a markdown table.

usage: scripts/bench-table.py GROUP [BASELINE_ID]

Reads target/criterion/GROUP/**/new/estimates.json and benchmark.json and
prints mean time, throughput and, if BASELINE_ID is given (e.g.
memcpy_rgba8), the ratio of each time to that baseline's time.
"""
import json
import pathlib
import sys

group = sys.argv[1]
base_id = sys.argv[2] if len(sys.argv) > 2 else None
root = pathlib.Path("target/criterion") / group
rows = []
for est in sorted(root.glob("**/new/estimates.json")):
    bench = json.loads((est.parent / "benchmark.json").read_text())
    mean = json.loads(est.read_text())["mean"]["point_estimate"]  # ns
    tp = bench.get("throughput") or {}
    elems = tp.get("Elements")
    name = bench["full_id"].split("/", 1)[1]
    rows.append((name, mean, elems))
base = next((m for n, m, _ in rows if n == base_id), None)
print(f"| benchmark | mean time | rate | {'× ' + base_id if base else ''} |")
print("|---|---:|---:|---:|")
for name, mean, elems in rows:
    rate = f"{elems / mean * 1e3:.1f} M/s" if elems else ""
    ratio = f"{mean / base:.2f}" if base else ""
    print(f"| {name} | {mean / 1e6:.2f} ms | {rate} | {ratio} |")
