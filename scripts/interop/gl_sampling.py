#!/usr/bin/env python3
"""parvo's sampler against Mesa's llvmpipe (issue 28): textureGather,
textureGrad / textureLod / texture(…, bias) on colour and on
sampler2DShadow, at awkward sizes (37×23, 19×64) with mip levels the
harness makes, every wrap mode (and mixed u/v pairs), nearest and linear
filters, every mip mode, the 8 compare functions, LOD bias and clamps.

How it runs:
- scripts/setup-gl.sh installs Mesa's EGL and llvmpipe (Debian packages);
  moderngl comes from scripts/interop-requirements.txt. Only when the
  packages cannot be installed does this print a "skip:" line.
- Each texture is a random RGBA float32 chain, one independent image per
  level (so a wrong level shows), channel 0 on a 1/16 lattice so depth
  comparisons hit equality. It is written as a mip-mapped float EXR that
  parvo reads, and uploaded level by level to GL (RGBA32F, and channel 0
  as DEPTH_COMPONENT32F): both sides sample identical texels.
- llvmpipe runs a compute shader over a buffer of queries (explicit
  derivatives or LOD), or, for the shader's bias argument, a fragment pass
  in which every query owns a 2×2 pixel quad whose finite differences are
  its derivatives (compute shaders have no implicit derivatives).
- Each llvmpipe result is first compared with _glmodel.py, a numpy model of
  the GL rules: this validates the harness whatever parvo does. Then
  `parvo sample` runs with the matching flags (parvo_sample below, the one
  place that knows parvo's command line) and is compared with llvmpipe.

Tolerances (measured by this script at its start, Mesa 22.3.6, LLVM 15):
- Gather: exact (parvo prints float32 values in shortest round-trip form,
  read back as float32).
- Filtered values: 2e-5. llvmpipe filters float textures (RGBA32F,
  DEPTH_COMPONENT32F) with float32 weights, not 8-bit fixed point: on a
  2×1 ramp (0, 1) its bilinear result equals frac(u·w − ½) exactly, for
  colour and for depth compare, and its LINEAR_MIPMAP_LINEAR blend weight
  equals frac(λ) exactly (8-bit weights would be off by up to 1/512).
  What is left against the float64 model comes from llvmpipe's repeat and
  mirrored-repeat wrapping the normalized coordinate before scaling
  (fract(u)·w rather than u·w), which moves a weight by a few float32 ulps
  of u·w: up to 8e-6 measured at |u| ≤ 4, w ≤ 64.
- λ from derivatives: llvmpipe takes ½·log2ₐ(ρ²) with a piecewise-linear
  log2 (exponent + mantissa − 1), up to 0.0431 below the exact λ; and it
  rounds a nearest-mip tie d' = k + ½ half to even, where GL 4.6 §8.14.3
  says ⌈d' + ½⌉ − 1 (Vulkan allows both). parvo follows the exact λ and
  GL's rounding (SPEC.md), so where llvmpipe's readings change a result
  (the blend of linear mips, the level of nearest mips) the per-query
  allowance against llvmpipe is |model(parvo's rules) − model(llvmpipe's
  rules)| + 2e-5, and parvo must also equal the model with its own rules
  within 2e-5 (the numpy model is itself held to llvmpipe within 2e-5
  with llvmpipe's rules, which the script measures first and adopts, so a
  later Mesa with other readings is followed, not failed).
- Mesa rounds the sampler's LOD bias to 1/256 (shader bias arguments are
  kept exact), so sampler biases here are multiples of 1/256.
- Coordinates within 1e-4 texel of a texel-selection boundary of any level
  are left out: two correct float32 implementations may floor them either
  way (a few per thousand queries; counted in the output).
"""
import itertools
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import OpenImageIO as oiio

