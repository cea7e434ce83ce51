"""Shared helpers of the interop checks (scripts/interop/*.py): one line per
check ("ok: ..." / "FAIL: ..." / "skip: ..."), subprocess runs that print
what failed, and readers of every level through OpenImageIO and Pillow.

Every check script is called by .ci/interop.sh as
    SCRIPT PARVO_BIN VENV_BIN WORKDIR
with the venv's python, and exits 1 when any check failed.
"""
import subprocess
import sys

import numpy as np
import OpenImageIO as oiio

failures = 0


def args():
    """(parvo binary, venv bin dir, work dir) from the command line."""
    return sys.argv[1], sys.argv[2], sys.argv[3]


def check(ok, what, detail=""):
    global failures
    print(("ok:   " if ok else "FAIL: ") + what + (f" ({detail})" if detail else ""), flush=True)
    if not ok:
        failures += 1
    return ok


def skip(what, why):
    print(f"skip: {what} ({why})", flush=True)


def run(*cmd):
    r = subprocess.run([str(c) for c in cmd], capture_output=True, text=True)
    if r.returncode != 0:
        print(f"       command failed ({r.returncode}): {' '.join(map(str, cmd))}\n{r.stdout}{r.stderr}")
    return r


def finish():
    sys.exit(1 if failures else 0)


def oiio_write(path, pixels, typedesc, unassociated=True):
    """Write an H x W x C array with OpenImageIO (PNG, TIFF, EXR ...), the
    values stored as given: OpenImageIO would otherwise take the array as
    associated alpha and divide it out for formats with unassociated alpha
    (PNG)."""
    h, w, c = pixels.shape
    out = oiio.ImageOutput.create(path)
    assert out is not None, oiio.geterror()
    spec = oiio.ImageSpec(w, h, c, typedesc)
    if unassociated:
        spec.attribute("oiio:UnassociatedAlpha", 1)
    assert out.open(path, spec), out.geterror()
    assert out.write_image(pixels), out.geterror()
    out.close()


def oiio_levels(path, fmt="float", unassociated=False):
    """Every MIP level of subimage 0 as OpenImageIO reads it, or None with
    OpenImageIO's error when it cannot open the file. OpenImageIO
    associates (premultiplies) the alpha of PNG and TIFF files on read;
    `unassociated` asks for the stored values instead."""
    config = oiio.ImageSpec()
    if unassociated:
        config.attribute("oiio:UnassociatedAlpha", 1)
    inp = oiio.ImageInput.open(path, config)
    if inp is None:
        return None, oiio.geterror()
    res = []
    level = 0
    while inp.seek_subimage(0, level):
        nch = inp.spec().nchannels
        res.append(np.asarray(inp.read_image(0, level, 0, nch, fmt)))
        level += 1
    inp.close()
    return res, ""


def with_channels(a):
    """An image array as H x W x C (grey images come back as H x W)."""
    a = np.asarray(a)
    return a[:, :, None] if a.ndim == 2 else a
