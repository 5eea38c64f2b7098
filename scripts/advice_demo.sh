#!/usr/bin/env bash
# Closing the loop across processes, on the wall clock (docs/milling.md, "Closing the loop across
# processes"): the HIL emulator cuts config/milling/active_damping_c2.yaml against the emulated robot at
# 700 rpm on a lobe, `robodamp run` controls it through CAN frames and Modbus, and the emulated robot
# follows robodamp's spindle-speed advice (spindle.apply_advice). Four cases: the damper on and off
# (controller.gain_ns_per_m 0, the drives' vibration off as in process), each with the robot publishing
# the depth it cuts (modbus.robot.depth_register: the advice comes from the depth above the limit, before
# chatter shows) and without (the controller knows only the job's 0.5 mm: the chatter indicator has to
# find it). For each: when the cut entered the lobe, when the controller's indicator and the emulator's
# (the same indicator on the plant's side) saw chatter, when the advice reached the robot, when the cut
# was quiet again, and the emulator's verdict of each speed.
#
#   bash scripts/advice_demo.sh            # realtime pacing, about 25 s a case
#   bash scripts/advice_demo.sh lockstep   # the emulator steps with each command frame (the controller
#                                          # still on the wall clock)
# Writes build/advice_demo/{report.md,<case>/{plant,run}.{json,log}}.
set -euo pipefail
cd "$(dirname "$0")/.."
pacing="${1:-realtime}"
source scripts/hil_demo_setup.sh
hil_demo_setup build/advice_demo

# case name, gain (N s/m), depth register (yes/no), cut depth (mm), drives (on/off)
cases=("damped_depth_register 2000 yes 0.85 on"
       "damped_chatter_only 2000 no 0.95 on"
       "open_depth_register 0 yes 1.3 off"
       "open_chatter_only 0 no 1.3 off")
for c in "${cases[@]}"; do
  read -r name gain depth_register depth drives <<<"$c"
  dir="$out/$name"
  mkdir -p "$dir"
  port=$((port + 1))
  registers="    spindle_rpm_register: 1\n    rpm_per_count: 0.1\n    advice_register: 4\n"
  [[ "$depth_register" == yes ]] && registers+="    depth_register: 2\n"
  sed -e "s|unix:/tmp/robodamp-hil.sock|unix:$PWD/$dir/can.sock|" -e "s|port: 1502|port: $port|" \
      -e "s|^  gain_ns_per_m: 2000 |  gain_ns_per_m: $gain |" -e "s|^    mounting_register: 0$|&\n$registers|" \
      -e "s|vertical: presets/|vertical: $PWD/config/presets/|" -e "s|model: robots/|model: $PWD/config/robots/|" \
      -e "s|^hil: |spindle:\n  teeth: 3\n  rpm_max: 1500\n  job: $job\n  apply_advice: true\n\nhil: |" \
      config/hil_horizontal_c2.yaml >"$dir/hil.yaml"
  plant_args=(plant --config "$dir/hil.yaml" --pacing "$pacing" --no-impacts --cut "$job" --cut-rpm 700
              --cut-axial-mm "$depth" --cut-revs 120 --cut-at 2 --cut-until 12 --json "$dir/plant.json")
  [[ "$drives" == off ]] && plant_args+=(--drives-off)
  echo "advice_demo: $name ($pacing): $depth mm at 700 rpm, gain $gain N s/m, depth register $depth_register"
  "$robodamp" "${plant_args[@]}" >"$dir/plant.log" 2>&1 &
  plant=$!
  "$robodamp" run --config "$dir/hil.yaml" --duration 26 --json "$dir/run.json" >"$dir/run.log" 2>&1 || true
  wait "$plant" || true
done

python3 - "$out" "$pacing" "${cases[@]}" <<'PY'
import json, sys
out, pacing, cases = sys.argv[1], sys.argv[2], sys.argv[3:]
def t(v):
    return "-" if v is None else f"{v:.2f}"
lines = [f"# Closing the loop across processes ({pacing} pacing)", "",
         "Plant time in s (the controller's loop time starts within 0.1 s of it). The cut enters the lobe at 700 rpm at "
         "2.00 s. Controller: when its view asked for its last advice, and why; emulator indicator: the same live "
         "indicator on the plant's accelerometer.", "",
         "| case | depth | trigger (last advice) | controller asked (last) | emulator indicator: chatter | first advice at the robot | advices | final speed | "
         "emulator indicator: quiet | verdicts (speed: emulator's detector) | trip |",
         "|---|---|---|---|---|---|---|---|---|---|---|"]
for c in cases:
    name, gain, reg, depth, drives = c.split()
    p = json.load(open(f"{out}/{name}/plant.json"))
    r = json.load(open(f"{out}/{name}/run.json"))
    seg = p["regenerative_cut"]["segments"]
    adv = r.get("advice") or {}
    seen = [a for a in p.get("advice", []) if a["action"] == "followed"]
    first_chatter = next((s["indicator_chatter_s"] for s in seg if s["indicator_chatter_s"] is not None), None)
    quiet = next((s["indicator_quiet_s"] for s in seg if s["indicator_quiet_s"] is not None), None)
    verdicts = "; ".join(f"{s['rpm']:.1f} rpm: {s['classification']}" + (f" {s['chatter_hz']:.1f} Hz" if s["chatter_hz"] else "")
                         for s in seg)
    lines.append(f"| {name} | {depth} mm | {adv.get('trigger', '-')} | {t(adv.get('time_s'))} | {t(first_chatter)} | "
                 f"{t(seen[0]['plant_time_s']) if seen else '-'} | {len(seen)} | {seen[-1]['rpm']:.1f} rpm | {t(quiet)} | {verdicts} | "
                 f"{r.get('trip', '?')} |" if seen else
                 f"| {name} | {depth} mm | {adv.get('trigger', '-')} | {t(adv.get('time_s'))} | {t(first_chatter)} | - | 0 | - | "
                 f"{t(quiet)} | {verdicts} | {r.get('trip', '?')} |")
open(f"{out}/report.md", "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
PY
