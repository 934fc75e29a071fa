#!/usr/bin/env bash
# Fit on some flights, predict another: diagnoses four NanoBench flights of the one Crazyflie
# jointly (figure-8s and the circle), then predicts the helix (B5), which no fit has seen, on
# its last 30 %: with the nominal model, with the airframe's values from the joint fit, and
# with those plus the helix's own flight parameters (motor trims, marker frame) calibrated
# on its first 70 % (quadgen predict --calibrate). The four training flights are predicted
# on their held-out ends with their own values. Prints the table of prediction_table.py.
# Then diagnoses the helix and the linear ramps (B6, in no joint fit) against the four
# flights' airframe (quadgen diagnose --airframe): do its named effects hold there, with
# the airframe's values?
#   scripts/cross_flight.sh [OUT_DIR]       (default /tmp/quadgen_cross_flight; ~4 min)
# UNSEEN=NAME holds out another usable flight instead of the helix (the other four are the
# training flights); EXTRA_CHECKS="..." are the further flights checked against the airframe
# (default the linear ramps B6). scripts/leave_one_flight_out.sh holds out each in turn.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-/tmp/quadgen_cross_flight}
q=${QUADGEN:-build/quadgen}
data=${QUADGEN_NANOBENCH:-../shared/data/crazyflie/nanobench}
# The airframe's vehicle file (the stock one with its motor map's slope measured in flight);
# the nominal model, the baseline of the ratios, is the stock file: nothing measured or fitted.
vehicle=${VEHICLE:-vehicles/crazyflie21_nanobench.yaml}
nominal_vehicle=vehicles/crazyflie21.yaml
mapping=data/mappings/nanobench.yaml
usable=(B2_circle_medium_rep1 B3_figure8_medium_rep1 B3_figure8_medium_rep2 B3_figure8_slow_rep1 B5_helix_slow_rep1)
unseen=${UNSEEN:-B5_helix_slow_rep1}
extra_checks=${EXTRA_CHECKS-B6_linear_ramp_rep1}
train=()
for n in "${usable[@]}"; do [ "$n" = "$unseen" ] || train+=("$n"); done
if [ "${#train[@]}" != 4 ]; then echo "UNSEEN must be one of: ${usable[*]}" >&2; exit 2; fi
mkdir -p "$out/table"
if [ ! -f "$out/joint_4_flights/diagnosis.json" ]; then
  logs=()
  for n in "${train[@]}"; do logs+=("$data/$n.csv"); done
  echo "diagnosing ${train[*]} jointly ..." >&2
  "$q" diagnose "$vehicle" "${logs[@]}" --mapping "$mapping" --max-effects 5 --out "$out/joint_4_flights" \
    > "$out/joint_4_flights.log" 2>&1 || { echo "failed: see $out/joint_4_flights.log" >&2; exit 1; }
fi
params="$out/joint_4_flights/diagnosis.json"
predict() {  # vehicle flight folder-name [flags...]
  local v=$1 n=$2 name=$3; shift 3
  rm -rf "$out/table/$n/$name"
  mkdir -p "$out/table/$n"
  "$q" predict "$v" "$data/$n.csv" --mapping "$mapping" "$@" --out "$out/table/$n/$name" > /dev/null 2>&1 ||
    echo "predict $n $name failed" >&2
}
for n in "${train[@]}"; do predict "$vehicle" "$n" joint_fit_own_values --params "$params"; done
predict "$nominal_vehicle" "$unseen" nominal
predict "$vehicle" "$unseen" unseen_airframe_values --params "$params"
predict "$vehicle" "$unseen" unseen_calibrated_first_70pct --params "$params" --calibrate
python3 scripts/prediction_table.py "$out/table"
for n in "$unseen" $extra_checks; do
  if [ ! -f "$out/check_$n/diagnosis.json" ]; then
    echo "checking $n against the airframe ..." >&2
    "$q" diagnose "$vehicle" "$data/$n.csv" --mapping "$mapping" --airframe "$params" --out "$out/check_$n" \
      > "$out/check_$n.log" 2>&1 || echo "check of $n failed: see $out/check_$n.log" >&2
  fi
  echo; echo "$n against the airframe of the four flights:"
  grep -E '^(this flight|named|suspected)' "$out/check_$n.log" | cut -c1-300 || true
done
