#!/usr/bin/env python3
"""Import circles in parvo's source: exit 1 and name them when there are any.

Two graphs are checked:

- the library's top-level modules (src/*.rs and src/*/ except main.rs and
  cli/): module A imports module B when a file of A names `crate::B` (or,
  from a file directly under src/, `super::B`), or a crate-root re-export
  of B (`crate::Texture`, resolved through lib.rs's `pub use` lines);
- the command line's files (src/cli/*.rs and src/main.rs): file A imports
  file B when it names `super::B`, `crate::cli::B` (B a file of cli/) or,
  for a child file, its parent `super::NAME` of an item that lives in
  cli/mod.rs. The CLI's files must import downward only: no circle, the
  dispatcher (mod.rs) included.

Comments (`//`, `//!`, `///`) are not read, so a doc link is no import.
Every import of a circle is printed with its file and line, so the edge to
cut can be chosen. Run: python3 scripts/import-cycles.py [SRC_DIR]
"""

import os
import re
import sys
from collections import defaultdict

SRC = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "src")
SRC = os.path.normpath(SRC)

IDENT = r"[A-Za-z_][A-Za-z0-9_]*"


def code_lines(path):
    """The file's lines with comments and string literals blanked."""
    out = []
    in_block = 0
    with open(path, encoding="utf-8") as f:
        for line in f:
            s = line
            if in_block:
                end = s.find("*/")
                if end < 0:
                    out.append("")
                    continue
                s = s[end + 2 :]
                in_block = 0
            s = re.sub(r'"(?:\\.|[^"\\])*"', '""', s)
            s = re.sub(r"/\*.*?\*/", "", s)
            start = s.find("/*")
            if start >= 0:
                s = s[:start]
                in_block = 1
            cut = s.find("//")
            if cut >= 0:
                s = s[:cut]
            out.append(s)
    return out


def paths_in(text):
    """Every path `a::b::...` in `text`, grouped `use` braces expanded."""
    found = []
    # Expand one level of braces at a time: `x::{a, b::{c, d}}`.
    def expand(prefix, body):
        parts, depth, cur = [], 0, ""
        for ch in body:
            if ch == "{":
                depth += 1
            elif ch == "}":
                depth -= 1
            if ch == "," and depth == 0:
                parts.append(cur)
                cur = ""
            else:
                cur += ch
        parts.append(cur)
        for p in parts:
            p = p.strip()
            if not p:
                continue
            m = re.match(r"^(.*?)::\{(.*)\}$", p, re.S)
            if m:
                expand(prefix + m.group(1).strip() + "::", m.group(2))
            else:
                found.append(prefix + p.split(" as ")[0].strip())

    for m in re.finditer(r"\b((?:crate|super|self)(?:::" + IDENT + r")*)::\{", text):
        # Find the matching brace.
        start = m.end()
        depth, i = 1, start
        while i < len(text) and depth:
            depth += {"{": 1, "}": -1}.get(text[i], 0)
            i += 1
        expand(m.group(1) + "::", text[start : i - 1])
    for m in re.finditer(r"\b((?:crate|super)(?:::" + IDENT + r")+)", text):
        found.append(m.group(1))
    return found


def module_of(path):
    """`src/io/exr.rs` -> ['io', 'exr']; `src/io/mod.rs` -> ['io']."""
    rel = os.path.relpath(path, SRC)[:-3].split(os.sep)
    if rel[-1] == "mod":
        rel = rel[:-1]
    return rel


def rust_files():
    for root, _, files in os.walk(SRC):
        for f in sorted(files):
            if f.endswith(".rs"):
                yield os.path.join(root, f)


def root_reexports():
    """Names lib.rs re-exports at the crate root -> their module."""
    names = {}
    text = "\n".join(code_lines(os.path.join(SRC, "lib.rs")))
    for m in re.finditer(r"pub use (" + IDENT + r")::(\{[^;]*\}|[^;]*);", text, re.S):
        module, items = m.group(1), m.group(2).strip("{} \n")
        for item in items.split(","):
            item = item.strip().split(" as ")[-1].split("::")[-1].strip()
            if item:
                names[item] = module
    return names


