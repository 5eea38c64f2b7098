#!/usr/bin/env python3
"""House checks that read the tree (ctest House.*):

  python3 scripts/check_house.py sources    # nothing cites a file outside the repository
"""
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SKIP_DIRS = {"build", ".git"}
TEXT = (".cpp", ".hpp", ".h", ".in", ".txt", ".md", ".yaml", ".yml", ".py", ".sh", ".csv", ".idl", ".msg",
        ".html", ".js", ".css", ".cmake", ".service", ".xml", ".json")
# A path outside the repository, the old reference file, and the sources' old code names: a user knows a
# paper by its authors and year (docs/physics.md).
OUTSIDE = re.compile(r"\.\./shared|shared/reference|REFERENCE\.md|[Ss]eed[ _]?00[0-4]")


def files():
    for d, dirs, names in os.walk(ROOT):
        dirs[:] = sorted(x for x in dirs if x not in SKIP_DIRS)
        for n in sorted(names):
            if n.endswith(TEXT) or n in ("CMakeLists.txt", "run"):
                yield os.path.join(d, n)


def sources():
    this = os.path.abspath(__file__)
    bad = []
    for f in files():
        if os.path.abspath(f) == this:
            continue
        rel = os.path.relpath(f, ROOT)
        if OUTSIDE.search(rel):
            bad.append(f"{rel}: the file's name")
        with open(f, encoding="utf-8", errors="replace") as fh:
            for i, line in enumerate(fh, 1):
                m = OUTSIDE.search(line)
                if m:
                    bad.append(f"{rel}:{i}: '{m.group(0)}' in: {line.strip()[:120]}")
    for b in bad:
        print(b)
    print(f"{len(bad)} citation(s) of a source outside the repository (cite docs/physics.md and the papers)"
          if bad else "no source outside the repository is cited")
    return 1 if bad else 0


if __name__ == "__main__":
    checks = {"sources": sources}
    if len(sys.argv) != 2 or sys.argv[1] not in checks:
        print(__doc__)
        sys.exit(2)
    sys.exit(checks[sys.argv[1]]())
