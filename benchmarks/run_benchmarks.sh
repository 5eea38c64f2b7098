#!/usr/bin/env bash
# Reproduces docs/performance.md's numbers: Google Benchmark ns/sample and callgrind
# instructions/sample for the plain cascade, the product's chain and the controller step; the simulated
# plant; the FFT back-ends; the parts of the main job; the milling analyses.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
./build/benchmarks/benchmark_chain --benchmark_repetitions=5 --benchmark_report_aggregates_only=true \
  --benchmark_min_time=0.5 --benchmark_counters_tabular=true
n=1000000
echo
echo "callgrind instructions per sample (N = $n, closed loop, Release flags):"
for k in plain chain controller plain_notched controller_notched; do
  out=$(mktemp)
  valgrind --tool=callgrind --callgrind-out-file="$out" '--toggle-collect=*run_kernel*' \
    ./build/benchmarks/callgrind_chain "$k" "$n" >/dev/null 2>&1
  ir=$(grep -E '^(summary|totals):' "$out" | head -1 | awk '{print $2}')
  rm -f "$out"
  awk -v k="$k" -v ir="$ir" -v n="$n" 'BEGIN { printf "  %-19s %8.2f\n", k, ir / n }'
done
echo
echo "simulated plant + controller, default preset (x_real_time = simulated s per wall s, one core):"
./build/benchmarks/benchmark_plant --benchmark_repetitions=5 --benchmark_report_aggregates_only=true --benchmark_min_time=0.5 \
  --benchmark_counters_tabular=true
echo
echo "the estimator's FFT, 400 000 real points (kissfft as before, FFTW as now):"
./build/benchmarks/benchmark_fft --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
echo
echo "what each part of the main job costs (robodamp bench on the default preset):"
./build/benchmarks/benchmark_main_job
echo
echo "milling in time (cut, damped cut, critical depth, SDM diagram), one core:"
taskset -c 0 ./build/benchmarks/benchmark_cut --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
echo "== modal identification of the robot SLE study's 46-mode FRF (x and y), one core"
taskset -c 0 ./build/benchmarks/benchmark_identify
echo "== robodamp chatter: 60 s at 48 kHz"
taskset -c 0 ./build/benchmarks/benchmark_chatter
echo
echo "milling analyses, one core: a 2000-speed lobe diagram of the 37-mode robot FRF (the robot SLE study), the direct test's"
echo "critical depth at one speed, SLE at one speed (40 slices, 64 harmonics):"
taskset -c 0 ./build/benchmarks/benchmark_lobes --benchmark_repetitions=5 --benchmark_report_aggregates_only=true \
  --benchmark_counters_tabular=true --benchmark_filter='-BM_DampedSdmLobes'
echo "the accurate damped lobes (the sampled loop's SDM) of active_damping_c2.yaml, 200 speeds, on 1 and 2 threads"
echo "(both cores: the command's default):"
./build/benchmarks/benchmark_lobes --benchmark_filter=BM_DampedSdmLobes --benchmark_counters_tabular=true
echo
echo "robodamp tune, one core: one candidate's evaluation (with the job's damped lobes, and without a job), the"
echo "impact's command prediction and its set-up per plant:"
taskset -c 0 ./build/benchmarks/benchmark_tune --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
