#!/usr/bin/env python3
"""Largest difference between two runs' mip outputs, level by level.

    scripts/compare-levels.py A_WORKDIR B_WORKDIR [FILE...]

A_WORKDIR and B_WORKDIR are two `scripts/output-hashes.sh` work
directories (e.g. main's binary and a branch's); FILE names files inside
them (`o7/a.ktx2`; default: every file whose bytes differ). Prints, per
file and level, the largest difference of the stored values: codes for
integer data, absolute value for floats.

Reads KTX2 without supercompression (the level index of the KTX2 header)
and EXR and PNG through OpenImageIO (set PARVO_INTEROP_VENV's python, see
scripts/setup-interop.sh, to run this); zstd-supercompressed KTX2 levels
are compared as bytes only.
"""
import os
import struct
import sys


def ktx2_levels(path):
    data = open(path, "rb").read()
    vk_format, type_size = struct.unpack_from("<II", data, 12)
    levels, scheme = struct.unpack_from("<II", data, 40)[0], struct.unpack_from("<I", data, 44)[0]
    count = max(levels, 1)
    out = []
    for k in range(count):
        off, length, _ = struct.unpack_from("<QQQ", data, 80 + 24 * k)
        raw = data[off : off + length]
        if scheme != 0:
            out.append(("bytes", raw))
        elif type_size == 2:
            out.append(("int", struct.unpack("<%dH" % (len(raw) // 2), raw)))
        elif type_size == 4 and vk_format in (100, 109, 103, 106):  # *_SFLOAT
            out.append(("float", struct.unpack("<%df" % (len(raw) // 4), raw)))
        else:
            out.append(("int", raw))
    return out


def oiio_levels(path):
    import OpenImageIO as oiio
    import numpy as np

    inp = oiio.ImageInput.open(path)
    out = []
    level = 0
    while inp.seek_subimage(0, level):
        spec = inp.spec()
        is_float = spec.format.basetype in (oiio.HALF, oiio.FLOAT, oiio.DOUBLE)
        px = inp.read_image(spec.format)
        out.append(("float" if is_float else "int", np.asarray(px, dtype=np.float64).ravel()))
        level += 1
    inp.close()
    return out


def levels(path):
    if path.endswith(".ktx2"):
        return ktx2_levels(path)
    return oiio_levels(path)


def differing(a, b):
    for root, _, files in os.walk(a):
        for f in sorted(files):
            rel = os.path.relpath(os.path.join(root, f), a)
            pb = os.path.join(b, rel)
            if os.path.exists(pb) and open(os.path.join(a, rel), "rb").read() != open(pb, "rb").read():
                yield rel


def main():
    a, b = sys.argv[1], sys.argv[2]
    files = sys.argv[3:] or sorted(differing(a, b))
    for rel in files:
        la, lb = levels(os.path.join(a, rel)), levels(os.path.join(b, rel))
        parts = []
        for k, ((ka, va), (_, vb)) in enumerate(zip(la, lb)):
            if ka == "bytes":
                parts.append("L%d %s" % (k, "same" if va == vb else "differs (zstd)"))
                continue
            d = max((abs(float(x) - float(y)) for x, y in zip(va, vb)), default=0.0)
            parts.append("L%d %g" % (k, d))
        print("%s: %s" % (rel, ", ".join(parts)))


if __name__ == "__main__":
    main()
