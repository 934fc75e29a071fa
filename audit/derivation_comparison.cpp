#include "audit/derivation_comparison.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <sstream>

#include "derive/exact_number.hpp"
#include "output/joined.hpp"
#include "output/numbers.hpp"
#include "output/sinks.hpp"

namespace quadgen {

namespace {

template <class T, class Name>
std::vector<std::string> names_of(const std::vector<T>& items, Name name) {
  std::vector<std::string> out;
  for (const auto& x : items) out.push_back(name(x));
  return out;
}

const auto name_of = [](const auto& x) { return x.name; };

std::vector<std::string> only_in_first(const std::vector<std::string>& a, const std::vector<std::string>& b) {
  std::vector<std::string> out;
  for (const auto& x : a)
    if (std::find(b.begin(), b.end(), x) == b.end()) out.push_back(x);
  return out;
}

// Where both lists hold the same names in another order: "what: a, b -> b, a" (the names both
// have, each list's order). The generated arrays follow the order.
void compare_order(const std::string& what, const std::vector<std::string>& a, const std::vector<std::string>& b,
                   std::vector<std::string>& out) {
  std::vector<std::string> in_a, in_b;
  for (const auto& x : a)
    if (std::find(b.begin(), b.end(), x) != b.end()) in_a.push_back(x);
  for (const auto& x : b)
    if (std::find(a.begin(), a.end(), x) != a.end()) in_b.push_back(x);
  if (in_a != in_b) out.push_back(what + ": " + output::joined(in_a) + " -> " + output::joined(in_b));
}

// Exactly equal, or both NaN: a vehicle file's numbers are compared as read, not as rounded.
bool same_number(double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); }

std::string a_to_b(double a, double b) { return output::one_then_other(a, b, " -> "); }

// What differs between two things of one name: "mass 0.02 -> 0.025 kg", one part each.
struct Differences {
  std::vector<std::string> parts;
  void number(const std::string& what, double a, double b, const std::string& unit) {
    if (!same_number(a, b)) parts.push_back(what + " " + a_to_b(a, b) + unit);
  }
  // Component by component, only those that differ: "position x -0.07465 -> -0.08 m".
  void vector(const std::string& what, const Vec3& a, const Vec3& b, const std::array<const char*, 3>& axes,
              const std::string& unit) {
    for (size_t i = 0; i < 3; ++i) number(what + " " + axes[i], a[i], b[i], unit);
  }
  void text(const std::string& what, const std::string& a, const std::string& b) {
    if (a != b) parts.push_back(what + " " + a + " -> " + b);
  }
};

// For each name in both lists: what differs, as "name: part; part".
template <class T, class Describe>
std::vector<std::string> changed(const std::vector<T>& a, const std::vector<T>& b, Describe describe) {
  std::vector<std::string> out;
  for (const auto& x : a)
    for (const auto& y : b) {
      if (x.name != y.name) continue;
      Differences d;
      describe(x, y, d);
      if (!d.parts.empty()) out.push_back(x.name + ": " + output::joined(d.parts, "; "));
    }
  return out;
}

constexpr std::array<const char*, 3> kXyz{"x", "y", "z"}, kYawPitchRoll{"yaw", "pitch", "roll"};

void compare_vehicles(const Vehicle& a, const Vehicle& b, DerivationComparison& c) {
  c.vehicle_name_a = a.name, c.vehicle_name_b = b.name;
  c.blocks_only_a = only_in_first(names_of(a.blocks, name_of), names_of(b.blocks, name_of));
  c.blocks_only_b = only_in_first(names_of(b.blocks, name_of), names_of(a.blocks, name_of));
  c.blocks_changed = changed(a.blocks, b.blocks, [](const Block& x, const Block& y, Differences& d) {
    d.number("mass", x.mass, y.mass, " kg");
    d.vector("size", x.size, y.size, kXyz, " m");
    d.vector("centre", x.centre, y.centre, kXyz, " m");
    d.vector("orientation", x.yaw_pitch_roll_deg, y.yaw_pitch_roll_deg, kYawPitchRoll, " deg");
  });
  c.rotors_only_a = only_in_first(names_of(a.rotors, name_of), names_of(b.rotors, name_of));
  c.rotors_only_b = only_in_first(names_of(b.rotors, name_of), names_of(a.rotors, name_of));
  c.rotors_changed = changed(a.rotors, b.rotors, [](const Rotor& x, const Rotor& y, Differences& d) {
    d.vector("position", x.position, y.position, kXyz, " m");
    d.text("spin", x.spin == Spin::ccw ? "ccw" : "cw", y.spin == Spin::ccw ? "ccw" : "cw");
    d.number("radius", x.radius, y.radius, " m");
    d.number("disc area", x.disc_area, y.disc_area, " m^2");
  });
}

void compare_parameters(const SymbolicModel& a, const SymbolicModel& b, DerivationComparison& c) {
  for (const auto& p : a.params)
    for (const auto& q : b.params) {
      if (p.name != q.name) continue;
      if (!same_number(p.nominal, q.nominal)) c.parameter_values.push_back({p.name, p.unit, p.nominal, q.nominal});
      Differences d;
      d.text("unit", p.unit, q.unit);
      // A parameter held on both sides has its value as its bounds: said with the value.
      const bool held = p.lower == p.upper && q.lower == q.upper;
      if (!held) d.number("lower bound", p.lower, q.lower, "");
      if (!held) d.number("upper bound", p.upper, q.upper, "");
      d.text("fitted", p.fit ? "yes" : "no", q.fit ? "yes" : "no");
      if (!d.parts.empty()) c.parameter_settings.push_back(p.name + ": " + output::joined(d.parts, "; "));
    }
  for (const auto& k : a.constants)
    for (const auto& l : b.constants)
      if (k.name == l.name && !same_number(k.nominal, l.nominal)) c.constants.push_back({k.name, k.unit, k.nominal, l.nominal});
  c.constants_only_a = only_in_first(names_of(a.constants, name_of), names_of(b.constants, name_of));
  c.constants_only_b = only_in_first(names_of(b.constants, name_of), names_of(a.constants, name_of));
}

// One list of the generated code's (states, inputs, parameters, outputs): the names one side
// alone has, and the order of those both have.
void compare_list(const std::string& what, const std::vector<Variable>& a, const std::vector<Variable>& b,
                  std::vector<std::string>& only_a, std::vector<std::string>& only_b, DerivationComparison& c) {
  const auto na = names_of(a, name_of), nb = names_of(b, name_of);
  only_a = only_in_first(na, nb);
  only_b = only_in_first(nb, na);
  compare_order(what, na, nb, c.order_changes);
}

void compare_structure(const SymbolicModel& a, const SymbolicModel& b, DerivationComparison& c) {
  c.effects_only_a = only_in_first(a.effects, b.effects);
  c.effects_only_b = only_in_first(b.effects, a.effects);
  compare_list("states", a.states, b.states, c.states_only_a, c.states_only_b, c);
  compare_list("inputs", a.inputs, b.inputs, c.inputs_only_a, c.inputs_only_b, c);
  compare_list("parameters", a.params, b.params, c.parameters_only_a, c.parameters_only_b, c);
  compare_list("outputs", a.outputs, b.outputs, c.outputs_only_a, c.outputs_only_b, c);
}

std::set<std::string> symbol_names(const GiNaC::ex& e) {
  std::set<std::string> out;
  for (auto i = e.preorder_begin(); i != e.preorder_end(); ++i)
    if (GiNaC::is_a<GiNaC::symbol>(*i)) out.insert(GiNaC::ex_to<GiNaC::symbol>(*i).get_name());
  return out;
}

// One random point: an exact rational for every state, input and parameter name either model
// has (the same under one name in both). States and inputs are +-(0.5 .. 1.5), the sign drawn
// too, so that |v| and sign branches are met both ways; parameters keep their nominal sign and
// order (0.5 .. 1.5 times it), so that roots of positive quantities stay real and denominators
// away from their poles; one whose nominal value is 0 (an effect's neutral value, a product
// of inertia) is drawn inside its bounds, a quarter to three quarters of the way up, or is 1
// without finite bounds. Constants are each model's own (their differences are the geometry's).
// The engine's raw draws, not a distribution's, keep the points the same on every standard library.
std::map<std::string, GiNaC::numeric> random_point(const SymbolicModel& a, const SymbolicModel& b, std::mt19937& rng) {
  const auto factor = [&] { return GiNaC::numeric(static_cast<long>(32 + rng() % 65), 64); };
  const auto parameter = [&](const Variable& p) {
    if (p.nominal != 0) return factor() * exact(p.nominal);
    if (!(std::isfinite(p.lower) && std::isfinite(p.upper) && p.lower < p.upper)) return GiNaC::numeric(1);
    return exact(p.lower) + factor() / 2 * (exact(p.upper) - exact(p.lower));
  };
  std::map<std::string, GiNaC::numeric> out;
  for (const auto* m : {&a, &b}) {
    for (const auto* list : {&m->states, &m->inputs})
      for (const auto& v : *list)
        if (!out.count(v.name)) out.emplace(v.name, factor() * (rng() % 2 ? 1 : -1));
    for (const auto& p : m->params)
      if (!out.count(p.name)) out.emplace(p.name, parameter(p));
  }
  return out;
}

GiNaC::lst substitution(const SymbolicModel& m, const std::map<std::string, GiNaC::numeric>& point) {
  GiNaC::lst l = m.constant_substitution();
  for (const auto* list : {&m.states, &m.inputs, &m.params})
    for (const auto& v : *list) l.append(v.sym == point.at(v.name));
  return l;
}

// GiNaC's working precision is one setting for the process: set for a scope, restored on
// the way out whatever happens (a test binary's later tests would run at 40 digits).
struct DigitsFor {
  explicit DigitsFor(long digits) : saved(GiNaC::Digits) { GiNaC::Digits = digits; }
  ~DigitsFor() { GiNaC::Digits = saved; }
  long saved;
};

// |a - b| at a point, relative to the larger magnitude, at 40 digits (exact where both are
// rationals); complex values (a root of a negative number) by the modulus of the difference.
// NaN where either side is no number there: a symbol left, or a pole (GiNaC throws on 1/0).
double relative_difference(const GiNaC::ex& a, const GiNaC::lst& at_a, const GiNaC::ex& b, const GiNaC::lst& at_b) {
  GiNaC::ex x, y;
  try {
    const DigitsFor forty(40);
    x = a.subs(at_a).evalf(), y = b.subs(at_b).evalf();
  } catch (const std::exception&) {
    return NAN;
  }
  if (!GiNaC::is_a<GiNaC::numeric>(x) || !GiNaC::is_a<GiNaC::numeric>(y)) return NAN;
  const GiNaC::numeric u = GiNaC::ex_to<GiNaC::numeric>(x), v = GiNaC::ex_to<GiNaC::numeric>(y);
  const GiNaC::numeric scale = std::max(GiNaC::abs(u), GiNaC::abs(v));
  return scale.is_zero() ? 0.0 : (GiNaC::abs(u - v) / scale).to_double();
}

struct NamedExpression {
  std::string name, kind;
  GiNaC::ex e;
};

// A TeX name as plain text for a terminal: "F_{\mathrm{M1}}" -> "F_M1", "\tau" -> "tau".
std::string plain(std::string tex) {
  for (size_t at; (at = tex.find("\\mathrm")) != std::string::npos;) tex.erase(at, 7);
  tex.erase(std::remove_if(tex.begin(), tex.end(), [](char ch) { return ch == '\\' || ch == '{' || ch == '}'; }), tex.end());
  return tex;
}

// The equations of a model by name: d<state>/dt, the outputs, the intermediates (a vector one
// entry each: "tau[0]").
std::vector<NamedExpression> equations_of(const SymbolicModel& m) {
  std::vector<NamedExpression> out;
  for (size_t i = 0; i < m.states.size(); ++i) out.push_back({"d" + m.states[i].name + "/dt", "right-hand side", m.f(i, 0)});
  for (size_t i = 0; i < m.outputs.size(); ++i) out.push_back({m.outputs[i].name, "measurement", m.h(i, 0)});
  for (const auto& [tex, e] : m.intermediates) {
    if (!GiNaC::is_a<GiNaC::matrix>(e)) {
      out.push_back({plain(tex), "intermediate", e});
      continue;
    }
    const auto& mat = GiNaC::ex_to<GiNaC::matrix>(e);
    for (unsigned k = 0; k < mat.nops(); ++k) out.push_back({plain(tex) + "[" + std::to_string(k) + "]", "intermediate", mat.op(k)});
  }
  return out;
}

// One equation in both models at the points (substitutions per point, A's and B's); the
// symbols each side has once its constants (`constants_a`, `constants_b`) are put in.
EquationComparison compare_equation(const NamedExpression& x, const NamedExpression& y, const GiNaC::lst& constants_a,
                                    const GiNaC::lst& constants_b,
                                    const std::vector<std::pair<GiNaC::lst, GiNaC::lst>>& points, double tolerance) {
  EquationComparison q{x.name, x.kind, true, 0, 0, {}, {}};
  const auto sa = symbol_names(x.e.subs(constants_a)), sb = symbol_names(y.e.subs(constants_b));
  std::set_difference(sa.begin(), sa.end(), sb.begin(), sb.end(), std::back_inserter(q.only_in_a));
  std::set_difference(sb.begin(), sb.end(), sa.begin(), sa.end(), std::back_inserter(q.only_in_b));
  for (const auto& [at_a, at_b] : points) {
    const double d = relative_difference(x.e, at_a, y.e, at_b);
    if (std::isnan(d)) ++q.points_not_compared;
    else q.largest_relative_difference = std::max(q.largest_relative_difference, d);
  }
  q.same = q.points_not_compared == 0 && q.largest_relative_difference <= tolerance;
  return q;
}

void compare_equations(const SymbolicModel& a, const SymbolicModel& b, const ComparisonOptions& opt, DerivationComparison& c) {
  std::mt19937 rng(opt.seed);
  std::vector<std::pair<GiNaC::lst, GiNaC::lst>> points;
  for (int k = 0; k < opt.points; ++k) {
    const auto point = random_point(a, b, rng);
    points.emplace_back(substitution(a, point), substitution(b, point));
  }
  c.points = opt.points;
  const auto ea = equations_of(a), eb = equations_of(b);
  const GiNaC::lst constants_a = a.constant_substitution(), constants_b = b.constant_substitution();
  for (const auto& x : ea) {
    const auto y = std::find_if(eb.begin(), eb.end(), [&](const NamedExpression& e) { return e.name == x.name; });
    if (y != eb.end())
      c.equations.push_back(compare_equation(x, *y, constants_a, constants_b, points, opt.relative_tolerance));
  }
  // Those of a state, an output or a rotor only one side has are said with it; an
  // intermediate (the drag, say) is said here.
  const auto intermediates = [](const std::vector<NamedExpression>& es) {
    std::vector<std::string> out;
    for (const auto& e : es)
      if (e.kind == "intermediate") out.push_back(e.name);
    return out;
  };
  c.equations_only_a = only_in_first(intermediates(ea), intermediates(eb));
  c.equations_only_b = only_in_first(intermediates(eb), intermediates(ea));
}

}  // namespace

