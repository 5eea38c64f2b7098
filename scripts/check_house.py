#!/usr/bin/env python3
"""House checks that read the tree and the build (ctest House.*), and the architecture picture:

  python3 scripts/check_house.py sources              # nothing cites a file outside the repository
  python3 scripts/check_house.py layers BUILD_DIR     # every library links and includes only downwards
  python3 scripts/check_house.py picture CMAKE.dot OUT.dot  # the layered picture from CMake's graphviz
  python3 scripts/check_house.py links                # every link between README.md and docs/ resolves
  python3 scripts/check_house.py parser-free          # rt/, control/, rt_settings/ use no config/ and no yaml-cpp
  python3 scripts/check_house.py format               # every .cpp/.hpp as clang-format 14 writes it (.clang-format)
"""
import glob
import json
import os
import re
import shutil
import subprocess
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
        dirs[:] = sorted(x for x in dirs if x not in SKIP_DIRS and not x.startswith("build-"))  # build-package, build-thread ...
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


# The architecture: each library's layer, bottom first. A library may link and include only libraries of
# lower layers (docs/architecture.md). A new library must be placed here.
LAYERS = [
    ("foundation", ["units", "threads", "rt_settings", "fields"]),
    ("data and numbers", ["filters", "config", "plot", "measfiles"]),
    ("physics", ["modal", "robot"]),
    ("controller and plant", ["control", "sim_plant"]),
    ("analysis and the loop", ["analysis", "rt"]),
    ("machining, devices, network", ["milling", "drivers", "dds"]),
    ("studies and composition", ["identify", "tune", "hil", "runtime", "dashboard"]),
    ("commissioning and the command line's machinery", ["commission", "command_line"]),
    ("command line", ["apps"]),
]
# Folder -> CMake target (the folder's name with the robodamp_ prefix, but for these).
TARGET = {"sim_plant": "robodamp_sim", "apps": "robodamp_cli"}


# Header-only INTERFACE libraries: CMake's code model lists no build dependency on them, so a use is not
# checked against the links; its layer still is.
HEADER_ONLY = {"units", "threads", "rt_settings", "fields", "control"}


def report(bad, failed, passed):
    """Each finding, then the verdict: failed (exit status 1) when there is one, passed (0) when none."""
    for b in bad:
        print(b)
    print(failed if bad else passed)
    return 1 if bad else 0


def layer_of():
    out = {}
    for i, (_, folders) in enumerate(LAYERS):
        for f in folders:
            out[f] = i
    return out


def build_graph(build_dir):
    """Each robodamp library's dependencies (transitive) from CMake's file-API code model."""
    reply = os.path.join(build_dir, ".cmake", "api", "v1", "reply")
    index = sorted(glob.glob(os.path.join(reply, "index-*.json")))
    if not index:
        return None
    objects = json.load(open(index[-1]))["objects"]
    model = json.load(open(os.path.join(reply, [o for o in objects if o["kind"] == "codemodel"][0]["jsonFile"])))
    targets = {}
    for t in model["configurations"][0]["targets"]:
        targets[t["id"]] = json.load(open(os.path.join(reply, t["jsonFile"])))
    folder = {v: k for k, v in TARGET.items()}
    graph = {}
    for t in targets.values():
        name = t["name"]
        if not name.startswith("robodamp_") or t["type"] != "STATIC_LIBRARY":
            continue
        f = folder.get(name, name[len("robodamp_"):])
        graph[f] = sorted({folder.get(targets[d["id"]]["name"], targets[d["id"]]["name"][len("robodamp_"):])
                           for d in t.get("dependencies", []) if targets[d["id"]]["name"].startswith("robodamp_")})
    return graph


def includes(folder):
    """The library folders a folder's sources include from."""
    used = set()
    pattern = re.compile(r'^\s*#\s*include\s+"([a-z_0-9]+)/')
    for d, _, names in os.walk(os.path.join(ROOT, folder)):
        for n in names:
            if n.endswith((".cpp", ".hpp", ".in")):
                for line in open(os.path.join(d, n), encoding="utf-8", errors="replace"):
                    m = pattern.match(line)
                    if m and os.path.isdir(os.path.join(ROOT, m.group(1))):
                        used.add((m.group(1), os.path.relpath(os.path.join(d, n), ROOT)))
    return used


