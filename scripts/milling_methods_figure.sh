#!/usr/bin/env bash
# docs/lobes_three_methods.png: the zero-order lobes, the semi-discretization lobes and time-domain critical
# depths (robodamp cut --critical) for a low-immersion job, drawn together (docs/milling.md).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
if ! command -v jq >/dev/null; then
  sudo=""
  [[ $(id -u) -eq 0 ]] || sudo="sudo"
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends jq >/dev/null
fi
job=config/milling/single_mode_low_immersion.yaml
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
./build/apps/robodamp lobes --job "$job" --method zoa --json > "$tmp/zoa.json"
./build/apps/robodamp lobes --job "$job" --method sdm --json > "$tmp/sdm.json"
speeds=$(seq 11000 1500 39500 | tr '\n' ' ')
# shellcheck disable=SC2086
./build/apps/robodamp cut --job "$job" --critical --rpm $speeds --json "$tmp/td.json" 2>/dev/null >/dev/null
for m in zoa sdm; do
  jq -r '.curve[] | select(.b_lim_mm != null) | "\(.rpm) \(.b_lim_mm)"' "$tmp/$m.json" > "$tmp/$m.dat"
done
jq -r '.curve[] | select(.type == "flip") | "\(.rpm) \(.b_lim_mm)"' "$tmp/sdm.json" > "$tmp/flip.dat"
jq -r '.critical[] | "\(.rpm) \(.critical_depth_mm) \(.mechanism)"' "$tmp/td.json" > "$tmp/td.dat"
gnuplot <<GP
set terminal pngcairo size 1000,600
set output 'docs/lobes_three_methods.png'
set title 'Single 600 Hz mode, 2 teeth, 5 % radial immersion: three stability methods'
set xlabel 'spindle speed (rpm)'
set ylabel 'limiting axial depth (mm)'
set yrange [0:60]
set grid
set key opaque box top center
plot '$tmp/zoa.dat' u 1:2 w l lw 2 lc rgb '#c0392b' t 'zero-order (frequency domain)', \
     '$tmp/sdm.dat' u 1:2 w l lw 2 lc rgb '#2471a3' t 'semi-discretization (40 steps per period)', \
     '$tmp/flip.dat' u 1:2 w p pt 7 ps 0.6 lc rgb '#2471a3' t 'SDM: period doubling (flip)', \
     '$tmp/td.dat' u 1:2 w p pt 5 ps 1.2 lc rgb '#1e8449' t 'time-domain cut (robodamp cut --critical)'
GP
echo "wrote docs/lobes_three_methods.png"
