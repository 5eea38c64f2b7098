#!/usr/bin/env bash
# Writes the deterministic outputs of robodamp's analyses on every preset and milling job into DIR, one
# file per command, so that a refactoring can be checked byte for byte:
#   bash scripts/outputs_snapshot.sh /tmp/before   # on the old commit
#   bash scripts/outputs_snapshot.sh /tmp/after    # on the new one
#   diff -r /tmp/before /tmp/after
# The JSON's wall-clock figures (wall_s, diagram_ms) are removed and DIR is written OUT. ROBODAMP_BIN overrides the
# binary (default build/apps/robodamp).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:?usage: outputs_snapshot.sh DIR}
bin=${ROBODAMP_BIN:-$PWD/build/apps/robodamp}
mkdir -p "$out"
# Lines that carry wall-clock time or host-dependent numbers.
scrub() { grep -vE '"(wall_s|diagram_ms)":' | sed -E 's/ in [0-9.]+ s( wall \([0-9]+x real time\))?$/ in T s/' | sed "s#$out#OUT#g" || true; }
run() { # NAME ARGS...: stdout and the exit status into NAME.txt, stderr dropped
  local name=$1; shift
  local status=0
  "$bin" "$@" 2>/dev/null | scrub >"$out/$name.txt" || status=$?
  echo "exit $status" >>"$out/$name.txt"
}
for p in config/presets/*.yaml; do
  n=$(basename "$p" .yaml)
  run "analyze_$n" analyze --config "$p" --json
  run "analyze_table_$n" analyze --config "$p"
  run "filters_$n" filters --config "$p" --json
  run "check_$n" check-config "$p"
  run "bench_$n" bench --config "$p" --json "$out/bench_$n.json" --jobs 1
done
run analyze_sweep_hil analyze --config config/hil_cutting_c2.yaml --spindle-sweep
run analyze_sweep_hil_json analyze --config config/hil_cutting_c2.yaml --spindle-sweep --json
run analyze_notch_hil analyze --config config/hil_cutting_c2.yaml --spindle-rpm 6000 --json
for j in config/milling/*.yaml config/commissioning/job_*.yaml; do
  n=$(basename "$j" .yaml)
  run "check_$n" check-config "$j"
  run "lobes_zoa_$n" lobes --job "$j" --method zoa --json
  run "sle_$n" sle --job "$j" --json
done
run lobes_sdm_c2 lobes --job config/milling/active_damping_c2.yaml --damped --json
run lobes_sdm_tuned lobes --job config/milling/active_damping_tuned.yaml --damped --json
run lobes_zoa_damped_c2 lobes --job config/milling/active_damping_c2.yaml --damped --method zoa --json
run sle_damped_c2 sle --job config/milling/active_damping_c2.yaml --damped --json
run cut_c2 cut --job config/milling/active_damping_c2.yaml --json "$out/cut_c2.json"
run cut_damped_c2 cut --job config/milling/active_damping_c2.yaml --damped --rpm 700 --axial-mm 1 --revs 40 \
  --json "$out/cut_damped_c2.json"
run pose_table pose table --model config/robots/planar_three_link.yaml --json
run pose_frf pose frf --model config/robots/planar_three_link.yaml --joints -100.59 119.81 -19.55 --json
run pose_map pose map --model config/robots/planar_three_link.yaml --joints -100.59 119.81 -19.55 --vary 2 3 --steps 5 --json
run tune_small tune --config config/presets/horizontal_c2.yaml --evaluations 20 --polish 10 --json "$out/tune_small.json"
for f in "$out"/*.json; do scrub <"$f" >"$f.tmp" && mv "$f.tmp" "$f"; done
