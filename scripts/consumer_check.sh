#!/usr/bin/env bash
# The library use of the README ("Use as a library"), checked end to end: install a quadgen
# build into a temporary prefix, configure examples/consumer against it with find_package(quadgen)
# (its CMakeLists runs `quadgen derive` on vehicles/finken3.yaml at build time), build it and run
# it (RK4 in float and double; non-zero exit unless they agree and stay finite), and the
# README's C++ example with it.
#   scripts/consumer_check.sh [BUILD_DIR]     (default: build; needs the quadgen target built)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
tmp=$(mktemp -d "${TMPDIR:-/tmp}/quadgen-consumer.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
cmake --install "$build" --prefix "$tmp/prefix" >"$tmp/install.log" || { cat "$tmp/install.log"; exit 1; }
# The README's C++ example (the fenced block after its "compiled and run by" marker) is built
# and run too, so that it cannot drift from the header.
awk '/<!-- compiled and run by scripts\/consumer_check.sh/ {found = 1; next}
     found && /^```cpp/ {copy = 1; next}
     copy && /^```/ {exit}
     copy {print}' README.md > "$tmp/readme_example.cpp"
[ -s "$tmp/readme_example.cpp" ] || { echo "consumer_check: no marked C++ example in README.md" >&2; exit 1; }
cmake -S examples/consumer -B "$tmp/build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$tmp/prefix" \
      -DQUADGEN_VEHICLE="$PWD/vehicles/finken3.yaml" -DQUADGEN_README_EXAMPLE="$tmp/readme_example.cpp" \
      >"$tmp/configure.log" || { cat "$tmp/configure.log"; exit 1; }
cmake --build "$tmp/build" -j2 >"$tmp/build.log" 2>&1 || { cat "$tmp/build.log"; exit 1; }
"$tmp/build/quadgen_consumer"
"$tmp/build/quadgen_consumer_effects" || { echo "consumer_check: the model generated with EFFECTS failed" >&2; exit 1; }
"$tmp/build/quadgen_consumer_two_models" || { echo "consumer_check: two models in one translation unit failed" >&2; exit 1; }
"$tmp/build/readme_example" || { echo "consumer_check: the README example ran and failed" >&2; exit 1; }
echo "consumer_check: installed package, quadgen_generate_model() and the generated header work"
