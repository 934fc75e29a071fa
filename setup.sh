#!/usr/bin/env bash
# First command of the README: install what is missing, build, and run the main job (the bundled
# vehicles, a generated flight, and a real NanoBench flight where the reference data sits beside the clone).
#   ./setup.sh            install + build + derive the bundled vehicles into out/, diagnose a
#                         test flight with a hidden weak motor and the NanoBench flight, and
#                         measure the extended model's prediction error on the latter
#   ./setup.sh --no-run   install + build only (used by .ci/run)
set -euo pipefail
cd "$(dirname "$0")"
scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc)"
if [ "${1:-}" != "--no-run" ]; then
  for v in finken3 crazyflie21; do
    build/quadgen derive "vehicles/$v.yaml" --out "out/$v"
  done
  build/quadgen derive vehicles/finken3.yaml --out out/finken3_all_effects --effects all
  # The main job end to end: a test flight with a weak motor C hidden in it, diagnosed.
  build/quadgen simulate vehicles/finken3.yaml --closed-loop --duration 60 --seed 1 \
      --effects motor_gain --set motor_gain.C=-0.08 --gyro-noise 0.01 --accel-noise 0.05 --out out/weak_motor_C.csv
  build/quadgen diagnose vehicles/finken3.yaml out/weak_motor_C.csv --out out/diagnosis_weak_motor_C
  # The real flights, when the shared data sits beside the clone (the Crazyflie that flew them:
  # the stock file with its motor map's slope measured in flight, docs/crazyflie_evidence.md).
  nb=../shared/data/crazyflie/nanobench/B3_figure8_medium_rep2.csv
  if [ -f "$nb" ]; then
    build/quadgen diagnose vehicles/crazyflie21_nanobench.yaml "$nb" --mapping data/mappings/nanobench.yaml --out out/diagnosis_nanobench
    # The measuring stick: prediction error at horizons, as published models report it.
    build/quadgen predict vehicles/crazyflie21_nanobench.yaml "$nb" --mapping data/mappings/nanobench.yaml \
        --params out/diagnosis_nanobench/diagnosis.json --out out/prediction_nanobench
    echo "derivation reports: out/*/derivation.md; diagnoses: out/diagnosis_*/report.html; prediction: out/prediction_nanobench/prediction.json"
  else
    echo "skipped: the real NanoBench flight's diagnosis and prediction ($nb not found: the reference data is"
    echo "  not part of the clone; the README's 'The reference data' says where it comes from)"
    echo "derivation reports: out/*/derivation.md; diagnosis: out/diagnosis_weak_motor_C/report.html"
  fi
fi
