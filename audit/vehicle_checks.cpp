#include "audit/vehicle_checks.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "derive/dynamics.hpp"
#include "derive/geometry.hpp"
#include "output/joined.hpp"
#include "output/numbers.hpp"
#include "derive/runtime_view.hpp"
#include "runtime/allocation_matrix.hpp"
#include "runtime/rigid_body_state.hpp"

namespace quadgen {

namespace {

AuditCheck advisory(const std::string& name, bool ok, const std::string& detail) {
  AuditCheck c{"vehicle", name, ok, detail};
  c.advisory = true;
  return c;
}

// Rounding residue (1e-17 N beside 0.13 N) reads as 0, as the trim's reason does, and values
// equal but for it print alike (two rotors' 1.2535 N read "1.254, ..., 1.253" at four digits:
// a derivation reviewer, helper-151).
std::string numbers(const Eigen::VectorXd& x, const char* unit) {
  const double scale = x.size() ? x.cwiseAbs().maxCoeff() : 0.0;
  std::vector<double> shown;
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    double v = std::abs(x(i)) <= 1e-9 * scale ? 0.0 : x(i);
    for (double earlier : shown)
      if (std::abs(v - earlier) <= 1e-9 * scale) v = earlier;
    shown.push_back(v);
  }
  const std::string list = output::joined(shown, ", ", [](double v) { return output::six_digits(v); });
  return *unit ? list + " " + unit : list;
}

AuditCheck check_motor_map(const std::vector<runtime::ThrustLaw>& laws) {
  const runtime::ThrustLaw& l = laws.front();  // one map for every rotor
  const bool rises = l.a1 > 0 && l.a1 + 2 * l.a2 > 0;
  std::ostringstream os;
  os.precision(5);
  os << "d(speed)/d(command) = a1 + 2 a2 u is " << l.a1 << " rad/s at u = 0 and " << l.a1 + 2 * l.a2
     << " rad/s at u = 1 (the map as the model turns it)";
  return advisory("the motor map rises with the command", rises, os.str());
}

// Thrust, roll, pitch and yaw apart: the allocation has rank 4. Rows scaled first (newtons
// and newton-metres of arms of centimetres), which leaves the rank as it is: roll and pitch
// by the longest arm together, so that a row of rounding noise (sin 180 deg) stays noise, and
// yaw by its largest entry.
AuditCheck check_controllable(const Eigen::MatrixXd& B, double weight) {
  Eigen::MatrixXd scaled = B;
  const double arm = std::max(B.row(1).cwiseAbs().maxCoeff(), B.row(2).cwiseAbs().maxCoeff());
  if (arm > 0) scaled.middleRows(1, 2) /= arm;
  const double yaw = B.row(3).cwiseAbs().maxCoeff();
  if (yaw > 0) scaled.row(3) /= yaw;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(scaled, Eigen::ComputeFullU);
  const Eigen::VectorXd s = svd.singularValues();
  int rank = 0;
  for (Eigen::Index i = 0; i < s.size(); ++i)
    if (s(i) > 1e-9 * s(0)) ++rank;
  const char* axes[4] = {"thrust", "roll", "pitch", "yaw"};
  std::string detail = "rank " + std::to_string(rank) + " of 4 of the map from the rotors' thrusts to (thrust, roll, "
                       "pitch, yaw)";
  if (rank < 4) {
    // The combination of the four the rotors cannot produce: the axes with a share in it are
    // the ones tied together (all counter-clockwise: thrust and yaw move as one).
    const Eigen::VectorXd lost = svd.matrixU().col(3).cwiseAbs();
    std::string tied;
    for (Eigen::Index i = 0; i < 4; ++i)
      if (lost(i) >= 0.25 * lost.maxCoeff()) tied += std::string(tied.empty() ? "" : " and ") + axes[i];
    detail += "; the rotors cannot set apart " + tied +
              (lost(3) >= 0.25 * lost.maxCoeff() ? " (do the spins cancel? as many ccw as cw rotors, placed in pairs)"
                                                 : " (where are the rotors?)");
  }
  // Spins that do not balance pass the rank and show only in the trim's spread: said here
  // (a hexacopter with four rotors of one spin, a derivation reviewer: helper-151).
  const double each = weight / static_cast<double>(B.cols()), unbalanced = B.row(3).sum() * each;
  if (B.cols() > 0 && std::abs(unbalanced) > 1e-9 * B.row(3).cwiseAbs().sum() * each)
    detail += "; equal thrusts (" + output::six_digits(each) + " N each) leave a yaw moment of " +
              output::six_digits(unbalanced) + " N m: the spins do not balance" +
              (rank == 4 ? ", and unequal thrusts must hold it" : "");
  return advisory("thrust, roll, pitch and yaw can be set apart", rank == 4, detail);
}

// A hover trim (runtime::hover_trim, which simulate's scenarios fly): every rotor pushing and
// within its motor's reach.
AuditCheck check_hover_trim(const runtime::HoverTrim& trim, double weight) {
  const Eigen::VectorXd F =
      Eigen::Map<const Eigen::VectorXd>(trim.thrusts.data(), static_cast<Eigen::Index>(trim.thrusts.size()));
  // More rotors than conditions: the trim is the least-norm one of a family (runtime::hover_trim).
  std::string detail = std::string(F.size() > 4 ? "thrusts for hover (the least-norm set: one of many for more than "
                                                  "four rotors) "
                                                : "thrusts for hover ") +
                       numbers(F, "N") + " (weight " + output::six_digits(weight) + " N)";
  if (trim.found()) {
    const Eigen::VectorXd u =
        Eigen::Map<const Eigen::VectorXd>(trim.commands.data(), static_cast<Eigen::Index>(trim.commands.size()));
    detail += ", commands " + numbers(u, "");
  } else {
    detail += ": " + trim.why_not;
  }
  return advisory("a hover trim exists within the motors' reach", trim.found(), detail);
}

// Hover at the very bottom of the command range is no design: most often a motor map in rpm
// written without its unit (read as rad/s, 9.5 times too fast). Near there fit and diagnose
// take a rotor for idle and leave the sample out. Without a trim it fails where the rotors
// at command 0 lift the weight (a motor map with a0 > 0 has no trim then), else it cannot say.
AuditCheck check_hover_above_the_bottom(const runtime::HoverTrim& trim) {
  constexpr double kLowestHoverCommand = 0.1;
  if (!trim.found()) {
    const bool low = trim.idle_lifts_weight;
    return advisory("hover needs a tenth of the command range or more", !low,
                    low ? std::string("no trim: the rotors at command 0 lift the weight; ") + runtime::kRpmWithoutUnit +
                              "? (or c_t too large?)"
                        : std::string("not judged: no hover trim (see the trim's check)"));
  }
  const double highest = *std::max_element(trim.commands.begin(), trim.commands.end());
  const bool low = highest < kLowestHoverCommand;
  std::ostringstream detail;
  detail << "the highest hover command " << output::six_digits(highest);
  if (low)
    detail << ", below " << kLowestHoverCommand
           << " of the command range: " << runtime::kRpmWithoutUnit
           << "? (near the bottom of the range fit and diagnose take a rotor for idle)";
  return advisory("hover needs a tenth of the command range or more", !low, detail.str());
}

// Hover near the top of the command range leaves nothing to steer or climb with: the trim
// check passes up to command 1 exactly (a review, helper-88), where any roll needs a rotor
// above full. A tenth of the range kept back is a floor, not a design margin (multirotors are
// built to hover near half their thrust).
AuditCheck check_hover_below_the_top(const runtime::HoverTrim& trim) {
  constexpr double kHighestHoverCommand = 0.9;
  const std::string name = "hover leaves a tenth of the command range to steer";
  if (!trim.found()) return advisory(name, true, "not judged: no hover trim (see the trim's check)");
  const double highest = *std::max_element(trim.commands.begin(), trim.commands.end());
  const bool high = highest > kHighestHoverCommand;
  std::string detail = "the highest hover command " + output::six_digits(highest);
  if (high)
    detail += ", above " + output::six_digits(kHighestHoverCommand) +
              " of the command range: too little is left to steer and climb (a vehicle too heavy for its motors, "
              "or a motor map of other motors?)";
  return advisory(name, !high, detail);
}

// No two rotor discs cut through each other: hubs in one plane (within a quarter of the
// smaller radius in z) closer than the sum of the radii. A coaxial pair (same place in x and
// y, apart in z, as on a Y6) is a design, not a mistake.
AuditCheck check_discs_apart(const Vehicle& v) {
  std::string clash;
  for (size_t i = 0; i < v.rotors.size() && clash.empty(); ++i)
    for (size_t j = i + 1; j < v.rotors.size() && clash.empty(); ++j) {
      const Rotor &a = v.rotors[i], &b = v.rotors[j];
      const double dx = a.position[0] - b.position[0], dy = a.position[1] - b.position[1];
      const double dz = std::fabs(a.position[2] - b.position[2]), apart = std::hypot(dx, dy);
      if (dz >= 0.25 * std::min(a.radius, b.radius) || apart >= a.radius + b.radius) continue;
      std::ostringstream os;
      os.precision(4);
      os << "rotors " << a.name << " and " << b.name << ": hubs " << apart << " m apart in one plane, radii " << a.radius
         << " and " << b.radius << " m" << (apart < 1e-9 ? " (the same place: a copied line?)" : "");
      clash = os.str();
    }
  return advisory("no two rotor discs overlap", clash.empty(),
                  clash.empty() ? "every pair of hubs in one plane is at least the sum of their radii apart" : clash);
}

using Point2 = std::array<double, 2>;

// The convex hull of points in a plane, counter-clockwise (Andrew's monotone chain).
std::vector<Point2> convex_hull(std::vector<Point2> p) {
  std::sort(p.begin(), p.end());
  p.erase(std::unique(p.begin(), p.end()), p.end());
  if (p.size() < 3) return p;
  const auto turn = [](const Point2& o, const Point2& a, const Point2& b) {
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
  };
  std::vector<Point2> h(2 * p.size());
  size_t k = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && turn(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  for (size_t i = p.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && turn(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  h.resize(k - 1);
  return h;
}

// The distance from q to a convex polygon given counter-clockwise: 0 inside.
double distance_to_polygon(const Point2& q, const std::vector<Point2>& poly) {
  bool inside = poly.size() >= 3;
  double nearest = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < poly.size(); ++i) {
    const Point2 &a = poly[i], &b = poly[(i + 1) % poly.size()];
    const double ex = b[0] - a[0], ey = b[1] - a[1], qx = q[0] - a[0], qy = q[1] - a[1];
    if (ex * qy - ey * qx < 0) inside = false;
    const double length2 = ex * ex + ey * ey;
    const double t = length2 > 0 ? std::clamp((qx * ex + qy * ey) / length2, 0.0, 1.0) : 0.0;
    nearest = std::min(nearest, std::hypot(qx - t * ex, qy - t * ey));
  }
  return inside ? 0.0 : nearest;
}

// A block cut by the horizontal plane z = z0 of the body frame: how far it reaches above and
// below the plane, and the cut's outline in body x and y (where its edges cross the plane).
struct PlaneCut {
  double above = 0, below = 0;  // m
  std::vector<Point2> outline;  // convex, counter-clockwise
};
PlaneCut cut_at_height(const Block& b, double z0) {
  const Mat3 R = to_mat3(block_rotation(b.yaw_pitch_roll_deg));  // block -> body
  std::array<std::array<double, 3>, 8> corner{};
  PlaneCut cut;
  for (int k = 0; k < 8; ++k) {
    for (int row = 0; row < 3; ++row) {
      corner[k][row] = b.centre[row];
      for (int i = 0; i < 3; ++i) corner[k][row] += R[row][i] * ((k >> i & 1) ? 0.5 : -0.5) * b.size[i];
    }
    cut.above = std::max(cut.above, corner[k][2] - z0);
    cut.below = std::max(cut.below, z0 - corner[k][2]);
  }
  std::vector<Point2> crossings;
  for (int k = 0; k < 8; ++k) {
    if (corner[k][2] == z0) crossings.push_back({corner[k][0], corner[k][1]});
    for (int i = 0; i < 3; ++i) {  // the edge to the corner one bit up
      const int j = k | 1 << i;
      if (j == k || (corner[k][2] - z0) * (corner[j][2] - z0) >= 0) continue;
      const double t = (z0 - corner[k][2]) / (corner[j][2] - corner[k][2]);
      crossings.push_back({corner[k][0] + t * (corner[j][0] - corner[k][0]), corner[k][1] + t * (corner[j][1] - corner[k][1])});
    }
  }
  cut.outline = convex_hull(crossings);
  return cut;
}

// No propeller sweeps through a block: each rotor's disc (its radius about the hub, in the
// plane through the hub normal to body z, where the model's thrust acts) kept out of every
// block. Two slips show so: a hub placed at its motor's centre rather than on top (the thrust
// point, and with it the arm of every rotor force about the centre of gravity, half a motor
// too low), and a block or rotor copied to the wrong place. Exact: the block is cut by the
// disc's plane and the cut's distance from the hub compared with the radius. 1 % of the
// radius is allowed either way, so that a propeller on its motor's top face, a disc's rim
// on a block's edge and a file's rounding pass.
AuditCheck check_discs_clear_of_blocks(const Vehicle& v) {
  std::ostringstream os;
  os.precision(3);
  for (const Rotor& r : v.rotors)
    for (const Block& b : v.blocks) {
      const double tol = 0.01 * r.radius;
      const PlaneCut cut = cut_at_height(b, r.position[2]);
      if (cut.above <= tol || cut.below <= tol) continue;
      const double apart = distance_to_polygon({r.position[0], r.position[1]}, cut.outline);
      if (apart >= r.radius - tol) continue;
      os << (os.tellp() > 0 ? "; " : "") << "rotor " << r.name << "'s disc passes through block " << b.name
         << ", which reaches " << cut.above * 1e3 << " mm above and " << cut.below * 1e3 << " mm below the disc's plane"
         << (apart == 0 ? " (its hub inside the block: is the hub's z the propeller's height, on top of the motor?)"
                        : " (a propeller cannot pass through it: is the block or the rotor misplaced?)");
    }
  const std::string found = os.str();
  return advisory("no propeller sweeps through a block", found.empty(),
                  found.empty() ? "every rotor's disc is clear of every block (a block that only touches a disc's "
                                  "plane, a hub on its motor's face, counts as clear)"
                                : found);
}

// Rotors and blocks on one scale: a number without a unit is read as metres, so a position or
// radius copied in millimetres puts a rotor a thousand times too far out, and an area in mm^2
// makes the disc larger than its radius allows. Thresholds wide enough for real layouts (a
// file of one hub block, with mass and inertia given, whose rotors reach 5x past it; a hull
// larger than its rotors' circle; the FINken 3's thrust-law area 0.13 of its disc), far
// below the factor of 1000 of the mistake.
AuditCheck check_one_scale(const Vehicle& v) {
  // m: a sphere about the origin holding every block (its centre's distance plus half its
  // diagonal, a bound, not the farthest corner), and the rotors' farthest reach (hub and tip)
  double reach = 0, farthest = 0;
  for (const Block& b : v.blocks)
    reach = std::max(reach, std::hypot(b.centre[0], b.centre[1], b.centre[2]) +
                                0.5 * std::hypot(b.size[0], b.size[1], b.size[2]));
  std::ostringstream os;
  os.precision(4);
  for (const Rotor& r : v.rotors) {
    const double out = std::hypot(r.position[0], r.position[1], r.position[2]) + r.radius;
    farthest = std::max(farthest, out);
    if (out > 30 * reach)
      os << (os.tellp() > 0 ? "; " : "") << "rotor " << r.name << " reaches " << out << " m from the origin, the blocks "
         << "lie within " << reach << " m of it (a position or radius in mm read as m?)";
    const double disc = M_PI * r.radius * r.radius;
    if (r.disc_area > 1.01 * disc)
      os << (os.tellp() > 0 ? "; " : "") << "rotor " << r.name << ": disc_area " << r.disc_area
         << " m^2 is more than the disc its radius sweeps, pi r^2 = " << disc << " m^2 (an area in mm^2 or a diameter as the radius?)";
  }
  if (farthest > 0 && reach > 20 * farthest)
    os << (os.tellp() > 0 ? "; " : "") << "the blocks lie within " << reach
       << " m of the origin (a bound: centre plus half diagonal), the rotors reach " << farthest
       << " m (a block's size or centre in mm read as m?)";
  const std::string found = os.str();
  std::ostringstream fine;
  fine.precision(4);
  fine << "the blocks lie within " << reach << " m of the origin (a bound: centre plus half diagonal), the rotors reach "
       << farthest << " m; every disc_area at most pi r^2 (1 % over allowed for rounding)";
  return advisory("rotors and blocks on one scale", found.empty(), found.empty() ? fine.str() : found);
}

// Block orientations in radians typed into orientation_deg: 0.785 for an arm at 45 deg turns it
// by 0.785 deg, and every check above still passes (a reviewer's trial, helper-103). A value
// within 0.0051 of a multiple of pi/6 or pi/4 (what radians written to two decimals allow:
// 0.79, 0.52, 1.57, 3.14) is most likely one, unless it is a whole or half degree (1.5, 5.5),
// as a real tilt is usually written.
AuditCheck check_orientations_in_degrees(const Vehicle& v) {
  const char* axes[3] = {"yaw", "pitch", "roll"};
  std::ostringstream os;
  os.precision(4);
  for (const Block& b : v.blocks)
    for (int k = 0; k < 3; ++k) {
      const double a = b.yaw_pitch_roll_deg[k];
      if (2 * a == std::round(2 * a) || std::fabs(a) > 10 * M_PI) continue;  // whole or half degrees, or far out
      const int t = static_cast<int>(std::round(std::fabs(a) / (M_PI / 12)));  // twelfths of pi
      if (t < 1 || t > 24 || (t % 2 != 0 && t % 3 != 0) || std::fabs(std::fabs(a) - t * M_PI / 12) > 0.0051) continue;
      const int common = std::gcd(t, 12), num = t / common, den = 12 / common;
      os << (os.tellp() > 0 ? "; " : "") << "block " << b.name << ": " << axes[k] << " " << a << " deg is "
         << (a < 0 ? "-" : "") << (num == 1 ? "" : std::to_string(num) + " ") << "pi"
         << (den == 1 ? "" : "/" + std::to_string(den)) << " in radians (" << (a < 0 ? -15 : 15) * t
         << " deg): orientation_deg takes degrees";
    }
  const std::string found = os.str();
  return advisory("block orientations are in degrees", found.empty(),
                  found.empty() ? "no block's yaw, pitch or roll reads as a round angle in radians (a multiple of pi/6 "
                                  "or pi/4)"
                                : found);
}

// The inertia tensor the model flies with, the vehicle file's `derived:` values where it gives
// them: the derivation's audit judges the blocks' tensor, which such values replace (a J_xy
// given larger than J_xx and J_yy allow has a negative principal moment, and a closed loop
// flown with it is lost without a word).
AuditCheck check_inertia_used(const Vehicle& v, const SymbolicModel& m) {
  const auto value = [&](const char* name) {
    for (const auto& p : m.params)
      if (p.name == name) return p.nominal;
    return 0.0;  // a model without the entry (products of inertia are always declared)
  };
  const Mat3 J{{{value("J_xx"), value("J_xy"), value("J_xz")},
                {value("J_xy"), value("J_yy"), value("J_yz")},
                {value("J_xz"), value("J_yz"), value("J_zz")}}};
  const PrincipalMoments pm = principal_moments(J);
  const auto& l = pm.moments;
  // Where the file gives none of J, this is the blocks' tensor the inertia group judged: say
  // so, rather than repeat its numbers as if they were a second finding (helper-103).
  bool given = false;
  for (const char* name : {"J_xx", "J_yy", "J_zz", "J_xy", "J_xz", "J_yz"}) given = given || v.derived_given.count(name);
  std::ostringstream detail;
  detail << "principal moments of the model's J " << l[0] << ", " << l[1] << ", " << l[2] << " kg m²"
         << (given ? " (with the vehicle file's `derived:` values)"
                   : " (the blocks' tensor, as in the inertia checks: the file gives no J in `derived:`)");
  if (!pm.positive) detail << ": not positive definite (a product of inertia too large for the moments given, or its sign?)";
  else if (!pm.triangle) detail << ": the largest exceeds the sum of the other two, which no mass distribution gives";
  return advisory("the inertia the model uses is a body's", pm.positive && pm.triangle, detail.str());
}

}  // namespace

namespace {

// The model's f at hover_residual's point as a function of the commands, its parameters and
// constants substituted once (a Gauss-Newton trim evaluates it some fifty times).
class HoverPoint {
 public:
  explicit HoverPoint(const SymbolicModel& m) : m_(m) {
    GiNaC::lst s = m.constant_substitution();
    for (const Variable& p : m.params) {
      s.append(p.sym == p.nominal);
      if (p.name == "vbat_ref") vbat_ref_ = p.nominal;
    }
    constants_ = s;
    f_ = GiNaC::ex_to<GiNaC::matrix>(GiNaC::ex(m.f).subs(s));
  }
  // Level and still 100 m up, each rotor-speed state where its own row (linear in its speed)
  // is zero. Its slope is taken over 1000 rad/s and the zero refined once: from speeds 0 and 1
  // (a difference of 1/tau beside a row of omega/tau) a Crazyflie's speed came out some 1e-10
  // off, and a motor lag's row 1e-8 from zero (a review, helper-119).
  std::vector<double> state(const std::vector<double>& commands) const {
    using namespace runtime::rigid_body;
    std::vector<double> x(m_.states.size(), 0.0);
    x[kPosition + 2] = 100.0;
    x[kAttitude] = 1.0;
    for (size_t k : m_.rotor_speed_states) {
      std::vector<double> far = x;
      far[k] = 1000.0;
      const double at_zero = row(k, x, commands), slope = (row(k, far, commands) - at_zero) / 1000.0;
      if (slope == 0 || !std::isfinite(slope)) continue;
      x[k] = -at_zero / slope;
      x[k] -= row(k, x, commands) / slope;
    }
    return x;
  }
  bool is_rotor_speed(size_t row) const {
    return std::find(m_.rotor_speed_states.begin(), m_.rotor_speed_states.end(), row) != m_.rotor_speed_states.end();
  }
  std::vector<double> rows(const std::vector<double>& commands) const { return rows_at(state(commands), commands); }
  std::vector<double> rows_at(const std::vector<double>& x, const std::vector<double>& commands) const {
    std::vector<double> r(m_.states.size());
    for (size_t i = 0; i < r.size(); ++i) r[i] = row(i, x, commands);
    return r;
  }
  double value(const GiNaC::ex& e, const std::vector<double>& commands) const {
    return to_double(e.subs(constants_).subs(point(state(commands), commands)));
  }

 private:
  GiNaC::lst point(const std::vector<double>& x, const std::vector<double>& commands) const {
    GiNaC::lst s;
    for (size_t i = 0; i < m_.inputs.size(); ++i)
      s.append(m_.inputs[i].sym == (i < commands.size() ? commands[i] : m_.inputs[i].name == "vbat" ? vbat_ref_ : 0.0));
    for (size_t k = 0; k < m_.states.size(); ++k) s.append(m_.states[k].sym == x[k]);
    return s;
  }
  double row(size_t i, const std::vector<double>& x, const std::vector<double>& commands) const {
    return to_double(f_(static_cast<unsigned>(i), 0).subs(point(x, commands)));
  }

  const SymbolicModel& m_;
  GiNaC::lst constants_;
  GiNaC::matrix f_;
  double vbat_ref_ = 0;
};

// Where the largest |r| is; a NaN's place where there is one (a larger |r| would pass it over,
// and a trim accept it). 0 for none.
size_t largest_at(const std::vector<double>& r) {
  size_t at = 0;
  for (size_t i = 0; i < r.size(); ++i) {
    if (std::isnan(r[i])) return i;
    if (std::fabs(r[i]) > std::fabs(r[at])) at = i;
  }
  return at;
}
double largest(const std::vector<double>& r) { return r.empty() ? 0 : std::fabs(r[largest_at(r)]); }

}  // namespace

HoverMiss hover_miss(const SymbolicModel& m, const std::vector<double>& commands) {
  const HoverPoint hover(m);
  const std::vector<double> x = hover.state(commands);
  const std::vector<double> r = hover.rows_at(x, commands);
  if (r.empty()) return {};
  const size_t at = largest_at(r);
  HoverMiss miss{std::fabs(r[at]), "d" + m.states[at].name + "/dt", {}};
  for (size_t k : m.rotor_speed_states) miss.rotor_speeds.push_back(x[k]);
  return miss;
}

runtime::HoverTrim model_hover_trim(const Vehicle& v, const SymbolicModel& m, const std::vector<double>& start) {
  const HoverPoint hover(m);
  runtime::HoverTrim trim;
  std::vector<double> u = start;
  // The rows the commands must zero: the rotor-speed rows are zero by construction (state()).
  const auto rows = [&](const std::vector<double>& commands) {
    std::vector<double> r = hover.rows(commands);
    for (size_t i = 0; i < r.size(); ++i)
      if (hover.is_rotor_speed(i)) r[i] = 0;
    return r;
  };
  std::vector<double> r = rows(u);
  const size_t n = u.size();
  // f is smooth in the commands; a few steps from a trim off by a weak motor reach 1e-12.
  for (int step = 0; step < 20 && !(largest(r) <= 1e-12); ++step) {
    Eigen::MatrixXd J(r.size(), n);
    for (size_t k = 0; k < n; ++k) {
      std::vector<double> moved = u;
      const double h = 1e-7 * std::max(1.0, std::fabs(u[k]));
      moved[k] += h;
      const std::vector<double> rk = rows(moved);
      for (size_t i = 0; i < r.size(); ++i) J(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(k)) = (rk[i] - r[i]) / h;
    }
    // Least squares, least norm where rotors outnumber the conditions (a hexacopter).
    const Eigen::VectorXd du = J.completeOrthogonalDecomposition().solve(-Eigen::Map<const Eigen::VectorXd>(r.data(), r.size()));
    for (size_t k = 0; k < n; ++k) u[k] += du(static_cast<Eigen::Index>(k));
    r = rows(u);
  }
  if (!(largest(r) <= 1e-9)) {
    trim.why_not = "no commands hold this model level and still (|f| = " + output::short_number(largest(r)) +
                   " at the nearest found): a force or a tilt no level hover holds";
    return trim;
  }
  for (size_t k = 0; k < n; ++k)
    if (!(u[k] >= 0 && u[k] <= 1)) {
      trim.why_not = "rotor " + v.rotors[k].name + " would need command " + output::short_number(u[k]) + ", outside 0 to 1";
      return trim;
    }
  trim.commands = u;
  for (const Rotor& rotor : v.rotors) trim.thrusts.push_back(hover.value(m.intermediate(rotor_thrust_name(rotor.name)), u));
  return trim;
}

runtime::HoverTrim nominal_hover_trim(const Vehicle& v, const SymbolicModel& m) {
  return runtime::hover_trim(nominal_controller_belief(v, m), rotor_names(v));
}

std::vector<AuditCheck> check_vehicle_can_fly(const Vehicle& v, const SymbolicModel& m) {
  return check_vehicle_can_fly(v, m, nominal_hover_trim(v, m));
}

std::vector<AuditCheck> check_vehicle_can_fly(const Vehicle& v, const SymbolicModel& m, const runtime::HoverTrim& trim) {
  const runtime::ControllerModel b = nominal_controller_belief(v, m);
  const Eigen::MatrixXd B = runtime::allocation_matrix(b);
  // The slips of the file first (a copied rotor line, millimetres read as metres): one of
  // them explains the flight checks after it, which fail with it.
  return {check_discs_apart(v),
          check_discs_clear_of_blocks(v),
          check_one_scale(v),
          check_orientations_in_degrees(v),
          check_inertia_used(v, m),
          check_motor_map(b.thrust_laws),
          check_controllable(B, b.mass * b.g),
          check_hover_trim(trim, b.mass * b.g),
          check_hover_above_the_bottom(trim),
          check_hover_below_the_top(trim)};
}

}  // namespace quadgen