# The real-time core knows no configuration file (issue 54): these folders neither include config/ or yaml-cpp
# nor link, through any library they link, robodamp_config or yaml-cpp. config/ fills their plain settings
# (rt_settings/rt_settings.hpp).
PARSER_FREE = ["rt_settings", "control", "rt"]


def linked(folder, seen=None):
    """Every target a folder's library links, through the libraries it links, read from the CMakeLists.txt."""
    seen = set() if seen is None else seen
    path = os.path.join(ROOT, folder, "CMakeLists.txt")
    if not os.path.exists(path):
        return seen
    text = open(path, encoding="utf-8").read()
    for m in re.finditer(r"target_link_libraries\(\s*robodamp_\w+([^)]*)\)", text):
        for token in m.group(1).split():
            if token in ("PUBLIC", "PRIVATE", "INTERFACE") or token in seen:
                continue
            seen.add(token)
            if token.startswith("robodamp_"):
                inv = {v: k for k, v in TARGET.items()}
                linked(inv.get(token, token[len("robodamp_"):]), seen)
    return seen


def parser_free():
    bad = []
    include = re.compile(r'^\s*#\s*include\s+[<"](config/|yaml-cpp/)')
    for folder in PARSER_FREE:
        for d, _, names in os.walk(os.path.join(ROOT, folder)):
            for n in names:
                if n.endswith((".cpp", ".hpp")):
                    for i, line in enumerate(open(os.path.join(d, n), encoding="utf-8", errors="replace"), 1):
                        if include.match(line):
                            bad.append(f"{os.path.relpath(os.path.join(d, n), ROOT)}:{i}: {line.strip()}")
        for t in sorted(linked(folder) & {"robodamp_config", "yaml-cpp"}):
            bad.append(f"{folder}/ links {t} (through the libraries it links)")
    return report(bad, f"{len(bad)} use(s) of the parser in the real-time core",
                  f"{', '.join(f + '/' for f in PARSER_FREE)} include and link no configuration parser and no yaml-cpp")


def layers(build_dir):
    graph = build_graph(build_dir)
    if graph is None:
        print(f"no CMake code model in {build_dir}: configure it again (cmake -S . -B {build_dir})")
        return 1
    level = layer_of()
    bad = []
    for lib, deps in sorted(graph.items()):
        if lib not in level:
            bad.append(f"{lib}: not placed in a layer (scripts/check_house.py LAYERS)")
            continue
        for d in deps:
            if d in level and level[d] >= level[lib]:
                bad.append(f"{lib} (layer {level[lib]}, {LAYERS[level[lib]][0]}) links {d} "
                           f"(layer {level[d]}, {LAYERS[level[d]][0]}): a library links only downwards")
        for used, where in sorted(includes(lib)):
            if used != lib and used in level and used not in deps and used not in HEADER_ONLY:
                bad.append(f"{where} includes {used}/, which {lib} does not link")
            elif used != lib and used in level and level[used] >= level[lib]:
                bad.append(f"{where} includes {used}/ (layer {level[used]}) from layer {level[lib]}")
    return report(bad, f"{len(bad)} link(s) or include(s) against the layers",
                  f"{len(graph)} libraries link and include only downwards ({len(LAYERS)} layers)")


def picture(cmake_dot, out_dot):
    """CMake's --graphviz output (direct links) redrawn in the layers, robodamp's libraries only."""
    text = open(cmake_dot).read()
    label = dict(re.findall(r'"(node\d+)"\s*\[\s*label\s*=\s*"([^"]+)"', text))
    edges = re.findall(r'"(node\d+)"\s*->\s*"(node\d+)"', text)
    folder = {v: k for k, v in TARGET.items()}
    def name(node):
        t = label.get(node, "")
        if t == "robodamp":
            return "apps"
        if not t.startswith("robodamp_"):
            return None
        return folder.get(t, t[len("robodamp_"):])
    level = layer_of()
    keep = {(name(a), name(b)) for a, b in edges if name(a) in level and name(b) in level and name(a) != name(b)}
    lines = ["digraph robodamp {", '  rankdir=BT; node [shape=box, style="rounded,filled", fillcolor="#eef3fb", '
             'fontname="Helvetica"]; edge [color="#55607a", arrowsize=0.7];', '  ranksep=0.6; nodesep=0.35;']
    for i, (title, folders) in enumerate(LAYERS):
        lines.append(f'  subgraph cluster_{i} {{ label="{i}: {title}"; fontname="Helvetica"; fontsize=11; '
                     f'color="#c8cfdd"; style=dashed; rank=same; ' + " ".join(f'"{f}";' for f in folders) + " }")
    for a, b in sorted(keep):
        lines.append(f'  "{a}" -> "{b}";')
    lines.append("}")
    open(out_dot, "w").write("\n".join(lines) + "\n")
    print(f"{len(keep)} direct links among {len(level)} libraries -> {out_dot}")
    return 0


