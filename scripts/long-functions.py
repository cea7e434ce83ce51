#!/usr/bin/env python3
"""List the functions under src/ longer than a limit (default 120 lines),
longest first: issue 29's "no function over 120 lines outside SIMD
kernels". A function runs from its `fn` line to the closing brace at its
own indentation (rustfmt's layout).

    python3 scripts/long-functions.py [LIMIT]
"""
import os
import re
import sys

limit = int(sys.argv[1]) if len(sys.argv) > 1 else 120
root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "src")
found = []
for d, _, files in os.walk(root):
    for f in files:
        if not f.endswith(".rs"):
            continue
        path = os.path.join(d, f)
        lines = open(path, encoding="utf-8").read().split("\n")
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
