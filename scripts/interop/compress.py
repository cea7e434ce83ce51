#!/usr/bin/env python3
"""Block-compression interop: the BC DDS files `parvo mip --compress`
writes (DX10 header) are opened by Pillow and OpenImageIO, which must find
the level count and decode level 0 to the texels parvo decodes, within the
rounding decoders are allowed to differ in (BC1/BC3 colour interpolation,
BC4/BC5 interpolation: at most a few codes; BC7: exactly). Then the KTX2
side: a zstd-supercompressed KTX2 written by parvo decodes (by parvo) to
the same texels as the plain one, and its level index is what the KTX 2.0
specification says (the Rust tests check every field; this checks the file
on disk from the command line).
"""
import json
import struct

import numpy as np
from PIL import Image

from common import args, check, finish, oiio_levels, run, skip, with_channels

parvo, venv_bin, work = args()

SRC = "builtin:photo:61"  # odd size: partial blocks at every level
# Per format: channels compared, and the largest code difference allowed
# between decoders (BC7's interpolation is exact in the specification).
# The input is opaque: BC7 is compared on RGB (the DDS is marked opaque,
# so parvo reads alpha 1 where ISPC's opaque modes store 254).
FORMATS = {"bc1": (3, 2), "bc3": (4, 2), "bc4": (1, 1), "bc5": (2, 1), "bc7": (3, 0)}
# What Pillow 13.0 does not read (measured): BC3's sRGB DXGI format.
# BC1 and BC3 are also written from the same codes read as linear
# (`--color linear`: the UNORM formats 71 and 77), which Pillow reads.
PILLOW_CANNOT = {
    "bc1": "Pillow 13.0 does not implement DXGI 72 (BC1_UNORM_SRGB)",
    "bc3": "Pillow 13.0 does not implement DXGI 78 (BC3_UNORM_SRGB)",
}


def parvo_level0(path):
    """parvo's decode of level 0 as codes, via a PNG written by parvo."""
    out = f"{path}.dec_{{level}}.png"
    r = run(parvo, "mip", path, "-o", out, "--levels", "1")
    assert r.returncode == 0, r.stderr
    with Image.open(out.replace("{level}", "0")) as im:
        return with_channels(np.array(im))


def levels_of(path):
    r = run(parvo, "info", "--json", path)
    assert r.returncode == 0, r.stderr
    return len(json.loads(r.stdout)["levels"])


def compare(what, ours, theirs, ch, tol):
    theirs = with_channels(theirs)
    if theirs.shape[:2] != ours.shape[:2]:
        return check(False, what, f"size {theirs.shape} vs {ours.shape}")
    c = min(ch, ours.shape[2], theirs.shape[2])
    d = np.abs(ours[:, :, :c].astype(int) - theirs[:, :, :c].astype(int)).max()
    return check(d <= tol, what, f"max difference {d} codes over {c} channels, allowed {tol}")


CASES = [(f, f, []) for f in FORMATS] + [
    (f"{f} linear", f, ["--color", "linear"]) for f in ("bc1", "bc3")
]
for name, fmt, extra in CASES:
    ch, tol = FORMATS[fmt]
    path = f"{work}/{name.replace(' ', '_')}.dds"
    r = run(parvo, "mip", SRC, "-o", path, "--compress", fmt, *extra)
    if not check(r.returncode == 0, f"parvo writes {name} DDS"):
        continue
    ours = parvo_level0(path)
    n = levels_of(path)
    try:
        with Image.open(path) as im:
            pil = np.array(im)
        compare(f"Pillow decodes parvo's {name} DDS level 0", ours, pil, ch, tol)
    except Exception as e:  # noqa: BLE001 - report any reader failure
        if name in PILLOW_CANNOT:
            skip(f"Pillow opens parvo's {name} DDS", f"{PILLOW_CANNOT[name]}: {e}")
        else:
            check(False, f"Pillow opens parvo's {name} DDS", str(e))
    levels, err = oiio_levels(path, fmt="uint8")
    if levels is None:
        check(False, f"OpenImageIO opens parvo's {name} DDS", err)
        continue
    check(len(levels) == n, f"OpenImageIO finds {name} DDS's {n} levels", f"found {len(levels)}")
    compare(f"OpenImageIO decodes parvo's {name} DDS level 0", ours, levels[0], ch, tol)

# BC6H: both readers open it; compared in float where one returns floats.
path = f"{work}/bc6h.dds"
hdr = f"{work}/photo.exr"
run(parvo, "mip", SRC, "-o", hdr)
r = run(parvo, "mip", hdr, "-o", path, "--compress", "bc6h")
if check(r.returncode == 0, "parvo writes bc6h DDS"):
    dec = f"{work}/bc6h_dec.exr"
    r = run(parvo, "mip", path, "-o", dec)
    ours, _ = oiio_levels(dec)
    levels, err = oiio_levels(path)
    if levels is None:
        skip("OpenImageIO reads parvo's bc6h DDS", err)
    else:
        a, b = with_channels(ours[0])[:, :, :3], with_channels(levels[0])[:, :, :3]
        d = float(np.abs(a - b).max()) if a.shape == b.shape else float("inf")
        check(d <= 1e-3, "OpenImageIO decodes parvo's bc6h DDS level 0", f"max difference {d:.2e}")

# KTX2 with zstd: same texels as the plain file, level index consistent.
plain, packed = f"{work}/p.ktx2", f"{work}/z.ktx2"
run(parvo, "mip", SRC, "-o", plain, "--compress", "bc7")
run(parvo, "mip", SRC, "-o", packed, "--compress", "bc7", "--zstd", "12")
check(
    np.array_equal(parvo_level0(plain), parvo_level0(packed)),
    "zstd-supercompressed BC7 KTX2 decodes to the plain file's texels",
)
with open(packed, "rb") as f:
    b = f.read()
vk, type_size, w, h, _, _, _, n, scheme = struct.unpack_from("<9I", b, 12)
check((vk, type_size, scheme) == (146, 1, 2), "KTX2 header: BC7_SRGB_BLOCK, typeSize 1, zstd", f"{vk} {type_size} {scheme}")
ok = True
for k in range(n):
    off, length, ulen = struct.unpack_from("<3Q", b, 80 + 24 * k)
    lw, lh = max(w >> k, 1), max(h >> k, 1)
    ok &= ulen == ((lw + 3) // 4) * ((lh + 3) // 4) * 16 and off + length <= len(b)
    ok &= b[off : off + 4] == b"\x28\xb5\x2f\xfd"  # a zstd frame
check(ok, f"KTX2 level index: {n} zstd frames, uncompressed lengths of whole 16-byte blocks")
finish()
