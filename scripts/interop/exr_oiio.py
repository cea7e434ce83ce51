#!/usr/bin/env python3
"""Interop checks of parvo's EXR output against OpenImageIO (oiiotool,
maketx, Python bindings). Called by .ci/interop.sh with the venv's python;
prints one line per check ("ok: ..." / "FAIL: ...") and exits 1 on any
failure.

Usage: exr_oiio.py PARVO_BIN VENV_BIN WORKDIR
"""
import json
import re

import numpy as np
import OpenImageIO as oiio

from common import args, check, finish, oiio_levels, run

parvo, venv_bin, work = args()


# A power-of-two, non-square float RGBA image of fixed-seed noise, written
# as a plain scanline EXR.
W, H = 256, 128
rng = np.random.default_rng(20261121)
pixels = rng.random((H, W, 4), dtype=np.float32)
src = f"{work}/src.exr"
out = oiio.ImageOutput.create(src)
spec = oiio.ImageSpec(W, H, 4, "float")
assert out.open(src, spec), oiio.geterror()
assert out.write_image(pixels)
out.close()

ours = f"{work}/parvo_box.exr"
theirs = f"{work}/maketx_box.exr"
r = run(parvo, "mip", src, "-o", ours, "--filter", "box", "--type", "f32", "--wrap", "clamp")
check(r.returncode == 0, "parvo mip --filter box --type f32 on a 256x128 float EXR")
r = run(f"{venv_bin}/maketx", "--filter", "box", "-d", "float", "--wrap", "clamp", src, "-o", theirs)
check(r.returncode == 0, "maketx --filter box -d float on the same image")

# oiiotool --info -v lists every MIP level and the tile size of our file.
info = run(f"{venv_bin}/oiiotool", "--info", "-v", ours).stdout
want_levels = []
w, h = W, H
while True:
    want_levels.append(f"{w}x{h}")
    if w == 1 and h == 1:
        break
    w, h = max(1, w // 2), max(1, h // 2)
m = re.search(r"MIP-map levels: (.*)", info)
got_levels = m.group(1).split() if m else []
check(got_levels == want_levels, "oiiotool --info -v lists every MIP level",
      " ".join(got_levels) or "no MIP-map line")
check("tile size: 64 x 64" in info, "oiiotool --info -v shows the 64x64 tile size")
check('wrapmodes: "clamp,clamp"' in info, "oiiotool sees wrapmodes clamp,clamp")
check('textureformat: "Plain Texture"' in info, 'oiiotool sees textureformat "Plain Texture"')


a, b = oiio_levels(ours)[0] or [], oiio_levels(theirs)[0] or []
check(len(a) == len(want_levels) and len(b) == len(want_levels),
      "both files have the full chain", f"parvo {len(a)}, maketx {len(b)}, expected {len(want_levels)}")
check(len(a) > 0 and np.array_equal(a[0], pixels), "parvo level 0 equals the source exactly")
worst = 0.0
for k, (x, y) in enumerate(zip(a, b)):
    if x.shape != y.shape:
        check(False, f"level {k} shapes", f"{x.shape} vs {y.shape}")
        continue
    d = float(np.max(np.abs(x - y)))
    worst = max(worst, d)
    check(d <= 1e-5, f"level {k} ({x.shape[1]}x{x.shape[0]}): parvo box == maketx box within 1e-5",
          f"max |diff| {d:.3g}")
print(f"       worst level difference parvo vs maketx: {worst:.3g}")

# parvo info reads maketx's output with all levels.
r = run(parvo, "info", "--json", theirs)
ok = r.returncode == 0
if ok:
    j = json.loads(r.stdout)
    n = len(j["levels"])
    ok = n == len(want_levels) and [f'{l["width"]}x{l["height"]}' for l in j["levels"]] == want_levels
    check(ok, "parvo info reads maketx's EXR with every level",
          f"{n} levels, tile {j['tile']}, wrapmodes {j['wrapmodes']}")
else:
    check(False, "parvo info reads maketx's EXR")

# A maketx file loads in parvo with the same texels OIIO reads.
r = run(parvo, "mip", theirs, "-o", f"{work}/roundtrip.exr", "--type", "f32")
check(r.returncode == 0, "parvo mip accepts maketx's EXR as input")

finish()
