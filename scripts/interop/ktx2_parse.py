#!/usr/bin/env python3
"""KTX2 interop: ktx-parse (npm, pinned 1.1.0; installed into
target/interop-node by this script) reads the KTX2 files parvo writes:
uncompressed, every block format, zstd and zlib supercompressed. The
vkFormat, typeSize, size, level count, supercompression scheme, DFD colour
model, transfer, texel block and bytesPlane0 it reports must be what the
KTX 2.0 specification says for the file, and each level's
uncompressedByteLength what the level needs. The DFD samples (bit offset,
bit length - 1, channel id and qualifiers) must be the format's, with
KHR_DF_SAMPLE_DATATYPE_LINEAR (0x10) on the alpha sample (channel 15) of an
sRGB file and on no other sample (KTX 2.0, "Data Format Descriptor",
Restrictions; `ktx validate` errors 6108/6109).
"""
import json
import os
import subprocess

from common import args, check, finish, run

parvo, venv_bin, work = args()
root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
node_dir = os.path.join(root, "target", "interop-node")
if not os.path.isdir(os.path.join(node_dir, "node_modules", "ktx-parse")):
    os.makedirs(node_dir, exist_ok=True)
    subprocess.run(["npm", "install", "--prefix", node_dir, "--no-audit", "--no-fund", "ktx-parse@1.1.0"],
                   check=True, capture_output=True)
reader = os.path.join(os.path.dirname(os.path.abspath(__file__)), "ktx2_read.cjs")
os.environ["NODE_PATH"] = os.path.join(node_dir, "node_modules")

N = 61  # odd: partial blocks on every level
# (name, parvo args, vkFormat, typeSize, colour model, transfer, block, bytesPlane0, bytes of a
# level, samples as (bit offset, bit length - 1, channel id | qualifiers))
blocks = lambda b: (lambda w, h: ((w + 3) // 4) * ((h + 3) // 4) * b)
LINEAR = 0x10
CASES = [
    ("RGB8 sRGB", [], 29, 1, 1, 2, [0, 0, 0, 0], 3, lambda w, h: w * h * 3,
     [[0, 7, 0], [8, 7, 1], [16, 7, 2]]),
    ("BC1", ["--compress", "bc1"], 132, 1, 128, 2, [3, 3, 0, 0], 8, blocks(8), [[0, 63, 0]]),
    ("BC3", ["--compress", "bc3"], 138, 1, 130, 2, [3, 3, 0, 0], 16, blocks(16),
     [[0, 63, 15 | LINEAR], [64, 63, 0]]),
    ("BC4", ["--compress", "bc4"], 139, 1, 131, 1, [3, 3, 0, 0], 8, blocks(8), [[0, 63, 0]]),
    ("BC5", ["--compress", "bc5"], 141, 1, 132, 1, [3, 3, 0, 0], 16, blocks(16),
     [[0, 63, 0], [64, 63, 1]]),
    ("BC7", ["--compress", "bc7", "--quality", "fast"], 146, 1, 134, 2, [3, 3, 0, 0], 16,
     blocks(16), [[0, 127, 0]]),
]
for name, extra, vk, ts, model, transfer, block, plane, need, samples in CASES:
    for sc in ([], ["--zstd", "9"], ["--zlib", "6"]):
        what = f"{name} {' '.join(sc) or 'plain'}"
        path = f"{work}/t.ktx2"
        r = run(parvo, "mip", f"builtin:photo:{N}", "-o", path, *extra, *sc)
        if not check(r.returncode == 0, f"parvo writes {what} KTX2"):
            continue
        r = run("node", reader, path)
        if not check(r.returncode == 0, f"ktx-parse reads parvo's {what} KTX2", r.stderr.strip()[-300:]):
            continue
        d = json.loads(r.stdout)
        scheme = {"": 0, "--zstd": 2, "--zlib": 3}[sc[0] if sc else ""]
        sizes = [(max(N >> k, 1), max(N >> k, 1)) for k in range(d["levels"])]
        got = (d["vkFormat"], d["typeSize"], d["width"], d["height"], d["levels"], d["scheme"],
               d["model"], d["transfer"], d["block"], d["bytesPlane0"], d["uncompressed"], d["samples"])
        want = (vk, ts, N, N, 6, scheme, model, transfer, block, plane, [need(w, h) for w, h in sizes],
                samples)
        check(got == want, f"ktx-parse finds parvo's {what} KTX2 fields as specified", f"got {got}, want {want}")
# Block-compressed cube maps and arrays (issue 51): OpenEXR's cube strip to
# BC6H and KTX-Software-CTS's sRGB array to BC7_SRGB. The header's face and
# layer counts, and each level holding every face's or layer's blocks.
peer = os.path.join(root, "tests", "data", "peer")
IMAGES = [
    ("BC6H cube map", os.path.join(peer, "openexr-images", "WavyLinesCube.exr"), ["--compress", "bc6h"],
     143, 0, 6),
    ("BC7 sRGB array", os.path.join(peer, "ktx-cts", "valid_R8G8B8A8_SRGB_2D_ARRAY.ktx2"),
     ["--compress", "bc7", "--quality", "fast"], 146, None, 1),
]
for what, src, extra, vk, layers, faces in IMAGES:
    path = f"{work}/images.ktx2"
    r = run(parvo, "mip", src, "-o", path, *extra)
    if not check(r.returncode == 0, f"parvo writes a {what} KTX2", r.stderr.strip()[-300:]):
        continue
    r = run("node", reader, path)
    if not check(r.returncode == 0, f"ktx-parse reads parvo's {what}", r.stderr.strip()[-300:]):
        continue
    d = json.loads(r.stdout)
    images = max(d["layers"], 1) * d["faces"]
    sizes = [(max(d["width"] >> k, 1), max(d["height"] >> k, 1)) for k in range(d["levels"])]
    got = (d["vkFormat"], d["faces"], d["uncompressed"])
    want = (vk, faces, [images * blocks(16)(w, h) for w, h in sizes])
    check(got == want and (layers is None or d["layers"] == layers) and (layers is not None or d["layers"] > 1),
          f"ktx-parse finds parvo's {what}: format, faces, layers and every image's blocks per level",
          f"got {got}, layers {d['layers']}, want {want}")
# Two-channel data: KTX-Software-CTS's R8G8_UNORM file through parvo stays
# R8G8_UNORM with samples R (0) and G (1), not grey + alpha.
cts = os.path.join(root, "tests", "data", "peer", "cts_valid_R8G8_UNORM_2D.ktx2")
path = f"{work}/rg.ktx2"
if check(run(parvo, "mip", cts, "-o", path).returncode == 0, "parvo writes CTS R8G8_UNORM to KTX2"):
    r = run("node", reader, path)
    if check(r.returncode == 0, "ktx-parse reads parvo's R8G8 KTX2", r.stderr.strip()[-300:]):
        d = json.loads(r.stdout)
        got = (d["vkFormat"], d["samples"], d["flags"])
        check(got == (16, [[0, 7, 0], [8, 7, 1]], 0), "ktx-parse finds R, G data in parvo's R8G8 KTX2",
              f"got {got}")
finish()
