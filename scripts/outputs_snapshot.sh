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
# Each command's help (its options, defaults and ranges) and the refusals of the commands that run a cell,
# with stderr (spdlog's time stamps removed).
run_err() { # NAME ARGS...: stdout, stderr and the exit status into NAME.txt
  local name=$1; shift
  local status=0
  "$bin" "$@" >"$out/$name.txt" 2>&1 || status=$?
  sed -i -E -e 's/^\[[0-9-]+ [0-9:.]+\] //' -e "s#$bin#robodamp#" "$out/$name.txt"
  echo "exit $status" >>"$out/$name.txt"
}
for c in bench analyze filters check-config run replay csv lobes sle cut identify measure commission pose tune \
  schedule chatter plant monitor request dashboard; do
  run_err "help_$c" "$c" --help
done
run_err refuse_run_rpm run --config config/presets/horizontal_c2.yaml --clock virtual --duration 1 --spindle-rpm 199999
run_err refuse_run_fault run --config config/presets/horizontal_c2.yaml --clock virtual --duration 1 --fault bogus:1
run_err refuse_run_pose run --config config/presets/horizontal_c2.yaml --clock virtual --duration 1 --pose 1 2 3
run_err refuse_plant_spindle plant --config config/hil_cutting_c2.yaml --spindle 1:fast
run_err refuse_plant_mounting plant --config config/hil_cutting_c2.yaml --mounting 1:sideways
run_err refuse_plant_pose plant --config config/hil_cutting_c2.yaml --pose-at 1:x
run_err refuse_plant_ramp plant --config config/hil_cutting_c2.yaml --depth-ramp 2:1:0.5
run_err refuse_monitor_config monitor --config config/milling/active_damping_c2.yaml --duration 0.1
"$bin" run --config config/presets/horizontal_c2.yaml --clock virtual --duration 2 2>/dev/null |
  grep -E '^  (state|arming|ticks [0-9]+|supervisor|vibration|telemetry)' | sed -E 's/ \(0\.0000 %\)//' >"$out/run_virtual.txt" || true
run cut_critical_c2 cut --job config/milling/active_damping_c2.yaml --critical --rpm 700 --json "$out/cut_critical_c2.json"
# A cut that chatters at 31 Hz beside 700 rpm's tooth-passing line (3 teeth, 35 Hz) (a table as a logger writes it), listened to
# and its speeds to try checked on the default cell.
signal=$(mktemp --suffix=.csv)
python3 -c "
import math
print('time_s,accel_mps2')
for i in range(5000 * 8):
    t = i / 5000
    print(f'{t:.4f},{0.3 * math.sin(2 * math.pi * 35.0 * t) + 2.0 * math.sin(2 * math.pi * 31.0 * t):.6f}')
" >"$signal"
run chatter_c2 chatter --signal "$signal" --teeth 3 --rpm 700 --config config/presets/horizontal_c2.yaml \
  --job config/milling/active_damping_c2.yaml --json
rm -f "$signal"
for f in "$out"/*.json; do scrub <"$f" >"$f.tmp" && mv "$f.tmp" "$f"; done
