#!/usr/bin/env python3
"""The cache model against pycachesim, an independent simulator: a texel
trace that `parvo cachesim --trace-out` writes for a scene, run through
`parvo cachesim --trace` and through pycachesim's bulk load, must give the
same hits and misses under LRU and FIFO for direct-mapped, set-associative
and fully associative caches (both count one hit or miss per cache line an
access touches). Scene mode must agree with replaying its own trace. For the
1920x1080 frame of the README's speed comparison is checked the same way;
the comparison itself (timed side by side) is `scripts/pycachesim-speed.py`,
run on a release build without CI's overflow checks.
"""
import json
import time

from cachesim import Cache, CacheSimulator, MainMemory

from common import args, check, finish, run

parvo, venv_bin, work = args()

trace = f"{work}/plane.trace"
scene = ["--scene", "plane", "--size", "256x192", "--texture", "builtin:checker:2048",
         "--filter", "trilinear", "--layout", "tiled:4x4"]
r = run(parvo, "cachesim", *scene, "--cache", "16K:64:4", "--trace-out", trace, "--json")
check(r.returncode == 0, "parvo cachesim writes the scene's texel trace")
scene_stats = json.loads(r.stdout)
with open(trace) as f:
    addrs = [int(line) for line in f if line.strip() and not line.startswith("#")]
check(len(addrs) == scene_stats["texel_reads"], "the trace has one line per texel read",
      f"{len(addrs)} lines, {scene_stats['texel_reads']} reads")

for spec, policy in [("16K:64:4", "LRU"), ("4K:64:1", "LRU"), ("8K:32:8", "FIFO"),
                     ("2K:64:32", "LRU"), ("16K:128:2", "FIFO")]:
    size, line, ways = spec.split(":")
    size_b = int(size[:-1]) * 1024
    line, ways = int(line), int(ways)
    r = run(parvo, "cachesim", "--trace", trace, "--cache", f"{spec}:{policy.lower()}",
            "--access-bytes", "4", "--json")
    if not check(r.returncode == 0, f"parvo cachesim --trace under {spec} {policy}"):
        continue
    ours = json.loads(r.stdout)
    mem = MainMemory()
    l1 = Cache("L1", size_b // (line * ways), ways, line, policy)
    mem.load_to(l1)
    mem.store_from(l1)
    cs = CacheSimulator(l1, mem)
    t0 = time.perf_counter()
    cs.load(addrs, length=4)
    dt = time.perf_counter() - t0
    theirs = next(iter(cs.stats()))
    check((ours["hits"], ours["misses"]) == (theirs["HIT_count"], theirs["MISS_count"]),
          f"{spec} {policy}: parvo's hits and misses equal pycachesim's",
          f"parvo {ours['hits']}/{ours['misses']}, pycachesim {theirs['HIT_count']}/{theirs['MISS_count']}; "
          f"pycachesim {len(addrs) / dt / 1e6:.1f} M accesses/s")
    if spec == "16K:64:4":
        check((ours["hits"], ours["misses"], ours["cold_misses"], ours["capacity_misses"])
              == (scene_stats["hits"], scene_stats["misses"], scene_stats["cold_misses"],
                  scene_stats["capacity_misses"]),
              "scene mode equals the replay of its own trace")

# The README's benchmark frame: the 1920x1080 trilinear plane (tiled
# raster order). The counts must agree: the scene run, its own trace
# replayed by parvo, and pycachesim on that trace.
big = f"{work}/plane_1080.trace"
frame = ["--scene", "plane", "--size", "1920x1080", "--texture", "builtin:checker:4096",
         "--filter", "trilinear", "--layout", "tiled:4x4", "--cache", "16K:64:4", "--order", "tiled:8"]
r = run(parvo, "cachesim", *frame, "--trace-out", big, "--json")
if check(r.returncode == 0, "parvo cachesim writes the 1920x1080 trilinear trace"):
    traced = json.loads(r.stdout)
    with open(big) as f:
        addrs = [int(line) for line in f if line.strip() and not line.startswith("#")]
    three_c = ("hits", "misses", "cold_misses", "capacity_misses", "conflict_misses")
    r = run(parvo, "cachesim", "--trace", big, "--cache", "16K:64:4", "--json")
    replay = json.loads(r.stdout) if r.returncode == 0 else {}
    check(all(replay.get(k) == traced[k] for k in three_c),
          "1920x1080: the replay of the trace counts what the scene run counted",
          " ".join(f"{k} {traced[k]}" for k in three_c))
    mem = MainMemory()
    l1 = Cache("L1", 64, 4, 64, "LRU")
    mem.load_to(l1)
    mem.store_from(l1)
    cs = CacheSimulator(l1, mem)
    cs.load(addrs, length=4)
    theirs = next(iter(cs.stats()))
    check((traced["hits"], traced["misses"]) == (theirs["HIT_count"], theirs["MISS_count"]),
          "1920x1080 trilinear trace: hits and misses equal pycachesim's",
          f"{len(addrs)} accesses")

finish()
