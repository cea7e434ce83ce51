#!/usr/bin/env python3
"""List the functions under src/ longer than a limit (default 120 lines),
longest first: issue 29's "no function over 120 lines outside SIMD
kernels". A function runs from its `fn` line to the closing brace at its
own indentation (rustfmt's layout). Also lists the files over 1,300 lines
(issue 51: a container past ~1,000 lines becomes a folder).

    python3 scripts/long-functions.py [LIMIT] [--check]

With --check (CI), exit 1 when a function or a file outside the SIMD
kernels (files named *simd*) is over its limit.
"""
import os
import re
import sys

args = [a for a in sys.argv[1:] if a != "--check"]
check = "--check" in sys.argv[1:]
limit = int(args[0]) if args else 120
FILE_LIMIT = 1300
long_files = []
root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "src")
found = []
for d, _, files in os.walk(root):
    for f in files:
        if not f.endswith(".rs"):
            continue
        path = os.path.join(d, f)
        lines = open(path, encoding="utf-8").read().split("\n")
        if len(lines) - 1 > FILE_LIMIT:
            long_files.append((len(lines) - 1, os.path.relpath(path, os.path.join(root, ".."))))
        for i, line in enumerate(lines):
            m = re.match(r"^(\s*)(pub(\([a-z]+\))? )?(const )?(unsafe )?fn (\w+)", line)
            if not m or line.rstrip().endswith(";"):
                continue
            close = m.group(1) + "}"
            j = i + 1
            while j < len(lines) and lines[j].rstrip() != close:
                j += 1
            n = j - i + 1
            if n > limit:
                found.append((n, os.path.relpath(path, os.path.join(root, "..")), m.group(6)))
for n, path, name in sorted(found, reverse=True):
    print(f"{n:5} {path} {name}")
for n, path in sorted(long_files, reverse=True):
    print(f"{n:5} {path} (file)")
if check:
    bad = [p for _, p, _ in found if "simd" not in os.path.basename(p)]
    bad += [p for _, p in long_files if "simd" not in os.path.basename(p)]
    if bad:
        print(f"over the limits outside the SIMD kernels: {', '.join(sorted(set(bad)))}")
        sys.exit(1)
