#include "runtime/attitude_pid.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "runtime/attitude.hpp"

namespace quadgen::runtime {

namespace {

constexpr double kDegPerRad = kDegreesPerRadian;  // short: the loop's formulas read it often

double clamp_to(double v, double limit) { return limit > 0 ? std::clamp(v, -limit, limit) : v; }

double sign_of(double v, double tolerance) { return v > tolerance ? 1.0 : (v < -tolerance ? -1.0 : 0.0); }

}  // namespace

AttitudeMixer AttitudeMixer::quad_x(const std::vector<std::array<double, 3>>& rotor_positions,
                                    const std::vector<int>& spins) {
  if (rotor_positions.size() != 4 || spins.size() != 4)
    throw std::invalid_argument("the attitude loop's mixing is the quad X's: the vehicle has " +
                                std::to_string(rotor_positions.size()) + " rotors, not 4");
  AttitudeMixer m;
  int quadrants = 0;
  for (const auto& p : rotor_positions) {
    m.roll.push_back(0.5 * sign_of(p[1], 1e-6));
    m.pitch.push_back(-0.5 * sign_of(p[0], 1e-6));
    if (m.roll.back() != 0 && m.pitch.back() != 0) quadrants |= 1 << ((m.roll.back() > 0) * 2 + (m.pitch.back() > 0));
  }
  double roll_sum = 0, pitch_sum = 0, roll_yaw = 0, pitch_yaw = 0;
  for (size_t i = 0; i < 4; ++i) {
    roll_sum += m.roll[i], pitch_sum += m.pitch[i];
    roll_yaw += m.roll[i] * spins[i], pitch_yaw += m.pitch[i] * spins[i];
  }
  if (quadrants != 0xF)
    throw std::invalid_argument("the attitude loop's mixing is the quad X's: a rotor in each quadrant of the body's x-y plane");
  if (roll_sum != 0 || pitch_sum != 0 || roll_yaw != 0 || pitch_yaw != 0)
    throw std::invalid_argument("the attitude loop's mixing is the quad X's: diagonal rotors spinning the same way");
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
                        const std::array<double, 2>& mean_output, const std::array<double, 2>& mean_rate,
                        const std::array<double, 2>& mean_angle_error) {
  for (int a = 0; a < 2; ++a) {
    Axis& x = axes_[a];
    const PidGains &att = o_.attitude, &r = o_.rate;
    const double held = kDegPerRad * mean_rate[a] - att.kp * kDegPerRad * mean_angle_error[a];  // deg/s
    x.attitude_integral = att.ki != 0 ? clamp_to(held / att.ki, att.integral_limit) : 0;
    // Zero but where the attitude integral met its limit.
    const double mean_rate_error = att.kp * kDegPerRad * mean_angle_error[a] + att.ki * x.attitude_integral - kDegPerRad * mean_rate[a];
    x.rate_integral = r.ki != 0 ? clamp_to((mean_output[a] - r.kp * mean_rate_error) / r.ki, r.integral_limit) : 0;
    x.previous_angle = kDegPerRad * angle[a], x.previous_rate = kDegPerRad * rate[a];
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
