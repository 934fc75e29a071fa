#!/usr/bin/env bash
# Every usable NanoBench flight of the one Crazyflie held out in turn: the other four are
# diagnosed jointly, the held-out flight is predicted with the nominal model, with the
# airframe's values and with those plus its own trims and marker frame calibrated on its
# first 70 % (scored on its last 30 %), and it is diagnosed against that airframe (do its
# named effects hold there, with the same values?). Each fold is scripts/cross_flight.sh
# with UNSEEN set; the table is scripts/leave_one_flight_out_table.py's.
#   scripts/leave_one_flight_out.sh [OUT_DIR]   (default /tmp/quadgen_lofo; ~15-20 min on 2 cores)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-/tmp/quadgen_lofo}
mkdir -p "$out"
for n in B2_circle_medium_rep1 B3_figure8_medium_rep1 B3_figure8_medium_rep2 B3_figure8_slow_rep1 B5_helix_slow_rep1; do
  echo "fold: $n held out ($(date +%H:%M:%S)) ..." >&2
  UNSEEN=$n EXTRA_CHECKS="" scripts/cross_flight.sh "$out/$n" > "$out/$n.txt" 2>&1 ||
    { echo "fold $n failed: see $out/$n.txt" >&2; exit 1; }
done
python3 scripts/leave_one_flight_out_table.py "$out"
