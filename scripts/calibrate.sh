#!/usr/bin/env bash
# Detection rate against effect size and noise level (docs/validation.md, "Calibration"):
#   scripts/calibrate.sh [OUT_DIR] [SEEDS]
# For each effect, size and noise level, closed-loop flights over the seeds are diagnosed;
# "named" counts flights where the hidden effect is named and nothing else, "detected"
# also those reporting it ambiguous with a look-alike. Prints a markdown table.
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
# One flight: prints "N A" — N = 1 if the hidden effect is named alone, A = 1 if it is at
# least detected (named, or reported ambiguous with a look-alike). Reuses earlier results.
one() {  # param value noise-name noise-flags seed
  local p=$1 val=$2 nn=$3 flags=$4 seed=$5 e=${1%%.*}
  local f="$out/$p=$val-$nn-$seed"
  if [ ! -f "$f.d/diagnosis.json" ]; then
    # shellcheck disable=SC2086
    $q simulate "$v" --closed-loop --duration 60 --seed "$seed" --effects "$e" --set "$p=$val" $flags --out "$f.csv" > /dev/null 2>&1 || { echo "0 0"; return; }
    $q diagnose "$v" "$f.csv" --out "$f.d" > /dev/null 2>&1 || { echo "0 0"; return; }
  fi
  # Named alone: the findings are exactly this effect; detected: named, or in a look-alike
  # group. (Suspected candidates count as neither.)
  local named detected
  read -r named detected < <(python3 - "$f.d/diagnosis.json" "$e" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
e = sys.argv[2]
named = [f["effect"] for f in j["findings"]] == [e]
grouped = any(e in a["effects"] for a in j.get("ambiguous", []))
print(int(named), int(named or grouped))
PY
)
  echo "$named $detected"
}
echo "| parameter | noise | size: named alone / detected (named or ambiguous with a look-alike) / flights |"
echo "|---|---|---|"
for p in motor_gain.C wind.x thrust_decay.rate attitude_bias.roll; do
  for n in "${noises[@]}"; do
    IFS='|' read -r nn flags <<<"$n"
    row="| $p | $nn |"
    for val in ${sizes[$p]}; do
      named=0; detected=0; total=0
      for seed in $seeds; do
        read -r a b <<<"$(one "$p" "$val" "$nn" "$flags" "$seed")"
        named=$((named + a)); detected=$((detected + b)); total=$((total + 1))
      done
      row="$row $val: $named/$detected/$total;"
    done
    echo "$row"
  done
done
