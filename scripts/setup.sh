#!/usr/bin/env bash
# Installs what robodamp needs on Debian 12 (only what is missing; quiet when all is there), then
# configures and builds in ./build (Release): the targets named (run.sh: only the executable, 57 of the 123
# objects, 60 % of the compiler's time), or everything (test.sh). Idempotent.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(cmake ninja-build g++ pkg-config libeigen3-dev libyaml-cpp-dev libgtest-dev libgmock-dev
          libbenchmark-dev libcli11-dev libspdlog-dev nlohmann-json3-dev gnuplot-nox valgrind
          libfftw3-dev libnlopt-dev libmodbus-dev libfastrtps-dev libfastcdr-dev fastddsgen libssl-dev openssl can-utils
          libcpp-httplib-dev libjs-dygraphs chromium chromium-driver python3-selenium graphviz
          universal-ctags libsndfile1-dev libspectra-dev clang-format-14 clang-tidy-14)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "robodamp: installing ${missing[*]}"
  sudo=""
  [[ $(id -u) -eq 0 ]] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# The code model CMake's file API writes at configure time (the layering test reads the build's graph).
mkdir -p build/.cmake/api/v1/query
touch build/.cmake/api/v1/query/codemodel-v2
if [[ ! -f build/CMakeCache.txt ]]; then
  cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
fi
targets=()
for t in "$@"; do targets+=(--target "$t"); done
cmake --build build --parallel "$(nproc)" "${targets[@]}" | { grep -vE '^(\[[0-9]+/[0-9]+\] |ninja: no work to do)' || true; }
