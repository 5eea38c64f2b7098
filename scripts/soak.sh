#!/usr/bin/env bash
# Soak: `robodamp run` on the wall clock for a long time (default 1 h; not in CI), set up for real time
# as deployed, with a 1000 N hit at the TCP every 2 s and the drives' vibration. Samples the process's
# resident memory every 10 s and reports the availability (the share of the asked time at full gain,
# rt/availability.hpp), every trip with its class, its time to the safe state and to full gain again,
# memory growth, telemetry drops, missed ticks, overruns and the wake-up latency. Exit status: 0 when the
# availability is at least MIN_PCT (default 99.9), no trip stayed latched, every trip was safe within
# 0.1 s, no frame was dropped and the memory grew less than 1 MiB after the first minute; 1 otherwise.
#
#   bash scripts/soak.sh                  # 3600 s on the default preset
#   bash scripts/soak.sh 600              # ten minutes, before you stop
#   bash scripts/soak.sh 600 config/presets/horizontal_c1.yaml 99
# Writes build/soak/{summary.json,rss.csv,run.log,report.md}.
set -euo pipefail
cd "$(dirname "$0")/.."
duration="${1:-3600}"
config="${2:-config/presets/horizontal_c2.yaml}"
min_pct="${3:-99.9}"
bash scripts/setup.sh
out=build/soak
mkdir -p "$out"
./build/apps/robodamp run --config "$config" --duration "$duration" --impact-every 2 --json "$out/summary.json" \
  >"$out/run.log" 2>&1 &
pid=$!
echo "t_s,rss_kib" >"$out/rss.csv"
start=$(date +%s)
while kill -0 "$pid" 2>/dev/null; do
  rss=$(awk '/^VmRSS:/ {print $2}' "/proc/$pid/status" 2>/dev/null || true)
  [[ -n "$rss" ]] && echo "$(( $(date +%s) - start )),$rss" >>"$out/rss.csv"
  sleep 10
done
set +e
wait "$pid"
status=$?
set -e
python3 - "$out" "$status" "$duration" "$config" "$min_pct" <<'PY'
import csv, json, sys
out, status, duration, config, min_pct = sys.argv[1], int(sys.argv[2]), float(sys.argv[3]), sys.argv[4], float(sys.argv[5])
s = json.load(open(f"{out}/summary.json"))
rows = [(int(r["t_s"]), int(r["rss_kib"])) for r in csv.DictReader(open(f"{out}/rss.csv"))]
settled = [kib for t, kib in rows if t >= 60] or [kib for _, kib in rows]
growth = max(settled) - min(settled) if settled else 0
trips = {k: v for k, v in s["supervisor"]["trips"].items() if v}
w = s["wake_latency"]
a = s["availability"]
share = 100.0 * a["share"]
unsafe = [t for t in a["trips"] if t["safe_after_s"] is None or t["safe_after_s"] > 0.1]
latched = s["trip"] != "none"  # a trip still standing at the end (latched, or not yet recovered)
ok = (share >= min_pct and not latched and not unsafe and s["telemetry"]["ring_drops"] == 0 and growth < 1024)
def seconds(v):
    return "never" if v is None else f"{v:.3f} s"
lines = [
    f"# Soak: {duration:.0f} s of `robodamp run` on {config}",
    "",
    f"- availability: at full gain {share:.4f} % of the {a['asked_s']:.1f} s asked (from {a['first_full_gain_s']} s; "
    f"required {min_pct} %); of it {100.0 * a['missed_ticks_while_active_s'] / max(a['asked_s'], 1e-9):.4f} % missed ticks "
    f"(the amplifier held the last command)",
    f"- exit status {status}, final state {s['final_state']}, trips by class: {trips or 'none'}, "
    f"recoveries {s['supervisor'].get('recoveries', 0)}, arming: {s['arming']['outcome']}",
]
for t in a["trips"]:
    lines.append(f"  - {t['trip']} at {t['trip_s']:.3f} s: safe after {seconds(t['safe_after_s'])}, "
                 f"re-armed after {seconds(t['rearmed_after_s'])}, at full gain after {seconds(t['full_gain_after_s'])}")
lines += [
    f"- ticks {s['ticks_run']}, missed {s['missed_ticks']}, overruns {s['overruns']} ({s['overrun_pct']:.4f} %)",
    f"- wake-up latency p50 {w['p50_us']:.0f} us, p99 {w['p99_us']:.0f} us, p99.9 {w['p999_us']:.0f} us, max {w['max_us']:.1f} us",
    f"- telemetry {s['telemetry']['frames']} frames, {s['telemetry']['ring_drops']} dropped",
    f"- supervisor: stale {s['supervisor']['stale_ticks']}, invalid {s['supervisor']['invalid_samples']}, saturated {s['supervisor']['saturated_ticks']} ticks",
    f"- resident memory {min(settled) if settled else 0}..{max(settled) if settled else 0} KiB after the first minute "
    f"(growth {growth} KiB, {len(rows)} samples)",
    f"- verdict: {'PASS' if ok else 'FAIL'}",
]
open(f"{out}/report.md", "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
sys.exit(0 if ok else 1)
PY
