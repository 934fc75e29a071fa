// Whether the vehicle a file describes can fly, checked at its nominal values: the motor maps
// rise with the command, thrust, roll, pitch and yaw can be set apart from one another, and a
// hover trim exists within every motor's reach. These are advisories about the vehicle, not
// about the derivation (which is right for a vehicle that cannot fly, too): a failed one is a
// warning in derive's summary and in derivation.md, and the audit still passes.
//
// They catch what a new vehicle's author gets wrong most often and no unit check sees: masses
// in grams written as kilograms (hover beyond the motor map), a centre of gravity outside the
// rotors (a rotor would have to pull down), spins that do not cancel (yaw cannot be held), a
// motor map copied with the wrong sign, two rotor discs in one place (a copied line), a
// propeller sweeping through a block (a hub at its motor's centre rather than on top), numbers
// in millimetres where the file reads metres (rotors and blocks on different scales).
#pragma once
#include <vector>

#include "audit/audit.hpp"
#include "derive/symbolic_model.hpp"
#include "model/vehicle.hpp"
#include "runtime/closed_loop.hpp"

namespace quadgen {

// The hover trim of the vehicle at the model's nominal values (runtime::hover_trim of the
// nominal controller belief): computed once per derivation, and read by the checks below, the
// generated header's kHoverCommand and model.json's hover_trim.
runtime::HoverTrim nominal_hover_trim(const Vehicle& v, const SymbolicModel& m);

// The largest |f| (every row; at rest only the accelerations and rotor-speed rates can be
// nonzero) of the model's own symbolic right-hand side at its nominal values with the rotors
// at `commands`: level and still 100 m up (clear of any ground effect), each rotor-speed state
// where its row is zero, t = 0 and a battery at vbat_ref (each effect's input where it is
// neutral). The trim comes from the base model's numbers; effect values fitted away from
// neutral (a motor gain, a wind, a CoG offset in a diagnosis' extended model) move the hover,
// and this says by how much (a review: the header's kHoverCommand did not hold such a model),
// and in which row, as "dp/dt" (for a reader: |f| mixes units). NaN where any row is.
// `rotor_speeds` [rad/s] are the rotor-speed states there, in the model's order of them (a
// header declares them with its trim: a simulation of a motor lag starts its hover there).
struct HoverMiss {
  double largest = 0;
  std::string row;
  std::vector<double> rotor_speeds;
};
HoverMiss hover_miss(const SymbolicModel& m, const std::vector<double>& commands);

// The hover trim of the model itself, at that same point: Gauss-Newton on the commands from
// `start` (the base model's trim) until every row of f is zero. Where effect values fitted
// away from neutral move the hover (a weak motor, a CoG offset), the base trim misses, and a
// diagnosis' extended model or a header derived with --params would otherwise declare none (a
// newcomer's trial, helper-118: the README's example program would then run at command 0).
// Each rotor's thrust is the model's own at the trim. Not found (why_not says why) where no
// commands within 0 to 1 zero f: a steady wind or a tilt, which no level hover holds.
runtime::HoverTrim model_hover_trim(const Vehicle& v, const SymbolicModel& m, const std::vector<double>& start);

std::vector<AuditCheck> check_vehicle_can_fly(const Vehicle& v, const SymbolicModel& m, const runtime::HoverTrim& trim);
// The same with the trim computed here (tests).
std::vector<AuditCheck> check_vehicle_can_fly(const Vehicle& v, const SymbolicModel& m);

}  // namespace quadgen