sys.dont_write_bytecode = True  # no __pycache__ of the helper modules in the checkout
sys.path.insert(0, str(Path(__file__).resolve().parent))
import _glmodel as model  # noqa: E402
from _llvmpipe import fragment_derivatives, gl_setup  # noqa: E402  (numpy only; GL loads on use)
from common import args, check, finish, oiio_levels, skip  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
SIZES = [(37, 23), (19, 64)]
WRAP_MODES = ["repeat", "mirror", "clamp", "border", "mirror-clamp"]
WRAPS = [(m, m) for m in WRAP_MODES] + [("repeat", "mirror-clamp"), ("border", "mirror")]
FILTERS = [  # (mag, min, mip)
    ("nearest", "nearest", "none"),
    ("linear", "linear", "none"),
    ("linear", "nearest", "nearest"),
    ("nearest", "linear", "nearest"),
    ("linear", "linear", "linear"),
    ("nearest", "linear", "linear"),
]
MIP_FILTERS = [f for f in FILTERS if f[2] != "none"]
OPS = list(model.COMPARE_OPS)
BORDER = (0.3125, 0.6, 0.9, 0.45)  # red on the depth lattice: equality with the border
# (sampler LOD bias, lod min, lod max); biases are multiples of 1/256.
SAMPLER_LODS = [(0.0, -1000.0, 1000.0), (0.375, -1000.0, 1000.0), (-0.625, 0.25, 3.5),
                (1.5, -1000.0, 2.75)]
# Explicit levels, with a sampler bias: ties at d' = 0.5 and 1.5 included.
LEVELS = [(-0.75, 0.0), (0.5, 0.0), (0.875, -0.375), (1.25, 0.0), (1.5, 0.0), (2.6, 0.25), (9.0, 0.0)]
SHADER_BIASES = [0.3, -1.37, 2.2]
TOL = 2e-5
N = 1200
MAX_SHOWN = 4


# --- parvo's side: the only code that knows `parvo sample`'s command line ---

def parvo_features(parvo):
    """Which of the issue-28 flags this parvo has (--gather, --compare, --level, --bias)."""
    r = subprocess.run([parvo, "sample", "--help"], capture_output=True, text=True)
    return {f for f in ("--gather", "--compare", "--level", "--bias") if f in r.stdout}


def parvo_sample(parvo, texture, q, mag="linear", min="linear", mip="none",
                 wrap=("repeat", "repeat"), border=BORDER, lod_bias=0.0, lod_min=-1000.0,
                 lod_max=1000.0, compare=None, level=None, gather=None, bias=None):
    """`parvo sample` on the queries (N x 8 float32: u v dudx dvdx dudy dvdy
    ref lod): N x 4 (colour, gather) or N x 1 (compare), or (None, error)."""
    cmd = [parvo, "sample", texture, "--color", "linear", "--filter", "trilinear", "--max-aniso", "1",
           "--wrap", f"{wrap[0]},{wrap[1]}", "--border", ",".join(repr(float(b)) for b in border)]
    if gather is not None:
        cmd += ["--gather", str(gather)]
    else:
        cmd += ["--mag", mag, "--min", min, "--mip", mip, "--lod-bias", repr(float(lod_bias)),
                "--lod-min", repr(float(lod_min)), "--lod-max", repr(float(lod_max))]
    if level is not None:
        cmd += ["--level", repr(float(level))]
    if bias is not None:
        cmd += ["--bias", repr(float(bias))]
    cols = 6
    if compare is not None:
        cmd += ["--compare", compare]
        cols = 7
    text = "\n".join(" ".join("%.9g" % x for x in row) for row in q[:, :cols]) + "\n"
    r = subprocess.run(cmd, input=text, capture_output=True, text=True)
    if r.returncode != 0:
        return None, f"exit {r.returncode}: {' '.join(cmd[2:])}: {r.stderr.strip()[:300]}"
    try:
        # parvo prints float32 values (shortest round trip): read them back
        # as float32, so equal texels compare equal.
        out = np.loadtxt(r.stdout.splitlines(), dtype=np.float32, ndmin=2)
    except ValueError as e:
        return None, f"unreadable output ({e}): {r.stdout[:200]!r}"
    if out.shape[0] != len(q):
        return None, f"{out.shape[0]} result lines for {len(q)} queries"
    return out, ""


# --- textures and queries ---

