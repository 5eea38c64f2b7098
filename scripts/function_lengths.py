#!/usr/bin/env python3
"""Lengths of every C++ function (universal-ctags' end lines) and file in the repository's libraries.

  python3 scripts/function_lengths.py            # functions over 80 lines and files over 500, longest first
  python3 scripts/function_lengths.py --all      # every function
  python3 scripts/function_lengths.py --check    # exit 1 when a function or a file is over its limit
                                                 # without a `// long:` comment saying why

A function's length counts its lines from the signature to the closing brace. A function or a file may
be longer when a comment `// long: <why>` stands within the three lines above its signature (a file: in
its first 20 lines). A postponement is not a reason: a `// long:` that says "later" excuses nothing. Tests
and generated code are left out.
"""
import json, os, shutil, subprocess, sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FUNCTION_LIMIT, FILE_LIMIT = 80, 500
SKIP = {"build", "tests", ".git", "ros2", "benchmarks"}


def sources():
    for d, dirs, files in os.walk(ROOT):
        dirs[:] = sorted(x for x in dirs if x not in SKIP and not x.startswith("build-"))  # build-package, build-thread ...
        for f in sorted(files):
            if f.endswith((".cpp", ".hpp")):
                yield os.path.relpath(os.path.join(d, f), ROOT)


def functions(paths):
    ctags = shutil.which("ctags-universal") or "ctags"  # Debian's universal-ctags
    out = subprocess.run([ctags, "--output-format=json", "--fields=+ne", "--c++-kinds=+fl", "--extras=-q",
                          "-o", "-"] + paths, cwd=ROOT, capture_output=True, text=True, check=True).stdout
    for line in out.splitlines():
        t = json.loads(line)
        if t.get("kind") in ("function",) and "end" in t and t["end"] >= t["line"]:
            yield t


def excused(lines, first_line, window):
    return any("// long:" in l and "later" not in l.lower() for l in lines[max(0, first_line - 1 - window):first_line])


def main():
    paths = list(sources())
    text = {p: open(os.path.join(ROOT, p), encoding="utf-8").read().splitlines() for p in paths}
    rows = []
    for t in functions(paths):
        n = t["end"] - t["line"] + 1
        name = t["name"] if not t["name"].startswith("__anon") else "lambda"
        scope = [x for x in t.get("scope", "").split("::") if x and not x.startswith("__anon")]
        if scope:
            name = scope[-1] + "::" + name
        rows.append((n, t["path"], t["line"], name, excused(text[t["path"]], t["line"], 3)))
    files = [(len(text[p]), p, excused(text[p], 20, 20)) for p in paths]
    show_all = "--all" in sys.argv
    bad = 0
    for n, p, line, name, ok in sorted(rows, reverse=True):
        if show_all or n > FUNCTION_LIMIT:
            print(f"{n:5d}  {p}:{line}  {name}{'  (long: said why)' if ok else ''}")
            bad += n > FUNCTION_LIMIT and not ok
    for n, p, ok in sorted(files, reverse=True):
        if n > FILE_LIMIT:
            print(f"{n:5d}  {p}  (file){'  (long: said why)' if ok else ''}")
            bad += not ok
    if "--check" in sys.argv and bad:
        print(f"{bad} over the limit ({FUNCTION_LIMIT} lines a function, {FILE_LIMIT} a file) without `// long:`")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