def heading_anchors(path):
    """The anchors a Markdown renderer gives the page's headings (GitHub's rule: lower case, punctuation
    other than '-' and '_' dropped, spaces to '-')."""
    out, fence = set(), False
    for line in open(path, encoding="utf-8"):
        fence = fence != line.startswith("```")
        m = None if fence else re.match(r"^#+\s+(.*)", line)
        if m:
            out.add(re.sub(r"[^\w\- ]", "", m.group(1).strip().lower()).replace(" ", "-"))
    return out


def links():
    """Every relative link of README.md and docs/*.md names a file that exists and, with '#', a heading of it."""
    bad, count = [], 0
    for page in ["README.md"] + sorted(os.path.relpath(p, ROOT) for p in glob.glob(os.path.join(ROOT, "docs", "*.md"))):
        fence = False
        for n, line in enumerate(open(os.path.join(ROOT, page), encoding="utf-8"), 1):
            fence = fence != line.startswith("```")
            for m in ([] if fence else re.finditer(r"\]\(([^)\s]+)\)", line)):
                url = m.group(1)
                if re.match(r"^[a-z]+:", url):
                    continue
                count += 1
                path, _, anchor = url.partition("#")
                target = os.path.normpath(os.path.join(ROOT, os.path.dirname(page), path)) if path else os.path.join(ROOT, page)
                if not os.path.exists(target):
                    bad.append(f"{page}:{n}: {url}: no such file")
                elif anchor and target.endswith(".md") and anchor not in heading_anchors(target):
                    bad.append(f"{page}:{n}: {url}: no heading with that anchor")
    return report(bad, f"{len(bad)} of {count} links do not resolve", f"all {count} links resolve")


def sources_cpp():
    """The repository's C++ sources and headers (git's list, else every .cpp/.hpp outside build directories)."""
    try:
        out = subprocess.run(["git", "-C", ROOT, "ls-files", "*.cpp", "*.hpp"], capture_output=True, text=True, check=True)
        return [f for f in out.stdout.split("\n") if f]
    except (OSError, subprocess.CalledProcessError):
        found = []
        for d, dirs, names in os.walk(ROOT):
            dirs[:] = [x for x in dirs if not x.startswith(("build", "."))]
            found += [os.path.relpath(os.path.join(d, n), ROOT) for n in names if n.endswith((".cpp", ".hpp"))]
        return sorted(found)


def formatted():
    """Every C++ file is as clang-format 14 writes it with the repository's .clang-format (issue 54)."""
    tool = shutil.which("clang-format-14") or shutil.which("clang-format")
    if tool is None:
        print("clang-format-14 is not installed (scripts/setup.sh installs it)")
        return 1
    files = sources_cpp()
    bad = []
    for i in range(0, len(files), 50):
        r = subprocess.run([tool, "--dry-run", "--Werror", "--style=file"] + files[i:i + 50], cwd=ROOT,
                           capture_output=True, text=True)
        for line in r.stderr.splitlines():
            m = re.match(r"^(\S+?):(\d+):\d+: error:", line)
            if m:
                bad.append(f"{os.path.relpath(m.group(1), ROOT) if os.path.isabs(m.group(1)) else m.group(1)}:{m.group(2)}")
    where = sorted({b.rsplit(":", 1)[0] for b in bad})
    return report([f"{w}: not as clang-format writes it (clang-format-14 -i {w})" for w in where],
                  f"{len(where)} of {len(files)} files not formatted ({len(bad)} places)",
                  f"all {len(files)} C++ files formatted (clang-format 14, .clang-format)")


if __name__ == "__main__":
    checks = {"sources": (sources, 0), "layers": (layers, 1), "picture": (picture, 2), "links": (links, 0),
              "parser-free": (parser_free, 0), "format": (formatted, 0)}
    if len(sys.argv) < 2 or sys.argv[1] not in checks or len(sys.argv) != 2 + checks[sys.argv[1]][1]:
        print(__doc__)
        sys.exit(2)
    sys.exit(checks[sys.argv[1]][0](*sys.argv[2:]))
