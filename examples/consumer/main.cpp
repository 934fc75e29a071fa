// Uses a model that quadgen derived at build time (CMakeLists.txt: quadgen_generate_model)
// through the generated header alone: RK4 from a hover state, in float and in double.
// Exits non-zero unless both stay finite, agree, and the hover holds.
#include <cmath>
#include <cstdio>

#include "model.hpp"                   // generated from vehicles/finken3.yaml
#include "rk4.hpp"
#include "runtime/dynamic_model.hpp"  // installed with quadgen: the runtime's interface to a model

namespace m = quadgen_generated::finken3;

template <typename S>
struct Simulation {
  S p[m::kNumParams];
  m::Precomputed<S> pre;

  Simulation() {
    for (int i = 0; i < m::kNumParams; ++i) p[i] = static_cast<S>(m::kNominalParams[i]);
    m::precompute(p, &pre);  // once per parameter vector, before any rhs()
  }
  // One classical Runge-Kutta step of dx/dt = f(x, u, p), attitude quaternion renormalised.
  void rk4_step(S* x, const S* u, S h) const {
    // f only; rhs(x, u, p, pre, f, dfdx, dfdu, dfdp) adds Jacobians
    ::rk4_step<m::kNumStates>(x, h, [&](const S* xs, S* f) { m::rhs(xs, u, p, pre, f); });
    using std::sqrt;
    const S n = sqrt(x[m::State::qw] * x[m::State::qw] + x[m::State::qx] * x[m::State::qx] +
                     x[m::State::qy] * x[m::State::qy] + x[m::State::qz] * x[m::State::qz]);
    for (int i = m::State::qw; i <= m::State::qz; ++i) x[i] /= n;
  }
};

// Level at 1 m, at rest.
void hover_state(double* x) {
  for (int i = 0; i < m::kNumStates; ++i) x[i] = 0;
  x[m::State::z] = 1;
  x[m::State::qw] = 1;
}

// The common command that holds the hover (vertical acceleration zero), by bisection: a check
// of the header's kHoverCommand (the FINken 3 is symmetric, so every rotor's is the same).
double hover_command_by_bisection(const Simulation<double>& sim) {
  double x[m::kNumStates], u[m::kNumInputs], f[m::kNumStates];
  hover_state(x);
  double lo = 0, hi = 1;
  for (int k = 0; k < 60; ++k) {
    const double mid = (lo + hi) / 2;
    for (double& ui : u) ui = mid;
    m::rhs(x, u, sim.p, sim.pre, f);
    (f[m::State::vz] < 0 ? lo : hi) = mid;
  }
  return (lo + hi) / 2;
}

// The same model through the runtime's interface (quadgen::runtime::CompiledModel, from the
// installed runtime/dynamic_model.hpp): f at a state must be the header's own, bit for bit.
int adapter_mismatches(const Simulation<double>& sim, double u_hover) {
  const quadgen::runtime::CompiledModel<m::Model> model;
  double x[m::kNumStates], u[m::kNumInputs], direct[m::kNumStates], adapted[m::kNumStates];
  hover_state(x);
  x[m::State::vx] = 0.3, x[m::State::p] = 0.1;  // moving, so that every term is exercised
  for (double& ui : u) ui = u_hover;
  m::rhs(x, u, sim.p, sim.pre, direct);
  model.rhs(x, u, adapted, nullptr, nullptr, nullptr);
  int bad = 0;
  for (int i = 0; i < m::kNumStates; ++i) bad += direct[i] == adapted[i] ? 0 : 1;
  std::printf("runtime adapter (%d states, %d parameters): %d mismatches with the header\n", model.num_states(),
              model.num_params(), bad);
  return bad;
}

int main() {
  const Simulation<double> sd;
  const Simulation<float> sf;
  const double u_hover = m::kHoverCommand[0];  // the header's trim: each rotor's command
  const double bisected = hover_command_by_bisection(sd);
  if (!(m::kHasHoverTrim && std::fabs(bisected - u_hover) < 1e-9)) {
    std::printf("the header's hover command %.12f differs from bisection's %.12f\n", u_hover, bisected);
    return 1;
  }

  double xd[m::kNumStates], ud[m::kNumInputs];
  float xf[m::kNumStates], uf[m::kNumInputs];
  hover_state(xd);
  for (int i = 0; i < m::kNumStates; ++i) xf[i] = static_cast<float>(xd[i]);
  for (int i = 0; i < m::kNumInputs; ++i) ud[i] = u_hover;
  ud[0] += 0.002;  // a slight imbalance on the first rotor, so that the attitude moves
  for (int i = 0; i < m::kNumInputs; ++i) uf[i] = static_cast<float>(ud[i]);

  const int steps = 100;
  const double h = 0.005;
  for (int k = 0; k < steps; ++k) {
    sd.rk4_step(xd, ud, h);
    sf.rk4_step(xf, uf, static_cast<float>(h));
  }

  int bad = 0;
  for (int i = 0; i < m::kNumStates; ++i) {
    const double d = xd[i], f = static_cast<double>(xf[i]);
    const bool ok = std::isfinite(d) && std::isfinite(f) && std::fabs(f - d) <= 1e-4 + 1e-3 * std::fabs(d);
    std::printf("%-3s double % .9f  float % .9f%s\n", m::kStateNames[i], d, f, ok ? "" : "  MISMATCH");
    bad += ok ? 0 : 1;
  }
  // Near hover after 0.5 s: the vehicle has not fallen or climbed away.
  if (!(std::fabs(xd[m::State::z] - 1) < 0.01)) {
    std::printf("hover not held: z = %g\n", xd[m::State::z]);
    ++bad;
  }
  std::printf("finken3: hover command %.6f, %d RK4 steps of %g s; float vs double: %d mismatches\n", u_hover,
              steps, h, bad);
  bad += adapter_mismatches(sd, u_hover);
  return bad == 0 ? 0 : 1;
}
