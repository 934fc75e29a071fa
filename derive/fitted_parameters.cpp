#include "fitted_parameters.hpp"

#include <cmath>
#include <fstream>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "effects.hpp"
#include "vehicle.hpp"

namespace quadgen {

namespace {

[[noreturn]] void fail(const std::string& path, const YAML::Node& at, const std::string& what) {
  const int line = at.Mark().line >= 0 ? at.Mark().line + 1 : 1;
  throw VehicleError(path + ":" + std::to_string(line) + ": " + what);
}

}  // namespace

FittedParameters load_fitted_parameters(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw VehicleError(path + ": cannot open fitted parameters");
  std::ostringstream text;
  text << in.rdbuf();
  YAML::Node root;
  try {
    root = YAML::Load(text.str());
  } catch (const YAML::Exception& e) {
    throw VehicleError(path + ":" + std::to_string(e.mark.line + 1) + ": malformed YAML: " + e.msg);
  }
  FittedParameters out;
  out.path = path;
  if (!root.IsMap()) throw VehicleError(path + ":1: expected 'effects' and 'parameters' (a fitted_parameters.yaml)");
  for (const auto& kv : root) {
    const std::string key = kv.first.as<std::string>("");
    if (key != "effects" && key != "parameters") fail(path, kv.first, "unknown key '" + key + "' (expected effects, parameters)");
  }
  const YAML::Node effects = root["effects"], params = root["parameters"];
  if (!effects || !effects.IsSequence()) fail(path, root, "expected a list 'effects' (may be empty: [])");
  try {
    for (const auto& e : effects) out.effects.push_back(find_effect(e.as<std::string>()).name);
  } catch (const std::invalid_argument& e) {
    fail(path, effects, e.what());
  } catch (const YAML::Exception&) {
    fail(path, effects, "expected effect names");
  }
  if (!params || !params.IsMap()) fail(path, root, "expected a map 'parameters' of name: {value, unit}");
  for (const auto& kv : params) {
    FittedValue v;
    v.name = kv.first.as<std::string>("");
    v.line = kv.first.Mark().line + 1;
    const YAML::Node& p = kv.second;
    if (!p.IsMap() || !p["value"] || !p["unit"]) fail(path, kv.first, "expected {value: NUMBER, unit: \"UNIT\"} for " + v.name);
    try {
      v.value = p["value"].as<double>();
      v.unit = p["unit"].as<std::string>();
    } catch (const YAML::Exception&) {
      fail(path, p, "expected {value: NUMBER, unit: \"UNIT\"} for " + v.name);
    }
    if (!std::isfinite(v.value)) fail(path, p, "the value of " + v.name + " is not finite");
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
    if (!p) throw VehicleError(where + "no parameter '" + v.name + "' in this model (effects: " + model.effect_list(", ") + ")");
    if (v.unit != p->unit) throw VehicleError(where + v.name + " is in " + p->unit + ", the file says " + v.unit);
    if (p->lower < p->upper && (v.value < p->lower || v.value > p->upper)) {
      std::ostringstream os;
      os << where << v.name << " = " << v.value << " is outside its bounds [" << p->lower << ", " << p->upper << "]";
      throw VehicleError(os.str());
    }
    p->nominal = v.value;
  }
}

}  // namespace quadgen