bool DerivationComparison::same() const {
  const bool vehicles = vehicle_name_a == vehicle_name_b && blocks_only_a.empty() && blocks_only_b.empty() &&
                        blocks_changed.empty() && rotors_only_a.empty() && rotors_only_b.empty() && rotors_changed.empty();
  const bool values = parameters_only_a.empty() && parameters_only_b.empty() && parameter_values.empty() &&
                      parameter_settings.empty() && constants.empty() && constants_only_a.empty() && constants_only_b.empty();
  const bool structure = effects_only_a.empty() && effects_only_b.empty() && states_only_a.empty() &&
                         states_only_b.empty() && inputs_only_a.empty() && inputs_only_b.empty() && outputs_only_a.empty() &&
                         outputs_only_b.empty() && order_changes.empty() &&
                         equations_only_a.empty() && equations_only_b.empty();
  return vehicles && values && structure &&
         std::all_of(equations.begin(), equations.end(), [](const EquationComparison& e) { return e.same; });
}

DerivationComparison compare_derivations(const DerivationSide& a, const DerivationSide& b, const ComparisonOptions& opt) {
  DerivationComparison c;
  compare_vehicles(a.vehicle, b.vehicle, c);
  compare_parameters(a.model, b.model, c);
  compare_structure(a.model, b.model, c);
  compare_equations(a.model, b.model, opt, c);
  return c;
}

