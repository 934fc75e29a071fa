#!/usr/bin/env bash
# Measures what the code generator promises (docs/benchmarks.md), each line with its target:
#   - derive + emit time of synthetic multirotors (4, 8 and 16 rotors, all effects) and of
#     vehicles of 1,000 and 10,000 blocks (scripts/multirotor_vehicle.py writes them);
#   - compile time of the all-effects model's f instantiated over ceres::Jet (the f-only entry
#     point, as a Ceres user would), and of tests/test_generated_jets.cpp with the build's
#     own flags.
# CPU seconds (user + sys) of one run each, so that a loaded machine inflates them less than
# wall-clock time. Not part of CI. Exit status 1 if a target is missed.
#   scripts/codegen_targets.sh            # uses build/ (builds quadgen-derive if missing)
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
CXX=${CXX:-c++}
[ -x "$BUILD/quadgen-derive" ] || cmake --build "$BUILD" --target quadgen-derive -j1 > /dev/null
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
status=0

cpu_seconds() {  # command...: runs it, prints its user + sys CPU seconds; fails with it
  /usr/bin/time -f "%U %S" -o "$tmp/time" "$@" > "$tmp/out" 2> "$tmp/err" || { cat "$tmp/err" >&2; return 1; }
  awk '{ printf "%.2f", $1 + $2 }' "$tmp/time"
}
report() {  # what seconds limit
  local verdict=met
  awk -v s="$2" -v l="$3" 'BEGIN { exit !(s < l) }' || { verdict=MISSED; status=1; }
  printf '| %s | %s s | < %s s | %s |\n' "$1" "$2" "$3" "$verdict"
}

echo "| what | CPU time | target | |"
echo "|---|---|---|---|"
for spec in "4 9 all" "8 17 all" "16 33 all" "4 1000 none" "4 10000 none"; do
  read -r rotors blocks effects <<< "$spec"
  vehicle="$tmp/v_${rotors}_${blocks}.yaml"
  python3 scripts/multirotor_vehicle.py "$rotors" "$blocks" "$vehicle"
  args=(derive "$vehicle" --out "$tmp/out_${rotors}_${blocks}")
  [ "$effects" = all ] && args+=(--effects all)
  secs=$(cpu_seconds "$BUILD/quadgen-derive" "${args[@]}")
  case "$spec" in
    "8 17 all") limit=2 ;;
    "4 1000 none") limit=2 ;;
    "4 10000 none") limit=20 ;;
    *) limit=1000 ;;  # no target: shows how the time grows with the rotors
  esac
  label="derive + emit, $rotors rotors, $blocks blocks, effects: $effects"
  if [ "$limit" = 1000 ]; then printf '| %s | %s s | — | |\n' "$label" "$secs"; else report "$label" "$secs" "$limit"; fi
done

# The all-effects f over ceres::Jet, as a Ceres cost functor would instantiate it.
cxxflags=(-std=c++17 -O3 -DNDEBUG -I/usr/include/eigen3)
cat > "$tmp/jet_f.cpp" << 'EOF'
#include <ceres/jet.h>
#include "finken3_all_effects/model.hpp"
namespace m = quadgen_generated::finken3_all_effects;
using Jet = ceres::Jet<double, 8>;
void evaluate(const Jet* x, const Jet* u, const Jet* p, Jet* f) {
  m::Precomputed<Jet> pre;
  m::precompute(p, &pre);
  m::rhs(x, u, p, pre, f);
}
EOF
secs=$(cpu_seconds "$CXX" "${cxxflags[@]}" -Igenerated -c "$tmp/jet_f.cpp" -o "$tmp/jet_f.o")
report "compile: all-effects f over ceres::Jet<double, 8> (-O3)" "$secs" 10

# tests/test_generated_jets.cpp with the flags the build uses (compile_commands.json).
command=$(python3 - "$BUILD/compile_commands.json" << 'EOF'
import json, sys
for entry in json.load(open(sys.argv[1])):
    if entry["file"].endswith("tests/test_generated_jets.cpp"):
        print(entry["command"])
EOF
)
command=${command/ -o * -c / -o $tmp/jets.o -c }
secs=$(cd "$BUILD/tests" && cpu_seconds bash -c "$command")
report "compile: tests/test_generated_jets.cpp (build flags)" "$secs" 40
exit $status
