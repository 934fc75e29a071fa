// The FINken 3 base model written once by hand, templated on the scalar type: the
// reference for benchmarks (evaluated with ceres::Jet for automatic differentiation)
// and an independent check of the derivation (tests compare it with the generated f).
// Parameter order: the generated header's Param enum.
#pragma once
#include <cmath>

#include "generated/finken3/model.hpp"

namespace quadgen::reference {

namespace model = quadgen_generated::finken3;

struct RotorLayout {
  double x[4], y[4], z[4];
  double spin[4];  // +1 counter-clockwise seen from above, -1 clockwise
  double disc_area[4], radius[4];
};

// FINken 3: A (-l,-l) ccw, B (+l,-l) cw, C (+l,+l) ccw, D (-l,+l) cw (docs/formats.md "Conventions").
inline RotorLayout finken3_layout() {
  const double l = 0.07465;
  return RotorLayout{{-l, l, l, -l}, {-l, -l, l, l}, {0, 0, 0, 0}, {1, -1, 1, -1},
                     {1.646e-3, 1.646e-3, 1.646e-3, 1.646e-3}, {0.0635, 0.0635, 0.0635, 0.0635}};
}

template <typename T>
void cross(const T* a, const T* b, T* out) {
  out[0] = a[1] * b[2] - a[2] * b[1];
  out[1] = a[2] * b[0] - a[0] * b[2];
  out[2] = a[0] * b[1] - a[1] * b[0];
}

template <typename T>
void reference_rhs(const T* x, const T* u, const T* p, const RotorLayout& rl, T* f) {
  using P = model::Param;
  const T qw = x[6], qx = x[7], qy = x[8], qz = x[9];
  const T R[3][3] = {{T(1) - T(2) * (qy * qy + qz * qz), T(2) * (qx * qy - qw * qz), T(2) * (qx * qz + qw * qy)},
                     {T(2) * (qx * qy + qw * qz), T(1) - T(2) * (qx * qx + qz * qz), T(2) * (qy * qz - qw * qx)},
                     {T(2) * (qx * qz - qw * qy), T(2) * (qy * qz + qw * qx), T(1) - T(2) * (qx * qx + qy * qy)}};
  const T c[3] = {p[P::cog_x], p[P::cog_y], p[P::cog_z]};
  const T w[3] = {x[10], x[11], x[12]};
  T force[3] = {T(0), T(0), T(0)}, torque[3] = {T(0), T(0), T(0)};
  for (int i = 0; i < 4; ++i) {
    const T speed = p[P::motor_a0] + p[P::motor_a1] * u[i] + p[P::motor_a2] * u[i] * u[i];
    const T thrust = p[P::c_t] * p[P::rho] * T(rl.disc_area[i]) * T(rl.radius[i] * rl.radius[i]) * speed * speed;
    const T arm[3] = {T(rl.x[i]) - c[0], T(rl.y[i]) - c[1], T(rl.z[i]) - c[2]};
    const T F[3] = {T(0), T(0), thrust};
    T t[3];
    cross(arm, F, t);
    for (int k = 0; k < 3; ++k) torque[k] += t[k];
    torque[2] -= T(rl.spin[i]) * p[P::kappa] * thrust;
    force[2] += thrust;
  }
  const T area[3] = {p[P::A_x], p[P::A_y], p[P::A_z]};
  for (int k = 0; k < 3; ++k) {
    const T vb = R[0][k] * x[3] + R[1][k] * x[4] + R[2][k] * x[5];  // R^T v
    const T mag = vb < T(0) ? -vb : vb;
    force[k] -= T(0.5) * p[P::c_w] * p[P::rho] * area[k] * vb * mag;
  }
  const T J[3][3] = {{p[P::J_xx], p[P::J_xy], p[P::J_xz]},
                     {p[P::J_xy], p[P::J_yy], p[P::J_yz]},
                     {p[P::J_xz], p[P::J_yz], p[P::J_zz]}};
  T Jw[3], wJw[3], rhs[3];
  for (int k = 0; k < 3; ++k) Jw[k] = J[k][0] * w[0] + J[k][1] * w[1] + J[k][2] * w[2];
  cross(w, Jw, wJw);
  for (int k = 0; k < 3; ++k) rhs[k] = torque[k] - wJw[k];
  // Solve J wdot = rhs by Cramer's rule.
  auto det3 = [](const T a[3][3]) {
    return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
           a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
  };
  const T D = det3(J);
  T wdot[3];
  for (int col = 0; col < 3; ++col) {
    T M[3][3];
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) M[r][k] = k == col ? rhs[r] : J[r][k];
    wdot[col] = det3(M) / D;
  }
  T a1[3], a2[3], wc[3], wwc[3];
  cross(wdot, c, a1);
  cross(w, c, wc);
  cross(w, wc, wwc);
  T ab[3];
  for (int k = 0; k < 3; ++k) ab[k] = force[k] / p[P::mass] - a1[k] - wwc[k];
  for (int k = 0; k < 3; ++k) {
    f[k] = x[3 + k];
    f[3 + k] = R[k][0] * ab[0] + R[k][1] * ab[1] + R[k][2] * ab[2];
  }
  f[5] -= p[P::g];
  f[6] = T(-0.5) * (qx * w[0] + qy * w[1] + qz * w[2]);
  f[7] = T(0.5) * (qw * w[0] + qy * w[2] - qz * w[1]);
  f[8] = T(0.5) * (qw * w[1] - qx * w[2] + qz * w[0]);
  f[9] = T(0.5) * (qw * w[2] + qx * w[1] - qy * w[0]);
  for (int k = 0; k < 3; ++k) f[10 + k] = wdot[k];
}

}  // namespace quadgen::reference
