// Rotation and quaternion properties, symbolic (via the audit) and numeric (against Eigen).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <set>

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

// Each rotation check, given a wrong attitude form, fails, and only the checks that form
// breaks: a check seen only to pass could be a constant (a review of the tests, helper-123).
TEST(Kinematics, EachRotationCheckFailsForAWrongAttitudeForm) {
  const std::string zyx_orth = "Z-Y-X matrix orthogonal", zyx_proper = "Z-Y-X matrix proper (det = +1)",
                    q_orth = "quaternion matrix orthogonal", q_proper = "quaternion matrix proper (det = +1)",
                    agree = "quaternion and Z-Y-X matrix agree";
  auto failed = [](const AttitudeForms& forms) {
    std::set<std::string> out;
    const auto checks = check_rotation(forms);
    EXPECT_EQ(checks.size(), 5u);
    for (const auto& c : checks)
      if (!c.passed) out.insert(c.name);
    return out;
  };
  using Set = std::set<std::string>;
  EXPECT_EQ(failed({}), Set{});
  const matrix flip_x(3, 3, lst{-1, 0, 0, 0, 1, 0, 0, 0, 1});
  AttitudeForms reflected;  // the thesis' kind of error: a reflection, orthogonal but not proper
  reflected.zyx = [&](const ex& psi, const ex& theta, const ex& phi) { return rotation_zyx(psi, theta, phi).mul(flip_x); };
  EXPECT_EQ(failed(reflected), (Set{zyx_proper, agree}));
  AttitudeForms slipped;  // one sign slipped in Rx: neither orthogonal nor proper
  slipped.zyx = [](const ex& psi, const ex& theta, const ex& phi) {
    const matrix bad_x(3, 3, lst{1, 0, 0, 0, cos(phi), -sin(phi), 0, -sin(phi), cos(phi)});
    return rot_z(psi).mul(rot_y(theta)).mul(bad_x);
  };
  EXPECT_EQ(failed(slipped), (Set{zyx_orth, zyx_proper, agree}));
  AttitudeForms world_to_body;  // the transpose: a rotation, but the other way round
  world_to_body.from_quaternion = [](const matrix& q) { return rotation_from_quaternion(q).transpose(); };
  EXPECT_EQ(failed(world_to_body), (Set{agree}));
  AttitudeForms row_negated;  // orthogonal, det = -1
  row_negated.from_quaternion = [&](const matrix& q) { return flip_x.mul(rotation_from_quaternion(q)); };
  EXPECT_EQ(failed(row_negated), (Set{q_proper, agree}));
  AttitudeForms entry_slipped;  // one entry's sign slipped: det = 1 - 2 R01^2 as well
  entry_slipped.from_quaternion = [](const matrix& q) {
    matrix R = rotation_from_quaternion(q);
    R(0, 1) = -R(0, 1);
    return R;
  };
  EXPECT_EQ(failed(entry_slipped), (Set{q_orth, q_proper, agree}));
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
