#!/usr/bin/env bash
# Side by side: quadgen's generated FINken 3 base model against the same model written
# independently in SymPy (scripts/sympy_compare.py) with sympy.cse over f and all
# Jacobians jointly. Prints the operation counts of both (counted the same way, on the C++
# text) and ns per call of both, compiled in one translation unit with the same flags.
# Not part of CI; installs python3-sympy (and python3-yaml) with apt-get when missing.
#
#   scripts/sympy_compare.sh            # FINken 3; uses build/quadgen-derive (builds it if missing)
#   scripts/sympy_compare.sh VEHICLE.yaml [EFFECTS]   # any vehicle, e.g. an octocopter written
#       by scripts/multirotor_vehicle.py 8 17 octo.yaml; EFFECTS as for derive --effects (all)
#   BUILD=build-codegen scripts/sympy_compare.sh
#   CXXFLAGS="-O3 -march=native" scripts/sympy_compare.sh
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
CXX=${CXX:-c++}
CXXFLAGS=${CXXFLAGS:--O2}

if ! python3 -c "import sympy, yaml" 2> /dev/null; then
  echo "installing python3-sympy python3-yaml"
  apt-get update > /dev/null
  DEBIAN_FRONTEND=noninteractive apt-get install -y python3-sympy python3-yaml > /dev/null
fi
[ -x "$BUILD/quadgen-derive" ] || cmake --build "$BUILD" --target quadgen-derive -j1 > /dev/null

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
VEHICLE=${1:-vehicles/finken3.yaml}
derive_args=(derive "$VEHICLE" --out "$tmp/quadgen")
[ -n "${2:-}" ] && derive_args+=(--effects "$2")
"$BUILD/quadgen-derive" "${derive_args[@]}" > /dev/null 2>&1
name=$(sed -n '/^namespace quadgen_generated {/{n;s/^namespace \([A-Za-z0-9_]*\) {$/\1/p;q}' "$tmp/quadgen/model.hpp")
echo "vehicle: $VEHICLE ($name), effects: ${2:-none}"
python3 scripts/sympy_compare.py emit "$VEHICLE" "$tmp/quadgen/model.json" "$tmp"
python3 scripts/sympy_compare.py count "$tmp/quadgen/model.hpp" "$tmp/sympy_model.hpp"

cat > "$tmp/harness.cpp" << 'EOF'
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>

#include "quadgen/model.hpp"
#include "sympy_model.hpp"

namespace q = quadgen_generated::MODEL_NAME;
namespace s = sympy_model;
constexpr int NX = q::kNumStates, NU = q::kNumInputs, NP = q::kNumParams;

__attribute__((noinline)) void run_quadgen(const double* x, const double* u, const double* p,
                                           const q::Precomputed<double>& pre, double* f, double* dx, double* du,
                                           double* dp) {
  q::rhs(x, u, p, pre, f, dx, du, dp);
}
__attribute__((noinline)) void run_quadgen_f(const double* x, const double* u, const double* p,
                                             const q::Precomputed<double>& pre, double* f) {
  q::rhs(x, u, p, pre, f, (double*)nullptr, (double*)nullptr, (double*)nullptr);
}
__attribute__((noinline)) void run_quadgen_with_precompute(const double* x, const double* u, const double* p,
                                                           q::Precomputed<double>* pre, double* f, double* dx,
                                                           double* du, double* dp) {
  q::precompute(p, pre);
  q::rhs(x, u, p, *pre, f, dx, du, dp);
}
__attribute__((noinline)) void run_sympy(const double* x, const double* u, const double* p, double* f, double* dx,
                                         double* du, double* dp) {
  s::rhs(x, u, p, f, dx, du, dp);
}

template <class F>
double ns_per_call(F&& fn) {
  double best = 1e300;
  for (int rep = 0; rep < 7; ++rep) {
    const int n = 20000;
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < n; ++i) {
      fn(i);
      asm volatile("" ::: "memory");
    }
    const auto t1 = std::chrono::steady_clock::now();
    best = std::min(best, std::chrono::duration<double, std::nano>(t1 - t0).count() / n);
  }
  return best;
}

