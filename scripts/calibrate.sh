#!/usr/bin/env bash
# Detection rate against effect size and noise level (README "Calibration"):
#   scripts/calibrate.sh [OUT_DIR] [SEEDS]
# For each effect, size and noise level, closed-loop flights over the seeds are diagnosed;
# a detection counts when the hidden effect is named (and nothing else). Prints a
# markdown table.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-/tmp/quadgen_calibration}
seeds=${2:-"1 2"}
q=${QUADGEN:-build/quadgen}
v=vehicles/finken3.yaml
mkdir -p "$out"
declare -A sizes=(
  [motor_gain.C]="-0.0025 -0.005 -0.01 -0.02"
  [wind.x]="0.25 0.5 1 2"
  [thrust_decay.rate]="0.00025 0.0005 0.001 0.002"
  [attitude_bias.roll]="0.0025 0.005 0.01 0.02"
)
noises=("low|--pose-noise 0.001 --gyro-noise 0.01 --accel-noise 0.05" "high|--pose-noise 0.005 --gyro-noise 0.05 --accel-noise 0.25")
one() {  # param value noise-name noise-flags seed -> 1 if found alone
  local p=$1 val=$2 nn=$3 flags=$4 seed=$5 e=${1%%.*}
  local f="$out/$p=$val-$nn-$seed"
  # shellcheck disable=SC2086
  $q simulate "$v" --closed-loop --duration 60 --seed "$seed" --effects "$e" --set "$p=$val" $flags --out "$f.csv" > /dev/null 2>&1 || { echo 0; return; }
  $q diagnose "$v" "$f.csv" --out "$f.d" > /dev/null 2>&1 || { echo 0; return; }
  # Only the findings block (the selection table repeats effect names).
  local found
  found=$(sed -n '/^  "findings"/,/^  "ambiguous"/p' "$f.d/diagnosis.json" | grep -o '"effect": "[a-z_]*"' || true)
  if [ "$found" = "\"effect\": \"$e\"" ]; then echo 1; else echo 0; fi
}
echo "| parameter | noise | sizes: detected / flights |"
echo "|---|---|---|"
for p in motor_gain.C wind.x thrust_decay.rate attitude_bias.roll; do
  for n in "${noises[@]}"; do
    IFS='|' read -r nn flags <<<"$n"
    row="| $p | $nn |"
    for val in ${sizes[$p]}; do
      hits=0; total=0
      for seed in $seeds; do
        hits=$((hits + $(one "$p" "$val" "$nn" "$flags" "$seed"))); total=$((total + 1))
      done
      row="$row $val: $hits/$total;"
    done
    echo "$row"
  done
done
