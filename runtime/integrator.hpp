// Integration of a flight model: fixed-step RK4 and adaptive Dormand–Prince 5(4) with
// error control and dense output, the quaternion kept on the unit sphere, divergence
// reported with time and state, and forward sensitivities dx/dp and dx/dx0 (RK4) for
// multiple-shooting fits.
#pragma once
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "runtime/dynamic_model.hpp"
#include "runtime/input_signal.hpp"

namespace quadgen::runtime {

struct DivergenceError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Trajectory {
  std::vector<double> t;
  std::vector<std::vector<double>> x;
};

// Supplies the model's inputs at time t (commands, and t / vbat where an effect needs them).
using InputFunction = std::function<void(double t, double* u)>;

struct IntegratorOptions {
  double step = 1e-3;           // RK4 step [s]
  double rtol = 1e-8, atol = 1e-10;  // DOPRI5 tolerances
  double max_step = 0.05;       // DOPRI5 upper step bound [s]
  double min_step = 1e-10;
  int quaternion_offset = 6;    // index of qw in the state, or -1
  double divergence_bound = 1e6;  // |x_i| beyond this counts as divergence
  // Applied to the state x after every RK4 step and every accepted DOPRI5 step (and to the
  // DOPRI5 dense output), after the quaternion is normalised, with the state the step began
  // from: a constraint the model's equations do not hold, such as a ground the vehicle rests
  // on (runtime/ground_contact.hpp). Not applied by the sensitivity integrator. None when empty.
  std::function<void(const std::vector<double>& before, std::vector<double>& x)> constrain;
};

struct Stats {
  long rhs_evaluations = 0, accepted_steps = 0, rejected_steps = 0;
};

// Fixed-step RK4 from t0 to t1, returning states at every step (and at t1).
Trajectory integrate_rk4(const DynamicModel& m, std::vector<double> x0, const InputFunction& u, double t0,
                         double t1, const IntegratorOptions& opt, Stats* stats = nullptr);

// Adaptive DOPRI5; the solution is reported at `output_times` by its dense output.
Trajectory integrate_dopri5(const DynamicModel& m, std::vector<double> x0, const InputFunction& u,
                            const std::vector<double>& output_times, const IntegratorOptions& opt,
                            Stats* stats = nullptr);

// RK4 with forward sensitivities: S = dx/d[x0, p] (n x (n + np), row-major) integrated with
// dS/dt = A S + [0 | B]. Returns states and sensitivities at every output step.
struct SensitivityTrajectory {
  Trajectory states;
  std::vector<std::vector<double>> S;  // per time: n x (n + np)
};
// `params`, when given, restricts the parameter columns to these indices (S is then
// n x (n + params.size())), which is what a fit with few free parameters needs.
SensitivityTrajectory integrate_rk4_sensitivities(const DynamicModel& m, std::vector<double> x0,
                                                  const InputFunction& u, double t0, double t1,
                                                  const IntegratorOptions& opt,
                                                  const std::vector<int>* params = nullptr);

void check_finite(const DynamicModel& m, const std::vector<double>& x, double t, double bound);

}  // namespace quadgen::runtime
