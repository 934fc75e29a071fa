#!/usr/bin/env bash
# Diagnoses every NanoBench flight of the one Crazyflie (CF_01) and checks the rules of
# what diagnose may name (docs/validation.md, "Real data"):
#   scripts/real_flights.sh [OUT_DIR]
# With JOINT=1 it also diagnoses the five usable flights jointly (B6 saturates its PWM; see
# docs/crazyflie_evidence.md): one set of airframe parameters for all.
# For each flight: named findings with their intervals and held-out fold gain, suspected
# candidates with the test they failed, look-alike groups, and the open-loop prediction
# error before/after. A finding with an open interval, an interval containing "off", or
# no held-out gain beyond its standard error is a violation (exit status 1).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-/tmp/quadgen_real_flights}
q=${QUADGEN:-build/quadgen}
vehicle=${VEHICLE:-vehicles/crazyflie21_nanobench.yaml}
data=${QUADGEN_NANOBENCH:-../shared/data/crazyflie/nanobench}
mkdir -p "$out"
for f in "$data"/*.csv; do
  name=$(basename "$f" .csv)
  if [ ! -f "$out/$name/diagnosis.json" ]; then
    echo "diagnosing $name ..." >&2
    "$q" diagnose "$vehicle" "$f" --mapping data/mappings/nanobench.yaml --out "$out/$name" \
      > "$out/$name.log" 2>&1 || echo "  failed: see $out/$name.log" >&2
  fi
done
if [ "${JOINT:-0}" = 1 ] && [ ! -f "$out/joint_5_flights/diagnosis.json" ]; then
  echo "diagnosing the five usable flights jointly ..." >&2
  logs=()
  for f in "$data"/*.csv; do
    case "$(basename "$f")" in B6_*) ;; *) logs+=("$f") ;; esac
  done
  "$q" diagnose "$vehicle" "${logs[@]}" --mapping data/mappings/nanobench.yaml \
    --out "$out/joint_5_flights" > "$out/joint_5_flights.log" 2>&1 || echo "  failed: see $out/joint_5_flights.log" >&2
fi
python3 scripts/real_flights_table.py "$out"
