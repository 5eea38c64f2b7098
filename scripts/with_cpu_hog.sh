#!/bin/bash
# Runs a command with a busy loop pinned on each of the machine's first two cores (the loaded runs of
# docs/tests.md), e.g. from build/: bash ../scripts/with_cpu_hog.sh ctest --parallel 2
set -u
taskset -c 0 bash -c 'while :; do :; done' & hog0=$!
taskset -c 1 bash -c 'while :; do :; done' & hog1=$!
trap 'kill "$hog0" "$hog1" 2>/dev/null' EXIT
"$@"
