#include "derive/kinematics.hpp"

namespace quadgen {
using namespace GiNaC;

matrix rot_x(const ex& a) { return matrix(3, 3, lst{1, 0, 0, 0, cos(a), -sin(a), 0, sin(a), cos(a)}); }
matrix rot_y(const ex& a) { return matrix(3, 3, lst{cos(a), 0, sin(a), 0, 1, 0, -sin(a), 0, cos(a)}); }
matrix rot_z(const ex& a) { return matrix(3, 3, lst{cos(a), -sin(a), 0, sin(a), cos(a), 0, 0, 0, 1}); }

matrix rotation_zyx(const ex& psi, const ex& theta, const ex& phi) {
  return rot_z(psi).mul(rot_y(theta)).mul(rot_x(phi));
}

matrix quaternion(const ex& w, const ex& x, const ex& y, const ex& z) { return matrix(4, 1, lst{w, x, y, z}); }

matrix quaternion_product(const matrix& a, const matrix& b) {
  const ex aw = a(0, 0), ax = a(1, 0), ay = a(2, 0), az = a(3, 0);
  const ex bw = b(0, 0), bx = b(1, 0), by = b(2, 0), bz = b(3, 0);
  return quaternion(aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
                    aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw);
}

matrix rotation_from_quaternion(const matrix& q) {
  const ex w = q(0, 0), x = q(1, 0), y = q(2, 0), z = q(3, 0);
  return matrix(3, 3,
                lst{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
                    2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                    2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)});
}

matrix quaternion_rate(const matrix& q, const matrix& omega) {
  const matrix pure = quaternion(0, omega(0, 0), omega(1, 0), omega(2, 0));
  return quaternion_product(q, pure).mul_scalar(numeric(1, 2));
}

matrix axis_quaternion(int axis, const ex& a) {
  matrix q = quaternion(cos(a / 2), 0, 0, 0);
  q(1 + axis, 0) = sin(a / 2);
  return q;
}

matrix cross(const matrix& a, const matrix& b) {
  return vec3(a(1, 0) * b(2, 0) - a(2, 0) * b(1, 0), a(2, 0) * b(0, 0) - a(0, 0) * b(2, 0),
              a(0, 0) * b(1, 0) - a(1, 0) * b(0, 0));
}

matrix vec3(const ex& x, const ex& y, const ex& z) { return matrix(3, 1, lst{x, y, z}); }

}  // namespace quadgen
