#include "codegen/header_writer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include <kainjow/mustache.hpp>

#include "codegen/cpp_printer.hpp"
#include "codegen/lowered_model.hpp"
#include "derive/exact_number.hpp"
#include "output/joined.hpp"
#include "output/names.hpp"
#include "output/sinks.hpp"
#include "derive/effects/effect_catalogue.hpp"
#include "model/sha256.hpp"
#include "model/vehicle.hpp"
#include "output/fnv1a.hpp"

extern const char* const kModelHeaderTemplate;  // templates/model.hpp.mustache, embedded by CMake

namespace quadgen::codegen {
using namespace GiNaC;
using kainjow::mustache::data;
using kainjow::mustache::list;
using kainjow::mustache::mustache;

namespace {

// A variable's enumerator: its name with '.' (effect parameters) as '_', checked to be an
// identifier whatever the vehicle parser let through.
std::string ident(const std::string& name) {
  std::string s;
  for (char c : name) s += (c == '.' ? '_' : c);
  return output::checked_cpp_identifier(s, "generated name");
}

std::string quoted_list(const std::vector<Variable>& vs) {
  return "{" + output::joined(vs, ", ", [](const Variable& v) { return output::cpp_string_literal(v.name); }) + "}";
}

// A nominal value as C++: never "inf" or "nan", identifiers the including project may define.
std::string number(double v) {
  if (!std::isfinite(v))
    throw std::domain_error("generated code: a nominal value is not finite (" + std::to_string(v) +
                            "): the vehicle's numbers overflow a double");
  return shortest_text(v);
}

// A bound as a C++ constant: an infinite one (no bound) is HUGE_VAL from <cmath>.
std::string bound(double v) {
  if (std::isinf(v)) return v > 0 ? "HUGE_VAL" : "-HUGE_VAL";
  return number(v);
}

data variables(const std::vector<Variable>& vs) {
  list l;
  for (size_t i = 0; i < vs.size(); ++i) {
    data d;
    d.set("ident", ident(vs[i].name));
    d.set("index", std::to_string(i));
    d.set("name", output::cpp_comment(vs[i].name));
    d.set("unit", output::cpp_comment(vs[i].unit));
    d.set("doc", output::cpp_comment(vs[i].doc));
    l.push_back(d);
  }
  return data{l};
}

std::string int_list(const std::vector<int>& v) {
  return "{" + output::joined(v, ", ", [](int i) { return std::to_string(i); }) + (v.empty() ? "0}" : "}");
}

}  // namespace

void set_provenance_fields(kainjow::mustache::data& d, const Provenance& p) {
  // Everything from a vehicle file or the command line goes through the sink's escaping:
  // comments cannot end early or splice the next line, literals cannot end early.
  // The regenerate command is one a reader may paste into a shell: the path is one quoted
  // word, and where the comment cannot hold it as it is (bytes outside printable ASCII, '%'
  // escaped as %XX) a placeholder stands for it rather than a path that names another file.
  const std::string word = output::shell_path(p.vehicle_file);
  d.set("vehicle_file", output::cpp_comment(word) == word ? word : std::string("VEHICLE_FILE"));
  // (Only a --params path can make the flags unprintable: effect names are the catalogue's.)
  const bool flag_as_is = output::cpp_comment(p.regenerate_flags) == p.regenerate_flags;
  d.set("regenerate_flags", flag_as_is ? p.regenerate_flags : std::string(" --params PARAMETERS_FILE"));
  d.set("vehicle", output::cpp_comment(p.vehicle_name));
  d.set("vehicle_hash", output::cpp_comment(p.vehicle_hash));
  d.set("vehicle_hash_literal", output::cpp_string_literal(p.vehicle_hash));
  d.set("effects", output::cpp_comment(p.effects_text));
  d.set("effects_list", output::cpp_string_literal(p.effects_list));
}

std::string model_name(const SymbolicModel& m) {
  std::string s = m.vehicle_name;
  if (m.effects.size() == effect_catalogue().size()) s += output::kAllEffectsSuffix;
  else if (!m.effects.empty()) s += output::kEffectsInfix;
  if (m.effects.size() != effect_catalogue().size())
    for (const auto& e : m.effects) s += "_" + e;
  if (const auto problem = output::vehicle_name_problem(m.vehicle_name))
    throw std::invalid_argument("vehicle name '" + output::printable(m.vehicle_name) + "': " + *problem);
  return output::checked_cpp_identifier(s, "model namespace");
}

namespace {

// The op counts and sizes the header prints in its comment and declares as constants.
void set_counts(data& d, const SymbolicModel& m, const GeneratedHeader& out) {
  d.set("ops_f_before", std::to_string(std::llround(out.ops_f_before)));
  d.set("ops_f_after", std::to_string(std::llround(out.ops_f_after)));
  d.set("ops_before", std::to_string(std::llround(out.ops_before)));
  d.set("ops_after", std::to_string(std::llround(out.ops_after)));
  d.set("ops_speeds_after", std::to_string(std::llround(out.ops_speeds_after)));
  d.set("pre_ops", std::to_string(std::llround(out.pre_ops)));
  d.set("pre_count", std::to_string(out.pre_count));
  d.set("n_states", std::to_string(m.states.size()));
  d.set("n_inputs", std::to_string(m.inputs.size()));
  d.set("n_params", std::to_string(m.params.size()));
  d.set("n_outputs", std::to_string(m.outputs.size()));
  d.set("pre_size", std::to_string(out.pre_count));
  std::vector<int> speed_rows(m.rotor_speed_states.begin(), m.rotor_speed_states.end());
  d.set("n_rotor_speed_states", std::to_string(speed_rows.size()));
  d.set("rotor_speed_states", int_list(speed_rows));
}

// Names, nominal values, units, bounds and fit flags, one array entry per variable.
void set_variable_tables(data& d, const SymbolicModel& m) {
  d.set("states", variables(m.states));
  d.set("inputs", variables(m.inputs));
  d.set("params", variables(m.params));
  d.set("outputs", variables(m.outputs));
  d.set("state_names", quoted_list(m.states));
  d.set("input_names", quoted_list(m.inputs));
  d.set("param_names", quoted_list(m.params));
  d.set("output_names", quoted_list(m.outputs));
  const auto table = [](const std::vector<Variable>& vs, auto entry) {
    return "{" + output::joined(vs, ", ", entry) + "}";
  };
  d.set("nominal_params", table(m.params, [](const Variable& v) { return number(v.nominal); }));
  d.set("param_units", table(m.params, [](const Variable& v) { return output::cpp_string_literal(v.unit); }));
  d.set("param_lower", table(m.params, [](const Variable& v) { return bound(v.lower); }));
  d.set("param_upper", table(m.params, [](const Variable& v) { return bound(v.upper); }));
  d.set("param_fit", table(m.params, [](const Variable& v) { return std::string(v.fit ? "true" : "false"); }));
  d.set("input_delay_param", m.input_delay_param ? std::to_string(*m.input_delay_param) : std::string("-1"));
  d.set("n_constants", std::to_string(m.constants.size()));
  d.set("constant_names", quoted_list(m.constants));
  d.set("constant_values", table(m.constants, [](const Variable& v) { return number(v.nominal); }));
}

// v rounded to `digits` significant digits, as printf's %g prints it.
double to_significant_digits(double v, int digits) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return std::strtod(buf, nullptr);
}

std::string trim_number(double v) { return number(declared_trim_value(v)); }

// A rotor speed at the trim to 15 significant digits (declared_trim_value says why).
std::string speed_number(double v) { return number(to_significant_digits(v, 15)); }

// The rotors' spins and the hover trim (EmitOptions), where the caller gives them.
void set_rotor_facts(data& d, const EmitOptions& opt, size_t rotor_speed_states) {
  const size_t n = opt.rotor_spin.size();
  d.set("has_rotors", data(n > 0));
  const bool trimmed = opt.hover_command.size() == n && opt.hover_thrust.size() == n && n > 0;
  std::string spin = "{", command = "{", thrust = "{";
  for (size_t i = 0; i < n; ++i) {
    const std::string sep = i ? ", " : "";
    spin += sep + std::to_string(opt.rotor_spin[i]);
    command += sep + (trimmed ? trim_number(opt.hover_command[i]) : "0");
    thrust += sep + (trimmed ? trim_number(opt.hover_thrust[i]) : "0");
  }
  d.set("n_rotors", std::to_string(n));
  d.set("rotor_spin", spin + "}");
  d.set("hover_command", command + "}");
  d.set("hover_thrust", thrust + "}");
  d.set("has_hover_trim", trimmed ? "true" : "false");
  // As many as the model has rotor-speed states (one unused 0 where it has none).
  const bool speeds = trimmed && rotor_speed_states > 0 && opt.hover_rotor_speed.size() == rotor_speed_states;
  std::string speed = "{";
  for (size_t i = 0; i < std::max<size_t>(1, rotor_speed_states); ++i)
    speed += (i ? ", " : "") + (speeds ? speed_number(opt.hover_rotor_speed[i]) : "0");
  d.set("hover_rotor_speed", speed + "}");
  d.set("hover_trim_line",
        trimmed ? (opt.hover_note.empty() ? std::string() : "// Hover trim: " + output::cpp_comment(opt.hover_note) + ".\n")
                : "// No hover trim: " + output::cpp_comment(opt.why_no_hover.empty() ? "not given" : opt.why_no_hover) + ".\n");
}

// Each Jacobian's sparsity pattern (row and column of every stored entry).
void set_sparsity(data& d, const LoweredModel& lm) {
  list sparsity;
  const std::pair<const char*, const SparsePattern*> sp[] = {
      {"Dfdx", &lm.dfdx}, {"Dfdu", &lm.dfdu}, {"Dfdp", &lm.dfdp}, {"Dhdx", &lm.dhdx}, {"Dhdp", &lm.dhdp}};
  for (const auto& [name, s] : sp) {
    data e;
    e.set("name", name);
    e.set("nnz", std::to_string(s->rows.size()));
    e.set("size", std::to_string(std::max<size_t>(1, s->rows.size())));
    e.set("rows", int_list(s->rows));
    e.set("cols", int_list(s->cols));
    sparsity.push_back(e);
  }
  d.set("sparsity", data{sparsity});
}

}  // namespace

