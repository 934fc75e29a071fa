#!/usr/bin/env bash
# Regenerates the golden files the tests compare byte for byte: the checked-in generated/
# headers and their derivation reports (a reviewer diffs derivation.md after a change to a
# vehicle or to the generator), and the closed-loop test flight of tests/golden/. Run after
# changing the generator, the templates, the simulator or a vehicle file:
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
# The closed-loop test flight that tests/test_runtime.cpp flies byte for byte (the same flight
# whichever compiler built quadgen).
cmake --build build --target quadgen -j"$(nproc)" > /dev/null
mkdir -p tests/golden
build/quadgen simulate vehicles/crazyflie21.yaml --closed-loop --seed 3 --duration 2 --out "$tmp/flight.csv" > /dev/null 2> "$tmp/err" ||
  { cat "$tmp/err" >&2; exit 1; }
cp "$tmp/flight.csv" tests/golden/closed_loop_crazyflie21_seed3.csv
echo tests/golden/closed_loop_crazyflie21_seed3.csv
