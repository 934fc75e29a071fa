// Header-only and dependency-free, so that derive/ (symbolic), runtime/ and fit/ share it.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace quadgen::runtime {

// The one home of the thrust law: a rotor's thrust is F = k w^2 with k = c_t rho A_p r_p^2
// (the thesis' law, c_t dimensionless), and its speed follows the command through the motor
// map w = a0 + a1 u + a2 u^2. Templated so that the symbolic model (GiNaC expressions), the
// runtime's thrust laws (doubles) and the fits of the thrust stand and the motor steps
// (their parameters) write each once.
template <typename T>
T rotor_thrust_coefficient(const T& c_t, const T& rho, const T& disc_area, const T& radius) {
  return c_t * rho * disc_area * radius * radius;
}
// c_t from a measured k: the inverse of rotor_thrust_coefficient.
inline double thrust_coefficient_c_t(double k, double rho, double disc_area, double radius) {
  return k / rotor_thrust_coefficient(1.0, rho, disc_area, radius);
}

// The motor map: rotor speed [rad/s] at command u [0, 1].
template <typename T, typename U>
T motor_map(const T& a0, const T& a1, const T& a2, const U& u) {
  return a0 + a1 * u + a2 * u * u;
}
// Its coefficients: a measurement at fewer different commands leaves the map undetermined
// (the fits of motor steps and of a thrust stand refuse such files with this number).
constexpr int kMotorMapCoefficients = 3;

// One rotor's law in numbers, and its inverse: what it takes to turn a thrust into a command.
struct ThrustLaw {
  double k = 0;
  double a0 = 0, a1 = 0, a2 = 0;
  double speed_at(double u) const { return motor_map(a0, a1, a2, u); }
  double thrust_at_speed(double w) const { return k * w * w; }
  // The thrust command u gives (a map below 0 rad/s there gives none).
  double thrust_at_command(double u) const { return thrust_at_speed(std::max(speed_at(u), 0.0)); }
  double command_for(double thrust) const;  // throws std::invalid_argument if unreachable for u in [0, 1]
};

inline double ThrustLaw::command_for(double thrust) const {
  // Six significant digits: std::to_string wrote a thrust of 1.6e299 N with 300 digits, and
  // an a1 of -1e-9 rad/s as -0.000000.
  const auto six = [](double v, const char* unit) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.6g %s", v, unit);
    return std::string(buf);
  };
  const auto newtons = [&](double f) { return six(f, "N"); };
  if (!(thrust >= 0)) throw std::invalid_argument("thrust " + newtons(thrust) + " requested of a rotor");
  // Why no command gives it: a map that does not rise over 0..1, or a thrust below what
  // command 0 gives, or above what command 1 gives.
  const auto unreachable = [&] {
    if (!(a1 > 0 && a1 + 2 * a2 > 0))
      return std::invalid_argument("the motor map's speed does not rise with the command over 0..1 (a1 = " +
                                   six(a1, "rad/s") + ", a2 = " + six(a2, "rad/s") + ")");
    const double lowest = thrust_at_command(0.0);
    if (thrust < lowest)
      return std::invalid_argument("thrust " + newtons(thrust) + " is below what the motor map gives at command 0 (" +
                                   newtons(lowest) + ")");
    // Tens to thousands of times beyond: most often masses in grams written as kilograms (a
    // newcomer's trial, helper-143: a file without mass bounds got no word of it).
    const double most = thrust_at_speed(speed_at(1.0)), times = thrust / most;
    char slip[96] = "";
    if (times > 30 && times < 3e4)
      std::snprintf(slip, sizeof slip, "; %.3g times that is asked: masses in grams written as kilograms?", times);
    return std::invalid_argument("thrust " + newtons(thrust) + " is beyond the motor map (at most " + newtons(most) +
                                 " at command 1" + slip + ")");
  };
  const double w = std::sqrt(thrust / k);
  // Solve a2 u^2 + a1 u + (a0 - w) = 0 for the root in [0, 1].
  double u;
  if (std::fabs(a2) < 1e-12) {
    u = (w - a0) / a1;
  } else {
    const double disc = a1 * a1 - 4 * a2 * (a0 - w);
    if (disc < 0) throw unreachable();
    u = (-a1 + std::sqrt(disc)) / (2 * a2);
    if (u < 0 || u > 1) u = (-a1 - std::sqrt(disc)) / (2 * a2);
  }
  if (u < 0 && u > -1e-12) u = 0;  // rounding at the ends: the thrust at command 0 or 1 itself
  if (u > 1 && u < 1 + 1e-12) u = 1;
  if (!(u >= 0 && u <= 1)) throw unreachable();
  return u;
}

}  // namespace quadgen::runtime
