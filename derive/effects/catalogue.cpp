#include "derive/effects/effect_catalogue.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>
#include <stdexcept>

#include "derive/effects/definitions.hpp"
#include "output/joined.hpp"
#include "output/names.hpp"
#include "output/numbers.hpp"
#include "output/nearest_word.hpp"

namespace quadgen {

namespace {

// Canonical order: the order effects are applied in. motor_lag_spread comes before motor_lag,
// whose time constant it scales (ModelContext::lag_factor). wind comes before the airspeed
// effects (rotor_drag, blade_flapping, inflow) because they act on the air-relative velocity
// it changes; thrust scalings commute, so their order only fixes the parameter order.
std::vector<Effect> build_catalogue() {
  std::vector<Effect> list = {effects::motor_gain(),     effects::motor_lag_spread(), effects::motor_lag(),
                              effects::input_delay(),    effects::cog_offset(),       effects::wind(),
                              effects::rotor_drag(),     effects::blade_flapping(),   effects::attitude_bias(),
                              effects::thrust_decay(),   effects::battery_sag(),      effects::ground_effect(),
                              effects::inflow()};
  std::set<std::string> names;
  for (const Effect& e : list) {
    if (e.name.empty() || !e.apply || !e.headline || e.meaning.empty())
      throw std::logic_error("effect '" + e.name + "' lacks a name, terms, a meaning or a headline");
    if (!names.insert(e.name).second) throw std::logic_error("effect '" + e.name + "' listed twice");
  }
  for (const Effect& e : list)
    if (!e.refines.empty() && !names.count(e.refines))
      throw std::logic_error("effect '" + e.name + "' refines an unknown effect");
  for (const Effect& e : list)
    for (const LookAlike& l : e.look_alikes)
      if (!names.count(l.effect)) throw std::logic_error("effect '" + e.name + "' names an unknown look-alike");
  return list;
}

}  // namespace

const std::vector<Effect>& effect_catalogue() {
  static const std::vector<Effect> list = build_catalogue();
  return list;
}

std::string catalogue_names() {
  return output::joined(effect_catalogue(), ", ", [](const Effect& e) { return e.name; });
}

std::string catalogue_parameter_names() {
  return output::joined(effect_catalogue(), ", ", [](const Effect& e) { return e.parameter_names; });
}

const Effect* effect_named(const std::string& name) {
  for (const auto& e : effect_catalogue())
    if (e.name == name) return &e;
  return nullptr;
}

const Effect& find_effect(const std::string& name) {
  if (const Effect* e = effect_named(name)) return *e;
  // As --effects says it (a hostile-input audit, helper-161: a fitted: section's zero-width
  // character printed raw, with no "did you mean").
  std::vector<std::string> known;
  for (const auto& e : effect_catalogue()) known.push_back(e.name);
  throw std::invalid_argument("unknown effect '" + output::printable(name) + "'" + output::did_you_mean(name, known));
}

bool are_look_alikes(const std::string& x, const std::string& y) {
  for (const auto& l : find_effect(x).look_alikes)
    if (l.effect == y) return true;
  for (const auto& l : find_effect(y).look_alikes)
    if (l.effect == x) return true;
  return false;
}

std::vector<std::string> flights_own_look_alikes(const std::string& effect) {
  std::vector<std::string> out;
  if (find_effect(effect).per_flight) return out;
  for (const Effect& e : effect_catalogue())
    if (e.per_flight && are_look_alikes(effect, e.name)) out.push_back(e.name);
  return out;
}

std::vector<std::string> refinements_without_their_effect(const std::vector<std::string>& effects) {
  std::vector<std::string> out;
  for (const auto& e : effects) {
    const std::string& refined = find_effect(e).refines;
    if (!refined.empty() && std::find(effects.begin(), effects.end(), refined) == effects.end()) out.push_back(e);
  }
  return out;
}

std::vector<std::string> effect_with_what_it_refines(const std::string& name) {
  const Effect& e = find_effect(name);
  if (e.refines.empty()) return {name};
  return {e.refines, name};
}

std::string effect_of_parameter(const std::string& parameter) {
  const auto dot = parameter.find('.');
  return dot == std::string::npos ? std::string() : parameter.substr(0, dot);
}

std::string missing_parameter_hint(const std::string& name, const std::vector<std::string>& model_parameters) {
  if (const std::string near = output::did_you_mean(name, model_parameters); !near.empty()) return near;
  const std::string effect = effect_of_parameter(name);
  if (!effect_named(effect)) return "";
  std::vector<std::string> its;
  for (const auto& p : model_parameters)
    if (effect_of_parameter(p) == effect) its.push_back(p);
  if (its.empty()) return " (its effect " + effect + " is not in the model: add it with --effects)";
  return "; " + effect + "'s parameters here: " + output::joined(its);
}

std::vector<std::string> reference_parameters(const std::vector<std::string>& names, const std::set<std::string>& fitted) {
  std::vector<std::string> out;
  std::set<std::string> seen;
  for (const auto& n : names) {
    const std::string e = effect_of_parameter(n);
    if (e.empty() || !seen.insert(e).second) continue;
    const std::string& anchor = find_effect(e).ratios_only_beside;
    if (!anchor.empty() && fitted.count(anchor)) out.push_back(n);
  }
  return out;
}

double off_value(const std::string& parameter, double nominal, double lower) {
  const std::string e = effect_of_parameter(parameter);
  return !e.empty() && find_effect(e).off_at_lower_bound ? lower : nominal;
}

Environment parse_environment(const std::string& text) {
  if (text == "indoor") return Environment::kIndoor;
  if (text == "outdoor") return Environment::kOutdoor;
  if (text == "unknown" || text.empty()) return Environment::kUnknown;
  throw std::invalid_argument("unknown environment '" + output::printable(text) + "' (expected " + output::joined(kEnvironmentNames) + ")");
}

std::string environment_name(Environment e) {
  return e == Environment::kIndoor ? "indoor" : e == Environment::kOutdoor ? "outdoor" : "unknown";
}

bool plausible_range(const std::string& parameter, Environment where, const VehicleScales& scales, double* lower,
                     double* upper, std::string* why) {
  const std::string effect = effect_of_parameter(parameter);
  if (effect.empty()) return false;
  // The best match: a range for this environment over one for any, then one for this
  // parameter over one for all of the effect's.
  const PlausibleRange* found = nullptr;
  int best = -1;
  for (const auto& r : find_effect(effect).plausible) {
    if (!r.parameter.empty() && r.parameter != parameter) continue;
    if (r.only_in != Environment::kUnknown && r.only_in != where) continue;
    const int rank = (r.only_in == where && where != Environment::kUnknown ? 2 : 0) + (r.parameter.empty() ? 0 : 1);
    if (rank > best) best = rank, found = &r;
  }
  if (!found) return false;
  const double unit = found->scale == PlausibleRange::Scale::kRotorArm      ? scales.rotor_arm
                      : found->scale == PlausibleRange::Scale::kRotorRadius ? scales.rotor_radius
                                                                            : 1.0;
  if (!(unit > 0)) return false;  // relative to a length the caller did not give
  *lower = found->lower * unit;
  *upper = found->upper * unit;
  *why = found->why;
  return true;
}

VehicleScales vehicle_scales(const Vehicle& v) {
  VehicleScales s;
  for (const auto& r : v.rotors) {
    s.rotor_arm = std::max(s.rotor_arm, std::hypot(r.position[0], r.position[1]));
    s.rotor_radius = std::max(s.rotor_radius, r.radius);
  }
  return s;
}

bool outside_plausible_range(const std::string& parameter, double value, Environment where, const VehicleScales& scales,
                             double* lower, double* upper, std::string* why) {
  return plausible_range(parameter, where, scales, lower, upper, why) && !(value >= *lower && value <= *upper);
}

double widths_outside(double value, double lower, double upper) {
  const double by = std::max(lower - value, value - upper) / std::max(upper - lower, 1e-300);
  return std::isnan(by) ? INFINITY : by;
}

std::string outside_physical_domain(const std::string& parameter, double value) {
  const Effect* e = effect_named(effect_of_parameter(parameter));
  if (!e) return "";
  for (const auto& d : e->domain) {
    if (!d.parameter.empty() && d.parameter != parameter) continue;
    if (d.lower_included ? value >= d.lower : value > d.lower) continue;
    // A value that prints as the bound (-1.0000000000000002 as -1) is given in full.
    const std::string full = value != d.lower && output::short_number(value) == output::short_number(d.lower)
                                 ? " (" + output::full_number(value) + " is below it)"
                                 : "";
    return std::string("must be ") + (d.lower_included ? "at least " : "above ") + output::short_number(d.lower) + full +
           ": " + d.why;
  }
  return "";
}

std::vector<std::string> parse_effect_list(const std::string& text) {
  std::vector<std::string> out;
  if (text.empty()) return out;
  if (text == "all") {
    for (const auto& e : effect_catalogue()) out.push_back(e.name);
    return out;
  }
  std::set<std::string> known;
  for (const auto& e : effect_catalogue()) known.insert(e.name);
  return output::split_name_list(text, "effect list", [&](const std::string& item) {
    if (item == "all")
      throw std::invalid_argument("effect list '" + output::printable(text) +
                                  "': 'all' stands alone (it is every effect); name effects or write all");
    if (!known.count(item)) {
      throw std::invalid_argument("unknown effect '" + output::printable(item) + "' (known: " + catalogue_names() +
                                  ", or all)" + output::did_you_mean(item, std::vector<std::string>(known.begin(), known.end())));
    }
  });
}

std::string canonical_effect_list(const std::vector<std::string>& effects) {
  std::string out;
  for (const auto& e : effect_catalogue())
    if (std::find(effects.begin(), effects.end(), e.name) != effects.end()) out += (out.empty() ? "" : ",") + e.name;
  return out;
}

}  // namespace quadgen
