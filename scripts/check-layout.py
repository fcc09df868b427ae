#!/usr/bin/env python3
"""Checks the layout rules of the repository (run by scripts/test-all.sh).

1. No Rust file is named with the `fast_` prefix: the engine's files are
   named by what they do, under folders named by pipeline stage.
2. No Rust file is over 700 lines, except tests.
3. No import cycle between the engine's files: data flows one way
   (volume -> dht -> spectrum -> slice -> image -> render, plan beside).
   A file imports another when it names an item of it through `crate::`,
   `super::`, `self::` or a child module; a cycle is a set of files that
   reach each other that way. Test modules are left out.

Usage: python3 scripts/check-layout.py   (exit 1 and one line per problem)
"""

import os
import re
import sys

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
MAX_LINES = 700
SKIP_DIRS = {"target", ".git", "node_modules"}


def rust_files():
    for d, dirs, files in os.walk(ROOT):
        dirs[:] = sorted(x for x in dirs if x not in SKIP_DIRS)
        for f in sorted(files):
            if f.endswith(".rs"):
                yield os.path.relpath(os.path.join(d, f), ROOT)


def is_test(path):
    parts = path.split(os.sep)
    return "tests" in parts[:-1] or parts[-1] in ("tests.rs", "test_volume.rs") or "benches" in parts


def strip_comments(text):
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
    text = re.sub(r"//[^\n]*", "", text)
    # String literals may hold `crate::` in messages.
    return re.sub(r'"(?:\\.|[^"\\])*"', '""', text)


def without_test_modules(text):
    """The text with inline `#[cfg(test)] mod NAME { ... }` blocks removed."""
    out, i = [], 0
    for m in re.finditer(r"#\[cfg\(test\)\]\s*(?:pub(?:\([^)]*\))?\s+)?mod\s+\w+\s*\{", text):
        if m.start() < i:
            continue
        out.append(text[i : m.start()])
        depth, j = 1, m.end()
        while j < len(text) and depth:
            depth += {"{": 1, "}": -1}.get(text[j], 0)
            j += 1
        i = j
    out.append(text[i:])
    return "".join(out)


def expand_use(tree):
    """`a::{b, c::{d, e}}` -> ['a::b', 'a::c::d', 'a::c::e']."""
    tree = re.sub(r"\s+", "", tree)
    m = re.match(r"^(.*?)\{(.*)\}$", tree)
    if not m:
        return [re.sub(r"\s+as\s+\w+$", "", tree)]
    prefix, inner = m.group(1), m.group(2)
    parts, depth, cur = [], 0, ""
    for ch in inner:
        if ch == "," and depth == 0:
            parts.append(cur)
            cur = ""
            continue
        depth += {"{": 1, "}": -1}.get(ch, 0)
        cur += ch
    parts.append(cur)
    out = []
    for p in parts:
        if p:
            out += [prefix + q for q in expand_use(p)]
    return out


class Crate:
    def __init__(self, src):
        self.src = src
        self.files = {}  # module path tuple -> file
        for d, _, files in os.walk(os.path.join(ROOT, src)):
            for f in files:
                if not f.endswith(".rs"):
                    continue
                rel = os.path.relpath(os.path.join(d, f), os.path.join(ROOT, src))
                parts = rel[:-3].split(os.sep)
                if parts[-1] in ("mod", "lib"):
                    parts = parts[:-1]
                self.files[tuple(parts)] = os.path.join(src, rel)

    def module_of(self, path):
        for mod, f in self.files.items():
            if f == path:
                return mod
        raise KeyError(path)

    def resolve(self, mod, segments):
        """The file holding the deepest module named by `segments` from `mod`."""
        segs = list(segments)
        if not segs:
            return None
        if segs[0] == "crate":
            base = ()
            segs = segs[1:]
        else:
            base = mod
            while segs and segs[0] in ("super", "self"):
                if segs.pop(0) == "super":
                    base = base[:-1]
        full = base + tuple(segs)
        for k in range(len(full), -1, -1):
            if full[:k] in self.files:
                return self.files[full[:k]]
        return None

    def edges(self):
        graph = {}
        for mod, path in self.files.items():
            if is_test(path):
                continue
            text = without_test_modules(strip_comments(open(os.path.join(ROOT, path)).read()))
            children = set(re.findall(r"^\s*(?:pub(?:\([^)]*\))?\s+)?mod\s+(\w+)\s*;", text, re.M))
            targets = set()
            for m in re.finditer(r"\buse\s+([^;]+);", text):
                for p in expand_use(m.group(1)):
                    segs = [s for s in p.split("::") if s]
                    if segs and (segs[0] in ("crate", "super", "self") or segs[0] in children):
                        targets.add(self.resolve(mod, segs))
            for m in re.finditer(r"\b((?:crate|super)(?:::\w+)+)", text):
                targets.add(self.resolve(mod, m.group(1).split("::")))
            targets.discard(None)
            targets.discard(path)
            graph[path] = {t for t in targets if not is_test(t)}
        return graph


def cycles(graph):
    """Strongly connected components of more than one file (Tarjan)."""
    index, low, stack, on, out = {}, {}, [], set(), []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
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
            if len(comp) > 1:
                out.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def main():
    problems = []
    for path in rust_files():
        name = os.path.basename(path)
        if name.startswith("fast_"):
            problems.append(f"{path}: named with the `fast_` prefix; name it by what it does")
        lines = sum(1 for _ in open(os.path.join(ROOT, path)))
        if lines > MAX_LINES and not is_test(path):
            problems.append(f"{path}: {lines} lines, over {MAX_LINES}; split it by job")
    engine = Crate("engine/src")
    graph = engine.edges()
    for comp in cycles(graph):
        detail = "; ".join(
            f"{a} -> {b}" for a in comp for b in sorted(graph[a]) if b in comp
        )
        problems.append(f"import cycle between engine files: {detail}")
    for p in problems:
        print(f"check-layout: {p}")
    if problems:
        return 1
    print(f"check-layout: ok ({len(graph)} engine files, no cycle; no fast_ file; none over {MAX_LINES} lines)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