def sccs(nodes, edges):
    """Tarjan's strongly connected components."""
    index, low, stack, on, out = {}, {}, [], set(), []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(edges.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            out.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in sorted(nodes):
        if v not in index:
            visit(v)
    return out


def report(title, nodes, edges, why):
    bad = [c for c in sccs(nodes, edges) if len(c) > 1]
    if not bad:
        print(f"{title}: no import circle ({len(nodes)} nodes, "
              f"{sum(len(v) for v in edges.values())} edges)")
        return 0
    for comp in bad:
        print(f"{title}: an import circle of {len(comp)}: {', '.join(comp)}")
        members = set(comp)
        for a in comp:
            for b in sorted(edges.get(a, ())):
                if b in members:
                    places = sorted(set(why[(a, b)]))
                    more = f" and {len(places) - 2} more" if len(places) > 2 else ""
                    print(f"    {a} -> {b}  ({', '.join(places[:2])}{more})")
    return 1


def library():
    exports = root_reexports()
    tops = set()
    for p in rust_files():
        m = module_of(p)
        if m and m[0] not in ("lib", "main", "cli"):
            tops.add(m[0])
    edges, why = defaultdict(set), defaultdict(list)
    for p in rust_files():
        m = module_of(p)
        if not m or m[0] not in tops:
            continue
        here = m[0]
        for n, line in enumerate(code_lines(p), 1):
            for path in paths_in(line):
                parts = path.split("::")
                target = None
                if parts[0] == "crate" and len(parts) > 1:
                    target = parts[1] if parts[1] in tops else exports.get(parts[1])
                elif parts[0] == "super" and len(m) == 1 and len(parts) > 1:
                    target = parts[1] if parts[1] in tops else exports.get(parts[1])
                if target and target != here and target in tops:
                    edges[here].add(target)
                    why[(here, target)].append(f"{os.path.relpath(p, SRC)}:{n}")
    return report("library modules", tops, edges, why)


def cli():
    cli_dir = os.path.join(SRC, "cli")
    if not os.path.isdir(cli_dir):
        return 0
    files = {f[:-3] for f in os.listdir(cli_dir) if f.endswith(".rs")}
    children = files - {"mod"}
    # Items defined in cli/mod.rs: a child naming `super::ITEM` imports it.
    mod_items = set()
    for line in code_lines(os.path.join(cli_dir, "mod.rs")):
        m = re.match(r"\s*(?:pub(?:\([^)]*\))?\s+)?(?:fn|struct|enum|const|static|type|trait)\s+(" + IDENT + ")", line)
        if m:
            mod_items.add(m.group(1))
    edges, why = defaultdict(set), defaultdict(list)
    for f in sorted(files):
        p = os.path.join(cli_dir, f + ".rs")
        for n, line in enumerate(code_lines(p), 1):
            if f == "mod":
                for m in re.finditer(r"\bmod (" + IDENT + ")", line):
                    if m.group(1) in children:
                        edges["mod"].add(m.group(1))
                        why[("mod", m.group(1))].append(f"cli/mod.rs:{n}")
            for path in paths_in(line):
                parts = path.split("::")
                if parts[0] == "crate" and len(parts) > 2 and parts[1] == "cli":
                    parts = ["super"] + parts[2:]
                if parts[0] == "super" and len(parts) > 1 and f != "mod":
                    target = parts[1] if parts[1] in children else (
                        "mod" if parts[1] in mod_items else None)
                elif parts[0] == "self" and f == "mod" and len(parts) > 1:
                    target = parts[1] if parts[1] in children else None
                else:
                    target = None
                if target and target != f:
                    edges[f].add(target)
                    why[(f, target)].append(f"cli/{f}.rs:{n}")
    return report("command-line files", files, edges, why)


if __name__ == "__main__":
    sys.exit(max(library(), cli()))
