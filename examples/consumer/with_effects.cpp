// A model generated with effects (CMakeLists.txt: quadgen_generate_model(... EFFECTS
// motor_gain,motor_lag)): the rotor speeds are states that follow the commanded speed through
// a first-order lag. Checked against the closed form: from rest, under a constant command,
// w(t) = w_cmd (1 - exp(-t / tau)), at t = tau and 3 tau, integrated by RK4 in double.
#include <cmath>
#include <cstdio>

#include "model.hpp"  // generated from vehicles/finken3.yaml with motor_gain,motor_lag
#include "rk4.hpp"

namespace m = quadgen_generated::finken3_with_motor_gain_motor_lag;

int main() {
  static_assert(m::kNumStates == 17, "motor_lag adds one rotor-speed state per rotor");
  double p[m::kNumParams];
  for (int i = 0; i < m::kNumParams; ++i) p[i] = m::kNominalParams[i];
  const double tau = 0.05;  // s, a Crazyflie-like rotor (the nominal value keeps the lag short)
  p[m::Param::motor_lag_tau] = tau;
  m::Precomputed<double> pre;
  m::precompute(p, &pre);
  double x[m::kNumStates] = {}, u[m::kNumInputs], f[m::kNumStates];
  x[m::State::z] = 1, x[m::State::qw] = 1;
  for (double& ui : u) ui = 0.5;
  m::rhs(x, u, p, pre, f);
  const double w_cmd = tau * f[m::State::w_A];  // dw/dt = (w_cmd - w) / tau, at w = 0
  const double h = 1e-4;
  int bad = 0;
  for (int k = 1; k <= 1500; ++k) {  // to 3 tau
    rk4_step<m::kNumStates>(x, h, [&](const double* xs, double* dxdt) { m::rhs(xs, u, p, pre, dxdt); });
    if (k == 500 || k == 1500) {
      const double t = k * h, expected = w_cmd * (1 - std::exp(-t / tau)), got = x[m::State::w_A];
      const bool ok = std::isfinite(got) && std::fabs(got - expected) <= 1e-6 * w_cmd;
      std::printf("effects %s: w_A(%.3f s) = %.6g rad/s, closed form %.6g: %s\n", m::kEffects, t, got, expected,
                  ok ? "ok" : "MISMATCH");
      bad += ok ? 0 : 1;
    }
  }
  return bad == 0 && w_cmd > 0 ? 0 : 1;
}
