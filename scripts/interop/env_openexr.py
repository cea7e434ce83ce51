#!/usr/bin/env python3
"""OpenEXR's own environment maps read as OpenEXR defines them (issue 52).

Lat-long: `parvo sample FILE --direction` with bilinear level-0 lookups
against a numpy implementation of ImfEnvmap.cpp's LatLongMap (latLong of a
direction, pixelPosition on the data window: row 0 on the +y pole, the
last row on -y, columns 0 and w-1 on the same meridian) read bilinearly
with clamped indices as exrenvmap's EnvmapImage::sample reads it, and
against OpenImageIO's environment() on the same file (which reads OpenEXR
environments with `oiio:sampleborder` 1).

Cube strips: `parvo sample FILE --direction` against ImfEnvmap.cpp's
CubeMap (faceAndPixelPosition, pixelPosition: OpenEXR's own face axes,
texel centres on the cube's edges) read bilinearly within the face.

Through `parvo mip`: OpenImageIO's environment() on parvo's .exr of an
OpenEXR lat-long file equals environment() on the file (level 0 is written
back as read), and a KTX2 cube made from an OpenEXR strip (GL's faces,
texels resampled to centred ones) looked up with `parvo sample` is printed
against ImfEnvmap's lookup on the strip (a resampled map cannot equal it
exactly; tests/files/env_openexr_conventions.rs checks the placement
against an analytic environment).

The bar: the 99th percentile of the relative difference within 2e-3. The
same lookups placed as maketx's .tx places texels (centres at (i + 1/2)/w),
what parvo read before, are printed beside it to show the check can tell
the two apart.
"""
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import OpenImageIO as oiio

sys.dont_write_bytecode = True
sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import args, check, finish  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
FILES = ["WavyLinesLatLong.exr"]
CUBES = ["WavyLinesCube.exr", "KernerEnvCube.exr"]
N = 3000
BAR = 2e-3


def imf_lat_long(d):
    """LatLongMap::latLong(dir): (latitude, longitude)."""
    x, y, z = d[:, 0], d[:, 1], d[:, 2]
    r = np.sqrt(z * z + x * x)
    length = np.sqrt(x * x + y * y + z * z)
    lat = np.where(r < np.abs(y),
                   np.arccos(np.clip(r / length, -1, 1)) * np.sign(y),
                   np.arcsin(np.clip(y / length, -1, 1)))
    lon = np.where((z == 0) & (x == 0), 0.0, np.arctan2(x, z))
    return lat, lon


def imf_pixel_position(d, w, h):
    """LatLongMap::pixelPosition(dataWindow, latLong(dir)), window at (0, 0)."""
    lat, lon = imf_lat_long(d)
    return (lon / (-2 * math.pi) + 0.5) * (w - 1), (lat / -math.pi + 0.5) * (h - 1)


def bilinear(img, px, py):
    """EnvmapImage::sample: floor, weights, indices clamped to the image."""
    h, w = img.shape[:2]
    x1, y1 = np.floor(px), np.floor(py)
    tx, ty = (px - x1)[:, None], (py - y1)[:, None]
    X1 = np.clip(x1, 0, w - 1).astype(np.int64)
    X2 = np.clip(x1 + 1, 0, w - 1).astype(np.int64)
    Y1 = np.clip(y1, 0, h - 1).astype(np.int64)
    Y2 = np.clip(y1 + 1, 0, h - 1).astype(np.int64)
    return ((img[Y1, X1] * (1 - tx) + img[Y1, X2] * tx) * (1 - ty)
            + (img[Y2, X1] * (1 - tx) + img[Y2, X2] * tx) * ty)


def imf_cube_pixel(d, sof):
    """CubeMap::faceAndPixelPosition then pixelPosition: face, (x, y) in the strip."""
    a = np.abs(d)
    S = sof - 1
    xm = (a[:, 0] >= a[:, 1]) & (a[:, 0] >= a[:, 2])
    ym = ~xm & (a[:, 1] >= a[:, 2])
    major = np.where(xm, a[:, 0], np.where(ym, a[:, 1], a[:, 2]))
    u = np.where(xm, d[:, 1], d[:, 0]) / major
    v = np.where(xm | ym, d[:, 2], d[:, 1]) / major
    pu, pv = (u + 1) / 2 * S, (v + 1) / 2 * S
    face = np.where(xm, np.where(d[:, 0] > 0, 0, 1),
                    np.where(ym, np.where(d[:, 1] > 0, 2, 3), np.where(d[:, 2] > 0, 4, 5)))
    y0 = face * sof
    x = np.select([face == 0, face == 1, face == 4], [pv, S - pv, S - pu], pu)
    y = np.select([face == 0, face == 1, face == 2, face == 3], [y0 + S - pu, y0 + S - pu, y0 + S - pv, y0 + pv],
                  y0 + S - pv)
    return face, x, y


def bilinear_face(img, face, px, py):
    """Bilinear with indices clamped to the face's rows."""
    sof = img.shape[1]
    x1, y1 = np.floor(px), np.floor(py)
    tx, ty = (px - x1)[:, None], (py - y1)[:, None]
    lo, hi = face * sof, face * sof + sof - 1
    X1 = np.clip(x1, 0, sof - 1).astype(np.int64)
    X2 = np.clip(x1 + 1, 0, sof - 1).astype(np.int64)
    Y1 = np.clip(y1, lo, hi).astype(np.int64)
    Y2 = np.clip(y1 + 1, lo, hi).astype(np.int64)
    return ((img[Y1, X1] * (1 - tx) + img[Y1, X2] * tx) * (1 - ty)
            + (img[Y2, X1] * (1 - tx) + img[Y2, X2] * tx) * ty)


