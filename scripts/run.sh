#!/usr/bin/env bash
# The main job: set up, build, and run robodamp on the default configuration. With arguments, runs
# `robodamp ARGS...` instead (e.g. scripts/run.sh check-config config/presets/vertical_c1.yaml).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
if (($#)); then exec ./build/apps/robodamp "$@"; fi
# Until the simulated plant lands, the main job is the chain's response at the dominant robot mode
# and its Bode diagram.
./build/apps/robodamp filters --config config/presets/horizontal_c2.yaml --freq 9.2 --plot build/filters_horizontal_c2.png
