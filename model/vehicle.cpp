#include "model/vehicle.hpp"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "output/names.hpp"
#include "output/numbers.hpp"
#include "model/sha256.hpp"
#include "model/yaml_reader.hpp"
#include "output/sinks.hpp"

namespace quadgen {
namespace {

// Parsing context: the generic reader (file:line errors, keys, numbers, text) and what
// only a vehicle file has.
struct Reader : YamlReader {
  double positive(const YAML::Node& n, const std::string& what) const {
    double v = number(n, what);
    if (!(v > 0)) fail(n, "expected a positive number for " + what + ", got " + n.Scalar());
    return v;
  }

  // Each entry's error says which of the three it is: a list on one line has one line number.
  Vec3 vec3(const YAML::Node& n, const std::string& what, bool must_be_positive = false) const {
    if (!n.IsSequence() || n.size() != 3) fail(n, "expected a list of 3 numbers for " + what);
    Vec3 v;
    for (int i = 0; i < 3; ++i) {
      const std::string entry = what + ", entry " + std::to_string(i + 1) + " of 3";
      v[i] = must_be_positive ? positive(n[i], entry) : number(n[i], entry);
    }
    return v;
  }

  // "block 'motor_C'" where the item's name can be read, for an error found before the name
  // is judged (an unknown key); "block" otherwise.
  static std::string item_where(const YAML::Node& n, const std::string& kind) {
    const YAML::Node name = n["name"];
    return name && name.IsScalar() ? kind + " '" + output::printable(name.Scalar()) + "'" : kind;
  }

  // A name that becomes a C++ identifier, a CSV column, a plot label and report text: one
  // rule for all of them (output/names.hpp).
  std::string name(const YAML::Node& n, const std::string& what) const {
    require_value(n, what, "a name");
    if (!n.IsScalar()) fail(n, "expected a name for " + what);
    const std::string s = n.Scalar();
    if (const auto problem = output::name_problem(s))
      fail(n, what + " '" + output::printable(s) + "': " + *problem + " (allowed: " + output::name_rule() + ")");
    return s;
  }

  // The factor from a parameter's written unit to its SI unit, which must have its dimension.
  double unit_scale(const YAML::Node& unit, const std::string& name, const Unit& si) const {
    Unit u;
    try {
      u = parse_unit(text(unit, "unit of " + name));
    } catch (const UnitError& e) {
      fail(unit, e.what());
    }
    if (u.dim != si.dim) fail(unit, "unit of " + name + " must have dimension " + si.dim.str() + ", got " + u.dim.str());
    return u.scale / si.scale;
  }

  // A parameter's bounds [lower, upper], in the value's unit (`scale` to SI), around its value.
  void read_bounds(const YAML::Node& n, double scale, Parameter& p) const {
    const std::string& name = p.name;
    const YAML::Node b = n["bounds"];
    if (!b.IsSequence() || b.size() != 2) fail(b, "expected bounds [lower, upper] for " + name);
    p.lower = number(b[0], "lower bound of " + name) * scale;
    p.upper = number(b[1], "upper bound of " + name) * scale;
    if (!(p.lower < p.upper)) fail(b, "expected lower < upper in bounds of " + name);
    if (p.nominal >= p.lower && p.nominal <= p.upper) return;
    const std::string unit = n["unit"] ? " " + n["unit"].as<std::string>() : "";
    const auto twelve_digits = [](double v) {
      std::ostringstream os;
      os.precision(12);
      os << v;
      return os.str();
    };
    fail(b, "nominal value of " + name + ", " + twelve_digits(p.nominal / scale) + unit + ", lies outside its bounds [" +
                twelve_digits(p.lower / scale) + ", " + twelve_digits(p.upper / scale) + "]" + unit +
                (unit.empty() ? "" : " (bounds are in the value's unit)"));
  }

  bool fit_flag(const YAML::Node& fit, const std::string& name) const {
    try {
      return fit.as<bool>();
    } catch (const YAML::Exception&) {
      fail(fit, "expected true or false for fit of " + name);
    }
  }

