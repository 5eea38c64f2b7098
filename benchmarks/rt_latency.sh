#!/usr/bin/env bash
# The loop's wake-up latency next to cyclictest's, on this machine, in one session: same priority
# (SCHED_FIFO 80), same period, memory locked, /dev/cpu_dma_latency at 0, CLOCK_MONOTONIC with
# clock_nanosleep(TIMER_ABSTIME), no CPU pinning (realtime.cpu: -1) for both. robodamp runs its real loop:
# the simulated plant, the supervisor and controller, telemetry and the drain thread.
# Both histograms are in whole microseconds and go through the same percentile code below.
#
#   bash benchmarks/rt_latency.sh              # 30 s per run at 5 and 10 kHz
#   DURATION=120 bash benchmarks/rt_latency.sh
# Writes build/rt_latency.md (a table) and the histograms in build/rt_latency/.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
build="${BUILD_DIR:-$here/build}"
duration="${DURATION:-30}"
out="$build/rt_latency"
mkdir -p "$out"

command -v cyclictest >/dev/null || { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends rt-tests; }
[ -x "$build/apps/robodamp" ] || { cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null && cmake --build "$build" --target robodamp; }

# p50 p99 p99.9 max overrun% from a histfile: "<us> <count>" lines; overrun = latency >= period.
stats() {  # file period_us
  awk -v period="$2" '
    /^[0-9]+ [0-9]+$/ { us = $1 + 0; n = $2 + 0; c[us] += n; total += n; if (n > 0 && us > maxbin) maxbin = us;
                         if (us >= period) over += n; next }
    /# Max Latencies:/ { max = $4 + 0 }
    /# Histogram Overflows:/ { overflow = $4 + 0 }
    /# Loop overruns:/ { loop_over = $4 + 0; have_loop = 1 }
    /# Missed ticks:/ { missed = $4 + 0 }
    END {
      total += overflow; over += overflow
      split("0.5 0.99 0.999", q, " ")
      for (k = 1; k <= 3; k++) {
        target = q[k] * total; seen = 0; p[k] = maxbin
        for (us = 0; us <= maxbin; us++) { seen += c[us]; if (seen >= target) { p[k] = us; break } }
      }
      if (have_loop) over_pct = 100 * loop_over / (total + missed); else over_pct = 100 * over / total
      printf "%d %d %d %s %.4f %d\n", p[1], p[2], p[3], max, over_pct, total
    }' "$1"
}

table="$build/rt_latency.md"
{
  echo "| rate | program | samples | p50 (us) | p99 (us) | p99.9 (us) | max (us) | overruns (%) |"
  echo "|---|---|---|---|---|---|---|---|"
} > "$table"
for rate in 5000 10000; do
  period=$((1000000 / rate))
  cfg="$out/horizontal_c2_${rate}.yaml"
  sed "s/^  rate_hz: .*/  rate_hz: $rate/" "$here/config/presets/horizontal_c2.yaml" > "$cfg"
  echo "== $rate Hz: cyclictest, ${duration} s" >&2
  cyclictest --mlockall --priority=80 --policy=fifo --interval="$period" --threads=1 --duration="${duration}s" \
    --histogram=10000 --histfile="$out/cyclictest_${rate}.hist" --quiet >/dev/null
  echo "== $rate Hz: robodamp run, ${duration} s" >&2
  "$build/apps/robodamp" run --config "$cfg" --duration "$duration" --impact-every 2 \
    --histogram "$out/robodamp_${rate}.hist" --json "$out/robodamp_${rate}.json" >&2
  read -r c50 c99 c999 cmax cover cn < <(stats "$out/cyclictest_${rate}.hist" "$period")
  read -r r50 r99 r999 rmax rover rn < <(stats "$out/robodamp_${rate}.hist" "$period")
  echo "| $rate Hz | cyclictest | $cn | $c50 | $c99 | $c999 | $cmax | $cover |" >> "$table"
  echo "| $rate Hz | robodamp loop | $rn | $r50 | $r99 | $r999 | $rmax | $rover |" >> "$table"
  awk -v a="$r99" -v b="$c99" -v c="$r999" -v d="$c999" -v r="$rate" \
    'BEGIN { printf "| %d Hz | ratio loop / cyclictest | | | %.2f | %.2f | | |\n", r, (b > 0 ? a / b : 0), (d > 0 ? c / d : 0) }' >> "$table"
done
echo "kernel: $(uname -r), $(nproc) CPUs, $(date -u +%Y-%m-%dT%H:%MZ), ${duration} s per run" >> "$table"
cat "$table"
