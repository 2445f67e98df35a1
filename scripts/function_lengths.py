#!/usr/bin/env python3
"""Lists the Rust functions of the repository longer than N lines (default 80), the longest
first, leaving out tests/ and benches/: `python3 scripts/function_lengths.py [N]`.

A function's length runs from its `fn` line to its closing brace. Comments, strings and
character literals are blanked before the braces are counted."""
import re
import subprocess
import sys

FN = re.compile(r"\bfn\s+([A-Za-z_][A-Za-z0-9_]*)")
LITERAL = re.compile(
    r"//[^\n]*|/\*.*?\*/|r(#*)\".*?\"\1|b?\"(?:\\.|[^\"\\])*\"|b?'(?:\\.|[^'\\])'",
    re.S,
)


def blank(src):
    """The source with comments and literals replaced by spaces (newlines kept)."""
    return LITERAL.sub(lambda m: re.sub(r"[^\n]", " ", m.group(0)), src)


def functions(path):
    """(length, line, name) of each function with a body in the file."""
    src = blank(open(path, encoding="utf-8").read())
    out = []
    for m in FN.finditer(src):
        i = m.end()
        depth = 0
        # The body starts at the first `{` before any `;` (a declaration has no body).
        while i < len(src) and src[i] not in "{;":
            i += 1
        if i >= len(src) or src[i] == ";":
            continue
        start = src.count("\n", 0, m.start()) + 1
        for j in range(i, len(src)):
            if src[j] == "{":
                depth += 1
            elif src[j] == "}":
                depth -= 1
                if depth == 0:
                    end = src.count("\n", 0, j) + 1
                    out.append((end - start + 1, start, m.group(1)))
                    break
    return out


def main():
    limit = int(sys.argv[1]) if len(sys.argv) > 1 else 80
    files = subprocess.check_output(["git", "ls-files", "*.rs"], text=True).split()
    files = [f for f in files if not f.startswith(("tests/", "benches/")) and "/tests/" not in f]
    total, long = 0, []
    for f in files:
        for n, line, name in functions(f):
            total += 1
            if n > limit:
                long.append((n, f"{f}:{line}", name))
    print(f"{len(long)} of {total} functions over {limit} lines")
    for n, at, name in sorted(long, reverse=True):
        print(f"{n:5} {at} {name}")


if __name__ == "__main__":
    main()
