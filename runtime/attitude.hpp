// Z-Y-X Euler angles (roll phi, pitch theta, yaw psi) of a unit quaternion body -> world,
// for logs, plots and reports (docs/formats.md "Conventions": R = Rz(psi) Ry(theta) Rx(phi)).
#pragma once
#include <array>
#include <cmath>

namespace quadgen::runtime {

// Angles in degrees where people or a firmware read them (plots, reports, the Crazyflie's
// attitude loop, which works in degrees).
inline constexpr double kDegreesPerRadian = 180.0 / 3.14159265358979323846;

inline std::array<double, 3> euler_zyx(double w, double x, double y, double z) {
  const double sin_theta = std::fmax(-1.0, std::fmin(1.0, 2 * (w * y - z * x)));
  return {std::atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y)), std::asin(sin_theta),
          std::atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))};
}

// The unit quaternion (w, x, y, z) of Z-Y-X Euler angles, q = q_z(psi) ⊗ q_y(theta) ⊗ q_x(phi)
// (one of q and -q, which are one attitude): the inverse of euler_zyx, for logs that give
// their attitude as angles.
inline std::array<double, 4> quaternion_from_euler_zyx(double phi, double theta, double psi) {
  const double cr = std::cos(phi / 2), sr = std::sin(phi / 2), cp = std::cos(theta / 2), sp = std::sin(theta / 2),
               cy = std::cos(psi / 2), sy = std::sin(psi / 2);
  return {cy * cp * cr + sy * sp * sr, cy * cp * sr - sy * sp * cr, cy * sp * cr + sy * cp * sr,
          sy * cp * cr - cy * sp * sr};
}

// Body -> world rotation matrix of a unit quaternion (w, x, y, z).
struct Rotation {
  double m[3][3];
};
inline Rotation rotation_matrix(const double* q) {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  return {{{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
           {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
           {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}}};
}

// Scales the quaternion q[0..3] to unit length (left alone at zero): integrators keep the
// attitude on the unit sphere with it after every full step.
inline void normalize_quaternion(double* q) {
  const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (n > 0)
    for (int i = 0; i < 4; ++i) q[i] /= n;
}

// Hamilton product a ⊗ b, scalar first.
inline void quaternion_product(const double* a, const double* b, double* q) {
  q[0] = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3];
  q[1] = a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2];
  q[2] = a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1];
  q[3] = a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0];
}

// True attitude from a logged one under attitude_bias (docs/effects.md: q_log = q ⊗ q_bias,
// q_bias = q_y(pitch) ⊗ q_x(roll)): q = q_log ⊗ conj(q_bias). In two steps for callers that
// unbias many samples with the same angles (the trigonometry once, not per sample).
inline void attitude_bias_conjugate(double roll, double pitch, double* conj_q_bias) {
  const double qp[4] = {std::cos(pitch / 2), 0, std::sin(pitch / 2), 0};
  const double qr[4] = {std::cos(roll / 2), std::sin(roll / 2), 0, 0};
  quaternion_product(qp, qr, conj_q_bias);
  for (int i = 1; i < 4; ++i) conj_q_bias[i] = -conj_q_bias[i];
}
inline void unbias_attitude(const double* q_log, double roll, double pitch, double* q) {
  double qb[4];
  attitude_bias_conjugate(roll, pitch, qb);
  quaternion_product(q_log, qb, q);
}

}  // namespace quadgen::runtime
