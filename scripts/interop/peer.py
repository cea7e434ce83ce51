#!/usr/bin/env python3
"""Other projects' test files, as a new user would try them (issue 27):
every file in tests/data/peer/ (Pillow, image-tiff, image-png, image-rs,
KTX-Software-CTS, openexr-images; tests/data/peer/README.md names each
file's repository, path, commit and licence) goes through `parvo info` and
`parvo mip`, and tests/data/peer/manifest.json says what must happen:

- `read`: both commands succeed, and level 0 of the chain parvo writes to a
  lossless container equals what another decoder makes of the same file:
  OpenImageIO or Pillow, or, for KTX2 (which neither reads), the output of
  `ktx extract` that KTX-Software-CTS keeps as its golden file. The
  comparison is in parvo's own terms: it keeps data and does not convert
  unless asked (README "What parvo reads from a file"), so integer inputs
  are compared as stored codes through parvo's PNG levels (`out: png`:
  straight alpha, the file's transfer kept), float inputs and
  associated-alpha TIFFs through its f32 EXR (`out: exr`: linear,
  premultiplied; a KTX2 integer format's golden EXR, which holds the
  numbers, is turned into the codes parvo keeps: `ref_transform`
  uint_codes / sint_codes); `tol` is the largest difference allowed in those units
  (0..1 for codes) and `why` in the manifest says where it comes from.
- `refuse`: both commands exit with status 1 and one message in plain words
  that matches `refuse` (a regular expression naming the format or
  feature): no panic, no "internal error", no Rust Debug output (`{ .. }`
  structures, `Unknown(34925)`, `ChunkType`), no doubled "error:"
  prefixes, and nothing left behind in the output directory.

Every run has a time limit (PEER_TIMEOUT seconds, 60 by default), so a
hang fails the check instead of blocking CI. Nothing is fetched: the files
are in the repository. PEER_MANIFEST and PEER_DATA point the script at
another manifest and data directory (used to survey a larger corpus).

Called by .ci/interop.sh as peer.py PARVO_BIN VENV_BIN WORKDIR.
"""
import json
import os
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import OpenImageIO as oiio
from PIL import Image, ImageOps

from common import args, check, finish, skip, with_channels

parvo, venv_bin, work = args()
ROOT = Path(__file__).resolve().parents[2]
DATA = Path(os.environ.get("PEER_DATA", ROOT / "tests" / "data" / "peer"))
MANIFEST = Path(os.environ.get("PEER_MANIFEST", DATA / "manifest.json"))
TIMEOUT = float(os.environ.get("PEER_TIMEOUT", "60"))

# What a message in plain words never contains, with what it shows.
UNCLEAN = [
    (re.compile(r"panicked|RUST_BACKTRACE|stack backtrace", re.I), "a panic"),
    (re.compile(r"internal error", re.I), "an internal error"),
    (re.compile(r"[{}]"), "a Rust Debug structure ({ .. })"),
    (re.compile(r"\b[A-Z][A-Za-z0-9_]*\([^)\s]*\)"), "a Rust Debug value"),
    (re.compile(r"\bChunkType\b|\bInsufficientInput\b|\bSome\(|\bNone\b"), "a Rust type or variant name"),
    (re.compile(r"\berror:|error decoding", re.I), "a decoder's own \"error:\" prefix inside parvo's message"),
    (re.compile(r"os error \d+"), "a raw operating-system error for a malformed file"),
]


