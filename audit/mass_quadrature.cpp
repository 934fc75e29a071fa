#include "audit/mass_quadrature.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>
// Boost 1.74's rescale policy reads a factor GCC 12 cannot prove set (-Wmaybe-uninitialized,
// inside Boost's own code, where the union is instantiated): silenced for this file alone.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
// Boost 1.74's Boost.Math, which Boost.Geometry includes, includes a header of its own that
// Boost has since deprecated and says so in a note on every build: not ours to change.
#define BOOST_ALLOW_DEPRECATED_HEADERS
// The whole of Boost.Geometry: naming only the four algorithms used saves 0.5 s of this
// file's 14 s; the time is the union's instantiation, not the headers.
#include <boost/geometry.hpp>

#include "output/numbers.hpp"

namespace quadgen {
namespace {

constexpr double kRelativeTolerance = 1e-9;
// Below this a difference is printed as "below 1e-12": the digits of rounding noise would
// change derivation.md (a checked-in golden file) with any change of summation order.
constexpr double kPrintedFloor = 1e-12;

// Block frame -> body frame, R = Rz(yaw) Ry(pitch) Rx(roll) as the vehicle file defines it,
// composed from Eigen's axis-angle rotations (not derive's rotation_zyx). The tests build
// the same matrix the same way on purpose (tests/test_geometry.cpp rotation_deg): each is a
// check of derive that leans on neither derive nor the other.
Eigen::Matrix3d block_to_body(const Vec3& yaw_pitch_roll_deg) {
  const auto rad = [](double deg) { return deg * EIGEN_PI / 180; };
  return (Eigen::AngleAxisd(rad(yaw_pitch_roll_deg[0]), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rad(yaw_pitch_roll_deg[1]), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rad(yaw_pitch_roll_deg[2]), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

// The eight points (block frame) at which two-point Gauss-Legendre quadrature, each weighing
// an eighth of the mass, integrates every polynomial of degree up to 3 in each coordinate over
// the cuboid exactly: its mass, first and second moments. With `fraction` 1, its corners.
std::vector<Eigen::Vector3d> cuboid_points(const Vec3& size, double fraction) {
  std::vector<Eigen::Vector3d> points;
  for (int k = 0; k < 8; ++k)
    points.emplace_back((k & 1 ? 0.5 : -0.5) * size[0] * fraction, (k & 2 ? 0.5 : -0.5) * size[1] * fraction,
                        (k & 4 ? 0.5 : -0.5) * size[2] * fraction);
  return points;
}

double cross(const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return (a - o).x() * (b - o).y() - (a - o).y() * (b - o).x();
}

// The convex hull of `p`, counter-clockwise, its first point repeated at the end (Andrew's
// monotone chain).
std::vector<Eigen::Vector2d> convex_hull(std::vector<Eigen::Vector2d> p) {
  std::sort(p.begin(), p.end(), [](const auto& a, const auto& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  std::vector<Eigen::Vector2d> hull(2 * p.size());
  size_t k = 0;
  for (size_t i = 0; i < p.size(); ++i) {  // lower chain
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], p[i]) <= 0) --k;
    hull[k++] = p[i];
  }
  for (size_t i = p.size() - 1, lower = k + 1; i-- > 0;) {  // upper chain
    while (k >= lower && cross(hull[k - 2], hull[k - 1], p[i]) <= 0) --k;
    hull[k++] = p[i];
  }
  hull.resize(k);
  return hull;
}

// Area of a closed polygon (the shoelace formula).
double polygon_area(const std::vector<Eigen::Vector2d>& ring) {
  double twice = 0;
  for (size_t i = 0; i + 1 < ring.size(); ++i) twice += ring[i].x() * ring[i + 1].y() - ring[i + 1].x() * ring[i].y();
  return 0.5 * std::abs(twice);
}

// The area of the union of closed convex polygons: what the blocks cover seen along an axis,
// overlaps counted once (Boost.Geometry's polygon union: a well-kept Debian library rather
// than clipping of our own).
double union_area(const std::vector<std::vector<Eigen::Vector2d>>& rings) {
  namespace bg = boost::geometry;
  using Point = bg::model::d2::point_xy<double>;
  using Polygon = bg::model::polygon<Point, false>;  // counter-clockwise, closed
  using Polygons = bg::model::multi_polygon<Polygon>;
  Polygons covered;
  try {  // coordinates of 1e300 overflow inside the overlay, which then throws: no number, not an abort
    for (const auto& ring : rings) {
      Polygon p;
      for (const auto& v : ring) bg::append(p.outer(), Point(v.x(), v.y()));
      bg::correct(p);
      Polygons grown;
      bg::union_(covered, p, grown);
      covered = std::move(grown);
    }
    return bg::area(covered);
  } catch (const std::exception&) {
    return std::numeric_limits<double>::quiet_NaN();
  }
}

std::string relative_text(double relative) {
  return relative < kPrintedFloor ? "below 1e-12" : output::short_number(relative);
}

// "; the blocks cover 10, 20, 30 % less than that sum along x, y, z (overlaps counted once;
// the model uses the sum)": whole per cents, stable across compilers in a checked-in file.
std::string covered_text(const QuadratureMassProperties& q) {
  for (double covered : q.covered)
    if (!std::isfinite(covered))
      return std::isnan(q.covered[0]) && q.blocks > kMostBlocksForCoveredArea
                 ? "; what they cover, overlaps counted once, is not computed for more than " +
                       std::to_string(kMostBlocksForCoveredArea) + " blocks"
                 : std::string("; what they cover, overlaps counted once, could not be computed");
  std::string out = "; the blocks cover ";
  for (size_t axis = 0; axis < 3; ++axis) {
    char percent[16];
    std::snprintf(percent, sizeof percent, "%.0f", 100 * (1 - q.covered[axis] / q.areas[axis]));
    out += std::string(axis ? ", " : "") + (std::string(percent) == "-0" ? "0" : percent);
  }
  return out + " % less than that sum along x, y, z (overlaps counted once; the model's drag uses the sum)";
}

}  // namespace

QuadratureMassProperties mass_properties_by_quadrature(const Vehicle& v) {
  QuadratureMassProperties q;
  std::array<std::vector<std::vector<Eigen::Vector2d>>, 3> footprints;  // per axis, each block's
  std::vector<std::pair<double, Eigen::Vector3d>> weighted;  // mass and body-frame position
  Eigen::Vector3d first = Eigen::Vector3d::Zero();
  for (const Block& b : v.blocks) {
    const Eigen::Matrix3d R = block_to_body(b.yaw_pitch_roll_deg);
    const Eigen::Vector3d centre(b.centre[0], b.centre[1], b.centre[2]);
    for (const Eigen::Vector3d& xi : cuboid_points(b.size, 1 / std::sqrt(3.0))) {
      weighted.emplace_back(b.mass / 8, centre + R * xi);
      first += b.mass / 8 * weighted.back().second;
    }
    q.mass += b.mass;
    std::vector<Eigen::Vector3d> corners;
    for (const Eigen::Vector3d& xi : cuboid_points(b.size, 1.0)) corners.push_back(centre + R * xi);
    for (size_t axis = 0; axis < 3; ++axis) {
      std::vector<Eigen::Vector2d> seen;  // the corners on the plane across `axis`
      for (const auto& c : corners)
        seen.emplace_back(c(static_cast<Eigen::Index>((axis + 1) % 3)), c(static_cast<Eigen::Index>((axis + 2) % 3)));
      footprints[axis].push_back(convex_hull(seen));
      q.areas[axis] += polygon_area(footprints[axis].back());
    }
  }
  q.blocks = v.blocks.size();
  for (size_t axis = 0; axis < 3; ++axis)
    q.covered[axis] = v.blocks.size() <= kMostBlocksForCoveredArea ? union_area(footprints[axis])
                                                                    : std::numeric_limits<double>::quiet_NaN();
  const Eigen::Vector3d cog = first / q.mass;
  Eigen::Matrix3d J = Eigen::Matrix3d::Zero();
  for (const auto& [m, r] : weighted) {
    const Eigen::Vector3d d = r - cog;
    J += m * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose());
  }
  for (size_t i = 0; i < 3; ++i) {
    q.cog[i] = cog(static_cast<Eigen::Index>(i));
    for (size_t j = 0; j < 3; ++j) q.inertia_cog[i][j] = J(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
  }
  return q;
}

std::vector<AuditCheck> check_mass_properties_by_quadrature(const Vehicle& v, const MassProperties& mp) {
  const QuadratureMassProperties q = mass_properties_by_quadrature(v);
  double extent = 0, inertia_scale = 0, area_scale = 0, cog_off = 0, inertia_off = 0, area_off = 0;
  for (const Block& b : v.blocks)
    for (int i = 0; i < 3; ++i) extent = std::max(extent, std::abs(b.centre[static_cast<size_t>(i)]) + b.size[static_cast<size_t>(i)]);
  for (size_t i = 0; i < 3; ++i) {
    cog_off = std::max(cog_off, std::abs(mp.cog_value[i] - q.cog[i]));
    area_scale = std::max(area_scale, std::abs(q.areas[i]));
    area_off = std::max(area_off, std::abs(mp.areas_value[i] - q.areas[i]));
    for (size_t j = 0; j < 3; ++j) {
      inertia_scale = std::max(inertia_scale, std::abs(q.inertia_cog[i][j]));
      inertia_off = std::max(inertia_off, std::abs(mp.inertia_cog_value[i][j] - q.inertia_cog[i][j]));
    }
  }
  const double mass_off = std::abs(mp.mass_value - q.mass);
  // Each difference relative to its scale; NaN (a derivation's NaN) fails.
  const auto check = [](const char* name, double relative, const std::string& how) {
    return AuditCheck{"inertia", name, relative <= kRelativeTolerance,
                      how + "; largest difference " + relative_text(relative) + " of its scale (allowed 1e-9)", false};
  };
  return {
      check("mass and centre of gravity by quadrature", std::max(mass_off / q.mass, cog_off / extent),
            "the blocks' masses summed and their Gauss points' first moments, against the derivation's; the centre's "
            "difference taken relative to the largest block extent"),
      check("inertia about the centre of gravity by quadrature", inertia_off / inertia_scale,
            "8 Gauss-Legendre points per block (exact for a cuboid's second moments), placed with a rotation built by "
            "Eigen from the file's angles, summed about the quadrature's own centre of gravity, against the "
            "derivation's J_cg, independent of its integrals and block rotations"),
      check("projected areas by convex hull", area_off / area_scale,
            "each block's eight corners seen along body x, y, z, the area of their convex hull, summed over blocks (no "
            "occlusion, as the model's drag uses them), against the derivation's face-cosine sums" + covered_text(q)),
  };
}

}  // namespace quadgen
