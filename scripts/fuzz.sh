#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (ASan + UBSan) and runs each for SECONDS
# (default 60) on a copy of its seed corpus. A crash input is printed and saved under
# fuzz/crashes/; keep it as a regression by moving it to fuzz/regressions/<target>/.
# Line tables only (-g1): a crash report still names file:line in each frame, and the
# build is faster than with full debug information.
#   scripts/fuzz.sh            a minute per target (CI runs it for 25 s: .ci/sanitize)
#   scripts/fuzz.sh 600        the longer run (10 minutes per target)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
export LSAN_OPTIONS="suppressions=$PWD/.ci/lsan.supp:print_suppressions=0"  # CLN/GiNaC static state
command -v clang++ >/dev/null || { echo "clang++ is needed for fuzzing (apt-get install clang)"; exit 1; }
CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
      "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 -g1 -DNDEBUG" -DQUADGEN_FUZZ=ON > /dev/null
targets=(vehicle flight_log template mapping ulog usd)
# Only the fuzz targets and what they link: the diagnosis, prediction and app libraries are
# not fuzzed, and building them instrumented took about 3 of the stage's minutes.
if ! cmake --build build-fuzz -j"$(nproc)" --target "${targets[@]/#/fuzz_}" > build-fuzz/build.log 2>&1; then
  echo "fuzz build FAILED (build-fuzz/build.log):"; grep -E -A5 "error|FAILED" build-fuzz/build.log | head -60; exit 1
fi
mkdir -p fuzz/crashes
# One target per core at a time: each is a single process, so on two cores two run side by
# side, each for the full SECONDS (the stage's time halves, the fuzzing does not).
fuzz_one() {
  local t=$1 work rc=0
  work=$(mktemp -d)
  cp -r "fuzz/corpus/$t/." "$work/"
  "build-fuzz/fuzz/fuzz_$t" "$work" -max_total_time="$seconds" -max_len=4096 -timeout=10 \
      -artifact_prefix="fuzz/crashes/${t}-" -print_final_stats=1 > "build-fuzz/fuzz_$t.log" 2>&1 || rc=$?
  echo "$rc" > "build-fuzz/fuzz_$t.status"
  rm -rf "$work"
}
jobs_at_once=$(nproc)
echo "fuzzing ${targets[*]} for $seconds s each, $jobs_at_once at a time"
for t in "${targets[@]}"; do
  rm -f "build-fuzz/fuzz_$t.status"
  while [ "$(jobs -rp | wc -l)" -ge "$jobs_at_once" ]; do wait -n || true; done
  fuzz_one "$t" &
done
wait
status=0
for t in "${targets[@]}"; do
  echo "fuzzed $t"
  if [ "$(cat "build-fuzz/fuzz_$t.status" 2>/dev/null)" != 0 ]; then
    echo "  FOUND a failure: see build-fuzz/fuzz_$t.log and fuzz/crashes/"; tail -30 "build-fuzz/fuzz_$t.log"; status=1
  else
    grep -E "stat::number_of_executed_units|cov:" "build-fuzz/fuzz_$t.log" | tail -2 | sed 's/^/  /'
  fi
done
exit $status