namespace {

std::string printable_list(const std::vector<std::string>& items, const std::string& separator = "; ") {
  return output::joined(items, separator, [](const std::string& x) { return output::printable(x); });
}

// "  label: a; b" with every name made printable; nothing where there is nothing.
void list_line(std::ostringstream& s, const std::string& label, const std::vector<std::string>& items) {
  if (!items.empty()) s << "  " << label << ": " << printable_list(items) << "\n";
}

void only_lines(std::ostringstream& s, const std::string& what, const std::vector<std::string>& a,
                const std::vector<std::string>& b) {
  list_line(s, what + " only in A", a);
  list_line(s, what + " only in B", b);
}

// "c_t 0.14175 -> 0.15 (+5.82 %)".
std::string change_text(const NumberChange& n) {
  std::string t = n.name + " " + a_to_b(n.a, n.b) + output::unit_after_number(n.unit);
  if (n.a != 0 && std::isfinite(n.a) && std::isfinite(n.b))
    t += std::string(" (") + (n.b > n.a ? "+" : "") + output::percent_text((n.b - n.a) / std::fabs(n.a)) + ")";
  return t;
}

std::vector<std::string> change_texts(const std::vector<NumberChange>& changes) {
  std::vector<std::string> out;
  for (const auto& n : changes) out.push_back(change_text(n));
  return out;
}

void vehicle_lines(std::ostringstream& s, const DerivationComparison& c) {
  const std::string before = s.str();
  if (c.vehicle_name_a != c.vehicle_name_b)
    s << "  vehicle name (in the generated code): " << output::printable(c.vehicle_name_a) << " -> "
      << output::printable(c.vehicle_name_b) << "\n";
  only_lines(s, "effects", c.effects_only_a, c.effects_only_b);
  list_line(s, "blocks changed", c.blocks_changed);
  only_lines(s, "blocks", c.blocks_only_a, c.blocks_only_b);
  list_line(s, "rotors changed", c.rotors_changed);
  only_lines(s, "rotors", c.rotors_only_a, c.rotors_only_b);
  list_line(s, "parameter values (A -> B)", change_texts(c.parameter_values));
  list_line(s, "parameter settings", c.parameter_settings);
  only_lines(s, "parameters", c.parameters_only_a, c.parameters_only_b);
  list_line(s, "constants (A -> B)", change_texts(c.constants));
  only_lines(s, "constants", c.constants_only_a, c.constants_only_b);
  only_lines(s, "states", c.states_only_a, c.states_only_b);
  only_lines(s, "inputs", c.inputs_only_a, c.inputs_only_b);
  only_lines(s, "outputs", c.outputs_only_a, c.outputs_only_b);
  list_line(s, "in another order (A -> B)", c.order_changes);
  if (s.str() == before) s << "  nothing differs\n";
}

std::string differing_text(const EquationComparison& e) {
  std::string t = "  differs: " + output::printable(e.name) + " (" + e.kind + ")";
  if (e.largest_relative_difference > 0)
    t += ", relative difference up to " + output::short_number(e.largest_relative_difference);
  if (e.points_not_compared > 0)
    t += ", no number at " + std::to_string(e.points_not_compared) + " point" + (e.points_not_compared == 1 ? "" : "s");
  if (e.only_in_a.empty() && e.only_in_b.empty()) t += "; the same symbols, other numbers (geometry or constants)";
  if (!e.only_in_a.empty()) t += "; symbols only in A: " + printable_list(e.only_in_a, ", ");
  if (!e.only_in_b.empty()) t += "; symbols only in B: " + printable_list(e.only_in_b, ", ");
  return t + "\n";
}

void equation_lines(std::ostringstream& s, const DerivationComparison& c) {
  std::vector<std::string> same;
  for (const auto& e : c.equations)
    if (e.same) same.push_back(e.name + (e.only_in_a.empty() && e.only_in_b.empty() ? "" : " (written with other symbols)"));
  s << "equations: " << c.equations.size() << " in both, each evaluated at " << c.points
    << " random points (the models' symbols matched by name, each model's own constants)\n";
  if (!same.empty()) s << "  the same function (" << same.size() << "): " << printable_list(same, ", ") << "\n";
  for (const auto& e : c.equations)
    if (!e.same) s << differing_text(e);
  only_lines(s, "intermediate quantities", c.equations_only_a, c.equations_only_b);
}

// What differs, counted: "3 of 33 equations, 1 effect, 2 parameter values".
std::string in_short(const DerivationComparison& c) {
  std::vector<std::string> parts;
  const auto differing = std::count_if(c.equations.begin(), c.equations.end(), [](const EquationComparison& e) { return !e.same; });
  if (differing > 0) parts.push_back(std::to_string(differing) + " of " + std::to_string(c.equations.size()) + " equations");
  const auto count = [&](size_t n, const std::string& one, const std::string& many) {
    if (n > 0) parts.push_back(std::to_string(n) + " " + (n == 1 ? one : many));
  };
  if (c.vehicle_name_a != c.vehicle_name_b) parts.push_back("the vehicle name");
  count(c.effects_only_a.size() + c.effects_only_b.size(), "effect", "effects");
  count(c.blocks_only_a.size() + c.blocks_only_b.size() + c.blocks_changed.size(), "block", "blocks");
  count(c.rotors_only_a.size() + c.rotors_only_b.size() + c.rotors_changed.size(), "rotor", "rotors");
  count(c.parameters_only_a.size() + c.parameters_only_b.size(), "parameter of one side", "parameters of one side");
  count(c.parameter_values.size(), "parameter value", "parameter values");
  count(c.parameter_settings.size(), "parameter's bounds or fit flag", "parameters' bounds or fit flags");
  count(c.constants.size() + c.constants_only_a.size() + c.constants_only_b.size(), "constant", "constants");
  count(c.states_only_a.size() + c.states_only_b.size() + c.inputs_only_a.size() + c.inputs_only_b.size() +
            c.outputs_only_a.size() + c.outputs_only_b.size(),
        "state, input or output of one side", "states, inputs or outputs of one side");
  count(c.order_changes.size(), "list in another order", "lists in another order");
  count(c.equations_only_a.size() + c.equations_only_b.size(), "intermediate of one side", "intermediates of one side");
  return output::joined(parts, ", ");
}

}  // namespace

std::string comparison_text(const DerivationComparison& c, const std::string& label_a, const std::string& label_b) {
  std::ostringstream s;
  s << "A: " << output::printable(label_a) << "\nB: " << output::printable(label_b) << "\n";
  s << "vehicle files and the values derived from them:\n";
  vehicle_lines(s, c);
  equation_lines(s, c);
  s << "In short: " << (c.same() ? "the two derivations are the same." : "the derivations differ in " + in_short(c) + ".") << "\n";
  return s.str();
}

}  // namespace quadgen
