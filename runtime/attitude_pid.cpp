#include "runtime/attitude_pid.hpp"

#include <algorithm>
#include <cmath>

namespace quadgen::runtime {

namespace {

constexpr double kDegPerRad = 57.29577951308232;

double clamp_to(double v, double limit) { return limit > 0 ? std::clamp(v, -limit, limit) : v; }

double sign_of(double v, double tolerance) { return v > tolerance ? 1.0 : (v < -tolerance ? -1.0 : 0.0); }

}  // namespace

AttitudeMixer AttitudeMixer::quad_x(const std::vector<std::array<double, 3>>& rotor_positions) {
  AttitudeMixer m;
  for (const auto& p : rotor_positions) {
    m.roll.push_back(0.5 * sign_of(p[1], 1e-6));
    m.pitch.push_back(-0.5 * sign_of(p[0], 1e-6));
  }
  return m;
}

std::array<double, 2> AttitudeMixer::outputs_in(const double* u, double counts_per_command) const {
  std::array<double, 2> out{};
  const std::vector<double>* columns[2] = {&roll, &pitch};
  for (int a = 0; a < 2; ++a) {
    double dot = 0, norm = 0;
    for (size_t i = 0; i < columns[a]->size(); ++i) dot += (*columns[a])[i] * u[i], norm += (*columns[a])[i] * (*columns[a])[i];
    out[a] = norm > 0 ? counts_per_command * dot / norm : 0.0;
  }
  return out;
}

void AttitudePid::start(const std::array<double, 2>& angle, const std::array<double, 2>& rate,
                        const std::array<double, 2>& ref, const std::array<double, 2>& output) {
  for (int a = 0; a < 2; ++a) {
    Axis& x = axes_[a];
    const double angle_error = kDegPerRad * (ref[a] - angle[a]), measured_rate = kDegPerRad * rate[a];
    const PidGains &att = o_.attitude, &r = o_.rate;
    x.attitude_integral = att.ki != 0 ? clamp_to((measured_rate - att.kp * angle_error) / att.ki, att.integral_limit) : 0;
    const double rate_ref = att.kp * angle_error + att.ki * x.attitude_integral;
    const double rate_error = rate_ref - measured_rate;
    x.rate_integral = r.ki != 0 ? clamp_to((output[a] - r.kp * rate_error) / r.ki, r.integral_limit) : 0;
    x.previous_angle = kDegPerRad * angle[a], x.previous_rate = measured_rate;
  }
}

// The firmware's PID step (src/modules/src/pid.c): P on the error, I on its integral clamped
// to the limit, D on the measurement's change over one period (not the error's: a step of
// the set point does not kick), no output limit but the int16 saturation of the rate loop's.
std::array<double, 2> AttitudePid::update(const std::array<double, 2>& angle, const std::array<double, 2>& rate,
                                          const std::array<double, 2>& ref) {
  const double dt = period();
  std::array<double, 2> out{};
  for (int a = 0; a < 2; ++a) {
    Axis& x = axes_[a];
    const PidGains &att = o_.attitude, &r = o_.rate;
    const double measured_angle = kDegPerRad * angle[a], angle_error = kDegPerRad * ref[a] - measured_angle;
    x.attitude_integral = clamp_to(x.attitude_integral + angle_error * dt, att.integral_limit);
    const double rate_ref = att.kp * angle_error + att.ki * x.attitude_integral - att.kd * (measured_angle - x.previous_angle) / dt;
    x.previous_angle = measured_angle;
    const double measured_rate = kDegPerRad * rate[a], rate_error = rate_ref - measured_rate;
    x.rate_integral = clamp_to(x.rate_integral + rate_error * dt, r.integral_limit);
    out[a] = clamp_to(r.kp * rate_error + r.ki * x.rate_integral - r.kd * (measured_rate - x.previous_rate) / dt,
                      o_.output_limit);
    x.previous_rate = measured_rate;
  }
  return out;
}

}  // namespace quadgen::runtime
