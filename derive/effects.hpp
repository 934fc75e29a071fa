// Model extensions (docs/effects.md). Each effect is a self-contained symbolic change:
// it declares its parameters (and states or inputs) and rewrites the intermediate
// quantities of the model context. At their nominal values the model is unchanged.
#pragma once
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "dynamics.hpp"

namespace quadgen {

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
Environment parse_environment(const std::string& text);  // "unknown", "indoor", "outdoor"
std::string environment_name(Environment e);

// The values of a parameter that the effect's physics can produce. A fitted value beyond
// them is the effect standing in for something the model lacks, not the effect itself.
struct PlausibleRange {
  std::string parameter;
  double lower = 0, upper = 0;
  // What lower and upper are in: SI, or fractions of the vehicle's rotor arm (the largest
  // distance of a rotor from the body z axis) or of its rotor radius.
  enum class Scale { kSI, kRotorArm, kRotorRadius } scale = Scale::kSI;
  Environment only_in = Environment::kUnknown;  // kUnknown: wherever no other range applies
  std::string why;  // the physical argument, with its source
};

// One home per effect: its symbolic change, and what fits and the diagnosis need to know
// about it.
struct Effect {
  std::string name;
  std::string meaning;
  std::function<void(ModelContext&)> apply;
  EffectNeeds needs = EffectNeeds::kNothing;
  // Where the cost is flat at "off" (a lag or a delay of zero, a radius of zero), fits
  // also start here: parameter -> value.
  std::vector<std::pair<std::string, double>> typical_start;
  // "Off" is the parameters' lower bound, not their nominal value (a nominal rotor lag of
  // 1 ms keeps simulations non-stiff; equation error has no such limit).
  bool off_at_lower_bound = false;
  // Beside c_t only ratios between the parameters are identifiable: the first is the
  // reference, held at off.
  bool first_parameter_is_reference = false;
  // A property of the flight rather than of the airframe (a motor trim that changes when a
  // motor or the battery is re-seated, the wind of the day): when several flights are
  // diagnosed together, each flight has its own values (runtime::PerFlightModel).
  bool per_flight = false;
  // Plausible values of its parameters (none for a parameter: any value in its bounds).
  std::vector<PlausibleRange> plausible;
  std::vector<LookAlike> look_alikes;
  // One sentence in words for a person reading a report ("Motor C gives 8 % less thrust than
  // motor A"), from the fitted values by parameter name; `reference` is the parameter held at
  // off (first_parameter_is_reference), or empty.
  std::function<std::string(const std::map<std::string, double>& values, const std::string& reference)> headline;
};

// All effects in canonical order (the order they are applied in, whatever the user wrote).
const std::vector<Effect>& effect_catalogue();

// The catalogue entry of this name; std::invalid_argument if there is none.
const Effect& find_effect(const std::string& name);

// The effect a parameter belongs to ("motor_gain.A" -> "motor_gain"); "" for a parameter of
// the base model.
std::string effect_of_parameter(const std::string& parameter);
// Whether a parameter belongs to an effect rather than to the vehicle file.
inline bool is_effect_parameter(const std::string& parameter) { return !effect_of_parameter(parameter).empty(); }

// Of these parameter names (in model order), those held at off whatever the fit flags
// say: the first parameter of each effect identifiable only as ratios (motor_gain's first
// rotor, when c_t is fitted beside the gains).
std::vector<std::string> reference_parameters(const std::vector<std::string>& parameter_names);

// The value at which an effect parameter means "off" (its nominal value, or its lower bound
// for effects off there); a base-model parameter's nominal value.
double off_value(const Variable& parameter);

// The vehicle lengths plausible ranges may be relative to.
struct VehicleScales {
  double rotor_arm = 0, rotor_radius = 0;  // m
};
// The plausible range of a parameter in this environment, in SI (lower, upper, why); false
// when its effect declares none.
bool plausible_range(const std::string& parameter, Environment where, const VehicleScales& scales, double* lower,
                     double* upper, std::string* why);
// Parses "motor_gain,motor_lag" or "all"; rejects unknown or repeated names.
std::vector<std::string> parse_effect_list(const std::string& text);
// These effects in canonical order joined by commas: SymbolicModel::effect_list() of the model
// derived with them, and a generated header's kEffects, known before deriving.
std::string canonical_effect_list(const std::vector<std::string>& effects);

}  // namespace quadgen
