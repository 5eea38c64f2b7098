#!/usr/bin/env bash
# The dashboard under load (docs/dashboard.md, "Measured"): N simulated cells (default 8; the preset at a
# 1 kHz loop, 50 Hz telemetry each, half of them cutting at 700 rpm so their lobes sweep), one dashboard and
# two open pages (the fleet and one cell, as server-sent event streams), for D seconds (default 600). Prints
# the dashboard's CPU share, its resident memory every minute, the time /api/fleet takes, and then how a
# real browser keeps up with the fleet page and a cell page (scripts/dashboard_browser_load.py, 30 s each).
# Usage: bash scripts/dashboard_load.sh [CELLS] [SECONDS]   (after scripts/setup.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
cells=${1:-8}
seconds=${2:-600}
bin=${ROBODAMP_BIN:-$(pwd)/build/apps/robodamp}
dir=$(mktemp -d)
domain=$((200 + RANDOM % 20))
pids=()
cleanup() { for p in "${pids[@]}"; do kill -INT "$p" 2>/dev/null || true; done; wait 2>/dev/null || true; }
trap cleanup EXIT
for i in $(seq 1 "$cells"); do
  { sed 's/^  rate_hz: 5000.*/  rate_hz: 1000/' config/presets/horizontal_c2.yaml
    printf '\ndds:\n  domain_id: %d\n  transport: udp_loopback\ncell:\n  name: load-%d\nspindle:\n  teeth: 3\n  job: %s\n' \
      "$domain" "$i" "$(pwd)/config/milling/active_damping_c2.yaml"; } > "$dir/cell$i.yaml"
  rpm=0; (( i % 2 == 0 )) && rpm=700
  "$bin" run --config "$dir/cell$i.yaml" --duration $((seconds + 120)) --spindle-rpm $rpm > "$dir/cell$i.log" 2>&1 &
  pids+=($!)
done
printf 'dashboard:\n  port: 0\ndds:\n  domain_id: %d\n  transport: udp_loopback\n' "$domain" > "$dir/dashboard.yaml"
"$bin" dashboard --config "$dir/dashboard.yaml" > "$dir/dashboard.log" 2>&1 &
dash=$!
pids+=($dash)
for _ in $(seq 1 100); do grep -q 'http://' "$dir/dashboard.log" && break; sleep 0.1; done
port=$(grep -o '127.0.0.1:[0-9]*' "$dir/dashboard.log" | cut -d: -f2)
for _ in $(seq 1 600); do
  n=$(curl -s "http://127.0.0.1:$port/api/fleet" | grep -o '"cell":"load-' | wc -l)
  (( n >= cells )) && break
  sleep 0.1
done
echo "dashboard on port $port sees $n of $cells cells"
curl -sN "http://127.0.0.1:$port/api/events" > /dev/null &
pids+=($!)
curl -sN "http://127.0.0.1:$port/api/events?cell=load-2" > /dev/null &
pids+=($!)
sleep 30  # the cells' start-up analysis and lobe sweeps
ticks() { awk '{print $14 + $15}' "/proc/$dash/stat"; }
hz=$(getconf CLK_TCK)
t0=$(ticks); s0=$(date +%s.%N)
echo "minute  RSS of the dashboard (kB)"
for m in $(seq 0 $((seconds / 60))); do
  echo "$m  $(awk '/VmRSS/ {print $2}' "/proc/$dash/status")"
  (( m < seconds / 60 )) && sleep 60
done
t1=$(ticks); s1=$(date +%s.%N)
awk -v a="$t0" -v b="$t1" -v s0="$s0" -v s1="$s1" -v hz="$hz" \
  'BEGIN { printf "dashboard CPU: %.1f %% of one core over %.0f s\n", 100 * (b - a) / hz / (s1 - s0), s1 - s0 }'
for _ in $(seq 1 20); do curl -s -o /dev/null -w '%{time_total}\n' "http://127.0.0.1:$port/api/fleet"; done |
  sort -n | awk '{ v[NR] = $1 } END { printf "GET /api/fleet: median %.1f ms, max %.1f ms (20 requests)\n", 1e3 * v[int((NR + 1) / 2)], 1e3 * v[NR] }'
/usr/bin/python3 scripts/dashboard_browser_load.py "$port" load-2 30
curl -s "http://127.0.0.1:$port/api/health"; echo
