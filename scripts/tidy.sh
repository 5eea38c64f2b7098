#!/usr/bin/env bash
# clang-tidy 14 with the repository's .clang-tidy (bugprone, performance, the modernisations that carry meaning)
# over the real-time path and the devices: rt/, filters/, drivers/, threads/ and the headers they include from
# rt_settings/, control/, fields/ and units/ (HeaderFilterRegex); and the command line's machinery, where every
# option a user types is parsed: command_line/ and config/number_text. Every finding is an error. Needs the build's
# compile_commands.json (scripts/setup.sh builds it). CI runs it (CI=true in scripts/test.sh); about 3 minutes of
# CPU here. Why not the whole tree: each translation unit costs 5-20 s under clang's front end (Eigen, Fast DDS),
# 250 of them half an hour on CI's two cores.
set -euo pipefail
cd "$(dirname "$0")/.."
tool=$(command -v clang-tidy-14 || command -v clang-tidy || true)
[[ -n $tool ]] || { echo "tidy.sh: clang-tidy-14 is not installed (scripts/setup.sh installs it)" >&2; exit 1; }
[[ -f build/compile_commands.json ]] || { echo "tidy.sh: no build/compile_commands.json: run scripts/setup.sh" >&2; exit 1; }
files=$(git ls-files 'rt/*.cpp' 'filters/*.cpp' 'drivers/*.cpp' 'threads/*.cpp' 'command_line/*.cpp' 'config/number_text.cpp')
log=$(mktemp)
db=$(mktemp -d)
trap 'rm -rf "$log" "$db"' EXIT
# The build's compile commands without GCC's precompiled header (cmake/build_speed.cmake), which clang cannot
# read: each file is checked with exactly the includes it names.
python3 - build/compile_commands.json "$db/compile_commands.json" <<'PY'
import json, re, sys
entries = json.load(open(sys.argv[1]))
for e in entries:
    e["command"] = re.sub(r" -Winvalid-pch| -include \S+/cmake_pch\.hxx", "", e["command"])
json.dump(entries, open(sys.argv[2], "w"))
PY
status=0
printf '%s\n' $files | xargs -P "$(nproc)" -n 1 "$tool" -p "$db" --quiet >"$log" 2>&1 || status=$?
grep -E "^/.*: (warning|error):" "$log" | sort -u || true
n=$(grep -cE "^/.*: (warning|error):" "$log" || true)
if ((status != 0 || n > 0)); then
  echo "tidy.sh: $n finding(s) in $(printf '%s\n' $files | wc -l) files (clang-tidy, .clang-tidy)"
  exit 1
fi
echo "tidy.sh: $(printf '%s\n' $files | wc -l) files clean under clang-tidy (.clang-tidy)"
