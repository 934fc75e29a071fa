#!/usr/bin/env bash
# Diagnoses every NanoBench flight of the one Crazyflie (CF_01) and checks the rules of
# what diagnose may name (README "Real flights"):
#   scripts/real_flights.sh [OUT_DIR]
# For each flight: named findings with their intervals and held-out fold gain, suspected
# candidates with the test they failed, look-alike groups, and the open-loop prediction
# error before/after. A finding with an open interval, an interval containing "off", or
# no held-out gain beyond its standard error is a violation (exit status 1).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-/tmp/quadgen_real_flights}
q=${QUADGEN:-build/quadgen}
data=${QUADGEN_NANOBENCH:-../shared/data/crazyflie/nanobench}
mkdir -p "$out"
for f in "$data"/*.csv; do
  name=$(basename "$f" .csv)
  if [ ! -f "$out/$name/diagnosis.json" ]; then
    echo "diagnosing $name ..." >&2
    "$q" diagnose vehicles/crazyflie21.yaml "$f" --mapping data/mappings/nanobench.yaml --out "$out/$name" \
      > "$out/$name.log" 2>&1 || echo "  failed: see $out/$name.log" >&2
  fi
done
python3 scripts/real_flights_table.py "$out"
