#!/usr/bin/env bash
# PortableRandom.TheSameDrawsWithLibcxx: the simulator's random numbers are the same with
# another standard library. Builds tests/portable_random_draws.cpp with clang and LLVM's libc++
# and compares its draws, exactly, with those of the copy the project's compiler built against
# libstdc++ (argument 1).
# A developers' check: without libc++ it is skipped (exit 77, reported as skipped), and
# scripts/install-deps.sh does not install it, because on Debian 12 libc++-14-dev pulls in
# libunwind-14-dev, which removes libunwind-dev, which glog and so Ceres's CMake package need.
# To run it: apt-get install libc++-14-dev, run this test, then apt-get install libunwind-dev.
set -euo pipefail
built_here=$1 source_dir=$2
work=$(mktemp -d "${TMPDIR:-/tmp}/portable_random.XXXXXX")
trap 'rm -rf "$work"' EXIT
if ! command -v clang++ > /dev/null || ! echo '#include <random>' | clang++ -std=c++17 -stdlib=libc++ -x c++ -fsyntax-only - 2> /dev/null; then
  echo "skipped: no clang++ with LLVM's libc++ here (apt-get install libc++-14-dev; see this script's header)"
  exit 77
fi
if ! clang++ -std=c++17 -O1 -ffp-contract=off -stdlib=libc++ -I"$source_dir" \
     "$source_dir/tests/portable_random_draws.cpp" -o "$work/draws_libcxx" 2> "$work/compile.txt"; then
  cat "$work/compile.txt" >&2
  echo "could not build tests/portable_random_draws.cpp with clang++ -stdlib=libc++" >&2
  exit 1
fi
"$built_here" > "$work/libstdcxx.txt"
"$work/draws_libcxx" > "$work/libcxx.txt"
lines=$(wc -l < "$work/libstdcxx.txt")
[ "$lines" -ge 18000 ] || { echo "only $lines draws from $built_here" >&2; exit 1; }
if ! cmp -s "$work/libstdcxx.txt" "$work/libcxx.txt"; then
  echo "portable_random.hpp gives other numbers with libc++ (draw: line, libstdc++, libc++):" >&2
  diff <(nl -ba "$work/libstdcxx.txt") <(nl -ba "$work/libcxx.txt") | head -5 >&2
  exit 1
fi
# What it replaces, shown for the record: the libraries' own distributions.
"$built_here" --std > "$work/std_libstdcxx.txt"
"$work/draws_libcxx" --std > "$work/std_libcxx.txt"
same=$(cmp -s "$work/std_libstdcxx.txt" "$work/std_libcxx.txt" && echo "the same" || echo "different")
echo "$lines draws the same with libstdc++ and libc++; std::normal_distribution's: $same"