def make_chain(rng, w, h):
    levels = []
    while True:
        a = rng.uniform(0.0, 1.0, (h, w, 4)).astype(np.float32)
        a[..., 0] = rng.integers(0, 17, (h, w)) / 16
        levels.append(a)
        if w == 1 and h == 1:
            return levels
        w, h = max(1, w // 2), max(1, h // 2)


def write_mip_exr(path, levels):
    """A tiled, mip-mapped float32 RGBA OpenEXR with exactly these levels
    (OpenEXR's round-down level sizes, which are GL's)."""
    out = oiio.ImageOutput.create(path)
    assert out is not None, oiio.geterror()
    for k, lv in enumerate(levels):
        h, w = lv.shape[:2]
        spec = oiio.ImageSpec(w, h, 4, "float")
        spec.tile_width = spec.tile_height = 16
        spec.attribute("compression", "zip")
        # OpenImageIO writes MIP levels to an EXR only for a texture.
        spec.attribute("textureformat", "Plain Texture")
        spec.attribute("openexr:levelmode", 1)  # MIPMAP_LEVELS
        spec.attribute("openexr:roundingmode", 0)  # ROUND_DOWN
        assert out.open(path, spec, "Create" if k == 0 else "AppendMIPLevel"), out.geterror()
        assert out.write_image(lv), out.geterror()
    out.close()


def make_queries(rng, w, h, top, n):
    """Random queries: 60 % of (u, v) in [0, 1), the rest in [-3, 4); derivative
    pairs of random direction and anisotropy with λ spread over [-3, top + 1.5];
    refs half on the depth lattice (equality), half anywhere in [-0.1, 1.1]."""
    q = np.zeros((n, 8), np.float32)
    inside = rng.random(n) < 0.6
    for c in (0, 1):
        q[:, c] = np.where(inside, rng.uniform(0, 1, n), rng.uniform(-3, 4, n))
    m = np.exp2(rng.uniform(-3, top + 1.5, n)) / max(w, h)
    a = rng.uniform(0, 2 * np.pi, n)
    q[:, 2], q[:, 3] = m * np.cos(a), m * np.sin(a)
    m2 = m * np.exp2(rng.uniform(-2.5, 0, n))
    a2 = rng.uniform(0, 2 * np.pi, n)
    q[:, 4], q[:, 5] = m2 * np.cos(a2), m2 * np.sin(a2)
    q[:, 6] = np.where(rng.random(n) < 0.5, rng.integers(-1, 18, n) / 16, rng.uniform(-0.1, 1.1, n))
    q[:, 7] = rng.uniform(-1, top + 1, n)
    return q


# --- comparison bookkeeping ---

class Tally:
    """Worst difference and failing queries of one family of runs."""

    def __init__(self):
        self.worst = 0.0
        self.where = ""
        self.bad = 0
        self.total = 0
        self.shown = []
        self.errors = []
        self.widened = 0
        self.same = 0  # lookups where both sides' rules give one result
        self.same_worst = 0.0

    def add(self, what, q, got, want, allow, base=None):
        got = np.asarray(got, np.float64)
        want = np.asarray(want, np.float64)
        diff = np.abs(got - want).max(axis=1)
        over = diff > allow
        if base is not None:
            self.widened += int((diff > base).sum())
            same = np.asarray(allow) - base <= 1e-12
            self.same += int(same.sum())
            if same.any():
                self.same_worst = max(self.same_worst, float(diff[same].max()))
        self.total += len(q)
        self.bad += int(over.sum())
        i = int(np.argmax(diff - allow))
        if diff[i] > self.worst:
            self.worst, self.where = float(diff[i]), what
        for k in np.flatnonzero(over)[: max(0, MAX_SHOWN - len(self.shown))]:
            self.shown.append(f"{what}: query {' '.join('%.9g' % x for x in q[k])} "
                              f"got {np.array2string(got[k], precision=7)} "
                              f"want {np.array2string(want[k], precision=7)}")

    def report(self, what, allowance):
        if self.errors:
            more = f" (+{len(self.errors) - 1} more)" if len(self.errors) > 1 else ""
            return check(False, what, self.errors[0] + more)
        ok = check(self.bad == 0, what, f"{self.total} lookups, max |diff| {self.worst:.3g}"
                   + (f" at {self.where}" if self.where else "") + ", "
                   f"allowed {allowance}"
                   + (f"; {self.widened} of them differ by more than {TOL:g}, within that change"
                      if self.widened else "")
                   + (f"; {self.bad} over" if self.bad else "")
                   + (f"; max |diff| {self.same_worst:.3g} over the {self.same} where both rules give "
                      f"one result" if self.same else ""))
        for s in self.shown:
            print("       " + s)
        return ok


def cases():
    """Every run of the check: (family, label, GL sampler options, call,
    shader bias or None, parvo options)."""
    lods = itertools.cycle(SAMPLER_LODS)
    levels = itertools.cycle(LEVELS)
    biases = itertools.cycle(SHADER_BIASES)
    for wrap in WRAPS:
        w = f"{wrap[0]},{wrap[1]}"
        for c in range(4):
            yield ("gather", f"{w} C={c}", dict(wrap=wrap), f"gather{c}", None, dict(wrap=wrap, gather=c))
        for mag, mn, mip in FILTERS:
            f = dict(mag=mag, min=mn, mip=mip, wrap=wrap)
            fl = f"{w} {mag}/{mn}/{mip}"
            for _ in range(2):
                bias, lo, hi = next(lods)
                s = dict(f, lod_bias=bias, lod_min=lo, lod_max=hi)
                yield ("grad", f"{fl} bias {bias} lod [{lo}, {hi}]", s, "grad", None, s)
            if mip != "none" or mag != mn:
                for _ in range(2):
                    lod, bias = next(levels)
                    s = dict(f, lod_bias=bias)
                    yield ("lod", f"{fl} level {lod} bias {bias}", s, ("lod", lod), None, dict(s, level=lod))
            sb = next(biases)
            bias, lo, hi = next(lods)
            s = dict(f, lod_bias=bias, lod_min=lo, lod_max=hi)
            yield ("bias", f"{fl} shader bias {sb} sampler bias {bias} lod [{lo}, {hi}]", s, "bias", sb,
                   dict(s, bias=sb))
            for op in OPS:
                bias, lo, hi = next(lods)
                s = dict(f, lod_bias=bias, lod_min=lo, lod_max=hi, compare=op)
                yield ("shadow_grad", f"{fl} {op} bias {bias}", s, "shadow_grad", None, s)
                if mip != "none" and op in ("lequal", "greater", "equal", "notequal"):
                    lod, bias = next(levels)
                    s = dict(f, lod_bias=bias, compare=op)
                    yield ("shadow_lod", f"{fl} {op} level {lod} bias {bias}", s, ("shadow_lod", lod), None,
                           dict(s, level=lod))
            op = OPS[(WRAPS.index(wrap) * 3 + FILTERS.index((mag, mn, mip))) % len(OPS)]
            sb = next(biases)
            bias, lo, hi = next(lods)
            s = dict(f, lod_bias=bias, lod_min=lo, lod_max=hi, compare=op)
            yield ("shadow_bias", f"{fl} {op} shader bias {sb} sampler bias {bias}", s, "shadow_bias", sb,
                   dict(s, bias=sb))


FAMILIES = {
    "gather": "textureGather(s, uv, C)",
    "grad": "textureGrad(sampler2D) with the sampler's LOD bias and clamps",
    "lod": "textureLod(sampler2D) with the sampler's LOD bias",
    "bias": "texture(sampler2D, uv, bias) in a fragment shader",
    "shadow_grad": "textureGrad(sampler2DShadow), 8 compare functions",
    "shadow_lod": "textureLod(sampler2DShadow)",
    "shadow_bias": "texture(sampler2DShadow, uvr, bias) in a fragment shader",
}
NEEDS = {"gather": "--gather", "lod": "--level", "bias": "--bias", "shadow_grad": "--compare",
         "shadow_lod": "--compare", "shadow_bias": "--compare"}


def weight_precision(gl, rng):
    """llvmpipe's filter weights, measured: a 2×1 level (0, 1) returns the
    bilinear weight of texel 1 (colour, and depth compared with `less` at
    ref ½), and levels holding 0 and 1 return the mip blend weight of a
    textureLod. 8-bit fixed-point weights would be off by up to 1/512;
    float32 weights by about 1e-7. Returns the worst error seen."""
    n = 4096
    q = np.zeros((n, 8), np.float32)
    q[:, 0] = rng.uniform(0.25, 0.75, n)
    q[:, 1] = 0.5
    q[:, 2] = q[:, 5] = 1e-3  # magnified: λ < 0
    q[:, 6] = 0.5
    a = (q[:, 0] * np.float32(2) - np.float32(0.5)).astype(np.float64)  # GL's α, float32 as a GPU has it
    ramp = np.zeros((1, 2, 4), np.float32)
    ramp[0, 1] = 1.0
    worst = 0.0
    for what, depth, call, cmp in (("RGBA32F bilinear", False, "grad", None),
                                   ("DEPTH_COMPONENT32F bilinear compare", True, "shadow_grad", "less")):
        tex = gl.texture([ramp if not depth else ramp[..., 0]], depth=depth)
        s = gl.sampler(mag="linear", min="linear", mip="none", wrap=("clamp", "clamp"), compare=cmp)
        got = gl.run(call, q)[:, 0].astype(np.float64)
        gl.delete_sampler(s)
        gl.delete_texture(tex)
        err = float(np.abs(got - a).max())
        worst = max(worst, err)
        check(err < 1e-6, f"llvmpipe's {what} weights are float, not 8-bit fixed point",
              f"{n} lookups of a (0, 1) ramp: max |result − frac(u·w − ½)| {err:.2g}, "
              f"8-bit weights would be off by up to {1 / 512:.2g}")
    levels = [np.zeros((4, 4, 4), np.float32), np.ones((2, 2, 4), np.float32), np.ones((1, 1, 4), np.float32)]
    tex = gl.texture(levels)
    q[:, 7] = rng.uniform(0.0, 1.0, n)
    s = gl.sampler(mag="linear", min="linear", mip="linear", wrap=("clamp", "clamp"))
    got = gl.run("lod", q)[:, 0].astype(np.float64)
    gl.delete_sampler(s)
    gl.delete_texture(tex)
    err = float(np.abs(got - q[:, 7]).max())
    worst = max(worst, err)
    check(err < 1e-6, "llvmpipe's mip blend weight (textureLod, LINEAR_MIPMAP_LINEAR) is float",
          f"{n} lookups between a level of 0 and one of 1: max |result − frac(λ)| {err:.2g}")
    return worst


def reference_behaviour(gl, rng):
    """The llvmpipe facts the tolerances rest on, measured with a texture
    whose level k holds the value k (a trilinear lookup returns its λ, a
    nearest-mip one its level): which λ from derivatives it computes (the
    exact log2 or ½·log2ₐ(ρ²)), that Mesa rounds the sampler's bias to
    1/256, and how nearest-mip ties round. Returns (lod_model, ties) for
    _glmodel.sample, or None when llvmpipe matches neither reading."""
    w, h = 37, 23
    levels = [np.full(lv.shape, k, np.float32) for k, lv in enumerate(make_chain(rng, w, h))]
    top = len(levels) - 1
    tex = gl.texture(levels)
    q = make_queries(rng, w, h, top, 4000)
    s = gl.sampler(mag="linear", min="linear", mip="linear", wrap=("clamp", "clamp"))
    got = gl.run("grad", q)[:, 0].astype(np.float64)
    gl.delete_sampler(s)
    exact = np.clip(model.lambda_of(q, w, h, False, 0.0, -1e3, 1e3, "exact"), 0, top)
    approx = np.clip(model.lambda_of(q, w, h, False, 0.0, -1e3, 1e3, "llvmpipe"), 0, top)
    e_exact, e_approx = np.abs(got - exact).max(), np.abs(got - approx).max()
    lod_model = "exact" if e_exact < 1e-5 else "llvmpipe" if e_approx < 1e-5 else None
    check(lod_model is not None,
          "llvmpipe's λ from derivatives is one of the model's: "
          + {"exact": "the exact log2 of ρ", "llvmpipe": "½·log2ₐ(ρ²), the piecewise-linear log2",
             None: "neither"}[lod_model],
          f"4000 lookups: max |λ − exact| {e_exact:.4f}, max |λ − ½·log2ₐ(ρ²)| {e_approx:.2g} "
          f"(that one is at most {model.LLVMPIPE_LOD_SHORTFALL:.4f} below the exact λ)")
    q[:, 7] = 1.0
    s = gl.sampler(mag="linear", min="linear", mip="linear", wrap=("clamp", "clamp"), lod_bias=0.3)
    got = float(gl.run("lod", q[:1])[0, 0])
    gl.delete_sampler(s)
    check(abs(got - (1 + 77 / 256)) < 1e-6 or abs(got - 1.3) < 1e-6,
          "the sampler's LOD bias: Mesa keeps it to 1/256 or exact (the biases here are multiples of 1/256)",
          f"textureLod(1.0) with bias 0.3 reads λ = {got:.7f}"
          + (" = 1 + 77/256" if abs(got - (1 + 77 / 256)) < 1e-6 else ""))
    s = gl.sampler(mag="linear", min="linear", mip="nearest", wrap=("clamp", "clamp"))
    picks = []
    for lod in (0.5, 1.5, 2.5):
        q[:, 7] = lod
        picks.append(float(gl.run("lod", q[:1])[0, 0]))
    gl.delete_sampler(s)
    ties = {(0.0, 1.0, 2.0): "preferred", (0.0, 2.0, 2.0): "even"}.get(tuple(picks))
    check(ties is not None, "llvmpipe's nearest mip level at a tie d' = k + ½ is one Vulkan allows: "
          + {"preferred": "⌈d' + ½⌉ − 1, the preferred rule (SPEC.md's, parvo's)",
             "even": "rounded half to even (level k for even k, k + 1 for odd k)", None: "neither"}[ties],
          f"textureLod at 0.5, 1.5, 2.5 reads levels {picks}")
    gl.delete_texture(tex)
    return (lod_model, ties) if lod_model and ties else None


def bias_with_compare(parvo, work):
    """The smallest case of the shader bias on a shadow lookup: a 2×1 depth
    level (0, 1), a lookup between the two texels at one texel per pixel
    (λ = 0: magnified, linear) with bias 1 (λ = 1: minified, nearest, texel
    1). GL 4.6 §8.14.1 adds bias_shader to λ before the mag/min choice,
    for shadow samplers as for colour (GLSL 4.60 §8.9.2,
    texture(sampler2DShadow, P, bias)), so `--bias 1` must equal
    `--lod-bias 1` here: ref ½ less than (0, 1) gives 1, not the linear ½."""
    path = os.path.join(work, "depth_2x1.exr")
    out = oiio.ImageOutput.create(path)
    out.open(path, oiio.ImageSpec(2, 1, 1, "float"))
    out.write_image(np.array([[[0.0], [1.0]]], np.float32))
    out.close()
    q = np.array([[0.5, 0.5, 0.5, 0.0, 0.0, 0.5, 0.5, 0.0]], np.float32)
    opts = dict(mag="linear", min="nearest", mip="none", wrap=("clamp", "clamp"), compare="less")
    res = {}
    for name, extra in (("--lod-bias 1", dict(lod_bias=1.0)), ("--bias 1", dict(bias=1.0))):
        o, err = parvo_sample(parvo, path, q, **opts, **extra)
        res[name] = err if o is None else float(o[0, 0])
    check(res["--lod-bias 1"] == 1.0 and res["--bias 1"] == 1.0,
          "parvo sample --compare takes the shader bias --bias into λ as it does --lod-bias",
          f"2×1 depth (0, 1), u ½, one texel per pixel, ref ½ less: --lod-bias 1 gives {res['--lod-bias 1']}, "
          f"--bias 1 gives {res['--bias 1']}; GL: 1 (λ = 1, minified, nearest texel 1)")


def main():
    parvo, _venv_bin, work = args()
    gl = gl_setup()
    if gl is None:
        return
    rng = np.random.default_rng(2807)
    weight_precision(gl, rng)
    rules = reference_behaviour(gl, rng)
    if rules is None:
        return
    lod_model, ties = rules
    features = parvo_features(parvo)
    if {"--compare", "--bias"} <= features:
        bias_with_compare(parvo, work)
    for w, h in SIZES:
        size_name = f"{w}x{h}"
        levels = make_chain(rng, w, h)
        top = len(levels) - 1
        path = os.path.join(work, f"chain_{size_name}.exr")
        write_mip_exr(path, levels)
        back, err = oiio_levels(path)
        check(back is not None and len(back) == len(levels)
              and all(np.array_equal(b, lv) for b, lv in zip(back, levels)),
              f"{size_name}: the {len(levels)}-level float EXR both sides read holds the GL levels exactly",
              err)
        color = gl.texture(levels)
        depth = gl.texture([lv[..., 0] for lv in levels], depth=True)
        q = make_queries(rng, w, h, top, N)
        near = model.boundary_distance(levels, q) <= 1e-4
        q = q[~near]
        print(f"       {size_name}: {len(q)} queries per run ({int(near.sum())} within 1e-4 texel "
              f"of a texel boundary left out)", flush=True)
        vs_model = {f: Tally() for f in FAMILIES}
        vs_parvo = {f: Tally() for f in FAMILIES}
        vs_exact = {f: Tally() for f in FAMILIES}
        for family, label, sampler, call, shader_bias, popts in cases():
            qq = q.copy()
            if isinstance(call, tuple):
                call, lod = call
                qq[:, 7] = lod
            gl.bind(depth if call.startswith("shadow") else color)
            s = gl.sampler(border=BORDER, **sampler)
            if shader_bias is not None:
                got = gl.run_fragment(call, qq, shader_bias)
                qq = fragment_derivatives(qq)
                mcall = "shadow_grad" if call.startswith("shadow") else "grad"
                msampler = dict(sampler, lod_bias=sampler.get("lod_bias", 0.0) + shader_bias)
            else:
                got = gl.run(call, qq)
                mcall, msampler = call, sampler
            gl.delete_sampler(s)
            if call.startswith("shadow"):
                got = got[:, :1]
            want = model.sample(levels, qq, mcall, border=BORDER, lod_model=lod_model, ties=ties, **msampler)
            exact = model.sample(levels, qq, mcall, border=BORDER, lod_model="exact", **msampler)
            if family == "gather":
                want = want.astype(np.float32)
                exact = exact.astype(np.float32)
            allow = 0.0 if family == "gather" else TOL
            vs_model[family].add(label, qq, got, want, allow)
            need = NEEDS.get(family)
            if need and need not in features:
                continue
            out, err = parvo_sample(parvo, path, qq, **popts)
            if out is None:
                vs_parvo[family].errors.append(f"{label}: {err}")
                continue
            # parvo follows the exact λ; llvmpipe's is up to 0.0431 lower.
            gap = np.abs(exact - want).max(axis=1)
            vs_parvo[family].add(label, qq, out, got, allow + gap, base=None if family == "gather" else allow)
            vs_exact[family].add(label, qq, out, exact, allow)
        for family, what in FAMILIES.items():
            allowance = "0 (exact)" if family == "gather" else f"{TOL:g}"
            vs_model[family].report(f"{size_name} llvmpipe {what} equals the GL rules (numpy model)", allowance)
        for family, what in FAMILIES.items():
            need = NEEDS.get(family)
            if need and need not in features:
                skip(f"{size_name} parvo sample vs llvmpipe {what}",
                     f"this parvo sample has no {need} yet")
                continue
            allowance = ("0 (exact)" if family == "gather"
                         else f"{TOL:g} + the change llvmpipe's λ and tie rounding make")
            if vs_parvo[family].report(f"{size_name} parvo sample equals llvmpipe {what}", allowance):
                if family != "gather":
                    vs_exact[family].report(f"{size_name} parvo sample equals the GL rules with exact log2, {what}",
                                            f"{TOL:g}")
        gl.delete_texture(color)
        gl.delete_texture(depth)


main()
finish()
