#!/usr/bin/env python3
"""DDS interop: every uncompressed format and channel count `parvo mip`
writes to DDS, read back by Pillow and by OpenImageIO, must equal parvo's
own PNG levels of the same input (level 0 for Pillow, every level for
OpenImageIO, which exposes them), after the reader's own conversion (both
readers return 8 bits per channel: OpenImageIO takes the top byte of a
16-bit value, Pillow floor(v / 65535 * 255)). Formats a reader does not
read are listed as `skip` with its error; a reader failing on a format it
is listed as reading is a failure (the table is the README's "which reader
reads what"). Then the other direction: DDS files Pillow writes (L, LA,
RGB, RGBA, DXT1, DXT3, DXT5, BC5) are read by `parvo info` and decoded by
`parvo mip` to the texels Pillow itself decodes, and so is Pillow's own
test file `bc1.dds` (DX10 resource dimension 0), also as BC1_TYPELESS.
"""
import json
import os

import numpy as np
from PIL import Image

from common import args, check, finish, oiio_levels, oiio_write, run, skip, with_channels

parvo, venv_bin, work = args()

W, H = 37, 20  # odd sizes: the level chain has odd and 1-texel levels
rng = np.random.default_rng(20261201)

# The stored format parvo writes (`dds:format` in `parvo info`) and whether
# each reader reads it; measured with Pillow 13.0 and OpenImageIO 3.2.
READS = {
    "legacy LUMINANCE 8-bit": ("pillow", "oiio"),  # L8
    "legacy LUMINANCE|ALPHAPIXELS 16-bit": ("pillow", "oiio"),  # A8L8
    "legacy RGB 32-bit, masks 0xff 0xff00 0xff0000 0x0": ("pillow", "oiio"),  # X8B8G8R8
    "legacy RGB|ALPHAPIXELS 32-bit": ("pillow", "oiio"),  # A8B8G8R8
    "DX10 R8G8B8A8_UNORM_SRGB": ("pillow", "oiio"),
    "DX10 R8G8B8A8_UNORM": ("pillow", "oiio"),
    "legacy LUMINANCE 16-bit": ("oiio",),  # L16
    "legacy RGB 32-bit, masks 0xffff 0xffff0000": ("pillow", "oiio"),  # G16R16
}


def readers_of(desc):
    for k, v in READS.items():
        if desc.startswith(k):
            return v
    return ()


def stored_format(path):
    r = run(parvo, "info", "--json", path)
    if r.returncode != 0:
        return None
    return json.loads(r.stdout)["attributes"].get("dds:format", "?")


def png_levels(template, n):
    """parvo's PNG levels as raw codes (H x W x C, uint8 or uint16)."""
    out = []
    for k in range(n):
        levels, err = oiio_levels(template.replace("{level}", str(k)), fmt="", unassociated=True)
        assert levels, err
        out.append(with_channels(levels[0]))
    return out


def as_stored(ref, desc, srgb_widened):
    """The reference PNG level arranged as the DDS stores it: sRGB grey,
    grey + alpha and RGB are widened to RGBA; G16R16 reads as RGB with B = 0."""
    h, w, c = ref.shape
    one = np.iinfo(ref.dtype).max
    if srgb_widened and c < 4:
        if c == 1:
            return np.concatenate([ref, ref, ref, np.full((h, w, 1), one, ref.dtype)], axis=2)
        if c == 2:
            return np.concatenate([ref[:, :, :1]] * 3 + [ref[:, :, 1:]], axis=2)
        return np.concatenate([ref, np.full((h, w, 1), one, ref.dtype)], axis=2)
    if "0xffff 0xffff0000" in desc and c == 2:
        return np.concatenate([ref, np.zeros((h, w, 1), ref.dtype)], axis=2)
    return ref


def to_8bit(a, reader):
    if a.dtype == np.uint8:
        return a
    if reader == "oiio":
        return (a >> 8).astype(np.uint8)
    return np.floor(a.astype(np.float64) / 65535 * 255).astype(np.uint8)


def read(reader, path):
    """Levels as the reader returns them (uint8 arrays) or (None, error)."""
    if reader == "pillow":
        try:
            with Image.open(path) as im:
                return [with_channels(np.asarray(im))], ""
        except Exception as e:  # noqa: BLE001 - any refusal is a "does not read"
            return None, f"{type(e).__name__}: {e}"
    levels, err = oiio_levels(path, fmt="uint8")
    return levels, err


