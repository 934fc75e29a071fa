// Mass properties: exact integration against closed forms computed here in plain
// doubles, against brute-force numerical integration, and the FINken 3 regression;
// a 1,000-block vehicle; derived quantities' declared bounds checked against the blocks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include <Eigen/Dense>

#include "audit/mass_quadrature.hpp"
#include "tests/test_helpers.hpp"

using namespace quadgen;

namespace {

Eigen::Matrix3d rotation_deg(const Vec3& ypr) {
  const double k = M_PI / 180;
  return (Eigen::AngleAxisd(ypr[0] * k, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(ypr[1] * k, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(ypr[2] * k, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

// Independent closed form: m/12 diag(b²+c², a²+c², a²+b²), rotated, parallel axis.
Eigen::Matrix3d closed_form(const Block& b) {
  const double a = b.size[0], bb = b.size[1], c = b.size[2];
  Eigen::Matrix3d Jc = Eigen::Vector3d(bb * bb + c * c, a * a + c * c, a * a + bb * bb).asDiagonal();
  Jc *= b.mass / 12;
  const Eigen::Matrix3d R = rotation_deg(b.yaw_pitch_roll_deg);
  const Eigen::Vector3d r(b.centre[0], b.centre[1], b.centre[2]);
  return R * Jc * R.transpose() + b.mass * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
}

// Midpoint rule on an n^3 grid of the block, mapped into the body frame.
Eigen::Matrix3d brute_force(const Block& b, int n) {
  const Eigen::Matrix3d R = rotation_deg(b.yaw_pitch_roll_deg);
  const Eigen::Vector3d c(b.centre[0], b.centre[1], b.centre[2]);
  const double dm = b.mass / (double(n) * n * n);
  Eigen::Matrix3d J = Eigen::Matrix3d::Zero();
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        const Eigen::Vector3d xi((i + 0.5) / n - 0.5, (j + 0.5) / n - 0.5, (k + 0.5) / n - 0.5);
        const Eigen::Vector3d r = R * xi.cwiseProduct(Eigen::Vector3d(b.size[0], b.size[1], b.size[2])) + c;
        J += dm * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
      }
  return J;
}

Eigen::Matrix3d to_eigen(const Mat3& m) {
  Eigen::Matrix3d e;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) e(i, j) = m[i][j];
  return e;
}

}  // namespace

TEST(Geometry, EveryBlockMatchesClosedForm) {
  const Vehicle v = test::finken3();
  const MassProperties mp = derive_mass_properties(v);
  for (size_t i = 0; i < v.blocks.size(); ++i) {
    const Eigen::Matrix3d want = closed_form(v.blocks[i]);
    const Eigen::Matrix3d got = to_eigen(mp.blocks[i].inertia_origin_value);
    EXPECT_LT((got - want).norm(), 1e-12 * want.norm()) << v.blocks[i].name;
  }
}

TEST(Geometry, EveryBlockMatchesBruteForceIntegration) {
  const Vehicle v = test::finken3();
  const MassProperties mp = derive_mass_properties(v);
  const int n = 40;
  for (size_t i = 0; i < v.blocks.size(); ++i) {
    const Block& b = v.blocks[i];
    // Midpoint rule error for a quadratic integrand: m (edge/n)^2 / 12 per edge.
    double tol = 0;
    for (double e : b.size) tol += b.mass * (e / n) * (e / n) / 12;
    const Eigen::Matrix3d got = to_eigen(mp.blocks[i].inertia_origin_value);
    EXPECT_LT((got - brute_force(b, n)).cwiseAbs().maxCoeff(), 2 * tol) << b.name;
  }
}

TEST(Geometry, Finken3MassCogInertiaAreas) {
  const Vehicle v = test::finken3();
  const MassProperties mp = derive_mass_properties(v);
  double m = 0, mz = 0;
  Eigen::Matrix3d J = Eigen::Matrix3d::Zero();
  Eigen::Vector3d A = Eigen::Vector3d::Zero();
  for (const Block& b : v.blocks) {
    m += b.mass;
    mz += b.mass * b.centre[2];
    J += closed_form(b);
    const Eigen::Matrix3d R = rotation_deg(b.yaw_pitch_roll_deg).cwiseAbs();
    A += R * Eigen::Vector3d(b.size[1] * b.size[2], b.size[0] * b.size[2], b.size[0] * b.size[1]);
  }
  const Eigen::Vector3d c(0, 0, mz / m);
  J -= m * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
  EXPECT_NEAR(mp.mass_value, 0.387, 1e-12);  // the thesis' total, 1.1
  EXPECT_NEAR(mp.cog_value[0], 0, 1e-15);
  EXPECT_NEAR(mp.cog_value[1], 0, 1e-15);
  EXPECT_NEAR(mp.cog_value[2], c.z(), 1e-15);
  EXPECT_LT((to_eigen(mp.inertia_cog_value) - J).norm(), 1e-12 * J.norm());
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(mp.areas_value[i], A(i), 1e-12);
  // Symmetry of the X layout: products of inertia vanish exactly.
  EXPECT_EQ(mp.inertia_cog_value[0][1], 0.0);
  EXPECT_EQ(mp.inertia_cog_value[0][2], 0.0);
  EXPECT_EQ(mp.inertia_cog_value[1][2], 0.0);
}

// The audit's own second road to the mass properties (Gauss points, Eigen's rotation, convex
// hulls) agrees with the derivation on every bundled vehicle and on a block tilted about all
// three axes; against a derivation of a slightly different vehicle (a block 1 mm off, turned
// by 10 degrees, or a tenth longer) the check concerned fails: a check that can fail.
TEST(Geometry, TheAuditsQuadratureAgreesAndCatchesAWrongBlock) {
  const auto passed = [](const Vehicle& v, const MassProperties& mp) {
    std::vector<bool> out;
    for (const AuditCheck& c : check_mass_properties_by_quadrature(v, mp)) out.push_back(c.passed);
    return out;
  };
  Vehicle tilted = test::finken3();
  tilted.blocks.push_back(Block{"tilted", 0.1, {0.1, 0.04, 0.02}, {0.02, -0.01, 0.03}, {30, 20, 10}, 1});
  for (const Vehicle& v : {test::finken3(), tilted, load_vehicle(test::source_path("vehicles/crazyflie21.yaml"))})
    EXPECT_EQ(passed(v, derive_mass_properties(v)), (std::vector<bool>{true, true, true})) << v.name;
  Vehicle moved = tilted, turned = tilted, longer = tilted;
  moved.blocks.back().centre[0] += 0.001;
  turned.blocks.back().yaw_pitch_roll_deg[1] += 10;
  longer.blocks.back().size[0] *= 1.1;
  EXPECT_FALSE(passed(tilted, derive_mass_properties(moved))[0]);
  const std::vector<bool> turned_checks = passed(tilted, derive_mass_properties(turned));
  EXPECT_TRUE(turned_checks[0]);  // a turn about the block's centre moves neither mass nor centre
  EXPECT_FALSE(turned_checks[1]);
  EXPECT_FALSE(turned_checks[2]);
  EXPECT_FALSE(passed(tilted, derive_mass_properties(longer))[1]);
  EXPECT_FALSE(passed(tilted, derive_mass_properties(longer))[2]);
  // The hull's area of an upright box seen from above is its footprint.
  Vehicle box = test::finken3();
  box.blocks = {Block{"box", 0.1, {0.1, 0.04, 0.02}, {0, 0, 0}, {90, 0, 0}, 1}};
  EXPECT_NEAR(mass_properties_by_quadrature(box).areas[2], 0.1 * 0.04, 1e-15);
  EXPECT_NEAR(mass_properties_by_quadrature(box).areas[0], 0.1 * 0.02, 1e-15);  // turned 90 degrees: its long side across x
  // What the blocks cover, overlaps counted once: a box stacked on another covers from
  // above what one does (the sum counts it twice), from the side what both do; moved half
  // its length along x, it covers one and a half footprints from above.
  Vehicle stacked = test::finken3();
  stacked.blocks = {Block{"lower", 0.1, {0.1, 0.04, 0.02}, {0, 0, 0}, {0, 0, 0}, 1},
                    Block{"upper", 0.1, {0.1, 0.04, 0.02}, {0, 0, 0.02}, {0, 0, 0}, 2}};
  QuadratureMassProperties q = mass_properties_by_quadrature(stacked);
  EXPECT_NEAR(q.areas[2], 2 * 0.1 * 0.04, 1e-15);
  EXPECT_NEAR(q.covered[2], 0.1 * 0.04, 1e-12);
  EXPECT_NEAR(q.covered[0], 2 * 0.04 * 0.02, 1e-12);
  stacked.blocks[1].centre[0] = 0.05;
  q = mass_properties_by_quadrature(stacked);
  EXPECT_NEAR(q.covered[2], 1.5 * 0.1 * 0.04, 1e-12);
  const std::vector<AuditCheck> said = check_mass_properties_by_quadrature(stacked, derive_mass_properties(stacked));
  EXPECT_NE(said[2].detail.find("the blocks cover 0, 0, 25 % less than that sum along x, y, z"), std::string::npos)
      << said[2].detail;
  // Beyond 200 blocks the union (one polygon at a time) is not computed, and said so.
  Vehicle many = stacked;
  many.blocks.clear();
  for (int k = 0; k <= static_cast<int>(kMostBlocksForCoveredArea); ++k)
    many.blocks.push_back(Block{"b" + std::to_string(k), 0.001, {0.01, 0.01, 0.01}, {0.02 * k, 0, 0}, {0, 0, 0}, k + 1});
  EXPECT_TRUE(std::isnan(mass_properties_by_quadrature(many).covered[2]));
  EXPECT_NE(check_mass_properties_by_quadrature(many, derive_mass_properties(many))[2].detail.find(
                "not computed for more than 200 blocks"),
            std::string::npos);
  many.blocks.pop_back();  // 200: computed, none overlapping
  EXPECT_NEAR(mass_properties_by_quadrature(many).covered[2], 200 * 1e-4, 1e-12);
  // Footprints 1e20 m apart overflow Boost's integer rescaling, which throws: no number and
  // the words say so, rather than an abort (a review, helper-145).
  Vehicle far = stacked;
  far.blocks[1].centre = {1e20, 0, 0};
  const QuadratureMassProperties q_far = mass_properties_by_quadrature(far);
  EXPECT_FALSE(std::isfinite(q_far.covered[2]));
  EXPECT_NE(check_mass_properties_by_quadrature(far, derive_mass_properties(far))[2].detail.find("could not be computed"),
            std::string::npos);
}

TEST(Geometry, TiltedBlockHasProductsOfInertia) {
  // A full rotation (not only yaw) must produce off-diagonal terms; checked against Eigen.
  Vehicle v = test::finken3();
  v.blocks = {Block{"tilted", 0.1, {0.1, 0.04, 0.02}, {0.02, -0.01, 0.03}, {30, 20, 10}, 1}};
  const MassProperties mp = derive_mass_properties(v);
  const Eigen::Matrix3d want = closed_form(v.blocks[0]);
  EXPECT_GT(std::fabs(want(0, 1)), 1e-6);
  EXPECT_LT((to_eigen(mp.inertia_origin_value) - want).norm(), 1e-12 * want.norm());
}

TEST(Geometry, ThousandBlockGridMatchesParallelAxisSums) {
  // 10 x 10 x 10 identical tilted blocks on a grid off the origin; every total against
  // sums written out here in doubles: m/12 diag(b²+c², a²+c², a²+b²) rotated, plus
  // m(|r|² I - r r^T) per block, shifted to the centre of gravity at the end. Guards
  // the per-block path (under a second in a release build; the quadratic one took minutes).
  const int n = 10;
  const double m = 0.002, a = 0.008, b = 0.005, c = 0.003;
  const Vec3 ypr{30, 20, 10};
  Vehicle v;
  v.name = "grid";
  v.source_path = "grid.yaml";
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        const std::string name = "g" + std::to_string(i) + "_" + std::to_string(j) + "_" + std::to_string(k);
        v.blocks.push_back(Block{name, m, {a, b, c}, {0.01 * i - 0.03, 0.012 * j - 0.05, 0.004 * k + 0.002}, ypr, 0});
      }
  ASSERT_EQ(v.blocks.size(), 1000u);
  const MassProperties mp = derive_mass_properties(v);
  ASSERT_EQ(mp.blocks.size(), 1000u);

  const Eigen::Matrix3d R = rotation_deg(ypr);
  const Eigen::Matrix3d J_block = R * (m / 12 * Eigen::Vector3d(b * b + c * c, a * a + c * c, a * a + b * b).asDiagonal()) *
                                  R.transpose();
  const Eigen::Vector3d A_block = R.cwiseAbs() * Eigen::Vector3d(b * c, a * c, a * b);
  double M = 0;
  Eigen::Vector3d first = Eigen::Vector3d::Zero(), A = Eigen::Vector3d::Zero();
  Eigen::Matrix3d J_o = Eigen::Matrix3d::Zero();
  for (const Block& bl : v.blocks) {
    const Eigen::Vector3d r(bl.centre[0], bl.centre[1], bl.centre[2]);
    M += m;
    first += m * r;
    J_o += J_block + m * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
    A += A_block;
  }
  const Eigen::Vector3d cog = first / M;
  const Eigen::Matrix3d J_cg = J_o - M * (cog.squaredNorm() * Eigen::Matrix3d::Identity() - cog * cog.transpose());

  EXPECT_NEAR(mp.mass_value, M, 1e-12 * M);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(mp.cog_value[i], cog(i), 1e-12 * cog.norm()) << i;
    EXPECT_NEAR(mp.areas_value[i], A(i), 1e-12 * A.norm()) << i;
  }
  EXPECT_LT((to_eigen(mp.inertia_origin_value) - J_o).norm(), 1e-12 * J_o.norm());
  EXPECT_LT((to_eigen(mp.inertia_cog_value) - J_cg).norm(), 1e-12 * J_cg.norm());
  EXPECT_GT(std::fabs(J_cg(0, 1)), 1e-4 * J_cg.norm());  // the tilt gives products of inertia
  // Every block on its own, and the totals still expressions in the block symbols.
  for (size_t i = 0; i < v.blocks.size(); i += 97) {
    const Eigen::Matrix3d want = closed_form(v.blocks[i]);
    EXPECT_LT((to_eigen(mp.blocks[i].inertia_origin_value) - want).norm(), 1e-12 * want.norm()) << v.blocks[i].name;
  }
  // (subs with the list itself would match every symbol against all 7,000 relations.)
  ASSERT_EQ(mp.values.nops(), 7 * v.blocks.size());
  GiNaC::exmap values;
  for (const GiNaC::ex& r : mp.values) values[r.lhs()] = r.rhs();
  EXPECT_NEAR(to_double(mp.inertia_cog(0, 1).subs(values, GiNaC::subs_options::no_pattern)), J_cg(0, 1),
              1e-12 * J_cg.norm());
}

namespace {

Parameter derived_bounds(const std::string& name, const std::string& unit, double lower, double upper) {
  return Parameter{{name, unit, parse_unit(unit).dim, lower, lower, upper, false, "", ""}};
}

std::string derive_error(const Vehicle& v) {
  try {
    derive_model(v, derive_mass_properties(v), {});
  } catch (const VehicleError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Geometry, DerivedQuantityOutsideItsBoundsIsAnError) {
  Vehicle v = test::finken3();
  const MassProperties mp = derive_mass_properties(v);
  const double Jxx = mp.inertia_cog_value[0][0];
  // Bounds that hold the blocks' value: accepted (the bundled file's mass bounds included).
  v.derived_overrides["J_xx"] = derived_bounds("J_xx", "kg m^2", 0.5 * Jxx, 2 * Jxx);
  EXPECT_EQ(derive_error(v), "");

  v.derived_overrides["J_xx"] = derived_bounds("J_xx", "kg m^2", 2e-5, 3e-5);
  char want[200];
  std::snprintf(want, sizeof want, "%s: derived quantity J_xx: the blocks give %.6g kg m^2, outside its bounds [2e-05, 3e-05]",
                v.source_path.c_str(), Jxx);
  EXPECT_EQ(derive_error(v), want);

  // Just outside a bound: the message does not show the value as equal to it.
  v.derived_overrides.erase("J_xx");
  v.derived_overrides["mass"] = derived_bounds("mass", "kg", 0.2, 0.38699999);
  EXPECT_EQ(derive_error(v), v.source_path + ": derived quantity mass: the blocks give 0.387 kg, outside its bounds [0.2, 0.38699999]");
  v.derived_overrides["mass"] = derived_bounds("mass", "kg", 0.2, std::nextafter(0.387, 0.0));
  const std::string msg = derive_error(v);
  EXPECT_NE(msg.find("the blocks give 0.387 kg, outside its bounds [0.2, 0.38699999999999996]"), std::string::npos) << msg;
}

TEST(Geometry, DerivedBoundsFromTheVehicleFileAreChecked) {
  // The `derived:` section as a user writes it: the file, line and quantity named.
  std::ifstream in(test::source_path("vehicles/crazyflie21.yaml"));
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str() + "  A_z: {fit: true, bounds: [0.5, 2.0]}\n";
  const Vehicle v = parse_vehicle(text, "vehicles/x.yaml");
  ASSERT_TRUE(v.derived_overrides.count("A_z"));
  const std::string msg = derive_error(v);
  // The line of the entry: the one appended after the bundled file's lines.
  const std::string line = std::to_string(std::count(text.begin(), text.end(), '\n'));
  EXPECT_EQ(msg.rfind("vehicles/x.yaml:" + line + ": derived quantity A_z: the blocks give ", 0), 0u) << msg;
  EXPECT_NE(msg.find(" m^2, outside its bounds [0.5, 2]"), std::string::npos) << msg;
}
