#!/usr/bin/env bash
# The main job: set up, build, and run robodamp on the default configuration. With arguments, runs
# `robodamp ARGS...` instead (e.g. scripts/run.sh check-config config/presets/vertical_c1.yaml).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh robodamp
if (($#)); then exec ./build/apps/robodamp "$@"; fi
# The main job: the simulated-plant bench run on the default preset (impact tests with control off and
# on, saturating impacts, gain sweep), what the damper and its speed schedule do for the default job's cut
# (config/milling/active_damping_c2.yaml, by the accurate method), its JSON report and plots.
exec ./build/apps/robodamp bench --config config/presets/horizontal_c2.yaml --job config/milling/active_damping_c2.yaml \
  --json build/bench_horizontal_c2.json \
  --plot-dir build/bench_plots
