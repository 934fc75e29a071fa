#include "audit/vehicle_checks.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

#include <Eigen/Dense>

#include "derive/geometry.hpp"
#include "derive/runtime_view.hpp"
#include "runtime/allocation_matrix.hpp"

namespace quadgen {

namespace {

AuditCheck advisory(const std::string& name, bool ok, const std::string& detail) {
  AuditCheck c{"vehicle", name, ok, detail};
  c.advisory = true;
  return c;
}

// Rounding residue (1e-17 N beside 0.13 N) reads as 0, as the trim's reason does.
std::string numbers(const Eigen::VectorXd& x, const char* unit) {
  std::ostringstream os;
  os.precision(4);
  const double scale = x.size() ? x.cwiseAbs().maxCoeff() : 0.0;
  for (Eigen::Index i = 0; i < x.size(); ++i) os << (i ? ", " : "") << (std::abs(x(i)) <= 1e-9 * scale ? 0.0 : x(i));
  if (*unit) os << " " << unit;
  return os.str();
}

AuditCheck check_motor_map(const std::vector<runtime::ThrustLaw>& laws) {
  const runtime::ThrustLaw& l = laws.front();  // one map for every rotor
  const bool rises = l.a1 > 0 && l.a1 + 2 * l.a2 > 0;
  std::ostringstream os;
  os.precision(5);
  os << "d(speed)/d(command) = a1 + 2 a2 u is " << l.a1 << " rad/s at u = 0 and " << l.a1 + 2 * l.a2
     << " at u = 1 (the map as the model turns it)";
  return advisory("the motor map rises with the command", rises, os.str());
}

// Thrust, roll, pitch and yaw apart: the allocation has rank 4. Rows scaled first (newtons
// and newton-metres of arms of centimetres), which leaves the rank as it is: roll and pitch
// by the longest arm together, so that a row of rounding noise (sin 180 deg) stays noise, and
// yaw by its largest entry.
AuditCheck check_controllable(const Eigen::MatrixXd& B) {
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
  return advisory("thrust, roll, pitch and yaw can be set apart", rank == 4, detail);
}

// A hover trim (runtime::hover_trim, which simulate's scenarios fly): every rotor pushing and
// within its motor's reach.
AuditCheck check_hover_trim(const Vehicle& v, const runtime::ControllerModel& b) {
  const runtime::HoverTrim trim = runtime::hover_trim(b, rotor_names(v));
  const Eigen::VectorXd F =
      Eigen::Map<const Eigen::VectorXd>(trim.thrusts.data(), static_cast<Eigen::Index>(trim.thrusts.size()));
  std::string detail = "thrusts for hover " + numbers(F, "N") + " (weight " + std::to_string(b.mass * b.g) + " N)";
  if (trim.found()) {
    const Eigen::VectorXd u =
        Eigen::Map<const Eigen::VectorXd>(trim.commands.data(), static_cast<Eigen::Index>(trim.commands.size()));
    detail += ", commands " + numbers(u, "");
  } else {
    detail += ": " + trim.why_not;
  }
  return advisory("a hover trim exists within the motors' reach", trim.found(), detail);
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

// No propeller sweeps through a block: each rotor's disc (its radius about the hub, in the
// plane through the hub normal to body z, where the model's thrust acts) kept out of every
// block's interior. Two slips show so: a hub placed at its motor's centre rather than on top
// (the thrust point, and with it the arm of every rotor force about the centre of gravity,
// half a motor too low), and a block or rotor copied to the wrong place. The disc is sampled
// on a polar grid (fine enough for a clip of a few per cent of the radius); a point counts
// as inside where it lies deeper than 1 % of the rotor's radius, so that a hub on a block's
// face, as a propeller sits on its motor, is outside, and so is a file's rounding.
AuditCheck check_discs_clear_of_blocks(const Vehicle& v) {
  constexpr int kRings = 16, kSpokes = 64;
  std::ostringstream os;
  os.precision(3);
  for (const Rotor& r : v.rotors)
    for (const Block& b : v.blocks) {
      const Mat3 R = to_mat3(block_rotation(b.yaw_pitch_roll_deg));
      const double h[3] = {b.size[0] / 2, b.size[1] / 2, b.size[2] / 2};
      // How deep a point of the body frame lies inside the block (negative: outside).
      const auto depth = [&](double x, double y, double z) {
        const double d[3] = {x - b.centre[0], y - b.centre[1], z - b.centre[2]};
        double least = std::numeric_limits<double>::infinity();
        for (int i = 0; i < 3; ++i) {
          const double local = R[0][i] * d[0] + R[1][i] * d[1] + R[2][i] * d[2];  // R^T d
          least = std::min(least, h[i] - std::fabs(local));
        }
        return least;
      };
      const double tol = 0.01 * r.radius;
      const bool hub_inside = depth(r.position[0], r.position[1], r.position[2]) > tol;
      bool cuts = hub_inside;
      for (int k = 1; k <= kRings && !cuts; ++k)
        for (int j = 0; j < kSpokes && !cuts; ++j) {
          const double rho = r.radius * k / kRings, phi = 2 * M_PI * j / kSpokes;
          cuts = depth(r.position[0] + rho * std::cos(phi), r.position[1] + rho * std::sin(phi), r.position[2]) > tol;
        }
      if (!cuts) continue;
      // The block's reach along body z about the disc's plane (from its corners): which way
      // the hub or the block would have to move.
      double above = 0, below = 0;  // m
      for (int corner = 0; corner < 8; ++corner) {
        double z = b.centre[2];
        for (int i = 0; i < 3; ++i) z += R[2][i] * ((corner >> i & 1) ? h[i] : -h[i]);
        above = std::max(above, z - r.position[2]);
        below = std::max(below, r.position[2] - z);
      }
      os << (os.tellp() > 0 ? "; " : "") << "rotor " << r.name << "'s disc passes through block " << b.name
         << ", which reaches " << above * 1e3 << " mm above and " << below * 1e3 << " mm below the disc's plane"
         << (hub_inside ? " (its hub inside the block: is the hub's z the propeller's height, on top of the motor?)"
                        : " (a propeller cannot pass through it: is the block or the rotor misplaced?)");
    }
  const std::string found = os.str();
  return advisory("no propeller sweeps through a block", found.empty(),
                  found.empty() ? "every rotor's disc is clear of every block" : found);
}

// Rotors and blocks on one scale: a number without a unit is read as metres, so a position or
// radius copied in millimetres puts a rotor a thousand times too far out, and an area in mm^2
// makes the disc larger than its radius allows. Thresholds wide enough for real layouts (a
// file of one hub block, with mass and inertia given, whose rotors reach 5x past it; a hull
// larger than its rotors' circle; the FINken 3's thrust-law area 0.13 of its disc), far
// below the factor of 1000 of the mistake.
AuditCheck check_one_scale(const Vehicle& v) {
  double reach = 0, farthest = 0;  // m, of the blocks (corners) and of the rotors (hub and tip)
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
         << reach << " m (a position or radius in mm read as m?)";
    const double disc = M_PI * r.radius * r.radius;
    if (r.disc_area > 1.01 * disc)
      os << (os.tellp() > 0 ? "; " : "") << "rotor " << r.name << ": disc_area " << r.disc_area
         << " m^2 is more than the disc its radius sweeps, pi r^2 = " << disc << " m^2 (an area in mm^2 or a diameter as the radius?)";
  }
  if (farthest > 0 && reach > 20 * farthest)
    os << (os.tellp() > 0 ? "; " : "") << "the blocks reach " << reach << " m from the origin, the rotors " << farthest
       << " m (a block's size or centre in mm read as m?)";
  const std::string found = os.str();
  std::ostringstream fine;
  fine.precision(4);
  fine << "the blocks reach " << reach << " m from the origin, the rotors " << farthest
       << " m; every disc_area at most pi r^2";
  return advisory("rotors and blocks on one scale", found.empty(), found.empty() ? fine.str() : found);
}

}  // namespace

std::vector<AuditCheck> check_vehicle_can_fly(const Vehicle& v, const SymbolicModel& m) {
  const runtime::ControllerModel b = nominal_controller_belief(v, m);
  const Eigen::MatrixXd B = runtime::allocation_matrix(b);
  // The slips of the file first (a copied rotor line, millimetres read as metres): one of
  // them explains the flight checks after it, which fail with it.
  return {check_discs_apart(v), check_discs_clear_of_blocks(v), check_one_scale(v), check_motor_map(b.thrust_laws), check_controllable(B),
          check_hover_trim(v, b)};
}

}  // namespace quadgen
