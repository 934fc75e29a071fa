// The vehicle description: what a user writes in vehicles/*.yaml, read and validated.
// Everything is converted to SI on load; every error names file, line and what was expected.
#pragma once
#include <array>
#include <map>
#include <set>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "model/parameter_spec.hpp"
#include "model/units.hpp"

namespace quadgen {

using Vec3 = std::array<double, 3>;

// A scalar the model treats as a parameter, as the vehicle file gives it.
struct Parameter : ParameterSpec {
  int line = 0;  // where the vehicle file gives it (0: not from a file), for error messages
};

// A cuboid of constant density, given in its own frame (edges along its axes, centred),
// placed in the body frame by a rotation (Z-Y-X Euler angles) and its centre.
struct Block {
  std::string name;
  double mass = 0;             // kg
  Vec3 size{};                 // m, edge lengths along the block's own x, y, z
  Vec3 centre{};               // m, body frame
  Vec3 yaw_pitch_roll_deg{};   // deg, block frame -> body frame, R = Rz Ry Rx
  int line = 0;
};

enum class Spin { ccw, cw };  // seen from above (body +z)

struct Rotor {
  std::string name;
  Vec3 position{};  // m, body frame (point where thrust acts)
  Spin spin = Spin::ccw;
  double radius = 0;     // m, propeller radius r_p
  double disc_area = 0;  // m^2, A_p of the thrust law
  int line = 0;
};

// +1 for a rotor spinning counter-clockwise seen from above, -1 clockwise: the sign of its
// spin about body +z (its drag torque on the body has the opposite sign).
inline int spin_sign(const Rotor& r) { return r.spin == Spin::ccw ? 1 : -1; }

// The quantities derive computes from the blocks, which a file's `derived` section may bound
// or give (name, unit, meaning), in the order the model declares them as parameters.
struct DerivedQuantity {
  const char* name;
  const char* unit;
  const char* meaning;
};
inline constexpr DerivedQuantity kDerivedQuantities[] = {
    {"mass", "kg", "total mass (sum of blocks)"},
    {"cog_x", "m", "centre of gravity, body frame"},
    {"cog_y", "m", "centre of gravity, body frame"},
    {"cog_z", "m", "centre of gravity, body frame"},
    {"J_xx", "kg m^2", "inertia tensor about the CoG"},
    {"J_yy", "kg m^2", "inertia tensor about the CoG"},
    {"J_zz", "kg m^2", "inertia tensor about the CoG"},
    {"J_xy", "kg m^2", "inertia tensor entry (= -product of inertia)"},
    {"J_xz", "kg m^2", "inertia tensor entry (= -product of inertia)"},
    {"J_yz", "kg m^2", "inertia tensor entry (= -product of inertia)"},
    {"A_x", "m^2", "exposed area along the body axis"},
    {"A_y", "m^2", "exposed area along the body axis"},
    {"A_z", "m^2", "exposed area along the body axis"}};

// The most rotors and blocks a vehicle file may list (load_vehicle refuses more). A multirotor
// has at most a few dozen rotors (a Volocopter 2X, 18); each rotor adds equations, inputs and
// effect parameters, and 300 of them took minutes to derive (a review, helper-135).
inline constexpr size_t kMaxRotors = 32, kMaxBlocks = 256;

struct Vehicle {
  std::string name;
  std::string source_path;
  std::string content_hash;  // SHA-256 of the file bytes, hex (model/sha256.hpp: why not FNV-1a)
  // The bytes parsed and hashed: a copy of the file quadgen writes (fitted_vehicle.yaml) starts
  // from these, never from a second read, which could find the file edited since.
  std::string source_text;
  std::string description;
  std::vector<Block> blocks;
  std::vector<Rotor> rotors;
  // Named scalar parameters under the file's keys: g, rho, c_w, c_t, kappa, a0..a2, slope,
  // pivot, vbat_ref.
  std::map<std::string, Parameter> params;
  // Fit flags and bounds for quantities derived from the blocks (kDerivedQuantities).
  std::map<std::string, Parameter> derived_overrides;
  // Those of them whose value the file gives (measured, or measured in flight): it replaces
  // the blocks' value as the nominal one.
  std::set<std::string> derived_given;
  // The file carries a `fitted:` section (effects and fitted values, as fitted_parameters.yaml
  // holds them, written by quadgen diagnose into fitted_vehicle.yaml): `quadgen derive` then
  // builds the fitted model. Read by derive's load_fitted_parameters, at this line.
  int fitted_line = 0;
};

// Whether a vehicle is the thesis' FINken 3 (vehicles/finken3.yaml), whose numbers the thesis
// comparisons use: named "finken3" with the thesis' four rotors A, B, C, D in that order. The
// name alone let a hexacopter copied under that name into the comparison, which then looked
// for rotors A..D and stopped derive. The one place that decides it.
inline bool is_thesis_vehicle(const std::string& vehicle_name, const std::vector<std::string>& rotor_names) {
  return vehicle_name == "finken3" && rotor_names == std::vector<std::string>{"A", "B", "C", "D"};
}

struct VehicleError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

Vehicle load_vehicle(const std::string& path);
Vehicle parse_vehicle(const std::string& text, const std::string& path_for_messages);

const Parameter& param(const Vehicle& v, const std::string& name);

// What `command` (fit, diagnose, predict) tells a user who hands it a file with a `fitted:`
// section (a diagnosis' fitted_vehicle.yaml): only derive reads that section, so the run uses
// the file's own values. Empty where the file has none. The path is made printable.
std::string fitted_section_note(const Vehicle& v, const std::string& command);

// The rotors' names in the vehicle file's order (the log columns u_<name>, the inputs' order).
std::vector<std::string> rotor_names(const Vehicle& v);
inline bool is_thesis_vehicle(const Vehicle& v) { return is_thesis_vehicle(v.name, rotor_names(v)); }

}  // namespace quadgen
