// The generated Jacobians against forward-mode automatic differentiation (ceres::Jet) of the
// generated f itself. A translation unit of its own: instantiating f over Jets is by far the
// most expensive thing to compile in the project (see tests/CMakeLists.txt).
#include <gtest/gtest.h>

#include <ceres/jet.h>

#include <algorithm>
#include <vector>

#include "tests/generated_models.hpp"

// Forward-mode automatic differentiation of the generated f: exact to rounding, so the
// analytic Jacobians must agree to 1e-8 relative. The derivative directions are seeded
// kJetWidth at a time: one narrow Jet type keeps the instantiation of f over thousands of
// generated operations cheap to compile (under the sanitizers above all).
constexpr int kJetWidth = 8;

template <class M>
void check_jacobians_against_jets(int trials) {
  constexpr int N = M::kNumStates + M::kNumInputs + M::kNumParams;
  using Jet = ceres::Jet<double, kJetWidth>;
  std::mt19937 rng(7);
  for (int t = 0; t < trials; ++t) {
    Point<M> pt = random_point<M>(rng);
    double fv[M::kNumStates], dfdx[M::kDfdxNnz + 1], dfdu[M::kDfduNnz + 1], dfdp[M::kDfdpNnz + 1];
    M::f(pt.x, pt.u, pt.p, fv, dfdx, dfdu, dfdp);
    // Dense analytic Jacobian over all N variables (states, inputs, parameters).
    std::vector<double> dense(M::kNumStates * N, 0.0);
    for (int k = 0; k < M::kDfdxNnz; ++k) dense[M::dfdx_row[k] * N + M::dfdx_col[k]] = dfdx[k];
    for (int k = 0; k < M::kDfduNnz; ++k) dense[M::dfdu_row[k] * N + M::kNumStates + M::dfdu_col[k]] = dfdu[k];
    for (int k = 0; k < M::kDfdpNnz; ++k)
      dense[M::dfdp_row[k] * N + M::kNumStates + M::kNumInputs + M::dfdp_col[k]] = dfdp[k];
    for (int first = 0; first < N; first += kJetWidth) {
      // Variable j carries derivative direction j - first when it lies in this block.
      auto seeded = [first](double value, int j) {
        Jet jet(value);
        if (j >= first && j < first + kJetWidth) jet.v[j - first] = 1.0;
        return jet;
      };
      Jet x[M::kNumStates], u[M::kNumInputs], p[M::kNumParams], f[M::kNumStates];
      for (int i = 0; i < M::kNumStates; ++i) x[i] = seeded(pt.x[i], i);
      for (int i = 0; i < M::kNumInputs; ++i) u[i] = seeded(pt.u[i], M::kNumStates + i);
      for (int i = 0; i < M::kNumParams; ++i) p[i] = seeded(pt.p[i], M::kNumStates + M::kNumInputs + i);
      M::f(x, u, p, f, (Jet*)nullptr, (Jet*)nullptr, (Jet*)nullptr);
      // Every entry, structural zeros of the analytic Jacobian included (a jet may carry a
      // rounding-sized remainder there), against the jet.
      for (int i = 0; i < M::kNumStates; ++i) {
        EXPECT_NEAR(f[i].a, fv[i], 1e-12 * (1 + std::fabs(fv[i])));
        for (int j = first; j < std::min(N, first + kJetWidth); ++j) {
          const double want = f[i].v[j - first], got = dense[i * N + j];
          EXPECT_NEAR(got, want, 1e-8 * (1 + std::fabs(want))) << "f[" << i << "] / var " << j;
        }
      }
    }
  }
}

TEST(Generated, Finken3JacobiansMatchJets) { check_jacobians_against_jets<finken3_traits>(50); }
TEST(Generated, AllEffectsJacobiansMatchJets) { check_jacobians_against_jets<finken3_all_effects_traits>(50); }
TEST(Generated, CrazyflieJacobiansMatchJets) { check_jacobians_against_jets<crazyflie21_traits>(50); }
// The Crazyflie's headers with every effect, the NanoBench airframe's (its motor map turned
// about its pivot by a parameter) and the stock one's (a review of the tests, helper-123: the
// Crazyflie's effects had finite differences only). About 2 s of build each, twice in CI.
TEST(Generated, CrazyflieEffectsJacobiansMatchJets) {
  check_jacobians_against_jets<crazyflie21_nanobench_all_effects_traits>(20);
  check_jacobians_against_jets<crazyflie21_all_effects_traits>(20);
}