double declared_trim_value(double v) { return to_significant_digits(v, 12); }

GeneratedHeader generate_header(const SymbolicModel& m, const EmitOptions& opt) {
  const LoweredModel lm = lower_model(m);
  const PrintedFunction pre = print_cpp(*lm.plan, lm.precompute);
  const PrintedFunction f_only = print_cpp(*lm.plan, lm.rhs_f);
  const PrintedFunction speeds = print_cpp(*lm.plan, lm.rotor_speed_rates);
  const PrintedFunction rhs_code = print_cpp(*lm.plan, lm.rhs);
  const PrintedFunction meas_code = print_cpp(*lm.plan, lm.measurement);

  GeneratedHeader out;
  out.name = model_name(m);
  out.ops_before = rhs_code.ops_before;
  out.ops_after = rhs_code.ops_after;
  out.ops_f_before = f_only.ops_before;
  out.ops_f_after = f_only.ops_after;
  out.ops_speeds_after = speeds.ops_after;
  out.pre_ops = pre.ops_after;
  out.pre_count = lm.plan->precompute_count();

  data d;
  d.set("namespace", out.name);
  d.set("version", QUADGEN_VERSION);
  set_provenance_fields(d, {m.vehicle_name, m.vehicle_hash, m.effects.empty() ? "none" : m.effect_list(", "),
                            m.effect_list(), opt.vehicle_file, opt.regenerate_flags});
  // A whole comment line or nothing (a mustache section would leave an empty line).
  d.set("parameter_source_line", opt.parameter_source.empty() ? std::string()
                                 : "// Parameter values (kNominalParams): " + output::cpp_comment(opt.parameter_source) + ".\n");
  d.set("options_hash", output::fnv1a_hex(m.vehicle_hash + "|" + m.effect_list(", ") + "|" + QUADGEN_VERSION));
  set_counts(d, m, out);
  set_variable_tables(d, m);
  set_sparsity(d, lm);
  set_rotor_facts(d, opt, m.rotor_speed_states.size());
  // The comment's notes that hold only with an effect or an input of the model.
  d.set("has_ground_effect", data(std::find(m.effects.begin(), m.effects.end(), "ground_effect") != m.effects.end()));
  d.set("has_vbat", data(std::any_of(m.inputs.begin(), m.inputs.end(), [](const Variable& v) { return v.name == "vbat"; })));
  d.set("has_rotor_speed_states", data(!m.rotor_speed_states.empty()));
  d.set("precompute_body", pre.body);
  d.set("rhs_body", rhs_code.body);
  d.set("rhs_f_body", f_only.body);
  d.set("rotor_speed_rates_body", speeds.body);
  d.set("measurement_body", meas_code.body);
  mustache tmpl{std::string(kModelHeaderTemplate)};
  if (!tmpl.is_valid()) throw std::runtime_error("templates/model.hpp.mustache: " + tmpl.error_message());
  // The inline namespace's name: a hash of the code (from the namespace on: not the opening
  // comment block, which names the path the vehicle file was read from). Rendered once without
  // it to hash, then with it (a text replacement would also hit a vehicle's or rotor's name).
  d.set("code_tag", std::string());
  const std::string untagged = tmpl.render(d);
  // At a line's start: a vehicle file's path in the regenerate comment may hold the words too
  // (a review, helper-88).
  const size_t code = untagged.find("\nnamespace quadgen_generated {");
  if (code == std::string::npos) throw std::logic_error("templates/model.hpp.mustache: no namespace quadgen_generated");
  // SHA-256 cut to 128 bits, not FNV-1a: an edited copy made to collide with another model's
  // tag (about 2^32 tries of a comment with a 64-bit FNV) would link as that model (a review,
  // helper-88).
  d.set("code_tag", "model_" + sha256_hex(untagged.substr(code)).substr(0, 32));
  out.content = tmpl.render(d);
  return out;
}

}  // namespace quadgen::codegen
