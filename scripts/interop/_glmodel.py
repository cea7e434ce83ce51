"""A numpy model of OpenGL 4.5's texture sampling rules (section 8.14,
"Texture Minification"; 8.14.2, "Coordinate Wrapping and Texel Selection";
8.22.1 textureGather; 8.23.1, "Depth Texture Comparison Mode"), written from
the specification and SPEC.md, not from parvo's code, to validate the
llvmpipe harness of gl_sampling.py and to bound parvo against llvmpipe.

Queries are N x 8 float32 rows (u, v, du/dx, dv/dx, du/dy, dv/dy, ref, lod);
levels are H x W x C float32 arrays. Coordinates are scaled in float32, as
a GPU does, so floors agree with llvmpipe away from texel boundaries.

`lod_model` names the two allowed readings of the rules that differ:
- "exact": λ = log2(ρmax), the specification's formula, and the preferred
  nearest-level rule d = ⌈d' + ½⌉ − 1 (level k at d' = k + ½): SPEC.md's,
  so parvo's.
- "llvmpipe": what llvmpipe does, measured by gl_sampling.py:
  λ = ½·log2ₐ(ρmax²), where log2ₐ(x) = e + (m − 1) for x = m·2^e,
  1 ≤ m < 2, is the piecewise-linear logarithm of gallivm's
  lp_build_fast_log2 on the squared ρ (equal to llvmpipe's λ to 3e-7);
  log2ₐ ≤ log2, short by at most 0.0861 at m = 1/ln 2, so this λ is at
  most 0.0431 below the exact one, and equal whenever ρ² is a power of two.
  And nearest-level rounding half to even (the x86 conversion gallivm's
  lp_build_iround uses): at d' = k + ½ level k for even k, k + 1 for odd
  k, so each tie takes one of the two roundings Vulkan allows,
  ⌈d' + ½⌉ − 1 (preferred) and ⌊d' + ½⌋.
"""
import numpy as np

F32 = np.float32
COMPARE_OPS = {
    "never": lambda r, d: np.zeros_like(d, dtype=bool),
    "less": lambda r, d: r < d,
    "equal": lambda r, d: r == d,
    "lequal": lambda r, d: r <= d,
    "greater": lambda r, d: r > d,
    "notequal": lambda r, d: r != d,
    "gequal": lambda r, d: r >= d,
    "always": lambda r, d: np.ones_like(d, dtype=bool),
}
# Worst shortfall of e + (m - 1) below log2(m·2^e), halved for ρ².
LLVMPIPE_LOD_SHORTFALL = 0.5 * (np.log2(1 / np.log(2)) - (1 / np.log(2) - 1))


def mirror(n):
    return np.where(n >= 0, n, -(1 + n))


def wrap_index(i, size, mode):
    """GL's table 8.20 on integer texel indices: (index to fetch, border
    mask). The fetched index of a border texel is clamped only to keep the
    array read in bounds; the mask replaces its value."""
    border = np.zeros(i.shape, dtype=bool)
    if mode == "repeat":
        j = np.mod(i, size)
    elif mode == "mirror":
        j = (size - 1) - mirror(np.mod(i, 2 * size) - size)
    elif mode == "clamp":
        j = np.clip(i, 0, size - 1)
    elif mode == "border":
        border = (i < 0) | (i >= size)
        j = np.clip(i, 0, size - 1)
    elif mode == "mirror-clamp":
        j = np.clip(mirror(i), 0, size - 1)
    else:
        raise ValueError(mode)
    return j, border


def fetch(level, i, j, wrap, border, shadow=None):
    """Texels (N x C float64) at integer indices after wrapping; with a
    `shadow` (op, refs) pair, channel 0 compared as GL's depth comparison
    (the border colour's first component is the border texel's depth)."""
    h, w = level.shape[:2]
    ii, bu = wrap_index(i, w, wrap[0])
    jj, bv = wrap_index(j, h, wrap[1])
    t = level[jj, ii].astype(np.float64)
    if t.ndim == 1:
        t = t[:, None]
    b = bu | bv
    t[b] = np.asarray(border, dtype=np.float64)[: t.shape[1]]
    if shadow is not None:
        op, ref = shadow
        t = COMPARE_OPS[op](ref.astype(np.float64), t[:, 0]).astype(np.float64)[:, None]
    return t


def scaled(c, size):
    """c·size in float32, as the texture unit computes it."""
    return c.astype(F32) * F32(size)


def filter_level(level, u, v, texel_filter, wrap, border, shadow=None):
    """GL's nearest or linear filter within one level (N x C)."""
    h, w = level.shape[:2]
    if texel_filter == "nearest":
        i = np.floor(scaled(u, w)).astype(np.int64)
        j = np.floor(scaled(v, h)).astype(np.int64)
        return fetch(level, i, j, wrap, border, shadow)
    x = scaled(u, w) - F32(0.5)
    y = scaled(v, h) - F32(0.5)
    i0 = np.floor(x)
    j0 = np.floor(y)
    a = (x - i0).astype(np.float64)[:, None]
    b = (y - j0).astype(np.float64)[:, None]
    i0 = i0.astype(np.int64)
    j0 = j0.astype(np.int64)
    t00 = fetch(level, i0, j0, wrap, border, shadow)
    t10 = fetch(level, i0 + 1, j0, wrap, border, shadow)
    t01 = fetch(level, i0, j0 + 1, wrap, border, shadow)
    t11 = fetch(level, i0 + 1, j0 + 1, wrap, border, shadow)
    return (1 - a) * (1 - b) * t00 + a * (1 - b) * t10 + (1 - a) * b * t01 + a * b * t11


