// Header-only and dependency-free, so that derive/ (symbolic), runtime/ and fit/ share it.
#pragma once

namespace quadgen::runtime {

// The one home of the thrust law: a rotor's thrust is F = k w^2 with k = c_t rho A_p r_p^2
// (the thesis' law, c_t dimensionless). Templated so that the symbolic model (GiNaC expressions), the runtime's
// thrust laws (doubles) and the thrust-stand fit (its inverse) write it once.
template <typename T>
T rotor_thrust_coefficient(const T& c_t, const T& rho, const T& disc_area, const T& radius) {
  return c_t * rho * disc_area * radius * radius;
}
// c_t from a measured k: the inverse of rotor_thrust_coefficient.
inline double thrust_coefficient_c_t(double k, double rho, double disc_area, double radius) {
  return k / rotor_thrust_coefficient(1.0, rho, disc_area, radius);
}

}  // namespace quadgen::runtime
