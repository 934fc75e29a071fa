// What an effect is, without its algebra: the record the fit, the diagnosis, the flight
// generator and the reports iterate over. Each effect fills one in its own file in this
// folder (motor_gain.cpp, ..., with its symbolic terms beside it); catalogue.cpp lists them
// in canonical order. The header has no GiNaC: code that only needs the facts (plausible
// ranges, look-alikes, headlines) does not see the symbolic layer.
#pragma once
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace quadgen {

struct ModelContext;  // derive/dynamics.hpp: the intermediate quantities an effect rewrites

// What a log must hold for an effect to be estimated from it.
enum class EffectNeeds { kNothing, kBatteryVoltage, kPose };

// Another effect that a flight can mistake for this one, and the manoeuvre that tells
// the two apart.
struct LookAlike {
  std::string effect, separating_manoeuvre;
};

// Where a flight was flown, as a log or the command line declares it: what is plausible
// depends on it (a steady wind indoors is not).
enum class Environment { kUnknown, kIndoor, kOutdoor };
// Their names as files and the command line spell them (parse_environment reads them; a
// mapping, DiagnoseJob::IsValid and --environment accept these and no other).
inline const std::vector<std::string> kEnvironmentNames = {"indoor", "outdoor", "unknown"};

// The values of a parameter that the effect's physics can produce. A fitted value beyond
// them is the effect standing in for something the model lacks, not the effect itself.
struct PlausibleRange {
  std::string parameter;  // empty: every parameter of the effect
  double lower = 0, upper = 0;
  // What lower and upper are in: SI, or fractions of the vehicle's rotor arm (the largest
  // distance of a rotor from the body z axis) or of its rotor radius.
  enum class Scale { kSI, kRotorArm, kRotorRadius } scale = Scale::kSI;
  Environment only_in = Environment::kUnknown;  // kUnknown: wherever no other range applies
  std::string why;  // the physical argument, with its source
};

// The values a parameter can take at all, whatever a fit searches: below `lower` (or at it,
// where it is excluded) the physics breaks (a delay below zero acts on commands not yet sent,
// a time constant of zero is no lag and the integration divides by it, a rotor at -100 % gives
// no thrust). simulate --set refuses such values; any other may be a test flight's truth.
struct PhysicalDomain {
  std::string parameter;  // empty: every parameter of the effect
  double lower = 0;
  bool lower_included = true;
  std::string why;
};

// One sentence in words for a person reading a report ("Motor C gives 8 % less thrust than
// motor A"), from the fitted values by parameter name; `reference` is the parameter held at
// off (the first parameter, where only ratios are identifiable: ratios_only_beside), or empty.
using Headline = std::function<std::string(const std::map<std::string, double>& values, const std::string& reference)>;

// One home per effect: its symbolic change, and what fits and the diagnosis need to know
// about it.
struct Effect {
  std::string name;
  std::string meaning;
  // Declares the effect's parameters (states, inputs) on the context and rewrites its
  // intermediate quantities; at the parameters' off values the model is unchanged.
  std::function<void(ModelContext&)> apply;
  // Its parameters' names as a person reads them in --help ("motor_gain.<rotor>", "wind.x/y");
  // the test Model.HelpListsEveryParameterName checks them against the derived model.
  std::string parameter_names;
  EffectNeeds needs = EffectNeeds::kNothing;
  // Where the cost is flat at "off" (a lag or a delay of zero, a radius of zero), fits
  // also start here: parameter -> value.
  std::vector<std::pair<std::string, double>> typical_start;
  // "Off" is the parameters' lower bound, not their nominal value (a nominal rotor lag of
  // 1 ms keeps simulations non-stiff; equation error has no such limit).
  bool off_at_lower_bound = false;
  // The parameter beside which only ratios between this effect's parameters are identifiable
  // ("c_t" for the motor gains: all four 10 % up is c_t 10 % up). Where the model fits it, the
  // effect's first parameter is the reference, held at off; where it is held (a vehicle file
  // without `fit: true`), every one is free, and a gain common to all motors is measured as
  // such (a researcher's trial, helper-148: with c_t held, a 1.2 % thrust change came out as
  // three motors 0.5-2.6 % stronger than the first). Empty: no reference. One parameter only:
  // a file that holds c_t but fits rho, or the whole motor map, scales every rotor alike
  // through those instead, and its common gain is again (nearly) not identifiable.
  std::string ratios_only_beside;
  // A property of the flight rather than of the airframe (a motor trim that changes when a
  // motor or the battery is re-seated, the wind of the day): when several flights are
  // diagnosed together, each flight has its own values (runtime::PerFlightModel).
  bool per_flight = false;
  // A flight's own quantity that acts on the force (the marker frame's tilt, a wind): its
  // held-out test may be the force model alone, the rollouts with the measured attitude
  // replayed (diagnose::held_out_test), since open-loop rollouts are dominated by the moment
  // model's attitude drift, which it cannot remove.
  bool judged_by_force_model = false;
  // Where it acts: in the equations of motion, on the logged commands before they reach them
  // (a delay), or on what the log measures (a misaligned IMU). The last two have no term of f:
  // the runtime applies them to the log (runtime/data_side_effects.hpp).
  enum class ActsOn { kDynamics, kCommands, kMeasurement } acts_on = ActsOn::kDynamics;
  // The effect whose terms it scales (motor_lag_spread: motor_lag's time constant): without
  // that one in the model it changes nothing, so derive refuses it alone and a diagnosis
  // drops it where that one is not in the final model. Empty: it stands alone.
  std::string refines;
  // Why it is no candidate when several flights are diagnosed together; empty: it is one.
  std::string not_in_joint_diagnosis;
  // Plausible values of its parameters (none for a parameter: any value in its bounds).
  std::vector<PlausibleRange> plausible;
  // Where its parameters' physics ends (none for a parameter: any finite value).
  std::vector<PhysicalDomain> domain;
  std::vector<LookAlike> look_alikes;
  Headline headline;
};

}  // namespace quadgen
