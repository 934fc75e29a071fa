// The mass properties again, by another road than the derivation's: each block's mass on the
// eight points of two-point Gauss-Legendre quadrature, placed in the body with a rotation
// built by Eigen from the file's angles, and each block's projected area as the convex hull
// of its eight corners seen along the axis. Nothing is shared with derive/geometry.cpp (GiNaC's
// exact integration, block_rotation, the face-cosine area formula) but the vehicle file's
// numbers, so a wrong integral, a transposed block rotation or a wrong area formula shows here.
// (Until the sixty-fifth session the audit's inertia check rebuilt the closed form with the
// block's own rotation matrix, and only the tests integrated independently: a review,
// helper-141.)
#pragma once
#include <array>
#include <vector>

#include "audit/audit.hpp"
#include "derive/geometry.hpp"
#include "model/vehicle.hpp"

namespace quadgen {

// The mass properties by quadrature, in the units of MassProperties' values.
struct QuadratureMassProperties {
  double mass = 0;                // kg
  std::array<double, 3> cog{};    // m, body frame
  Mat3 inertia_cog{};             // kg m^2, about the centre of gravity, body axes
  std::array<double, 3> areas{};  // m^2, each block's projection along body x, y, z, summed (no occlusion, as the model)
  // m^2, what the blocks cover seen along body x, y, z, overlaps counted once: not what the
  // model's drag uses (the sum above), shown beside it so that a reader sees how much the sum
  // counts twice (the thesis' A_z left the stacked upper body out). NaN beyond
  // kMostBlocksForCoveredArea blocks (a union of polygons one at a time grows with their count).
  std::array<double, 3> covered{};
  size_t blocks = 0;
};
inline constexpr size_t kMostBlocksForCoveredArea = 200;
QuadratureMassProperties mass_properties_by_quadrature(const Vehicle& v);

// Mass, centre of gravity, inertia about it and projected areas of `mp` against the
// quadrature's, each to a relative 1e-9 of its scale (the total mass; the largest block
// extent for the centre; the largest |J_ij|; the largest area): double rounding is ~1e-15,
// an error of the derivation orders above it.
std::vector<AuditCheck> check_mass_properties_by_quadrature(const Vehicle& v, const MassProperties& mp);

}  // namespace quadgen
