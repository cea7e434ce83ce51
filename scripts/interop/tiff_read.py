#!/usr/bin/env python3
"""Interop checks of parvo's TIFF reading: TIFFs written by OpenImageIO
(contiguous and planar, strips and tiles over odd sizes, 8/16-bit, half and
float, 1 to 4 channels, uncompressed, LZW and ZIP) and by Pillow (palette)
read by parvo as their writers meant them; maketx's lat-long environment
maps refused by `parvo mip` and described by `parvo info`.

parvo's reading of a file is taken from `parvo mip FILE -o X.exr --type f32
--alpha none` (level 0 holds the stored values as f32, channels as data)
read back with OpenImageIO.

Usage: tiff_read.py PARVO_BIN VENV_BIN WORKDIR
"""
import json
import subprocess

import numpy as np
import OpenImageIO as oiio
from PIL import Image

from common import args, check, finish, oiio_levels, run

parvo, venv_bin, work = args()


def parvo_read(path):
    """Level 0 as parvo reads it (f32, channels as stored), or None."""
    out = f"{work}/read.exr"
    r = run(parvo, "mip", path, "-o", out, "--type", "f32", "--alpha", "none")
    if r.returncode != 0:
        return None
    levels, _ = oiio_levels(out)
    return levels[0] if levels else None


def oiio_tiff(path, pixels, typedesc, planar, tile, compression):
    h, w, c = pixels.shape
    out = oiio.ImageOutput.create(path)
    spec = oiio.ImageSpec(w, h, c, typedesc)
    spec.attribute("oiio:UnassociatedAlpha", 1)
    spec.attribute("planarconfig", "separate" if planar else "contig")
    spec.attribute("compression", compression)
    if tile:
        spec.tile_width, spec.tile_height = tile, tile
    else:
        spec.attribute("tiff:RowsPerStrip", 5)
    assert out.open(path, spec), out.geterror()
    assert out.write_image(pixels), out.geterror()
    out.close()


rng = np.random.default_rng(20270327)
W, H = 37, 23  # odd: strips of 5 rows and 16x16 tiles overhang the edges
cases = 0
for typedesc, scale in [("uint8", 255), ("uint16", 65535), ("half", 1), ("float", 1)]:
    for channels in [1, 2, 3, 4]:
        for planar in [False, True]:
            for tile in [None, 16]:
                compression = ["none", "lzw", "zip"][cases % 3]
                cases += 1
                if scale > 1:
                    dtype = np.uint8 if scale == 255 else np.uint16
                    px = rng.integers(0, scale + 1, (H, W, channels)).astype(dtype)
                    want = px.astype(np.float32) / scale
                else:
                    px = (rng.random((H, W, channels), dtype=np.float32) * 8 - 2).astype(
                        np.float16 if typedesc == "half" else np.float32
                    )
                    want = px.astype(np.float32)
                path = f"{work}/t.tif"
                oiio_tiff(path, px, typedesc, planar, tile, compression)
                got = parvo_read(path)
                what = (
                    f"parvo reads OpenImageIO's {channels}-channel {typedesc} "
                    f"{'planar' if planar else 'contiguous'} "
                    f"{'16x16 tiles' if tile else 'strips'} ({compression}) as written"
                )
                ok = got is not None and got.shape == want.shape
                d = float(np.abs(got - want).max()) if ok else float("inf")
                check(ok and d <= 1e-6, what, f"max |diff| {d:.3g}")

# A palette TIFF written by Pillow: parvo reads it as OpenImageIO does
# (each 16-bit colour-map entry / 257, rounded down).
idx = rng.integers(0, 200, (H, W)).astype(np.uint8)
pal = Image.fromarray(idx, mode="P")
pal.putpalette(list(rng.integers(0, 256, 768).astype(int)))
path = f"{work}/palette.tif"
pal.save(path)
got = parvo_read(path)
theirs, err = oiio_levels(path)
ok = got is not None and theirs is not None and got.shape == theirs[0].shape
check(ok and np.array_equal(got, theirs[0]),
      "parvo reads Pillow's palette TIFF as OpenImageIO does", err)

# maketx's lat-long environment maps (TIFF and OpenEXR): built by mip as
# lat-long maps (the output keeps the kind), described by info.
src = f"{work}/latlong.exr"
run(f"{venv_bin}/oiiotool", "--pattern", "checker:width=8:height=8", "64x32", "3",
    "-d", "float", "-o", src)
for ext in ["tx", "exr"]:
    env = f"{work}/env.{ext}"
    r = run(f"{venv_bin}/maketx", "--envlatl", src, "-o", env)
    if r.returncode != 0:
        check(False, f"maketx --envlatl writes a .{ext}")
        continue
    out = f"{work}/env_out_{ext}.exr"
    r = run(parvo, "mip", env, "-o", out)
    r2 = run(parvo, "info", "--json", out) if r.returncode == 0 else r
    built = json.loads(r2.stdout) if r2.returncode == 0 else {}
    check(built.get("kind") == "latlong",
          f"parvo mip builds maketx's lat-long .{ext} as a lat-long map",
          (r.stderr + r2.stderr).strip())
    r = run(parvo, "info", "--json", env)
    info = json.loads(r.stdout) if r.returncode == 0 else {}
    check(any("lat-long environment map" in n for n in info.get("notes", [])),
          f"parvo info describes maketx's lat-long .{ext}")

finish()
