#!/usr/bin/env bash
# Draws docs/architecture.svg (and .png) from the build: CMake's graphviz output of the targets' direct
# links, redrawn in the layers of scripts/check_house.py by Debian's graphviz (dot). Run after a change
# of a library's links; House.LibrariesLinkOnlyDownwards checks the same layers in every test run.
set -euo pipefail
cd "$(dirname "$0")/.."
command -v dot >/dev/null || { echo "architecture.sh: needs graphviz (apt-get install graphviz)" >&2; exit 1; }
out=build/graphviz
mkdir -p "$out"
cat >"$out/CMakeGraphVizOptions.cmake" <<'OPTIONS'
set(GRAPHVIZ_EXTERNAL_LIBS FALSE)
set(GRAPHVIZ_GENERATE_PER_TARGET FALSE)
set(GRAPHVIZ_GENERATE_DEPENDERS FALSE)
set(GRAPHVIZ_IGNORE_TARGETS "^test_" "^benchmark_" "^callgrind_" "robodamp_warnings")
OPTIONS
# The options file is read from the build directory.
cp "$out/CMakeGraphVizOptions.cmake" build/CMakeGraphVizOptions.cmake
cmake -S . -B build --graphviz="$out/cmake.dot" >/dev/null
rm -f build/CMakeGraphVizOptions.cmake
python3 scripts/check_house.py picture "$out/cmake.dot" "$out/robodamp.dot"
# Drawn without the links another path already implies (graphviz's transitive reduction): the picture
# shows what each library adds; build/graphviz/robodamp.dot keeps every direct link.
tred "$out/robodamp.dot" >"$out/robodamp_reduced.dot"
dot -Tsvg "$out/robodamp_reduced.dot" -o docs/architecture.svg
dot -Tpng -Gdpi=110 "$out/robodamp_reduced.dot" -o docs/architecture.png
echo "wrote docs/architecture.svg and docs/architecture.png"
