#include "fit/motor_steps.hpp"

#include <cmath>
#include <set>
#include <sstream>

#include "fit/flight_data.hpp"
#include "runtime/flight_log.hpp"
#include "runtime/thrust_law.hpp"

namespace quadgen::fit {

namespace {

// Sanity bounds (the file's units; measurement_column has refused columns with a non-finite cell):
// |time_ms| <= 1e13 (a Unix time in ms is allowed), 0 <= throttle_percent <= 100,
// 0 <= rpm <= 1e9.
void check_row(const runtime::CsvTable& t, size_t row) {
  struct Bound {
    const char* column;
    double lo, hi;
    const char* expected;
  };
  static const Bound bounds[] = {{"time_ms", -1e13, 1e13, "|time_ms| <= 1e13"},
                                 {"throttle_percent", 0, 100, "a throttle in [0, 100] %"},
                                 {"rpm", 0, 1e9, "a rotor speed in [0, 1e9] rpm"}};
  for (const auto& b : bounds) {
    const double v = t.rows[row][t.column(b.column)];
    if (v >= b.lo && v <= b.hi) continue;
    std::ostringstream os;
    os << t.path << ":" << t.line_of(row) << ": column '" << b.column << "' is " << v << ", expected " << b.expected;
    throw FitError(os.str());
  }
}

// The steady rotor speed at command u and its gradient in (a0, a1, a2): the map, and 0 with
// the motor off. predict and evaluate both use it; evaluate once spelled the map itself and
// zeroed only the old level, so a step down to 0 was fitted towards a0 (a review, helper-137).
double steady_rpm(const double* p, double u, double grad[3]) {
  const double on = u == 0 ? 0.0 : 1.0;
  grad[0] = on, grad[1] = on * u, grad[2] = on * u * u;
  return on * runtime::motor_map(p[0], p[1], p[2], u);
}

}  // namespace

std::vector<MotorStep> read_motor_steps(const std::string& path) {
  const runtime::CsvTable t = read_measurement_csv(path);
  for (const char* c : {"time_ms", "throttle_percent", "rpm"})
    if (measurement_column(t, c) < 0) throw FitError(path + ":1: missing column '" + std::string(c) + "' (motor step layout)");
  for (size_t i = 0; i < t.rows.size(); ++i) check_row(t, i);
  const auto time = t.values("time_ms"), thr = t.values("throttle_percent"), rpm = t.values("rpm");
  std::vector<MotorStep> steps;
  for (size_t i = 1; i < time.size(); ++i) {
    if (!(time[i] > time[i - 1]))
      throw FitError(path + ":" + std::to_string(t.line_of(i)) + ": time not strictly increasing");
    if (thr[i] == thr[i - 1]) {
      if (!steps.empty() && thr[i] == steps.back().u_new * 100 && time[i] > steps.back().t_first) {
        steps.back().t.push_back(time[i] / 1000);
        steps.back().rpm.push_back(rpm[i]);
      }
      continue;
    }
    MotorStep s;
    s.t_before = time[i - 1] / 1000;
    s.t_first = time[i] / 1000;
    s.u_old = thr[i - 1] / 100;
    s.u_new = thr[i] / 100;
    s.t.push_back(time[i] / 1000);
    s.rpm.push_back(rpm[i]);
    steps.push_back(s);
  }
  if (steps.empty()) throw FitError(path + ": no throttle steps found");
  // The map rpm = a0 + a1 u + a2 u^2 has three coefficients: fewer commands to step to leave it
  // undetermined, and the fit ended in "J^T J overflows ... a corrupt or mis-scaled sample?"
  // with the solver's warnings on the terminal (a review, helper-135: one step 0 -> 50 %).
  // The levels the steps start from count as well; a motor off (0) gives the map no point
  // (a second review, helper-137: 0 -> 30 -> 60 -> 0 passed as three).
  std::set<double> levels;
  for (const auto& s : steps)
    for (double u : {s.u_old, s.u_new})
      if (u > 0) levels.insert(u);
  if (levels.size() < runtime::kMotorMapCoefficients)
    throw FitError(path + ": " + std::to_string(steps.size()) + " throttle step" + (steps.size() == 1 ? "" : "s") + " at " +
                   std::to_string(levels.size()) + " command" + (levels.size() == 1 ? "" : "s") +
                   " above 0: the motor map rpm = a0 + a1 u + a2 u^2 needs at least " +
                   std::to_string(runtime::kMotorMapCoefficients) + " different ones");
  return steps;
}

MotorStepModel::MotorStepModel(std::vector<MotorStep> steps) : steps_(std::move(steps)) {
  for (const auto& s : steps_) n_ += static_cast<int>(s.t.size());
}

std::vector<FitParameter> MotorStepModel::parameters() const {
  std::vector<FitParameter> p = {{"a0", "rpm", 1500, -20000, 20000, true},
                                 {"a1", "rpm", 20000, 0, 100000, true},
                                 {"a2", "rpm", -3000, -100000, 100000, true},
                                 {"tau", "s", 0.05, 1e-4, 1.0, true}};
  for (size_t k = 0; k < steps_.size(); ++k) {
    const double gap = steps_[k].t_first - steps_[k].t_before;
    p.push_back({"step_" + std::to_string(k + 1), "s", gap / 2, 0.0, gap, true});
  }
  return p;
}

double MotorStepModel::predict(const double* p, size_t k, double t) const {
  const MotorStep& s = steps_[k];
  double unused[3];
  const double ss_old = steady_rpm(p, s.u_old, unused), ss_new = steady_rpm(p, s.u_new, unused);
  const double ts = s.t_before + p[kFirstStepTime + k];
  if (t < ts) return ss_old;
  return ss_new + (ss_old - ss_new) * std::exp(-(t - ts) / p[kTau]);
}

void MotorStepModel::evaluate(const double* p, double* r, double* J) const {
  const int np = 4 + static_cast<int>(steps_.size());
  int row = 0;
  for (size_t k = 0; k < steps_.size(); ++k) {
    const MotorStep& s = steps_[k];
    double g_old[3], g_new[3];
    const double ss_old = steady_rpm(p, s.u_old, g_old), ss_new = steady_rpm(p, s.u_new, g_new);
    const double ts = s.t_before + p[kFirstStepTime + k], tau = p[kTau];
    for (size_t i = 0; i < s.t.size(); ++i, ++row) {
      const double t = s.t[i];
      const double e = t < ts ? 1.0 : std::exp(-(t - ts) / tau);
      r[row] = ss_new + (ss_old - ss_new) * e - s.rpm[i];
      if (!J) continue;
      double* Jr = J + static_cast<size_t>(row) * np;
      for (int j = 0; j < np; ++j) Jr[j] = 0;
      for (int c = 0; c < 3; ++c) Jr[c] = (1 - e) * g_new[c] + e * g_old[c];
      if (t >= ts) {
        Jr[3] = (ss_old - ss_new) * e * (t - ts) / (tau * tau);
        Jr[4 + k] = (ss_old - ss_new) * e / tau;
      }
    }
  }
}

}  // namespace quadgen::fit
