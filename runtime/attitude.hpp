// Z-Y-X Euler angles (roll phi, pitch theta, yaw psi) of a unit quaternion body -> world,
// for logs, plots and reports (contracts.md §1: R = Rz(psi) Ry(theta) Rx(phi)).
#pragma once
#include <array>
#include <cmath>

namespace quadgen::runtime {

inline std::array<double, 3> euler_zyx(double w, double x, double y, double z) {
  const double sin_theta = std::fmax(-1.0, std::fmin(1.0, 2 * (w * y - z * x)));
  return {std::atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y)), std::asin(sin_theta),
          std::atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))};
}

}  // namespace quadgen::runtime
