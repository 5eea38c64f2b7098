#!/usr/bin/env bash
# docs/milling.md, "The damped cut by semi-discretization": the accurate limit (lobes' default method) against
# the time-domain critical depth (robodamp cut --critical, the real Controller and the simulated plant) on
# config/milling/active_damping_c2.yaml with C1, C2, C3 and both tuned presets, open loop and damped, at
# 252, 282, 381, 672 and 700 rpm. Prints a markdown table.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
if ! command -v jq >/dev/null; then
  sudo=""
  [[ $(id -u) -eq 0 ]] || sudo="sudo"
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends jq >/dev/null
fi
job=config/milling/active_damping_c2.yaml
# Near the limit the growth per tooth period is small: 60 revolutions read a slow decay as chatter, and at
# 252-282 rpm a 9.4 Hz motion needs more than 300 revolutions (71 s of cut) to show that it grows.
groups=("252 282:${REVS_LOW:-1500}" "381 672 700:${REVS:-300}")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
row() {  # label, json
  jq -r --arg l "$1" '.critical[] | "| \($l) | \(.rpm) | \(.accurate_rpm*100|round/100) | \(.critical_depth_mm*1000|round/1000) (\(.mechanism)) | \(.accurate_b_lim_mm*1000|round/1000) (\(.accurate_type)) | \((.accurate_b_lim_mm/.critical_depth_mm-1)*1000|round/10) % | \(.lobes_b_lim_mm*1000|round/1000) | \((.lobes_b_lim_mm/.critical_depth_mm-1)*1000|round/10) % |"' "$2"
}
echo "| controller | rpm | analysed rpm | time domain (mm) | SDM (mm) | SDM error | zero-order preview (mm) | zero-order error |"
echo "|---|---|---|---|---|---|---|---|"
for g in "${groups[@]}"; do
  # shellcheck disable=SC2086
  ./build/apps/robodamp cut --job "$job" --critical --revs "${g#*:}" --rpm ${g%:*} --json "$tmp/open.json" >/dev/null 2>&1
  row "open loop" "$tmp/open.json"
done
for c in horizontal_c1 horizontal_c2 horizontal_c3 tuned_horizontal tuned_vertical; do
  for g in "${groups[@]}"; do
    # shellcheck disable=SC2086
    ./build/apps/robodamp cut --job "$job" --controller "config/presets/$c.yaml" --critical --damped --revs "${g#*:}" \
      --rpm ${g%:*} --json "$tmp/$c.json" >/dev/null 2>&1
    row "$c" "$tmp/$c.json"
  done
done
