#!/usr/bin/env python3
"""The README's speed comparison of the cache model with pycachesim, side by
side: the whole `parvo cachesim` process on the 1920x1080 trilinear plane
(tiled raster order) against pycachesim's simulation alone of the same
trace (loaded into memory beforehand, bulk `load`), each best of five,
interleaved (parvo's two threads feel a busy neighbour on the VM more than
pycachesim's one: with three runs one batch in twenty-two was all slow).
The counts must agree; the times are printed, never checked.

Run it on a release build made without CI's overflow checks, with the
interop venv's python (scripts/setup-interop.sh installs pycachesim):

    cargo build --release && scripts/setup-interop.sh
    target/interop-venv/bin/python scripts/pycachesim-speed.py target/release/parvo
"""
import json
import os
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "interop"))

from cachesim import Cache, CacheSimulator, MainMemory  # noqa: E402

from common import check, finish, run  # noqa: E402

parvo = sys.argv[1] if len(sys.argv) > 1 else "target/release/parvo"
with tempfile.TemporaryDirectory() as work:
    big = f"{work}/plane_1080.trace"
    frame = ["--scene", "plane", "--size", "1920x1080", "--texture", "builtin:checker:4096",
             "--filter", "trilinear", "--layout", "tiled:4x4", "--cache", "16K:64:4",
             "--order", "tiled:8"]
    r = run(parvo, "cachesim", *frame, "--trace-out", big, "--json")
    if not check(r.returncode == 0, "parvo cachesim writes the 1920x1080 trilinear trace"):
        finish()
    traced = json.loads(r.stdout)
    with open(big) as f:
        addrs = [int(line) for line in f if line.strip() and not line.startswith("#")]
ours_t, theirs_t, ours, theirs = [], [], None, None
for _ in range(5):
    t0 = time.perf_counter()
    r = run(parvo, "cachesim", *frame, "--json")
    ours_t.append(time.perf_counter() - t0)
    if r.returncode == 0:
        ours = json.loads(r.stdout)
    mem = MainMemory()
    l1 = Cache("L1", 64, 4, 64, "LRU")
    mem.load_to(l1)
    mem.store_from(l1)
    cs = CacheSimulator(l1, mem)
    t0 = time.perf_counter()
    cs.load(addrs, length=4)
    theirs_t.append(time.perf_counter() - t0)
    theirs = next(iter(cs.stats()))
three_c = ("hits", "misses", "cold_misses", "capacity_misses", "conflict_misses")
check(ours is not None and all(ours[k] == traced[k] for k in three_c),
      "1920x1080: the timed scene run counts what the trace-writing run counted")
check(ours is not None and (ours["hits"], ours["misses"]) == (theirs["HIT_count"], theirs["MISS_count"]),
      "1920x1080 trilinear trace: hits and misses equal pycachesim's", f"{len(addrs)} accesses")
best, py = min(ours_t), min(theirs_t)
print(f"time: parvo cachesim, whole process (sample + simulate + 3C) {best:.3f} s; "
      f"pycachesim simulate alone (trace in memory) {py:.3f} s "
      f"({len(addrs) / py / 1e6:.1f} M accesses/s); pycachesim / parvo = {py / best:.2f}",
      flush=True)
finish()
