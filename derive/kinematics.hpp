// Attitude kinematics: rotation matrices, quaternions (Hamilton, scalar first,
// body -> world) and their rates. Small functions on GiNaC matrices.
#pragma once
#include <ginac/ginac.h>

namespace quadgen {

GiNaC::matrix rot_x(const GiNaC::ex& a);
GiNaC::matrix rot_y(const GiNaC::ex& a);
GiNaC::matrix rot_z(const GiNaC::ex& a);
// R = Rz(psi) Ry(theta) Rx(phi): body -> world for Z-Y-X Euler angles.
GiNaC::matrix rotation_zyx(const GiNaC::ex& psi, const GiNaC::ex& theta, const GiNaC::ex& phi);

// q as a 4x1 matrix (w, x, y, z).
GiNaC::matrix quaternion(const GiNaC::ex& w, const GiNaC::ex& x, const GiNaC::ex& y, const GiNaC::ex& z);
GiNaC::matrix quaternion_product(const GiNaC::matrix& a, const GiNaC::matrix& b);
// Rotation matrix of a unit quaternion (body -> world).
GiNaC::matrix rotation_from_quaternion(const GiNaC::matrix& q);
// dq/dt = 1/2 q ⊗ (0, omega) with omega in body axes.
GiNaC::matrix quaternion_rate(const GiNaC::matrix& q, const GiNaC::matrix& omega);
// Quaternion of a rotation by angle a about a unit axis given by index 0, 1, 2.
GiNaC::matrix axis_quaternion(int axis, const GiNaC::ex& a);

GiNaC::matrix cross(const GiNaC::matrix& a, const GiNaC::matrix& b);
GiNaC::matrix vec3(const GiNaC::ex& x, const GiNaC::ex& y, const GiNaC::ex& z);

}  // namespace quadgen