def source(bits, ch, name, premultiplied):
    dt = np.uint8 if bits == 8 else np.uint16
    px = rng.integers(0, 1 << bits, (H, W, ch)).astype(dt)
    if premultiplied:
        # Valid associated alpha: no colour above its alpha.
        top = (1 << bits) - 1
        px[:, :, :-1] = (px[:, :, :-1].astype(np.uint64) * px[:, :, -1:] // top).astype(dt)
    path = f"{work}/{name}.png"
    oiio_write(path, px, "uint8" if bits == 8 else "uint16")
    return path, px


# (bits of the input PNG, channels, options, what the options exercise)
CASES = []
for bits in (8, 16):
    for ch in (1, 2, 3, 4):
        CASES.append((bits, ch, ["--color", "linear"], "linear"))
        if bits == 8:
            CASES.append((bits, ch, ["--color", "srgb"], "sRGB"))
        if ch in (2, 4):
            CASES.append((bits, ch, ["--color", "linear", "--alpha", "none"], "data channels"))
            CASES.append((bits, ch, ["--color", "linear", "--alpha", "premultiplied"], "premultiplied"))
    for ty in ("f16", "f32"):
        for ch in (1, 2, 3, 4):
            CASES.append((bits, ch, ["--color", "linear", "--type", ty], ty))

n_levels = len(bin(max(W, H))) - 2  # floor(log2(37)) + 1 = 6
supported = {"pillow": set(), "oiio": set()}
for i, (bits, ch, opts, what) in enumerate(CASES):
    name = f"c{i}_{bits}bit_{ch}ch"
    src, px = source(bits, ch, name, "premultiplied" in opts)
    dds = f"{work}/{name}.dds"
    label = f"{bits}-bit {ch}-channel PNG, {what}"
    if not check(run(parvo, "mip", src, "-o", dds, *opts).returncode == 0, f"parvo mip {label} -> .dds"):
        continue
    desc = stored_format(dds)
    float_out = "--type" in opts
    if float_out:
        for reader in ("pillow", "oiio"):
            levels, err = read(reader, dds)
            if levels is None:
                skip(f"{reader} reads {desc}", err.strip().splitlines()[0] if err else "refused")
            else:
                check(False, f"{reader} now reads {desc}: add float comparisons and update the README")
        continue
    template = f"{work}/{name}_ref_{{level}}.png"
    if not check(run(parvo, "mip", src, "-o", template, *opts).returncode == 0, f"parvo mip {label} -> PNG levels"):
        continue
    refs = png_levels(template, n_levels)
    srgb_widened = "_SRGB" in desc
    premultiplied = "premultiplied" in opts
    for reader in ("pillow", "oiio"):
        levels, err = read(reader, dds)
        expected_to_read = reader in readers_of(desc)
        if levels is None:
            if expected_to_read:
                check(False, f"{reader} reads {desc} ({label})", err)
            else:
                skip(f"{reader} reads {desc}", err.strip().splitlines()[0] if err else "refused")
            continue
        if not expected_to_read:
            check(False, f"{reader} now reads {desc}: list it in READS and the README")
            continue
        supported[reader].add(desc)
        if reader == "oiio":
            check(len(levels) == n_levels, f"oiio sees every level of {desc} ({label})",
                  f"{len(levels)} of {n_levels}")
        worst = 0
        for k, got in enumerate(levels[:n_levels]):
            want = to_8bit(as_stored(refs[k], desc, srgb_widened), reader)
            if k == 0 and premultiplied:
                # Level 0 is the input as stored; PNG is straight by
                # definition, so the premultiplied DDS is compared with
                # the input codes.
                want = to_8bit(px, reader)
            if got.shape != want.shape:
                check(False, f"{reader} level {k} of {desc} ({label}) has the reference's shape",
                      f"{got.shape} vs {want.shape}")
                worst = None
                break
            d = int(np.max(np.abs(got.astype(np.int32) - want.astype(np.int32))))
            if premultiplied and k > 0:
                # PNG levels are straight; premultiplying them back rounds
                # once more (at most one code).
                a = refs[k][:, :, -1:].astype(np.float64) / np.iinfo(refs[k].dtype).max
                sc = np.iinfo(refs[k].dtype).max
                pm = refs[k].astype(np.float64).copy()
                pm[:, :, :-1] = np.round(pm[:, :, :-1] * a)
                want = to_8bit(np.clip(np.round(pm), 0, sc).astype(refs[k].dtype), reader)
                d = int(np.max(np.abs(got.astype(np.int32) - want.astype(np.int32))))
                d = 0 if d <= 1 else d
            worst = max(worst, d)
        if worst is not None:
            lv = "level 0" if reader == "pillow" else f"all {len(levels)} levels"
            check(worst == 0, f"{reader} reads {desc} ({label}): {lv} equal parvo's PNG levels",
                  f"max |diff| {worst} codes")

# Which reader read what (for the README table).
for reader, descs in supported.items():
    print(f"       {reader} read: " + "; ".join(sorted(descs)))

# Pillow-written DDS files, read by parvo.
base = np.zeros((H, W, 4), np.uint8)
yy, xx = np.mgrid[0:H, 0:W]
base[..., 0] = (xx * 255 // (W - 1)).astype(np.uint8)
base[..., 1] = (yy * 255 // (H - 1)).astype(np.uint8)
base[..., 2] = rng.integers(0, 256, (H, W))
base[..., 3] = ((xx + yy) % 7 * 40).astype(np.uint8)
PILLOW = [
    ("L", None), ("LA", None), ("RGB", None), ("RGBA", None),
    ("RGB", "DXT1"), ("RGBA", "DXT1"), ("RGBA", "DXT3"), ("RGBA", "DXT5"), ("RGB", "BC5"),
]
for mode, pixel_format in PILLOW:
    name = f"pillow_{mode}_{pixel_format or 'raw'}"
    path = f"{work}/{name}.dds"
    img = Image.fromarray(base, "RGBA").convert(mode)
    kw = {"pixel_format": pixel_format} if pixel_format else {}
    img.save(path, **kw)
    label = f"Pillow's {mode} DDS" + (f" ({pixel_format})" if pixel_format else "")
    with Image.open(path) as im:
        theirs = with_channels(np.asarray(im))
    r = run(parvo, "info", "--json", path)
    if not check(r.returncode == 0, f"parvo info reads {label}"):
        continue
    j = json.loads(r.stdout)
    check((j["width"], j["height"]) == (W, H), f"parvo info: {label} is {W}x{H}",
          f"{j['width']}x{j['height']}, {j['channels']} channels, {j['attributes'].get('dds:format')}")
    dump = f"{work}/{name}_{{level}}.png"
    if not check(run(parvo, "mip", path, "-o", dump, "--levels", "1").returncode == 0,
                 f"parvo mip decodes {label}"):
        continue
    ours = with_channels(oiio_levels(dump.replace("{level}", "0"), fmt="", unassociated=True)[0][0])
    if pixel_format == "BC5":
        # BC5 holds R, G; Pillow returns RGB with B = 0, parvo writes R, G
        # data as RGB with B = 0 to PNG (PNG has no two-channel colour).
        theirs = theirs[:, :, :3]
    if ours.shape != theirs.shape:
        check(False, f"parvo decodes {label} to Pillow's channels", f"{ours.shape} vs {theirs.shape}")
        continue
    d = int(np.max(np.abs(ours.astype(np.int32) - theirs.astype(np.int32))))
    # Block decoders may round the interpolated BC1 colours differently
    # (bcdec and Pillow): one code is allowed there, none elsewhere.
    tol = 1 if pixel_format else 0
    check(d <= tol, f"parvo decodes {label} to the texels Pillow decodes", f"max |diff| {d} codes, allowed {tol}")

# Pillow's own test file `bc1.dds` (tests/data/peer/pillow_bc1.dds): a DX10
# header whose resource dimension and array size are 0, and the same file
# with DXGI format 70 (BC1_TYPELESS), as Pillow's `bc1_typeless.dds` is.
# Pillow reads both; parvo must read both to Pillow's texels (BC1 rounding:
# one code).
root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
with open(os.path.join(root, "tests", "data", "peer", "pillow_bc1.dds"), "rb") as f:
    bc1 = f.read()
for name, data in (("bc1", bc1), ("bc1_typeless", bc1[:128] + (70).to_bytes(4, "little") + bc1[132:])):
    path = f"{work}/peer_{name}.dds"
    with open(path, "wb") as f:
        f.write(data)
    with Image.open(path) as im:
        theirs = np.asarray(im.convert("RGBA"))
    dump = f"{work}/peer_{name}_{{level}}.png"
    if not check(run(parvo, "mip", path, "-o", dump, "--levels", "1").returncode == 0,
                 f"parvo reads Pillow's {name}.dds (resource dimension 0)"):
        continue
    ours = with_channels(oiio_levels(dump.replace("{level}", "0"), fmt="", unassociated=True)[0][0])
    d = int(np.max(np.abs(ours.astype(np.int32) - theirs.astype(np.int32))))
    check(d <= 1, f"parvo decodes Pillow's {name}.dds to the texels Pillow decodes", f"max |diff| {d} codes")

finish()