def run(what, *cmd):
    """(returncode, stdout, stderr); returncode None when it timed out."""
    try:
        r = subprocess.run([str(c) for c in cmd], capture_output=True, text=True, timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        return None, "", f"{what} still running after {TIMEOUT:.0f} s"
    return r.returncode, r.stdout, r.stderr


def lines(text):
    return [ln for ln in text.splitlines() if ln.strip()]


def unclean(text):
    """What in `text` a message in plain words never shows, with the words."""
    found = []
    for pattern, what in UNCLEAN:
        m = pattern.search(text)
        if m:
            found.append(f"{what}: `{m.group(0)}`")
    return found


def check_refusal(name, cmd, path, rc, out, err, pattern):
    """A refusal: exit 1, a last stderr line in plain words matching
    `pattern`, nothing unclean anywhere in stderr (the file's own name, which
    parvo puts first, is not part of what is judged)."""
    if rc is None:
        return check(False, f"{name}: {cmd} refuses it", err)
    err = err.replace(str(path), "FILE")
    msgs = lines(err)
    last = msgs[-1] if msgs else ""
    problems = []
    if rc != 1:
        problems.append(f"exit {rc}, expected 1")
    if not msgs:
        problems.append("no message on stderr")
    problems += [f"shows {u}" for u in unclean(err)]
    if msgs and not re.search(pattern, last):
        problems.append(f"message does not match /{pattern}/")
    detail = "; ".join(problems) + (": " if problems else "") + last.split(": ", 1)[-1][:240]
    return check(not problems, f"{name}: {cmd} refuses it in plain words", detail)


def check_clean_dir(name, d, keep=()):
    left = sorted(p.name for p in d.iterdir() if p.name not in keep)
    return check(not left, f"{name}: nothing else left in the output directory", ", ".join(left[:5]))


# --- references -------------------------------------------------------------


def oiio_read(path, subimage=0, unassociated=True, reorient=False, display_window=False):
    """Level 0 of a subimage as float H x W x C, or (None, error)."""
    config = oiio.ImageSpec()
    if unassociated:
        config.attribute("oiio:UnassociatedAlpha", 1)
    buf = oiio.ImageBuf(str(path), subimage, 0, config)
    if buf.has_error:
        return None, buf.geterror()
    if reorient:
        buf = oiio.ImageBufAlgo.reorient(buf)
    if display_window:
        buf = oiio.ImageBufAlgo.crop(buf, buf.roi_full)
    px = buf.get_pixels(oiio.FLOAT)
    if px is None or buf.has_error:
        return None, buf.geterror() or "no pixels"
    return with_channels(np.asarray(px, dtype=np.float64)), ""


def pillow_read(path, reorient=False):
    try:
        with Image.open(path) as im:
            im.load()
            if reorient:
                im = ImageOps.exif_transpose(im)
            if im.mode == "P":
                im = im.convert("RGBA" if "transparency" in im.info else "RGB")
            elif im.mode == "1":
                im = im.convert("L")
            a = np.asarray(im)
    except Exception as e:  # noqa: BLE001 - any failure is "Pillow cannot read it"
        return None, f"{type(e).__name__}: {e}"
    return normalise(with_channels(a)), ""


def normalise(a):
    if a.dtype == np.uint8:
        return a.astype(np.float64) / 255
    if a.dtype == np.uint16 or a.dtype.str.endswith("u2"):
        return a.astype(np.float64) / 65535
    return a.astype(np.float64)


def raw_read(path, raw):
    """A raw level as `ktx extract --raw` writes it: rows of texels of
    `channels` channels of `dtype`, top row first."""
    a = np.fromfile(path, dtype=np.dtype(raw["dtype"]))
    a = a[: raw["height"] * raw["width"] * raw["channels"]]
    a = a.reshape(raw["height"], raw["width"], raw["channels"])
    return normalise(a), ""


def reference(entry):
    ref = entry["ref"]
    f = DATA / entry["file"]
    a, err = reference_values(entry, ref, f)
    if a is not None and entry.get("fixnan"):
        # `--fixnan black`: parvo replaces NaN and Inf with 0 before anything else.
        a = np.where(np.isfinite(a), a, 0.0)
    if a is not None and entry.get("premultiply"):
        # A straight-alpha reference against parvo's EXR, which OpenEXR
        # defines as premultiplied; in f32, as parvo multiplies (products of
        # the CTS files' huge values overflow to Inf there).
        f = a.astype(np.float32)
        with np.errstate(over="ignore"):
            a = np.concatenate([f[:, :, :-1] * f[:, :, -1:], f[:, :, -1:]], axis=2).astype(np.float64)
    if a is not None and entry.get("ref_transform") == "invert":
        a = 1.0 - a
    if a is not None and entry.get("ref_transform") in ("uint_codes", "sint_codes"):
        a = integer_codes(a, entry["ref_transform"], int(entry["ref_bits"]))
    if a is not None and entry.get("ref_transform") == "snorm8_biased":
        # Pillow stores signed (SNORM) BC4/BC5 codes c in -127..127 as
        # c + 128; the value they stand for is max(c / 127, -1).
        a = np.maximum((np.rint(a * 255) - 128) / 127, -1.0)
    return a, err


def integer_codes(a, transform, bits):
    """`ktx extract`'s EXR of an integer format holds the numbers as floats;
    parvo keeps them as `bits`-bit codes n / (2^bits - 1), a signed format's
    offset by 2^(bits-1) (two's complement with the sign bit flipped).
    KTX-Software's convertSIntToFloat reads sign and magnitude (a stored
    0xFF is -127, not -1), so a negative reading -m is the stored code
    2^(bits-1) | m; a stored 2^(bits-1) reads as 0, like 0, so the
    manifest's signed files are ones without that code."""
    half = 2 ** (bits - 1)
    n = np.rint(a).astype(np.int64)
    if transform == "sint_codes":
        n = np.where(n < 0, half | -n, n) ^ half
    return n.astype(np.float64) / (2.0 ** bits - 1)


def reference_values(entry, ref, f):
    if ref == "oiio":
        return oiio_read(f, entry.get("subimage", 0), entry.get("out", "png") == "png",
                         entry.get("reorient", False), entry.get("display_window", False))
    if ref == "pillow":
        return pillow_read(f, entry.get("reorient", False))
    if ref == "golden":
        g = DATA / entry["golden"]
        if "raw" in entry:
            return raw_read(g, entry["raw"])
        return oiio_read(g, unassociated=True)
    raise ValueError(f"unknown reference {ref}")


# --- comparison ---------------------------------------------------------------


def align(ours, theirs, names, rg_data=False):
    """Match channel counts the ways that change no value: an opaque alpha
    (all 1) one side adds to grey or RGB, and `ktx extract`'s PNG of R data
    (red, G = B = 0). Anything else is a different reading: in particular
    a two-channel PNG is grey + alpha, so R,G data must come out as RGB
    with B = 0 (README). Returns (ours, theirs, note) or (None, None, why)."""
    co, ct = ours.shape[2], theirs.shape[2]
    if co == ct:
        return ours, theirs, ""
    if ct == co + 1 and co in (1, 3) and np.all(theirs[:, :, co:] == 1):
        return ours, theirs[:, :, :co], "the reference adds an opaque alpha"
    if co == ct + 1 and ct in (1, 3) and np.all(ours[:, :, ct:] == 1):
        return ours[:, :, :ct], theirs, "parvo adds an opaque alpha"
    if rg_data and co == 3 and ct == 2 and np.all(ours[:, :, 2] == 0):
        return ours[:, :, :2], theirs, "two data channels, which parvo's PNG stores as RGB with B = 0"
    if co == 1 and ct == 3 and np.all(theirs[:, :, 1:] == 0):
        return ours, theirs[:, :, :1], "the reference writes R data as red (G = B = 0)"
    if co == 2 and ct == 3 and np.all(theirs[:, :, 2] == 0) and tuple(names) == ("R", "G"):
        return ours, theirs[:, :, :2], "R,G data against the reference's RGB with B = 0"
    if co == 2 and ct == 3 and np.all(theirs[:, :, 2] == 0):
        return None, None, "R,G data written as a grey + alpha PNG (PNG's two channels), not as RGB with B = 0"
    return None, None, f"{co} channels against {ct}"


def compare(name, entry, ours, names, theirs):
    by = {"oiio": "OpenImageIO", "pillow": "Pillow"}.get(entry["ref"]) or f"the reference rendering {entry.get('golden')}"
    what = f"{name}: level 0 equals {by}"
    if ours.shape[:2] != theirs.shape[:2]:
        return check(False, what, f"parvo {ours.shape[1]}x{ours.shape[0]}, reference {theirs.shape[1]}x{theirs.shape[0]}")
    ours, theirs, note = align(ours, theirs, names, entry.get("rg_data", False))
    if ours is None:
        return check(False, what, note)
    tol = float(entry.get("tol", 0))
    rtol = float(entry.get("rtol", 0))
    nan_t = np.isnan(theirs)
    if not np.array_equal(nan_t, np.isnan(ours)):
        return check(False, what, "NaN in different texels")
    fin = ~nan_t
    a, b = ours[fin], theirs[fin]
    if entry.get("metric") == "rmse":
        d = float(np.sqrt(np.mean((a - b) ** 2)))
        ok = d <= tol
        detail = f"RMSE {d:.3g}, allowed {tol:.3g}; max |diff| {float(np.max(np.abs(a - b))):.3g}"
    else:
        inf_eq = np.isinf(a) | np.isinf(b)
        diff = np.where(inf_eq, np.where(a == b, 0.0, np.inf), np.abs(a - b))
        allowed = tol + rtol * np.where(inf_eq, 0.0, np.abs(b))
        ok = bool(np.all(diff <= allowed + 1e-7))
        d = float(np.max(diff)) if diff.size else 0.0
        over = int(np.sum(diff > allowed + 1e-7))
        detail = f"max |diff| {d:.3g}, allowed {tol:.3g}" + (f" + {rtol:.3g} relative" if rtol else "")
        if over:
            detail += f"; {over} of {diff.size} values over"
    if note:
        detail += f"; {note}"
    return check(ok, what, detail)


def parvo_level0(outdir, mode):
    """parvo's level 0 (float H x W x C) and its channel names."""
    path = outdir / ("l_0.png" if mode == "png" else "l.exr")
    a, err = oiio_read(path, unassociated=(mode == "png"))
    names = ()
    if a is not None:
        inp = oiio.ImageInput.open(str(path))
        names = inp.spec().channelnames
        inp.close()
    return a, names, err


# --- the run ------------------------------------------------------------------

manifest = json.loads(MANIFEST.read_text())
entries = manifest["files"]
seen = {}
for i, entry in enumerate(entries):
    f = DATA / entry["file"]
    opts = [str(o) for o in entry.get("options", [])]
    name = entry["file"] + (" " + " ".join(opts) if opts else "")
    if not f.is_file():
        check(False, f"{name}: the file is in {DATA}")
        continue
    tag = entry.get("fixed_by") or entry.get("gap")
    if tag:
        print(f"       ({entry['expect']}: {tag})", flush=True)
    outdir = Path(work) / f"{i:03d}"
    shutil.rmtree(outdir, ignore_errors=True)
    outdir.mkdir(parents=True)

    if entry["expect"] == "kind":
        # A cube map, an array or an environment: `parvo info` names its
        # kind and `parvo mip` writes a file of the same kind.
        want = entry["kind"]
        rc, out, err = run("parvo info", parvo, "info", "--json", f)
        got = json.loads(out).get("kind") if rc == 0 else None
        check(got == want, f"{name}: parvo info reads it as a {want}",
              f"exit {rc}, kind {got}; {lines(err)[-1] if lines(err) else ''}")
        target = outdir / ("l." + entry.get("out", "ktx2"))
        rc, out, err = run("parvo mip", parvo, "mip", f, *opts, "-o", target)
        kept = None
        if rc == 0:
            rc2, out2, _ = run("parvo info", parvo, "info", "--json", target)
            kept = json.loads(out2).get("kind") if rc2 == 0 else None
        check(rc == 0 and kept == want, f"{name}: parvo mip keeps it a {want} ({target.suffix})",
              f"exit {rc}, kind {kept}; {lines(err)[-1] if lines(err) else ''}")
        seen[f] = True
        continue

    if entry["expect"] == "refuse":
        pattern = entry["refuse"]
        if f not in seen:
            rc, out, err = run("parvo info", parvo, "info", f)
            if entry.get("info", "refuse") == "refuse":
                check_refusal(name, "parvo info", f, rc, out, err, pattern)
            else:
                # `parvo info` may describe what `parvo mip` refuses to build
                # (NaN texels, an environment map): either way in plain words.
                u = unclean((err + out).replace(str(f), "FILE"))
                want = (0,) if entry["info"] == "read" else (0, 1)
                check(rc in want and not u, f"{name}: parvo info {'reads' if want == (0,) else 'describes or refuses'} it",
                      "; ".join(([f"exit {rc}"] if rc not in want else []) + [f"shows {x}" for x in u]))
        rc, out, err = run("parvo mip", parvo, "mip", f, *opts, "-o", outdir / "l.exr")
        check_refusal(name, "parvo mip", f, rc, out, err, pattern)
        check_clean_dir(name, outdir)
        seen[f] = True
        continue

    if f not in seen:
        rc, out, err = run("parvo info", parvo, "info", f)
        u = unclean((err + out).replace(str(f), "FILE"))
        check(rc == 0 and not u, f"{name}: parvo info reads it",
              "; ".join(([f"exit {rc}"] if rc != 0 else []) + [f"shows {x}" for x in u]
                        + ([lines(err)[-1].split(': ', 1)[-1][:200]] if lines(err) else [])))
        seen[f] = True
    mode = entry.get("out", "png")
    target = outdir / ("l_{level}.png" if mode == "png" else "l.exr")
    typ = ["--type", "f32"] if mode == "exr" else []
    rc, out, err = run("parvo mip", parvo, "mip", f, *opts, *typ, "-o", target)
    u = unclean(err.replace(str(f), "FILE"))
    if not check(rc == 0 and not u, f"{name}: parvo mip builds its chain ({mode})",
                 "; ".join(([f"exit {rc}"] if rc != 0 else []) + [f"shows {x}" for x in u]
                           + ([lines(err)[-1].split(': ', 1)[-1][:240]] if lines(err) else []))):
        continue
    stray = [p.name for p in outdir.iterdir() if not re.fullmatch(r"l_\d+\.png|l\.exr", p.name)]
    check(not stray, f"{name}: only the outputs in the output directory", ", ".join(stray[:5]))
    ours, names, err = parvo_level0(outdir, mode)
    if ours is None:
        check(False, f"{name}: OpenImageIO reads parvo's level 0", err)
        continue
    if "ref" not in entry:
        skip(f"{name}: level 0", "the manifest names no reference decoder")
        continue
    theirs, err = reference(entry)
    if theirs is None:
        check(False, f"{name}: {entry['ref']} reads the file (the manifest's reference)", err[:200])
        continue
    compare(name, entry, ours, names, theirs)

finish()
