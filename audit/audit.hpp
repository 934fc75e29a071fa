// The audit: independent checks that make the derivation trustworthy: units,
// rotation properties, inertia validity and cross-checks, energy conservation.
#pragma once
#include <array>
#include <functional>
#include <string>
#include <vector>

#include "derive/geometry.hpp"
#include "derive/kinematics.hpp"
#include "derive/symbolic_model.hpp"

namespace quadgen {

struct AuditCheck {
  std::string group;   // "units", "rotation", "inertia", "energy", "vehicle"
  std::string name;
  bool passed = false;
  std::string detail;  // what was computed, in words a reviewer can follow
  // About the vehicle, not the derivation (audit/vehicle_checks.hpp): a failure is a warning.
  bool advisory = false;
};

struct AuditResult {
  std::vector<AuditCheck> checks;
  bool all_passed() const;  // every check that is not advisory
  std::vector<const AuditCheck*> warnings() const;  // the advisory checks that failed
};

AuditResult audit(const SymbolicModel& m, const MassProperties& mp);

// Individual checks, exposed for tests.
// The attitude forms the rotation checks judge: the derivation's own unless a test gives wrong
// ones, to see each check fail (a check only ever seen to pass could be a constant).
struct AttitudeForms {
  std::function<GiNaC::matrix(const GiNaC::ex& psi, const GiNaC::ex& theta, const GiNaC::ex& phi)> zyx = rotation_zyx;
  std::function<GiNaC::matrix(const GiNaC::matrix& q)> from_quaternion = rotation_from_quaternion;
};
// The Z-Y-X matrix and the quaternion matrix each orthogonal and proper, and the two agreeing.
std::vector<AuditCheck> check_rotation(const AttitudeForms& forms = {});
// Dimension of every f_i against state_i / s, and of every term of every sum.
std::vector<AuditCheck> check_units(const SymbolicModel& m);
// Reduces a polynomial in sin/cos of the given angles modulo sin^2 + cos^2 = 1.
GiNaC::ex reduce_trig(const GiNaC::ex& e, const std::vector<GiNaC::ex>& angles);
// Reduces modulo qw^2 + qx^2 + qy^2 + qz^2 = 1 (eliminating qw^2).
GiNaC::ex reduce_unit_quaternion(const GiNaC::ex& e, const GiNaC::ex& qw, const GiNaC::ex& qx,
                                 const GiNaC::ex& qy, const GiNaC::ex& qz);
// The substitutions that switch off every torque of a model (thrust, gravity, effects whose
// formula adds a moment, terms beyond the catalogue), as the energy checks use them.
GiNaC::lst torque_free_substitutions(const SymbolicModel& m);
// Closed-form inertia of a cuboid about its centre, m/12 diag(b^2+c^2, a^2+c^2, a^2+b^2),
// rotated and moved to the origin with the parallel-axis theorem.
GiNaC::matrix closed_form_block_inertia(const BlockSymbols& s);

// Whether a symmetric 3x3 tensor can be a body's inertia: its principal moments (ascending)
// are positive and each is at most the sum of the other two. One home for the test that the
// derivation audit applies to the blocks' tensor and the vehicle checks to the tensor the
// model uses (which a file's `derived:` may give).
struct PrincipalMoments {
  std::array<double, 3> moments{};  // kg m^2, ascending
  bool positive = false;
  bool triangle = false;    // l0 + l1 >= l2 (to a relative 1e-12); the others follow when ascending
};
PrincipalMoments principal_moments(const Mat3& J);

}  // namespace quadgen
