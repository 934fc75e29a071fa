// Mass properties of a vehicle made of cuboid blocks, derived by exact symbolic
// integration: a generic cuboid is integrated in its own frame (once per derivation),
// rotated and shifted into the body frame (once per orientation), and each block gets
// that closed form with its own symbols and, for the values, its own numbers, so the
// cost is linear in the number of blocks. Results stay expressions in the geometry
// symbols (so a changed vehicle file re-derives them) and are also evaluated.
#pragma once
#include <string>
#include <vector>

#include <ginac/ginac.h>

#include "model/vehicle.hpp"

namespace quadgen {

using Mat3 = std::array<std::array<double, 3>, 3>;

// The symbols that describe one block, and its exact orientation matrix.
struct BlockSymbols {
  std::string name;
  GiNaC::symbol m, a, b, c;     // mass, edge lengths along the block's own x, y, z
  GiNaC::symbol cx, cy, cz;     // centre in the body frame
  GiNaC::matrix R;              // block frame -> body frame (exact numbers)
};

struct BlockContribution {
  std::string name;
  GiNaC::matrix local_second_moment;  // ∫ ξ ξ^T dm in the block frame (from integration)
  GiNaC::matrix inertia_origin;       // inertia tensor about the body origin, body axes
  GiNaC::matrix areas;                // projected area along body x, y, z
  Mat3 inertia_origin_value{};
  std::array<double, 3> areas_value{};
};

struct MassProperties {
  std::vector<BlockSymbols> symbols;
  GiNaC::lst values;  // symbol == number for every geometry symbol
  std::vector<BlockContribution> blocks;

  GiNaC::ex mass;
  GiNaC::matrix cog{3, 1};             // centre of gravity, body frame
  GiNaC::matrix inertia_origin{3, 3};  // about the body origin
  GiNaC::matrix inertia_cog{3, 3};     // about the centre of gravity (what the dynamics use)
  GiNaC::matrix areas{3, 1};           // exposed area per body axis (sum of block projections)

  double mass_value = 0;
  std::array<double, 3> cog_value{};
  Mat3 inertia_origin_value{};
  Mat3 inertia_cog_value{};
  std::array<double, 3> areas_value{};
};

MassProperties derive_mass_properties(const Vehicle& v);

// Rotation block frame -> body frame from Z-Y-X Euler angles in degrees, as exact
// GiNaC numbers where the angle is a rational number of degrees.
GiNaC::matrix block_rotation(const Vec3& yaw_pitch_roll_deg);

double to_double(const GiNaC::ex& e);
Mat3 to_mat3(const GiNaC::matrix& m);

}  // namespace quadgen
