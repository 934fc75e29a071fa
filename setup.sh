#!/usr/bin/env bash
# First command of the README: install what is missing, build, and run the main job on bundled data.
#   ./setup.sh            install + build + derive the bundled vehicles into out/
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
  echo "derivation reports: out/*/derivation.md"
fi