def log2_llvmpipe(x):
    """llvmpipe's piecewise-linear log2 of float32 x: exponent + mantissa − 1."""
    bits = np.asarray(x, dtype=F32).view(np.int32).astype(np.int64)
    e = ((bits >> 23) & 0xFF) - 127
    m = (bits & 0x7FFFFF).astype(np.float64) / float(1 << 23)
    return e + m


def lambda_of(q, w, h, explicit_lod, bias, lod_min, lod_max, lod_model):
    """GL's λ per query: the explicit lod, or log2 of the larger derivative
    vector's length in level-0 texels; plus the sampler's bias; clamped to
    [lod_min, lod_max]."""
    if explicit_lod:
        lam = q[:, 7].astype(np.float64)
    else:
        W, H = F32(w), F32(h)
        rx2 = (q[:, 2] * W) ** 2 + (q[:, 3] * H) ** 2
        ry2 = (q[:, 4] * W) ** 2 + (q[:, 5] * H) ** 2
        rho2 = np.maximum(rx2, ry2).astype(F32)
        if lod_model == "exact":
            with np.errstate(divide="ignore"):
                lam = 0.5 * np.log2(rho2.astype(np.float64))
        else:
            lam = 0.5 * log2_llvmpipe(rho2)
    return np.clip(lam + bias, lod_min, lod_max)


def sample(levels, q, call, mag="linear", min="linear", mip="none", wrap=("repeat", "repeat"),
           border=(0.0, 0.0, 0.0, 0.0), lod_bias=0.0, lod_min=-1000.0, lod_max=1000.0,
           compare=None, lod_model="exact", ties=None):
    """The GL result of texture function `call` (as _llvmpipe.GL.CALLS names
    them) per query: N x 4 for colour and gather, N x 1 for shadow lookups.
    `ties` is the nearest-level rounding at d' = k + ½: "preferred"
    (⌈d' + ½⌉ − 1) or "even"; by default the one `lod_model` names."""
    if ties is None:
        ties = "preferred" if lod_model == "exact" else "even"
    u, v = q[:, 0], q[:, 1]
    if call.startswith("gather"):
        c = int(call[-1])
        lv = levels[0]
        h, w = lv.shape[:2]
        i0 = np.floor(scaled(u, w) - F32(0.5)).astype(np.int64)
        j0 = np.floor(scaled(v, h) - F32(0.5)).astype(np.int64)
        taps = [(i0, j0 + 1), (i0 + 1, j0 + 1), (i0 + 1, j0), (i0, j0)]
        return np.stack([fetch(lv, i, j, wrap, border)[:, c] for i, j in taps], axis=1)
    shadow = (compare, q[:, 6]) if call.startswith("shadow") else None
    h0, w0 = levels[0].shape[:2]
    lam = lambda_of(q, w0, h0, call.endswith("lod"), lod_bias, lod_min, lod_max, lod_model)
    top = len(levels) - 1
    magnified = lam <= 0
    per_level = [filter_level(lv, u, v, min, wrap, border, shadow) for lv in levels]
    if mip == "none":
        out = per_level[0]
    else:
        d = np.clip(lam, 0, top)
        stack = np.stack(per_level)  # L x N x C
        n = np.arange(len(q))
        if mip == "nearest":
            if ties == "preferred":
                k = np.where(d <= 0.5, 0, np.ceil(d + 0.5) - 1).astype(np.int64)
            else:
                k = np.rint(d).astype(np.int64)  # ties to even
            out = stack[np.minimum(k, top), n]
        else:
            hi = np.floor(d).astype(np.int64)
            lo = np.minimum(hi + 1, top)
            frac = (d - hi)[:, None]
            out = (1 - frac) * stack[hi, n] + frac * stack[lo, n]
    mag_result = filter_level(levels[0], u, v, mag, wrap, border, shadow)
    out = np.where(magnified[:, None], mag_result, out)
    return out


def boundary_distance(levels, q):
    """Per query, the smallest distance in texels from a texel-selection
    discontinuity of any level (u·w and u·w − ½ integer, likewise v): where
    nearest filtering and gather footprints change, so two correct
    implementations may differ by a rounding there."""
    u, v = q[:, 0], q[:, 1]
    dist = np.full(len(q), np.inf)
    for lv in levels:
        h, w = lv.shape[:2]
        for c, size in ((u, w), (v, h)):
            s = scaled(c, size).astype(np.float64)
            for off in (0.0, 0.5):
                t = s - off
                dist = np.minimum(dist, np.abs(t - np.round(t)))
    return dist
