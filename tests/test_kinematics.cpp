// Rotation and quaternion properties, symbolic (via the audit) and numeric (against Eigen).
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "audit/audit.hpp"
#include "derive/kinematics.hpp"
#include "tests/test_helpers.hpp"
#include "runtime/portable_random.hpp"

using namespace quadgen;
using namespace GiNaC;

TEST(Kinematics, SymbolicRotationChecksPass) {
  const Vehicle v = test::finken3();
  const MassProperties mp = derive_mass_properties(v);
  const SymbolicModel m = derive_model(v, mp, {});
  const AuditResult r = audit(m, mp);
  int rotation_checks = 0;
  for (const auto& c : r.checks)
    if (c.group == "rotation") {
      ++rotation_checks;
      EXPECT_TRUE(c.passed) << c.name << ": " << c.detail;
    }
  EXPECT_EQ(rotation_checks, 7);  // the Z-Y-X and quaternion matrices (5), |q| kept, Euler's equations
}

TEST(Kinematics, ReduceTrigDetectsANonRotation) {
  // The thesis' T (78)-(81) is a reflection: the same reduction must find det = -1.
  realsymbol a("a"), b("b"), c("c");
  const matrix R = rotation_zyx(c, b, a);
  const matrix bad = R.mul(matrix(3, 3, lst{-1, 0, 0, 0, 1, 0, 0, 0, 1}));  // a reflection
  EXPECT_TRUE(reduce_trig(R.determinant() - 1, {a, b, c}).is_zero());
  EXPECT_FALSE(reduce_trig(bad.determinant() - 1, {a, b, c}).is_zero());
}

TEST(Kinematics, QuaternionMatrixMatchesEigen) {
  std::mt19937 rng(7);
  quadgen::runtime::Normal d(0.0, 1.0);
  for (int k = 0; k < 20; ++k) {
    const double w = d(rng), x = d(rng), y = d(rng), z = d(rng);  // in this order, whatever the compiler
    Eigen::Quaterniond q(w, x, y, z);
    q.normalize();
    const matrix R = rotation_from_quaternion(quaternion(q.w(), q.x(), q.y(), q.z()));
    const Eigen::Matrix3d E = q.toRotationMatrix();
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) EXPECT_NEAR(to_double(R(i, j)), E(i, j), 1e-14);
  }
}

TEST(Kinematics, ZyxMatrixMatchesEigenAngleAxis) {
  const double psi = 0.3, theta = -0.2, phi = 0.7;
  const matrix R = rotation_zyx(psi, theta, phi);
  const Eigen::Matrix3d E = (Eigen::AngleAxisd(psi, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(phi, Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(to_double(R(i, j)), E(i, j), 1e-14);
}

TEST(Kinematics, QuaternionRateIsHalfQTimesOmega) {
  // dq/dt from the formula against a finite difference of q(t) = q0 * exp(ω t / 2).
  Eigen::Quaterniond q0(Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()));
  const Eigen::Vector3d w(0.3, -0.5, 0.8);
  const double h = 1e-6;
  auto at = [&](double t) { return q0 * Eigen::Quaterniond(Eigen::AngleAxisd(w.norm() * t, w.normalized())); };
  const Eigen::Quaterniond qp = at(h), qm = at(-h);
  const matrix qd = quaternion_rate(quaternion(q0.w(), q0.x(), q0.y(), q0.z()), vec3(w.x(), w.y(), w.z()));
  EXPECT_NEAR(to_double(qd(0, 0)), (qp.w() - qm.w()) / (2 * h), 1e-8);
  EXPECT_NEAR(to_double(qd(1, 0)), (qp.x() - qm.x()) / (2 * h), 1e-8);
  EXPECT_NEAR(to_double(qd(2, 0)), (qp.y() - qm.y()) / (2 * h), 1e-8);
  EXPECT_NEAR(to_double(qd(3, 0)), (qp.z() - qm.z()) / (2 * h), 1e-8);
}
