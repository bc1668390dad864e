#!/usr/bin/env python3
"""List the functions longer than a limit outside tests (issue 37: none over 150 lines).

    scripts/long-functions.py [LIMIT] [DIR ...]      (defaults: 150, grainlaw-core/src/scenarios datasets/src)

Prints `LINES FILE:LINE NAME` per function, longest first; exits 1 when one is listed. A
function is counted from its `fn` line to its closing brace (braces in strings, character
literals and `//` comments ignored); a file's `#[cfg(test)]` module and what follows it are
left out, as are the files under `tests/`. A nested function counts inside its parent.
"""
import os
import re
import sys

FN = re.compile(r"\s*(pub(\([^)]*\))?\s+)?(const\s+)?(async\s+)?(unsafe\s+)?fn\s+(\w+)")


def code(line):
    """The line without its comment, strings and character literals."""
    line = re.sub(r'"(\\.|[^"\\])*"', '""', line)
    line = re.sub(r"'(\\.|[^'\\])'", "''", line)
    return re.sub(r"//.*", "", line)


def long_functions(path, limit):
    lines = open(path, encoding="utf-8").read().split("\n")
    found = []
    for i, line in enumerate(lines):
        if re.match(r"\s*#\[cfg\(test\)\]", line):
            break
        m = FN.match(line)
        if not m:
            continue
        depth, opened, j = 0, False, i
        while j < len(lines):
            text = code(lines[j])
            for ch in text:
                if ch == "{":
                    depth, opened = depth + 1, True
                elif ch == "}":
                    depth -= 1
            if opened and depth == 0:
                break
            if not opened and text.rstrip().endswith(";"):
                break
            j += 1
        n = j - i + 1
        if opened and n > limit:
            found.append((n, f"{path}:{i + 1}", m.group(6)))
    return found


def main():
    args = sys.argv[1:]
    limit = int(args.pop(0)) if args and args[0].isdigit() else 150
    dirs = args or ["grainlaw-core/src/scenarios", "datasets/src"]
    found = []
    for d in dirs:
        for root, _, files in os.walk(d):
            for f in sorted(files):
                if f.endswith(".rs"):
                    found += long_functions(os.path.join(root, f), limit)
    for n, where, name in sorted(found, reverse=True):
        print(n, where, name)
    sys.exit(1 if found else 0)


if __name__ == "__main__":
    main()
