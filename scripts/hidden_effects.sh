#!/usr/bin/env bash
# Hides each effect of the catalogue in generated closed-loop flights and diagnoses them:
#   scripts/hidden_effects.sh [OUT_DIR] [SEEDS]
# One line per flight: the hidden effect and value, what the diagnosis named, and its
# estimate. Used for the README's table; the CI suite (tests/test_diagnose.cpp) runs a
# subset with assertions.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-/tmp/quadgen_hidden}
seeds=${2:-"1 2"}
q=${QUADGEN:-build/quadgen}
v=vehicles/finken3.yaml
mkdir -p "$out"
noise=(--gyro-noise 0.01 --accel-noise 0.05)
cases=(
  "clean||"
  "motor_gain|motor_gain|motor_gain.C=-0.08"
  "motor_lag|motor_lag|motor_lag.tau=0.05"
  "input_delay|input_delay|input_delay.seconds=0.025"
  "cog_offset|cog_offset|cog_offset.x=0.01 cog_offset.y=-0.005"
  "rotor_drag|rotor_drag|rotor_drag.k=2e-5"
  "wind|wind|wind.x=1.5 wind.y=-1.0"
  "attitude_bias|attitude_bias|attitude_bias.roll=0.03 attitude_bias.pitch=-0.02"
  "thrust_decay|thrust_decay|thrust_decay.rate=0.002"
  "battery_sag|battery_sag|battery_sag.exponent=1.5"
  "ground_effect|ground_effect|ground_effect.radius=0.0635"
)
for seed in $seeds; do
  for c in "${cases[@]}"; do
    IFS='|' read -r name effects sets <<<"$c"
    args=(simulate "$v" --closed-loop --duration 60 --seed "$seed" --out "$out/$name-$seed.csv" "${noise[@]}")
    [ -n "$effects" ] && args+=(--effects "$effects")
    for s in $sets; do args+=(--set "$s"); done
    [ "$name" = ground_effect ] && args+=(--height 0.25 --height-amplitude 0.1)
    $q "${args[@]}" > /dev/null 2>&1 || { echo "$name seed $seed: flight lost"; continue; }
    start=$(date +%s.%N)
    result=$($q diagnose "$v" "$out/$name-$seed.csv" --out "$out/d-$name-$seed" 2>/dev/null | head -n -1 | tr '\n' ' ')
    end=$(date +%s.%N)
    printf '%s seed %s (%s): %s[%.1f s]\n' "$name" "$seed" "$sets" "$result" "$(awk "BEGIN{print $end - $start}")"
  done
done