  // A parameter is either a bare number (in the SI unit) or
  // {value, unit, bounds: [lo, hi], fit: bool}.
  Parameter parameter(const YAML::Node& n, const std::string& name, const std::string& si_unit,
                      const std::string& doc) const {
    Parameter p;
    p.name = name;
    p.unit = si_unit;
    p.doc = doc;
    if (n.Mark().line >= 0) p.line = n.Mark().line + 1;
    const Unit si = parse_unit(si_unit);
    p.dim = si.dim;
    double scale = 1.0;
    require_value(n, "parameter " + name, (si_unit == "1" ? std::string("a plain number") : "a number in " + si_unit) +
                                              ", or {value, unit, bounds: [lo, hi], fit}");
    if (n.IsScalar()) {
      p.nominal = number(n, name);
    } else {
      require_map(n, "parameter " + name);
      only_keys(n, {"value", "unit", "bounds", "fit", "source"}, "parameter " + name);
      if (n["unit"]) scale = unit_scale(n["unit"], name, si);
      p.nominal = number(need(n, "value", "parameter " + name), name) * scale;
      if (scale != 1.0) p.as_written = n["value"].Scalar() + " " + n["unit"].Scalar();
      if (n["bounds"]) read_bounds(n, scale, p);
      if (n["fit"]) p.fit = fit_flag(n["fit"], name);
      if (p.fit && !n["bounds"]) fail(n, "parameter " + name + " is to be fitted but has no bounds");
    }
    if (p.lower == 0 && p.upper == 0) {  // no bounds given: the nominal value only
      p.lower = p.upper = p.nominal;
    }
    return p;
  }
};

Block read_block(const Reader& r, const YAML::Node& n) {
  r.require_map(n, "a block");
  r.only_keys(n, {"name", "mass", "size", "centre", "orientation_deg", "source"}, Reader::item_where(n, "block"));
  Block b;
  b.line = n.Mark().line + 1;
  b.name = r.name(r.need(n, "name", "block"), "block name");
  const std::string where = "block '" + b.name + "'";
  b.mass = r.positive(r.need(n, "mass", where), "mass of " + where + " [kg]");
  b.size = r.vec3(r.need(n, "size", where), "size of " + where + " [m]", true);
  b.centre = r.vec3(r.need(n, "centre", where), "centre of " + where + " [m]");
  if (n["orientation_deg"]) {
    b.yaw_pitch_roll_deg = r.vec3(n["orientation_deg"], "orientation of " + where + " [yaw, pitch, roll in deg]");
    // An angle of 1e300 deg passed and turned the block by whatever sin(1e300) rounds to (a
    // review, helper-135): beyond a whole turn an angle is a mistyped number.
    for (double angle : b.yaw_pitch_roll_deg)
      if (!(std::fabs(angle) <= 360))
        r.fail(n["orientation_deg"], "orientation of " + where + ": " + output::six_digits(angle) +
                                         " deg, expected each angle within +-360 deg");
  }
  return b;
}

Rotor read_rotor(const Reader& r, const YAML::Node& n) {
  r.require_map(n, "a rotor");
  // A block may be turned (orientation_deg), so a user may try it on a rotor: say why not.
  for (const char* tilt : {"orientation_deg", "axis", "tilt", "tilt_deg"})
    if (n[tilt])
      r.fail(n[tilt], std::string("a rotor takes no '") + tilt +
                          "': every rotor's thrust acts along body +z (tilted rotors are not modelled; README, Scope)");
  r.only_keys(n, {"name", "position", "spin", "radius", "disc_area", "source"}, Reader::item_where(n, "rotor"));
  Rotor ro;
  ro.line = n.Mark().line + 1;
  ro.name = r.name(r.need(n, "name", "rotor"), "rotor name");  // also the CSV column u_<name>
  const std::string where = "rotor '" + ro.name + "'";
  ro.position = r.vec3(r.need(n, "position", where), "position of " + where + " [m]");
  const std::string spin = r.text(r.need(n, "spin", where), "spin of " + where);
  if (spin == "ccw") ro.spin = Spin::ccw;
  else if (spin == "cw") ro.spin = Spin::cw;
  else r.fail(n["spin"], "expected spin 'ccw' or 'cw' (seen from above) for " + where + ", got '" + spin + "'");
  ro.radius = r.positive(r.need(n, "radius", where), "radius of " + where + " [m]");
  ro.disc_area = r.positive(r.need(n, "disc_area", where), "disc_area of " + where + " [m^2]");
  return ro;
}

// One parameter a section may hold. A struct, not a row of strings: a row with an item
// missing once put c_t's doc text in the "required" slot, so a file without c_t parsed.
struct SectionKey {  // one key a vehicle section may hold
  std::string key, unit;  // unit: SI, what the value is converted to
  bool required;
  std::string doc;
};

void read_section(const Reader& r, const YAML::Node& root, Vehicle& v, const std::string& section,
                  const std::vector<SectionKey>& specs) {
  const YAML::Node s = root[section];
  if (!s) r.fail(root, "missing section '" + section + "'");
  r.require_map(s, "section '" + section + "'");
  std::set<std::string> keys{"source"};
  for (const auto& sp : specs) keys.insert(sp.key);
  r.only_keys(s, keys, "section '" + section + "'");
  for (const auto& sp : specs) {
    if (!s[sp.key]) {
      if (sp.required) r.fail(s, "missing key '" + sp.key + "' in section '" + section + "'");
      continue;
    }
    v.params[sp.key] = r.parameter(s[sp.key], sp.key, sp.unit, sp.doc);
    // Judged as --set and --params judge a value from outside (a review, helper-88: a vbat_ref
    // of 0 ended in GiNaC's "division by zero" without a line).
    const auto& p = v.params[sp.key];
    if (const std::string problem = runtime::value_problem(runtime_parameter(p), p.nominal, false); !problem.empty())
      r.fail(s[sp.key].IsMap() && s[sp.key]["value"] ? s[sp.key]["value"] : s[sp.key], sp.key + " " + problem);
  }
}

}  // namespace


namespace {
Vehicle parse_vehicle_checked(const std::string& content, const std::string& path);
}

// yaml-cpp reports type mismatches anywhere in a document by exception; each becomes a
// one-line error with its position rather than escaping to the caller.
Vehicle parse_vehicle(const std::string& content, const std::string& path) {
  try {
    return parse_vehicle_checked(content, path);
  } catch (const YAML::Exception& e) {
    throw VehicleError(path + ":" + std::to_string(e.mark.line + 1) +
                       ": unexpected YAML structure: " + output::printable(e.msg));
  }
}

namespace {
// The sections of named parameters: environment, frame, rotor model, motor map (with its
// optional slope and pivot, which go together) and battery (4 V when absent).
void read_parameter_sections(const Reader& r, const YAML::Node& root, Vehicle& v) {
  read_section(r, root, v, "environment",
               {{"g", "m/s^2", true, "gravitational acceleration"}, {"rho", "kg/m^3", true, "air density"}});
  read_section(r, root, v, "frame", {{"c_w", "1", true, "drag coefficient of the frame"}});
  read_section(r, root, v, "rotor_model",
               {{"c_t", "1", true, "thrust coefficient of F = c_t rho A_p (omega r_p)^2"},
                {"kappa", "m", true, "yaw torque per thrust, Q = kappa F (a flight measures kappa / J_zz)"}});
  read_section(r, root, v, "motor_map",
               {{"a0", "rad/s", true, "the motor map's speed at command 0 (its constant term)"},
                {"a1", "rad/s", true, "rotor speed per command"},
                {"a2", "rad/s", true, "rotor speed per command squared"},
                {"slope", "1", false, "slope of the rotor speed over the command at the pivot, relative to a0..a2's"},
                {"pivot", "1", false, "command about which `slope` turns the map (its speed there is kept)"}});
  if (v.params.count("slope") != v.params.count("pivot"))
    r.fail(root["motor_map"], "motor_map: 'slope' and 'pivot' go together (the slope turns the map about the pivot)");
  if (v.params.count("slope")) {
    const Parameter& slope = v.params.at("slope");
    if (!(slope.nominal > 0 && slope.lower > 0))
      r.fail(root["motor_map"]["slope"], "motor_map: 'slope' and its lower bound must be positive (a map whose speed falls "
                                         "as the command rises)");
    const double pivot = v.params.at("pivot").nominal;
    if (!(pivot >= 0 && pivot <= 1))
      r.fail(root["motor_map"]["pivot"], "motor_map: 'pivot' is a command, expected 0..1, got " + output::six_digits(pivot));
  }
  if (root["battery"])
    read_section(r, root, v, "battery", {{"vbat_ref", "V", true, "reference battery voltage"}});
  else
    v.params["vbat_ref"] = Parameter{{"vbat_ref", "V", parse_unit("V").dim, 4.0, 4.0, 4.0, false,
                                      "reference battery voltage", ""}};
}

// A non-empty list of blocks or rotors (`what`), each read by `read` and named once.
template <class Item, class ReadItem>
std::vector<Item> read_named_list(const Reader& r, const YAML::Node& root, const char* key, const std::string& what,
                                  ReadItem read, size_t most) {
  const YAML::Node list = r.need(root, key, "the vehicle file");
  if (!list.IsSequence() || list.size() == 0) r.fail(list, "expected a non-empty list of " + std::string(key));
  if (list.size() > most)
    r.fail(list, std::to_string(list.size()) + " " + key + ": at most " + std::to_string(most) +
                     " are derived (each adds equations and parameters; beyond this the derivation takes minutes)");
  std::vector<Item> items;
  std::set<std::string> names;
  for (const auto& node : list) {
    items.push_back(read(r, node));
    if (!names.insert(items.back().name).second)
      r.fail(node["name"], "duplicate " + what + " name '" + items.back().name + "'");
  }
  return items;
}

// `derived:` — each quantity the blocks give (mass, inertia, areas) either with bounds (and
// whether it may be fitted) or with a measured value that replaces the blocks'.
void read_derived(const Reader& r, const YAML::Node& d, Vehicle& v) {
  r.require_map(d, "section 'derived'");
  std::map<std::string, std::string> derived_units;  // name -> unit
  for (const DerivedQuantity& q : kDerivedQuantities) derived_units[q.name] = q.unit;
  std::set<std::string> allowed;
  for (const auto& kv : derived_units) allowed.insert(kv.first);
  r.only_keys(d, allowed, "section 'derived'");
  for (const auto& kv : d) {
    const std::string key = kv.first.as<std::string>();
    const YAML::Node spec = kv.second;
    r.require_map(spec, "fit and bounds (or a value) of derived quantity " + key);
    r.only_keys(spec, {"fit", "bounds", "value", "unit", "source"}, "derived quantity " + key);
    if (spec["value"]) {  // given: it replaces the blocks' value
      v.derived_overrides[key] = r.parameter(spec, key, derived_units.at(key), "");
      v.derived_given.insert(key);
      // As --set and --params judge a value from outside (a mass of 0 passed the audit, and the
      // trim blamed a motor map in rpm; a J_zz of 0 diverged in simulate).
      const double value = v.derived_overrides[key].nominal;
      if (const std::string problem = runtime::value_problem(runtime_parameter(v.derived_overrides[key]), value, false);
          !problem.empty())
        r.fail(spec["value"], "derived quantity " + key + " " + problem);
    } else {
      if (!spec["bounds"]) r.fail(spec, "derived quantity " + key + " needs bounds (or a value)");
      if (spec["unit"]) r.fail(spec["unit"], "derived quantity " + key + ": a unit belongs to a value");
      // The nominal value comes from the blocks; parse bounds via a dummy value inside them.
      YAML::Node tmp;
      tmp["value"] = spec["bounds"][0];
      tmp["bounds"] = spec["bounds"];
      if (spec["fit"]) tmp["fit"] = spec["fit"];
      v.derived_overrides[key] = r.parameter(tmp, key, derived_units.at(key), "");
    }
    v.derived_overrides[key].line = kv.first.Mark().line + 1;
  }
}

Vehicle parse_vehicle_checked(const std::string& content, const std::string& path) {
  Reader r{{path, {}}};
  const YAML::Node root = r.parse(content);
  if (!root || root.IsNull()) throw VehicleError(path + ":1: empty vehicle file");
  r.require_map(root, "a vehicle description");
  r.only_keys(root, {"name", "description", "environment", "frame", "rotor_model", "motor_map",
                     "battery", "blocks", "rotors", "derived", "fitted"},
              "the vehicle file");
  Vehicle v;
  if (root["fitted"]) v.fitted_line = root["fitted"].Mark().line + 1;
  v.source_path = path;
  v.content_hash = sha256_hex(content);
  v.source_text = content;
  const YAML::Node name = r.need(root, "name", "the vehicle file");
  v.name = r.name(name, "vehicle name");
  if (const auto problem = output::vehicle_name_problem(v.name)) r.fail(name, "vehicle name '" + v.name + "': " + *problem);
  if (root["description"]) v.description = r.text(root["description"], "description");
  read_parameter_sections(r, root, v);
  v.blocks = read_named_list<Block>(r, root, "blocks", "block", read_block, kMaxBlocks);
  v.rotors = read_named_list<Rotor>(r, root, "rotors", "rotor", read_rotor, kMaxRotors);
  if (root["derived"]) read_derived(r, root["derived"], v);
  return v;
}
}  // namespace

Vehicle load_vehicle(const std::string& path) { return parse_vehicle(YamlReader{path, {}}.read_file("vehicle file"), path); }

std::string fitted_section_note(const Vehicle& v, const std::string& command) {
  if (v.fitted_line == 0) return "";
  std::string note = "note: " + output::printable(v.source_path) + ":" + std::to_string(v.fitted_line) +
                     ": its `fitted:` section is read only by `quadgen derive`; " + command +
                     " uses the file's own values";
  if (command == "predict") note += " (to predict with a diagnosis' values, pass its diagnosis.json with --params)";
  if (command == "simulate") note += " (to fly other values, give them with --set)";
  return note;
}

std::vector<std::string> rotor_names(const Vehicle& v) {
  std::vector<std::string> names;
  for (const Rotor& r : v.rotors) names.push_back(r.name);
  return names;
}

const Parameter& param(const Vehicle& v, const std::string& name) {
  auto it = v.params.find(name);
  if (it == v.params.end()) throw VehicleError(v.source_path + ": no parameter '" + name + "'");
  return it->second;
}

}  // namespace quadgen
