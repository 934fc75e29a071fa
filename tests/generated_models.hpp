// The generated models the tests evaluate, behind one traits type each, and a random but
// physical evaluation point. Shared by the golden/finite-difference tests and the Jet tests
// (a translation unit of their own: see tests/CMakeLists.txt).
#pragma once

#include <cmath>
#include <random>
#include <string>
#include <type_traits>

#include "generated/crazyflie21/model.hpp"
#include "generated/crazyflie21_all_effects/model.hpp"
#include "generated/crazyflie21_nanobench/model.hpp"
#include "generated/crazyflie21_nanobench_all_effects/model.hpp"
#include "generated/finken3/model.hpp"
#include "generated/finken3_all_effects/model.hpp"
#include "runtime/portable_random.hpp"

namespace gen = quadgen_generated;

// A random but physical evaluation point for model M: unit quaternion, commands in range,
// parameters perturbed by up to ±20 % (effect parameters moved off zero).
template <class M>
struct Point {
  double x[M::kNumStates], u[M::kNumInputs], p[M::kNumParams];
};

#define QUADGEN_MODEL_TRAITS(NS)                                                            \
  struct NS##_traits {                                                                      \
    static constexpr int kNumStates = gen::NS::kNumStates;                                  \
    static constexpr int kNumInputs = gen::NS::kNumInputs;                                  \
    static constexpr int kNumParams = gen::NS::kNumParams;                                  \
    static constexpr int kDfdxNnz = gen::NS::kDfdxNnz;                                      \
    static constexpr int kDfdpNnz = gen::NS::kDfdpNnz;                                      \
    static constexpr int kDfduNnz = gen::NS::kDfduNnz;                                      \
    static constexpr const int* dfdx_row = gen::NS::kDfdxRow;                               \
    static constexpr const int* dfdx_col = gen::NS::kDfdxCol;                               \
    static constexpr const int* dfdp_row = gen::NS::kDfdpRow;                               \
    static constexpr const int* dfdp_col = gen::NS::kDfdpCol;                               \
    static constexpr const int* dfdu_row = gen::NS::kDfduRow;                               \
    static constexpr const int* dfdu_col = gen::NS::kDfduCol;                               \
    static constexpr const char* const* state_names = gen::NS::kStateNames;                 \
    static constexpr const char* const* input_names = gen::NS::kInputNames;                 \
    static constexpr const char* const* param_names = gen::NS::kParamNames;                 \
    static constexpr const double* nominal = gen::NS::kNominalParams;                       \
    static constexpr const char* effects = gen::NS::kEffects;                               \
    template <typename S>                                                                   \
    static void f(const S* x, const S* u, const S* p, S* out, S* dx, S* du, S* dp) {        \
      gen::NS::Precomputed<S> pre;                                                          \
      gen::NS::precompute(p, &pre);                                                         \
      if constexpr (std::is_floating_point<S>::value) {                                     \
        gen::NS::rhs(x, u, p, pre, out, dx, du, dp);                                        \
      } else { /* ceres::Jet: the f-only entry point, Jacobian code not instantiated */     \
        (void)dx, (void)du, (void)dp;                                                       \
        gen::NS::rhs(x, u, p, pre, out);                                                    \
      }                                                                                     \
    }                                                                                       \
  };

QUADGEN_MODEL_TRAITS(finken3)
QUADGEN_MODEL_TRAITS(finken3_all_effects)
QUADGEN_MODEL_TRAITS(crazyflie21)
QUADGEN_MODEL_TRAITS(crazyflie21_all_effects)
QUADGEN_MODEL_TRAITS(crazyflie21_nanobench)
QUADGEN_MODEL_TRAITS(crazyflie21_nanobench_all_effects)

template <class M>
int index_of_param(const std::string& name) {
  for (int i = 0; i < M::kNumParams; ++i)
    if (name == M::param_names[i]) return i;
  return -1;
}

template <class M>
Point<M> random_point(std::mt19937& rng) {
  Point<M> pt;
  quadgen::runtime::UniformReal d(-1, 1);
  double n = 0;
  for (int i = 0; i < M::kNumStates; ++i) pt.x[i] = d(rng);
  pt.x[2] = 0.5 + std::fabs(pt.x[2]);  // above the ground (ground effect)
  for (int i = 6; i < 10; ++i) n += pt.x[i] * pt.x[i];
  for (int i = 6; i < 10; ++i) pt.x[i] /= std::sqrt(n);
  for (int i = 10; i < 13; ++i) pt.x[i] *= 3;
  for (int i = 13; i < M::kNumStates; ++i) pt.x[i] = 800 + 200 * d(rng);  // rotor speeds
  for (int i = 0; i < M::kNumInputs; ++i) {
    const std::string name = M::input_names[i];
    pt.u[i] = name == "t" ? 5 + 5 * d(rng) : name == "vbat" ? 3.9 + 0.2 * d(rng) : 0.5 + 0.3 * d(rng);
  }
  for (int i = 0; i < M::kNumParams; ++i) {
    const std::string name = M::param_names[i];
    double v = M::nominal[i] * (1 + 0.2 * d(rng));
    if (name.find('.') != std::string::npos) v = 0.01 + 0.01 * d(rng);  // effects off their neutral value
    if (name == "motor_lag.tau") v = 0.02 + 0.01 * d(rng);
    if (name == "ground_effect.radius") v = 0.06 + 0.01 * d(rng);
    if (name == "J_xy" || name == "J_xz" || name == "J_yz")  // products of inertia: 5 % of J_xx
      v = 0.05 * M::nominal[index_of_param<M>("J_xx")] * d(rng);
    if (name == "cog_x" || name == "cog_y") v = 2e-3 * d(rng);
    pt.p[i] = v;
  }
  return pt;
}
