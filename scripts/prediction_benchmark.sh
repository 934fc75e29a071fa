#!/usr/bin/env bash
# Prediction error on real flights, the way published models report it, for the nominal
# Crazyflie model and for the models `quadgen diagnose` fits and extends (base fit and
# extended model, on each flight's held-out last 30 %). Prints one table with the published
# numbers beside ours (scripts/prediction_table.py). Not part of CI: about 2-5 minutes per
# flight on 2 cores, most of it the diagnoses.
#   scripts/prediction_benchmark.sh [OUT_DIR]        (default out/prediction_benchmark)
# DIAGNOSES=DIR reuses the diagnoses of scripts/real_flights.sh DIR instead of running them;
# when DIR holds its joint diagnosis (JOINT=1), each flight is also predicted with the joint
# fit's values for that flight ("joint fit"). The nominal model and the joint fit are also
# scored with a linear correction fitted on the first 70 % (`predict --linear-correction`): on
# the nominal model a linear-regression baseline on the same split, on the joint fit what a
# linear model of the same signals would still explain.
# On the NanoBench flights, which log the firmware's attitude set points, the extended model
# and the joint fit also fly them with the replica of the firmware's attitude loop
# (`predict --controller crazyflie-pid`, the "set points flown" columns): not the open loop,
# and not what the published models report (their inputs are the motor commands). The loop's
# output reaches the logged commands through the firmware's battery compensation, whose
# slope there (0.48-0.77, median 0.57, on five flights: scripts/set_point_kinematics.py
# --slopes) CONTROLLER_GAIN sets (default 0.6, the median rounded).
# QUADGEN=BINARY selects the quadgen binary (default build/quadgen), as in real_flights.sh.
# Needs the build (./setup.sh --no-run), ../shared/data beside the clone, and python3.
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-out/prediction_benchmark}"
data=../shared/data/crazyflie
command -v python3 > /dev/null || { echo "python3 is needed for the table (apt-get install python3)"; exit 1; }
# The NanoBench Crazyflie's vehicle file (its motor map's slope measured in flight) and the
# stock one for the ARPL log's Crazyflie; VEHICLE=FILE overrides the NanoBench one.
# The nominal model, the baseline of every ratio, is the stock file on every log: nothing
# measured on the airframe or fitted.
nanobench_vehicle=${VEHICLE:-vehicles/crazyflie21_nanobench.yaml}
arpl_vehicle=vehicles/crazyflie21.yaml
nominal_vehicle=vehicles/crazyflie21.yaml
reuse="${DIAGNOSES:-}"
q="${QUADGEN:-build/quadgen}"
run() {  # name vehicle log mapping [extra diagnose flags...]
  local name=$1 vehicle=$2 log=$3 mapping=$4; shift 4
  echo "== $name" >&2
  mkdir -p "$out/$name"
  "$q" predict "$nominal_vehicle" "$log" --mapping "$mapping" "$@" --linear-correction --out "$out/$name/nominal" > /dev/null
  if [ -n "$reuse" ] && [ -f "$reuse/$name/diagnosis.json" ]; then
    ln -sfn "$(cd "$reuse/$name" && pwd)" "$out/$name/diagnosis"
  else
    "$q" diagnose "$vehicle" "$log" --mapping "$mapping" "$@" --out "$out/$name/diagnosis" > /dev/null
  fi
  local fly=()
  [ "$name" != arpl_log10 ] && fly=(--controller crazyflie-pid --controller-gain "${CONTROLLER_GAIN:-0.6}")
  if [ ${#fly[@]} -gt 0 ]; then
    "$q" predict "$vehicle" "$log" --mapping "$mapping" "$@" --params "$out/$name/diagnosis/diagnosis.json" \
      "${fly[@]}" --out "$out/$name/extended_set_points_flown" > /dev/null
  fi
  if [ -n "$reuse" ] && [ -f "$reuse/joint_5_flights/diagnosis.json" ] && [ "$name" != arpl_log10 ]; then
    "$q" predict "$vehicle" "$log" --mapping "$mapping" "$@" --params "$reuse/joint_5_flights/diagnosis.json" \
      --linear-correction "${fly[@]}" --out "$out/$name/joint_fit" > /dev/null 2>&1 || echo "  (not in the joint diagnosis)" >&2
  fi
}
for log in "$data"/nanobench/*.csv; do
  run "$(basename "$log" .csv)" "$nanobench_vehicle" "$log" data/mappings/nanobench.yaml
done
run arpl_log10 "$arpl_vehicle" "$data/arpl/log10.csv" data/mappings/arpl.yaml --resample 200
python3 scripts/prediction_table.py "$out"
