#include "derive/fitted_parameters.hpp"

#include <algorithm>

#include "derive/effects/effect_catalogue.hpp"
#include "output/nearest_word.hpp"
#include "output/sinks.hpp"
#include "model/yaml_reader.hpp"
#include "runtime/parameter.hpp"

namespace quadgen {

FittedParameters load_fitted_parameters(const std::string& path) {
  YamlReader r{path, {}};
  const YAML::Node file = r.parse(r.read_file("fitted-parameters file"));
  if (!file.IsMap()) throw VehicleError(path + ":1: expected 'effects' and 'parameters' (a fitted_parameters.yaml)");
  // The other files a user may hand over by mistake (YAML reads JSON too): name the one expected.
  if (file["final_fit"] || file["estimates"] || file["findings"])
    throw VehicleError(path + ":1: a diagnosis.json or fit.json; derive --params takes the "
                              "fitted_parameters.yaml (or fitted_vehicle.yaml) a diagnose run writes beside its diagnosis.json");
  if (file["columns"])
    throw VehicleError(path + ":1: a column mapping; derive --params takes the fitted_parameters.yaml (or "
                              "fitted_vehicle.yaml) a diagnose run writes");
  if (file["name"] && !file["fitted"])
    throw VehicleError(path + ":1: a vehicle file without a 'fitted:' section; derive --params takes the "
                              "fitted_parameters.yaml (or fitted_vehicle.yaml) a diagnose run writes");
  // A vehicle file with a `fitted:` section (fitted_vehicle.yaml) holds the same map there.
  const bool in_vehicle = file["fitted"] && file["name"];
  const YAML::Node root = in_vehicle ? file["fitted"] : file;
  if (in_vehicle && !root.IsMap()) r.fail(root, "expected 'fitted' to hold 'effects' and 'parameters'");
  r.only_keys(root, {"vehicle", "effects", "parameters"}, "fitted parameters");
  FittedParameters out;
  out.path = path;
  if (root["vehicle"]) out.vehicle = r.text(root["vehicle"], "the vehicle they were fitted for");
  const YAML::Node effects = root["effects"], params = root["parameters"];
  if (!effects || !effects.IsSequence()) r.fail(root, "expected a list 'effects' (may be empty: [])");
  for (const auto& e : effects) {
    std::string name;
    try {
      name = find_effect(r.text(e, "an effect name")).name;
    } catch (const std::invalid_argument& x) {
      r.fail(e, x.what());
    }
    if (std::find(out.effects.begin(), out.effects.end(), name) != out.effects.end())
      r.fail(e, "effect '" + name + "' listed twice");
    out.effects.push_back(name);
  }
  if (!params || !params.IsMap()) r.fail(root, "expected a map 'parameters' of name: {value, unit}");
  r.unique_keys(params, "parameters");
  for (const auto& kv : params) {
    FittedValue v;
    v.name = r.text(kv.first, "a parameter name");
    v.line = kv.first.Mark().line + 1;
    const YAML::Node& p = kv.second;
    if (!p.IsMap()) r.fail(kv.first, "expected {value: NUMBER, unit: \"UNIT\"} for " + output::printable(v.name));
    r.only_keys(p, {"value", "unit"}, "parameter " + output::printable(v.name));
    v.value = r.number(r.need(p, "value", "parameter " + output::printable(v.name)), v.name);
    v.unit = r.text(r.need(p, "unit", "parameter " + output::printable(v.name)), "the unit of " + v.name);
    out.values.push_back(v);
  }
  return out;
}

void apply_fitted_parameters(SymbolicModel& model, const FittedParameters& fitted) {
  for (const auto& v : fitted.values) {
    const std::string where = fitted.path + ":" + std::to_string(v.line) + ": ";
    Variable* p = nullptr;
    for (auto& q : model.params)
      if (q.name == v.name) p = &q;
    if (!p) {
      std::vector<std::string> names;
      for (const auto& q : model.params) names.push_back(q.name);
      const std::string effects = model.effect_list(", ");
      throw VehicleError(where + "no parameter '" + output::printable(v.name) + "' in this model (effects: " +
                         (effects.empty() ? "none" : effects) + ")" + output::did_you_mean(v.name, names));
    }
    if (const std::string u = runtime::unit_problem(runtime_parameter(*p), v.unit); !u.empty())
      throw VehicleError(where + output::printable(v.name) + " " + u);
    const std::string problem = runtime::value_problem(runtime_parameter(*p), v.value, true);
    if (!problem.empty()) throw VehicleError(where + v.name + " " + problem);
    set_fitted_nominal(*p, v.value);
  }
}

}  // namespace quadgen
