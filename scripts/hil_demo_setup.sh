# Sourced by the cross-process demos (scripts/advice_demo.sh, scripts/derate_soak.sh) from the repository's
# root: installs what is missing, starts the output folder OUT afresh with a copy of the binary (a rebuild during
# the run does not pull it away), and sets robodamp, job (the default milling job) and a Modbus port to start from.
hil_demo_setup() {  # OUT
  bash scripts/setup.sh
  out=$1
  rm -rf "$out"
  mkdir -p "$out"
  robodamp="$out/robodamp"
  cp build/apps/robodamp "$robodamp"
  job="$PWD/config/milling/active_damping_c2.yaml"
  port=$((20000 + RANDOM % 20000))
}
