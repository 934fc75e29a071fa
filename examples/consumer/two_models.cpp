// Two models in one translation unit (a simulator comparing the plain model with one that has
// motor lag): each generated header is called model.hpp, so each is included by its target's
// folder. Their namespaces differ by the effects, and each header's hover trim holds its own
// model. Exits non-zero unless both trims hold.
#include <cmath>
#include <cstdio>

#include "finken3_lag_model/model.hpp"  // finken3 with motor_gain, motor_lag
#include "finken3_model/model.hpp"      // finken3

// The largest |f| at the model's hover trim (kHoverCommand): level and still at 1 m, the
// rotor speeds (states where the model has motor_lag) at the trim's (kHoverRotorSpeed).
template <class M>
double hover_residual() {
  double x[M::kNumStates] = {}, u[M::kNumInputs] = {}, f[M::kNumStates];
  x[M::State::z] = 1, x[M::State::qw] = 1;
  for (int i = 0; i < M::kNumRotors; ++i) u[i] = M::kHoverCommand[i];
  for (int k = 0; k < M::kNumRotorSpeedStates; ++k) x[M::kRotorSpeedStates[k]] = M::kHoverRotorSpeed[k];
  typename M::template Precomputed<double> pre;
  M::precompute(M::kNominalParams, &pre);
  M::rhs(x, u, M::kNominalParams, pre, f);
  double worst = 0;
  for (double v : f) worst = std::fmax(worst, std::fabs(v));
  return worst;
}

int main() {
  using Plain = quadgen_generated::finken3::Model;
  using Lagged = quadgen_generated::finken3_with_motor_gain_motor_lag::Model;
  const double plain = hover_residual<Plain>(), lagged = hover_residual<Lagged>();
  std::printf("two models in one translation unit: |f| at hover %.3g (%d states) and %.3g (%d states)\n", plain,
              Plain::kNumStates, lagged, Lagged::kNumStates);
  return plain < 1e-8 && lagged < 1e-8 && Lagged::kNumStates == Plain::kNumStates + 4 ? 0 : 1;
}