int main() {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> d(-1, 1);
  double worst = 0;
  for (int t = 0; t < 50; ++t) {  // the two models agree (dense comparison of all Jacobians)
    double x[NX], u[NU], p[NP], n = 0;
    for (double& v : x) v = d(rng);
    for (int i = 6; i < 10; ++i) n += x[i] * x[i];
    for (int i = 6; i < 10; ++i) x[i] /= std::sqrt(n);
    for (double& v : u) v = 0.5 + 0.3 * d(rng);
    for (int i = 0; i < NP; ++i) p[i] = q::kNominalParams[i] * (1 + 0.2 * d(rng)) + 1e-4 * d(rng);
    q::Precomputed<double> pre;
    q::precompute(p, &pre);
    double f1[NX], f2[NX], a1[q::kDfdxNnz], b1[q::kDfduNnz], c1[q::kDfdpNnz];
    double a2[s::kdfdxNnz], b2[s::kdfduNnz], c2[s::kdfdpNnz];
    q::rhs(x, u, p, pre, f1, a1, b1, c1);
    s::rhs(x, u, p, f2, a2, b2, c2);
    auto cmp = [&](double a, double b) { worst = std::max(worst, std::fabs(a - b) / (1 + std::fabs(b))); };
    for (int i = 0; i < NX; ++i) cmp(f1[i], f2[i]);
    auto dense = [&](int cols, int nnz1, const int* r1, const int* k1, const double* v1, int nnz2, const int* r2,
                     const int* k2, const double* v2) {
      std::vector<double> A(NX * cols, 0.0), B(NX * cols, 0.0);
      for (int k = 0; k < nnz1; ++k) A[r1[k] * cols + k1[k]] = v1[k];
      for (int k = 0; k < nnz2; ++k) B[r2[k] * cols + k2[k]] = v2[k];
      for (int k = 0; k < NX * cols; ++k) cmp(A[k], B[k]);
    };
    dense(NX, q::kDfdxNnz, q::kDfdxRow, q::kDfdxCol, a1, s::kdfdxNnz, s::kdfdxRow, s::kdfdxCol, a2);
    dense(NU, q::kDfduNnz, q::kDfduRow, q::kDfduCol, b1, s::kdfduNnz, s::kdfduRow, s::kdfduCol, b2);
    dense(NP, q::kDfdpNnz, q::kDfdpRow, q::kDfdpCol, c1, s::kdfdpNnz, s::kdfdpRow, s::kdfdpCol, c2);
  }
  std::printf("agreement: f and all Jacobian entries, 50 random points: max |quadgen - sympy| / (1 + |sympy|) = %.1e\n",
              worst);
  if (!(worst < 1e-9)) {
    std::printf("the two models disagree\n");
    return 1;
  }

  double x[NX] = {0.1, -0.2, 1.2, 0.5, -0.3, 0.1, 0.98, 0.1, -0.1, 0.1, 0.4, -0.2, 0.3};
  double u[NU], p[NP];
  for (int i = 0; i < NU; ++i) u[i] = 0.4 + 0.03 * (i % 4);
  for (int i = 0; i < NP; ++i) p[i] = q::kNominalParams[i];
  q::Precomputed<double> pre;
  q::precompute(p, &pre);
  double f[NX], a[q::kDfdxNnz + s::kdfdxNnz], b[q::kDfduNnz + s::kdfduNnz], c[q::kDfdpNnz + s::kdfdpNnz];
  auto wiggle = [&](int i) { x[10] = 0.4 + 1e-9 * (i & 7); };
  const double tq = ns_per_call([&](int i) { wiggle(i); run_quadgen(x, u, p, pre, f, a, b, c); });
  const double tqf = ns_per_call([&](int i) { wiggle(i); run_quadgen_f(x, u, p, pre, f); });
  const double tqp = ns_per_call([&](int i) { wiggle(i); run_quadgen_with_precompute(x, u, p, &pre, f, a, b, c); });
  const double ts = ns_per_call([&](int i) { wiggle(i); run_sympy(x, u, p, f, a, b, c); });
  std::printf("ns per call (f and all Jacobians, best of 7 x 20000 calls):\n");
  std::printf("  quadgen rhs (precompute() once per parameter vector) %8.0f\n", tq);
  std::printf("  quadgen precompute() + rhs every call                %8.0f\n", tqp);
  std::printf("  sympy.cse                                            %8.0f\n", ts);
  std::printf("  quadgen rhs / sympy.cse                              %8.2fx\n", tq / ts);
  std::printf("  (quadgen f alone: %.0f ns)\n", tqf);
  return 0;
}
EOF
echo "compiling both with: $CXX -std=c++17 $CXXFLAGS"
# shellcheck disable=SC2086
$CXX -std=c++17 $CXXFLAGS -DMODEL_NAME="$name" -I"$tmp" "$tmp/harness.cpp" -o "$tmp/harness"
"$tmp/harness"
