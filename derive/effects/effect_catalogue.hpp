// The catalogue of effects (docs/effects.md) and the questions asked of it. Each effect is a
// self-contained change of the model, described in its own file of this folder (effect.hpp
// says what such a description holds); at its parameters' off values the model is unchanged.
#pragma once
#include <set>
#include <string>
#include <vector>

#include "model/effect.hpp"
#include "model/vehicle.hpp"

namespace quadgen {

// All effects in canonical order (the order they are applied in, whatever the user wrote).
const std::vector<Effect>& effect_catalogue();

// Their names in canonical order, joined by ", " (what --help says --effects accepts).
std::string catalogue_names();

// Every effect's parameter names as --help lists them, joined by ", ".
std::string catalogue_parameter_names();

// The catalogue entry of this name; std::invalid_argument if there is none.
const Effect& find_effect(const std::string& name);
// The same, or nullptr for a name that is no effect (for a caller that words its own error).
const Effect* effect_named(const std::string& name);
// Whether either of two effects declares the other a look-alike (Effect::look_alikes).
bool are_look_alikes(const std::string& x, const std::string& y);
// The flight's own effects (Effect::per_flight) that look like this effect of the airframe's:
// a single flight cannot say which of them it saw (motor trims that leave the yaw alone give a
// CoG offset's moments at every thrust); several flights can, since the airframe's value is
// the same on each. Empty for an effect that is itself the flight's own.
std::vector<std::string> flights_own_look_alikes(const std::string& effect);
// The effect and the one it refines, in canonical order ({"motor_lag", "motor_lag_spread"}
// for motor_lag_spread), or the effect alone: the smallest model it can be derived in.
std::vector<std::string> effect_with_what_it_refines(const std::string& name);
// The effects of `effects` that refine one not among them (Effect::refines): they change
// nothing there. Empty when every refinement has what it refines.
std::vector<std::string> refinements_without_their_effect(const std::vector<std::string>& effects);

// The effect a parameter belongs to ("motor_gain.A" -> "motor_gain"); "" for a parameter of
// the base model.
std::string effect_of_parameter(const std::string& parameter);
// Whether a parameter belongs to an effect rather than to the vehicle file.
inline bool is_effect_parameter(const std::string& parameter) { return !effect_of_parameter(parameter).empty(); }

// What to say after "no parameter 'NAME' in the model": "; did you mean 'X'?" for a slip (a
// rotor name's case), the effect to add with --effects where NAME is a catalogue effect's
// parameter the model lacks, or the effect's parameters where it is in the model; else "".
// `model_parameters`: the model's parameter names.
std::string missing_parameter_hint(const std::string& name, const std::vector<std::string>& model_parameters);

// Of these parameter names (in model order), those held at off whatever the fit flags
// say: the first parameter of each effect identifiable only as ratios beside a parameter
// among `fitted` (motor_gain's first rotor where c_t is fitted; Effect::ratios_only_beside).
std::vector<std::string> reference_parameters(const std::vector<std::string>& parameter_names,
                                              const std::set<std::string>& fitted);

// The value at which a parameter means "off": an effect parameter's nominal value, or its
// lower bound for effects off there; a base-model parameter's nominal value.
double off_value(const std::string& parameter, double nominal, double lower);
// The same for any parameter record with name, nominal and lower (a symbolic Variable).
template <class Record>
double off_value(const Record& p) {
  return off_value(p.name, p.nominal, p.lower);
}

Environment parse_environment(const std::string& text);  // "unknown", "indoor", "outdoor"
std::string environment_name(Environment e);

// The vehicle lengths plausible ranges may be relative to.
struct VehicleScales {
  double rotor_arm = 0, rotor_radius = 0;  // m
};
// The largest distance of a rotor from the body z axis, and the largest rotor radius.
VehicleScales vehicle_scales(const Vehicle& v);
// The plausible range of a parameter in this environment, in SI (lower, upper, why); false
// when its effect declares none, or declares it relative to a length `scales` does not give.
bool plausible_range(const std::string& parameter, Environment where, const VehicleScales& scales, double* lower,
                     double* upper, std::string* why);
// Whether `value` lies outside the plausible range of `parameter` here (the range and why it
// is plausible in lower, upper, why): the one test behind the search's ranking and the
// stand-ins. False inside the range or without one.
bool outside_plausible_range(const std::string& parameter, double value, Environment where, const VehicleScales& scales,
                             double* lower, double* upper, std::string* why);
// How far `value` lies outside [lower, upper], in widths of the range (0 or less inside it;
// infinity for a value that is no number): which of an effect's implausible parameters is
// said, for a suspect and a stand-in alike.
double widths_outside(double value, double lower, double upper);
// Why `value` lies outside the values `parameter` can physically take (Effect::domain:
// "must be 0 or above: ..."), or "" when it can, or when it is no effect's parameter.
std::string outside_physical_domain(const std::string& parameter, double value);
// Parses "motor_gain,motor_lag" or "all"; rejects unknown or repeated names.
std::vector<std::string> parse_effect_list(const std::string& text);
// These effects in canonical order joined by commas: SymbolicModel::effect_list() of the model
// derived with them, and a generated header's kEffects, known before deriving.
std::string canonical_effect_list(const std::vector<std::string>& effects);

}  // namespace quadgen
