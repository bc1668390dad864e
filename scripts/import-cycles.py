#!/usr/bin/env python3
"""Import cycles between the modules of a Rust crate (issue 37: no module imports one that
imports it back).

    scripts/import-cycles.py DIR [DIR ...]     e.g. dem/src identify/src src

Each DIR is a crate's source folder. A module (`a.rs`, `a/mod.rs`, `a/b.rs` -> `a::b`)
depends on the modules its non-test code names through `crate::` or `super::` paths (in
`use` items, `use` groups `{...}` included, and in expressions); comments, doc comments and
the `#[cfg(test)] mod tests` module are left out. A path that names an item of a module
counts as that module (`crate::cell::Mat` -> `cell`; `crate::fc::FcProblem`, an item re-exported
by `fc.rs`, -> `fc`). The strongly connected components of more than one module are the
import cycles: one line each, `SIZE [modules]`, under the DIR they are in.

Exit code: 0 when no DIR has a cycle, 1 when one has, 2 on a usage error.
"""

import os
import re
import sys

IDENT = r"[A-Za-z_][A-Za-z_0-9]*"


def strip(src):
    """The source without its test module and comments."""
    src = re.split(r"#\[cfg\(test\)\]\s*mod tests\b", src)[0]
    src = re.sub(r"/\*.*?\*/", "", src, flags=re.S)
    return "\n".join(re.sub(r"//.*", "", line) for line in src.split("\n"))


def expand(text, pos):
    """The paths of the use tree or path that starts at `text[pos]`: lists of segments
    (identifiers, `self`, `*`), reading `a::b::{c, d::{e, f}}` as [a,b,c], [a,b,d,e], [a,b,d,f]."""
    prefix = []
    while True:
        m = re.compile(r"\s*(" + IDENT + r"|\*)").match(text, pos)
        if m:
            prefix.append(m.group(1))
            pos = m.end()
            m2 = re.compile(r"\s*::").match(text, pos)
            if m2:
                pos = m2.end()
                continue
            return [prefix]
        m = re.compile(r"\s*\{").match(text, pos)
        if not m:
            return [prefix]
        # A group: split at the top-level commas.
        depth, start, i, out = 1, m.end(), m.end(), []
        while i < len(text) and depth:
            c = text[i]
            if c == "{":
                depth += 1
            elif c == "}":
                depth -= 1
            if (c == "," and depth == 1) or depth == 0:
                part = text[start:i]
                if part.strip():
                    out.extend(prefix + p for p in expand(part, 0))
                start = i + 1
            i += 1
        return out or [prefix]


def modules(root):
    """`{module: source}` of the crate under `root` (`lib.rs`/`main.rs` are the root, '')."""
    mods = {}
    for dirpath, _, files in os.walk(root):
        for f in files:
            if not f.endswith(".rs"):
                continue
            path = os.path.join(dirpath, f)
            rel = os.path.relpath(path, root)[:-3].replace(os.sep, "::")
            if rel.endswith("::mod"):
                rel = rel[: -len("::mod")]
            if rel in ("lib", "main"):
                rel = ""
            with open(path, encoding="utf-8") as fh:
                mods[rel] = strip(fh.read())
    return mods


def dependencies(mods):
    """`{module: set of modules it names}`, itself and the crate root left out."""
    names = set(mods)
    graph = {}
    for m, src in mods.items():
        deps = set()
        for hit in re.finditer(r"\b(crate|super)\s*::", src):
            base = [] if hit.group(1) == "crate" else m.split("::")[:-1]
            pos = hit.end()
            while hit.group(1) == "super":
                more = re.compile(r"\s*super\s*::").match(src, pos)
                if not more:
                    break
                base, pos = base[:-1], more.end()
            for path in expand(src, pos):
                segs = base + [s for s in path if s not in ("self", "*")]
                # The longest prefix of the path that is a module.
                for k in range(len(segs), 0, -1):
                    cand = "::".join(segs[:k])
                    if cand in names:
                        deps.add(cand)
                        break
        deps.discard(m)
        deps.discard("")
        graph[m] = deps
    return graph


def cycles(graph):
    """The strongly connected components of more than one module (Tarjan), sorted."""
    index, low, stack, on, out = {}, {}, [], set(), []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(graph.get(v, ())):
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

    sys.setrecursionlimit(100000)
    for v in sorted(graph):
        if v not in index:
            visit(v)
    return sorted(out)


def main(argv):
    if len(argv) < 2 or any(a.startswith("-") for a in argv[1:]):
        print(__doc__.strip(), file=sys.stderr)
        return 2
    found = False
    for root in argv[1:]:
        if not os.path.isdir(root):
            print(f"{root}: not a directory", file=sys.stderr)
            return 2
        for comp in cycles(dependencies(modules(root))):
            found = True
            print(f"{root}: {len(comp)} {comp}")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
