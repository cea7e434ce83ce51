#!/usr/bin/env python3
"""Roughness chains (issue 14) and the trade-off report's images (issue 13)
as other readers see them:

1. `parvo mip --normal-map --roughness 0.3` of a bumpy RGB8 normal map,
   roughness written as EXR, as PNG levels and as DDS: OpenImageIO reads
   every level equal to the SPEC formula computed here in numpy (unit
   level-0 normals, 2^k x 2^k block means, r = |mean|, kappa = (3r - r^3) /
   (1 - r^2), alpha' = min(1, sqrt(alpha^2 + 2/kappa))), within the stored
   type's precision; the normal EXR's levels equal mean / r.
2. `parvo tradeoff` and `parvo render --shade` PNGs open in Pillow and
   OpenImageIO with the frame's size, and the report's reference image is
   the same picture in both readers.
"""
import json

import numpy as np
from PIL import Image

from common import args, check, finish, oiio_levels, run

parvo, venv_bin, work = args()
rng = np.random.default_rng(1402)
N, ALPHA = 64, 0.3

# A bumpy height field's normals as RGB8 codes.
y, x = np.mgrid[0:N, 0:N].astype(np.float64)
h = np.zeros((N, N))
for _ in range(60):
    cx, cy = rng.uniform(0, N, 2)
    s = rng.uniform(1.0, 4.0)
    h += rng.choice([-1.0, 1.0]) * s * np.exp(-((x - cx) ** 2 + (y - cy) ** 2) / (2 * s * s))
gx, gy = np.gradient(h, axis=1), np.gradient(h, axis=0)
v = np.stack([-gx, -gy, np.ones_like(h)], -1)
v /= np.linalg.norm(v, axis=-1, keepdims=True)
codes = np.round((v + 1) / 2 * 255).astype(np.uint8)
src = f"{work}/normals.png"
Image.fromarray(codes, "RGB").save(src)

# The SPEC chain in numpy.
n0 = codes.astype(np.float64) / 255 * 2 - 1
n0 /= np.linalg.norm(n0, axis=-1, keepdims=True)
want_r, want_n = [], []
for k in range(int(np.log2(N)) + 1):
    b = 1 << k
    m = n0.reshape(N // b, b, N // b, b, 3).mean(axis=(1, 3))
    r = np.linalg.norm(m, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        kappa = (3 * r - r ** 3) / (1 - r * r)
        a = np.where(1 - r < 2.0 ** -20, ALPHA, np.minimum(1.0, np.sqrt(ALPHA ** 2 + 2 / kappa)))
    want_r.append(a)
    want_n.append(m / r[..., None])
check(float(want_r[3].max()) > ALPHA + 0.05, "the test map spreads its normals", f"max alpha' {want_r[3].max():.3f}")


def compare_levels(what, path, want, tol, channel=0):
    levels, err = oiio_levels(path, "float", unassociated=True)
    if not levels:
        return check(False, what, err)
    if len(levels) != len(want):
        return check(False, what, f"{len(levels)} levels, want {len(want)}")
    worst = 0.0
    for got, w in zip(levels, want):
        g = got[..., channel] if w.ndim == 2 else got[..., :3]
        if g.shape != w.shape:
            return check(False, what, f"shape {g.shape} vs {w.shape}")
        worst = max(worst, float(np.max(np.abs(g - w))))
    return check(worst <= tol, what, f"max |diff| {worst:.3g} over {len(levels)} levels, allowed {tol:.3g}")


r = run(parvo, "mip", src, "--normal-map", "--roughness", ALPHA, "-o", f"{work}/n.exr",
        "--roughness-out", f"{work}/r.exr")
if check(r.returncode == 0, "parvo mip --normal-map --roughness writes EXR"):
    compare_levels("roughness EXR (half) read by OpenImageIO equals the SPEC formula (numpy)",
                   f"{work}/r.exr", want_r, 1e-3)
    compare_levels("normal EXR (half) read by OpenImageIO equals mean / |mean| (numpy)",
                   f"{work}/n.exr", want_n, 2e-3)
r = run(parvo, "mip", src, "--normal-map", "--roughness", ALPHA, "-o", f"{work}/n_{{level}}.png",
        "--roughness-out", f"{work}/r_{{level}}.png")
if check(r.returncode == 0, "parvo mip --normal-map --roughness writes PNG levels"):
    worst = 0.0
    for k, w in enumerate(want_r):
        got, err = oiio_levels(f"{work}/r_{k}.png", "float", unassociated=True)
        worst = max(worst, float(np.max(np.abs(got[0][..., 0] - w)))) if got else 1.0
    check(worst <= 0.5 / 255 + 1e-6, "roughness PNG levels read by OpenImageIO equal the formula to the 8-bit code",
          f"max |diff| {worst:.3g}")
    img = Image.open(f"{work}/r_0.png")
    check(img.mode == "L" and img.size == (N, N), "Pillow reads the roughness PNG as one 8-bit channel",
          f"{img.mode} {img.size}")
r = run(parvo, "mip", src, "--normal-map", "--roughness", ALPHA, "-o", f"{work}/n.dds",
        "--roughness-out", f"{work}/r.dds")
if check(r.returncode == 0, "parvo mip --normal-map --roughness writes DDS"):
    compare_levels("roughness DDS (L8) read by OpenImageIO equals the formula to the 8-bit code",
                   f"{work}/r.dds", want_r, 0.5 / 255 + 1e-6)
    img = Image.open(f"{work}/r.dds")
    got = np.asarray(img.convert("L")).astype(np.float64) / 255
    check(float(np.max(np.abs(got - want_r[0]))) <= 0.5 / 255 + 1e-6,
          "Pillow reads the roughness DDS's level 0 as the base roughness", f"mode {img.mode}")

# --- 2. the report's images ---------------------------------------------------
out = f"{work}/tradeoff"
r = run(parvo, "tradeoff", "--size", "48x32", "--runs", "1", "--filters", "trilinear,ewa", "--out", out)
if check(r.returncode == 0, "parvo tradeoff writes its report"):
    report = json.load(open(f"{out}/report.json"))
    check([f["name"] for f in report["filters"]] == ["trilinear", "ewa"], "report.json names the filters run")
    for name in ["reference", "trilinear", "trilinear-error", "trilinear-levels", "ewa", "ewa-error"]:
        p = f"{out}/{name}.png"
        pil = Image.open(p)
        levels, err = oiio_levels(p, "float")
        ok = pil.size == (48, 32) and levels and levels[0].shape[:2] == (32, 48)
        if ok and name == "reference":
            same = np.max(np.abs(np.asarray(pil.convert("RGB")) / 255 - levels[0][..., :3]))
            ok = same < 1e-6
        check(bool(ok), f"{name}.png opens in Pillow and OpenImageIO as the same 48x32 image", err)
p = f"{work}/shaded.png"
r = run(parvo, "render", "--shade", "cook-torrance", "--texture", "builtin:bumps:64", "--size", "40x30", "-o", p)
if check(r.returncode == 0, "parvo render --shade writes a PNG"):
    check(Image.open(p).size == (40, 30), "Pillow reads the shaded render with the frame's size")

finish()