def read_level0(path):
    inp = oiio.ImageInput.open(str(path))
    spec = inp.spec()
    px = inp.read_image(0, 0, 0, 3, "float")
    inp.close()
    return np.asarray(px, dtype=np.float64).reshape(spec.height, spec.width, 3)


def directions(rng, n):
    z = rng.uniform(-1, 1, n)
    phi = rng.uniform(0, 2 * math.pi, n)
    r = np.sqrt(1 - z * z)
    d = np.stack([r * np.cos(phi), z, r * np.sin(phi)], axis=1)
    # The poles and the seam meridian (-z), where the conventions part most.
    extra = np.array([[0, 1, 0], [0, -1, 0], [0, 0, -1], [0.3, 0.2, -1], [-0.3, 0.2, -1],
                      [1e-4, 0.5, -1], [-1e-4, 0.5, -1]], dtype=np.float64)
    return np.concatenate([d, extra])


def parvo_lookup(parvo, path, d):
    cmd = [parvo, "sample", str(path), "--color", "linear", "--direction",
           "--filter", "bilinear", "--mip", "none"]
    queries = np.concatenate([d, np.zeros((len(d), 6))], axis=1)
    text = "\n".join(" ".join("%.9g" % x for x in row) for row in queries) + "\n"
    r = subprocess.run(cmd, input=text, capture_output=True, text=True)
    if r.returncode != 0:
        return None, f"exit {r.returncode}: {r.stderr.strip()[:300]}"
    return np.loadtxt(r.stdout.splitlines(), dtype=np.float64, ndmin=2)[:, :3], ""


def oiio_lookup(path, d):
    ts = oiio.TextureSystem()
    opt = oiio.TextureOpt()
    opt.interpmode = oiio.InterpMode.Bilinear
    opt.mipmode = oiio.MipMode.NoMIP
    out = np.zeros((len(d), 3))
    for i, v in enumerate(d):
        out[i] = ts.environment(str(path), opt, tuple(v), (0, 0, 0), (0, 0, 0), 3)
    return out


def rel(a, b):
    return np.abs(a - b).max(axis=1) / np.maximum(np.abs(b).max(axis=1), 1.0)


def main():
    parvo, _venv, work = args()
    rng = np.random.default_rng(52)
    for name in FILES:
        path = ROOT / "tests/data/peer/openexr-images" / name
        img = read_level0(path)
        h, w = img.shape[:2]
        d = directions(rng, N)
        want = bilinear(img, *imf_pixel_position(d, w, h))
        got, why = parvo_lookup(parvo, path, d)
        if not check(got is not None, f"{name}: parvo sample --direction", why):
            continue
        e = rel(got, want)
        # maketx's placement (texel centres at (i + 1/2)/w, s wrapping):
        # what parvo read before, for scale.
        lat, lon = imf_lat_long(d)
        cx = np.mod((lon / (-2 * math.pi) + 0.5) * w - 0.5, w)
        cy = (lat / -math.pi + 0.5) * h - 0.5
        centred = rel(bilinear(img, cx, cy), want)
        check(np.percentile(e, 99) <= BAR,
              f"{name}: bilinear lookups equal ImfEnvmap's at the 99th percentile",
              f"p99 {np.percentile(e, 99):.2e}, max {e.max():.2e} over {len(d)} directions; "
              f"maketx's centred placement: p99 {np.percentile(centred, 99):.2e}")
        ref = oiio_lookup(path, d)
        eo = rel(got, ref)
        check(np.percentile(eo, 99) <= BAR,
              f"{name}: and OpenImageIO's environment() on the file",
              f"p99 {np.percentile(eo, 99):.2e}, max {eo.max():.2e}")
        out = Path(work) / f"{name}.parvo.exr"
        r = subprocess.run([parvo, "mip", str(path), "-o", str(out)], capture_output=True, text=True)
        if check(r.returncode == 0, f"{name}: parvo mip to .exr", r.stderr.strip()[:300]):
            er = rel(oiio_lookup(out, d), ref)
            check(er.max() <= 1e-6,
                  f"{name}: OpenImageIO's environment() on parvo's .exr equals it on the file",
                  f"max {er.max():.2e} over {len(d)} directions")
    for name in CUBES:
        path = ROOT / "tests/data/peer/openexr-images" / name
        img = read_level0(path)
        d = directions(rng, N)
        want = bilinear_face(img, *imf_cube_pixel(d, img.shape[1]))
        got, why = parvo_lookup(parvo, path, d)
        if not check(got is not None, f"{name}: parvo sample --direction", why):
            continue
        e = rel(got, want)
        check(np.percentile(e, 99) <= BAR,
              f"{name}: bilinear lookups equal ImfEnvmap's cube lookup at the 99th percentile",
              f"p99 {np.percentile(e, 99):.2e}, max {e.max():.2e} over {len(d)} directions")
        out = Path(work) / f"{name}.ktx2"
        r = subprocess.run([parvo, "mip", str(path), "--type", "f32", "-o", str(out)],
                           capture_output=True, text=True)
        if check(r.returncode == 0, f"{name}: parvo mip to a KTX2 cube", r.stderr.strip()[:300]):
            got, why = parvo_lookup(parvo, out, d)
            if check(got is not None, f"{name}: parvo sample on the KTX2 cube", why):
                e = rel(got, want)
                print(f"       (the KTX2 cube against ImfEnvmap on the strip: median {np.median(e):.2e}, "
                      f"p90 {np.percentile(e, 90):.2e}, p99 {np.percentile(e, 99):.2e})")
    finish()


if __name__ == "__main__":
    main()
