#!/usr/bin/env bash
# Regenerates the checked-in generated/ headers and their derivation reports (the golden
# files tests/test_generated.cpp compares byte for byte: a reviewer diffs derivation.md after
# a change to a vehicle or to the generator). Run after changing the generator, templates or vehicle files:
#   scripts/regenerate.sh
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --build build --target quadgen-derive -j"$(nproc)" > /dev/null
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
regen() {  # vehicle-file folder-name [effects]
  local args=(derive "$1" --out "$tmp/$2")
  [ -n "${3:-}" ] && args+=(--effects "$3")
  build/quadgen-derive "${args[@]}" > /dev/null 2> "$tmp/err" || { cat "$tmp/err" >&2; exit 1; }
  mkdir -p "generated/$2"
  cp "$tmp/$2/model.hpp" "generated/$2/model.hpp"
  cp "$tmp/$2/derivation.md" "generated/$2/derivation.md"
  echo "generated/$2/model.hpp generated/$2/derivation.md"
}
regen vehicles/finken3.yaml finken3
regen vehicles/finken3.yaml finken3_all_effects all
regen vehicles/crazyflie21.yaml crazyflie21
regen vehicles/crazyflie21.yaml crazyflie21_all_effects all
regen vehicles/crazyflie21_nanobench.yaml crazyflie21_nanobench
regen vehicles/crazyflie21_nanobench.yaml crazyflie21_nanobench_all_effects all
