#include "audit/derivation_comparison.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <sstream>

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

std::vector<std::string> only_in_first(const std::vector<std::string>& a, const std::vector<std::string>& b) {
  std::vector<std::string> out;
  for (const auto& x : a)
    if (std::find(b.begin(), b.end(), x) == b.end()) out.push_back(x);
  return out;
}

// Exactly equal, or both NaN: a vehicle file's numbers are compared as read, not as rounded.
bool same_number(double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); }

// "0.07465 -> 0.08", with as many digits as tell the two apart.
std::string a_to_b(double a, double b) {
  std::string t = output::one_then_other(a, b);
  return t.replace(t.find(" then "), 6, " -> ");
}

std::string vec_text(const Vec3& v) {
  return "(" + output::six_digits(v[0]) + ", " + output::six_digits(v[1]) + ", " + output::six_digits(v[2]) + ")";
}

// What differs between two things of one name: "centre (0.1, 0, 0) -> (0.12, 0, 0) m".
struct Differences {
  std::vector<std::string> parts;
  void number(const std::string& what, double a, double b, const std::string& unit) {
    if (!same_number(a, b)) parts.push_back(what + " " + a_to_b(a, b) + unit);
  }
  void vector(const std::string& what, const Vec3& a, const Vec3& b, const std::string& unit) {
    if (a != b) parts.push_back(what + " " + vec_text(a) + " -> " + vec_text(b) + unit);
  }
  void text(const std::string& what, const std::string& a, const std::string& b) {
    if (a != b) parts.push_back(what + " " + a + " -> " + b);
  }
};

// For each name in both lists: what differs, as "name: part; part". `describe` fills a
// Differences from the two items.
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

void compare_vehicles(const Vehicle& a, const Vehicle& b, DerivationComparison& c) {
  const auto name = [](const auto& x) { return x.name; };
  c.blocks_only_a = only_in_first(names_of(a.blocks, name), names_of(b.blocks, name));
  c.blocks_only_b = only_in_first(names_of(b.blocks, name), names_of(a.blocks, name));
  c.blocks_changed = changed(a.blocks, b.blocks, [](const Block& x, const Block& y, Differences& d) {
    d.number("mass", x.mass, y.mass, " kg");
    d.vector("size", x.size, y.size, " m");
    d.vector("centre", x.centre, y.centre, " m");
    d.vector("yaw, pitch, roll", x.yaw_pitch_roll_deg, y.yaw_pitch_roll_deg, " deg");
  });
  c.rotors_only_a = only_in_first(names_of(a.rotors, name), names_of(b.rotors, name));
  c.rotors_only_b = only_in_first(names_of(b.rotors, name), names_of(a.rotors, name));
  c.rotors_changed = changed(a.rotors, b.rotors, [](const Rotor& x, const Rotor& y, Differences& d) {
    d.vector("position", x.position, y.position, " m");
    d.text("spin", x.spin == Spin::ccw ? "ccw" : "cw", y.spin == Spin::ccw ? "ccw" : "cw");
    d.number("radius", x.radius, y.radius, " m");
    d.number("disc area", x.disc_area, y.disc_area, " m^2");
  });
}

void compare_parameters(const SymbolicModel& a, const SymbolicModel& b, DerivationComparison& c) {
  const auto name = [](const Variable& v) { return v.name; };
  c.parameters_only_a = only_in_first(names_of(a.params, name), names_of(b.params, name));
  c.parameters_only_b = only_in_first(names_of(b.params, name), names_of(a.params, name));
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
  c.states_only_a = only_in_first(names_of(a.states, name), names_of(b.states, name));
  c.states_only_b = only_in_first(names_of(b.states, name), names_of(a.states, name));
  c.inputs_only_a = only_in_first(names_of(a.inputs, name), names_of(b.inputs, name));
  c.inputs_only_b = only_in_first(names_of(b.inputs, name), names_of(a.inputs, name));
}

std::set<std::string> symbol_names(const GiNaC::ex& e) {
  std::set<std::string> out;
  for (auto i = e.preorder_begin(); i != e.preorder_end(); ++i)
    if (GiNaC::is_a<GiNaC::symbol>(*i)) out.insert(GiNaC::ex_to<GiNaC::symbol>(*i).get_name());
  return out;
}

// Every symbol of a model by name: states, inputs, parameters, constants and the symbols the
// derivation keeps inside f (dω/dt is not among them: f has it replaced).
std::map<std::string, GiNaC::symbol> symbols_by_name(const SymbolicModel& m) {
  std::map<std::string, GiNaC::symbol> out;
  for (const auto* list : {&m.states, &m.inputs, &m.params, &m.constants})
    for (const auto& v : *list) out.emplace(v.name, v.sym);
  return out;
}

// One random point: a value for every symbol name either model has (the same value under
// one name in both), positive and of the order of the parameter's nominal value, so that
// square roots and denominators stay real and away from their poles. Constants are each
// model's own (their differences are the geometry's), so they are not drawn.
std::map<std::string, double> random_point(const SymbolicModel& a, const SymbolicModel& b, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> factor(0.5, 1.5);
  std::map<std::string, double> out;
  for (const auto* m : {&a, &b}) {
    for (const auto* list : {&m->states, &m->inputs})
      for (const auto& v : *list) out.emplace(v.name, factor(rng));
    for (const auto& p : m->params) out.emplace(p.name, factor(rng) * (p.nominal != 0 ? std::fabs(p.nominal) : 1.0));
  }
  return out;
}

GiNaC::lst substitution(const SymbolicModel& m, const std::map<std::string, double>& point) {
  GiNaC::lst l = m.constant_substitution();
  for (const auto& [name, sym] : symbols_by_name(m)) {
    const auto v = point.find(name);
    if (v != point.end()) l.append(sym == GiNaC::numeric(v->second));
  }
  return l;
}

// |a - b| relative to the larger magnitude; complex values (a square root of a negative
// number at a point) compare by their modulus. NaN where either is no number.
double relative_difference(const GiNaC::ex& a, const GiNaC::ex& b) {
  const GiNaC::ex x = a.evalf(), y = b.evalf();
  if (!GiNaC::is_a<GiNaC::numeric>(x) || !GiNaC::is_a<GiNaC::numeric>(y)) return NAN;
  const GiNaC::numeric u = GiNaC::ex_to<GiNaC::numeric>(x), v = GiNaC::ex_to<GiNaC::numeric>(y);
  const double diff = GiNaC::abs(u - v).to_double(), scale = std::max(GiNaC::abs(u).to_double(), GiNaC::abs(v).to_double());
  return scale == 0 ? diff : diff / scale;
}

struct NamedExpression {
  std::string name, kind;
  GiNaC::ex e;
};

// The equations of a model by name: d<state>/dt, the outputs, the intermediates (a vector one
// entry each: "\tau[0]").
std::vector<NamedExpression> equations_of(const SymbolicModel& m) {
  std::vector<NamedExpression> out;
  for (size_t i = 0; i < m.states.size(); ++i) out.push_back({"d" + m.states[i].name + "/dt", "right-hand side", m.f(i, 0)});
  for (size_t i = 0; i < m.outputs.size(); ++i) out.push_back({m.outputs[i].name, "measurement", m.h(i, 0)});
  for (const auto& [name, e] : m.intermediates) {
    if (!GiNaC::is_a<GiNaC::matrix>(e)) {
      out.push_back({name, "intermediate", e});
      continue;
    }
    const auto& mat = GiNaC::ex_to<GiNaC::matrix>(e);
    for (unsigned k = 0; k < mat.nops(); ++k) out.push_back({name + "[" + std::to_string(k) + "]", "intermediate", mat.op(k)});
  }
  return out;
}

void compare_equations(const SymbolicModel& a, const SymbolicModel& b, const ComparisonOptions& opt, DerivationComparison& c) {
  std::mt19937_64 rng(opt.seed);
  std::vector<GiNaC::lst> subs_a, subs_b;
  for (int k = 0; k < opt.points; ++k) {
    const auto point = random_point(a, b, rng);
    subs_a.push_back(substitution(a, point));
    subs_b.push_back(substitution(b, point));
  }
  c.points = opt.points;
  const auto eb = equations_of(b);
  for (const auto& x : equations_of(a)) {
    const auto y = std::find_if(eb.begin(), eb.end(), [&](const NamedExpression& e) { return e.name == x.name; });
    if (y == eb.end()) continue;  // its state or intermediate is only in one model: said there
    EquationComparison q{x.name, x.kind, true, 0, {}, {}};
    const auto sa = symbol_names(x.e.subs(a.constant_substitution())), sb = symbol_names(y->e.subs(b.constant_substitution()));
    std::set_difference(sa.begin(), sa.end(), sb.begin(), sb.end(), std::back_inserter(q.only_in_a));
    std::set_difference(sb.begin(), sb.end(), sa.begin(), sa.end(), std::back_inserter(q.only_in_b));
    for (int k = 0; k < opt.points; ++k) {
      const double d = relative_difference(x.e.subs(subs_a[k]), y->e.subs(subs_b[k]));
      if (!(d <= opt.relative_tolerance)) q.same = false;
      if (!(d <= q.largest_relative_difference)) q.largest_relative_difference = d;  // NaN stays NaN
    }
    if (!q.only_in_a.empty() || !q.only_in_b.empty()) q.same = false;
    if (q.same) q.largest_relative_difference = 0;
    c.equations.push_back(std::move(q));
  }
}

}  // namespace

bool DerivationComparison::same() const {
  const bool vehicles = blocks_only_a.empty() && blocks_only_b.empty() && blocks_changed.empty() && rotors_only_a.empty() &&
                        rotors_only_b.empty() && rotors_changed.empty();
  const bool values = parameters_only_a.empty() && parameters_only_b.empty() && parameter_values.empty() &&
                      parameter_settings.empty() && constants.empty();
  const bool structure = effects_only_a.empty() && effects_only_b.empty() && states_only_a.empty() &&
                         states_only_b.empty() && inputs_only_a.empty() && inputs_only_b.empty();
  return vehicles && values && structure &&
         std::all_of(equations.begin(), equations.end(), [](const EquationComparison& e) { return e.same; });
}

DerivationComparison compare_derivations(const DerivationSide& a, const DerivationSide& b, const ComparisonOptions& opt) {
  DerivationComparison c;
  c.effects_only_a = only_in_first(a.model.effects, b.model.effects);
  c.effects_only_b = only_in_first(b.model.effects, a.model.effects);
  compare_vehicles(a.vehicle, b.vehicle, c);
  compare_parameters(a.model, b.model, c);
  compare_equations(a.model, b.model, opt, c);
  return c;
}

namespace {

// "label: a, b" with every name made printable; nothing where there is nothing.
void list_line(std::ostringstream& s, const std::string& label, const std::vector<std::string>& items) {
  if (items.empty()) return;
  s << "  " << label << ": " << output::joined(items, "; ", [](const std::string& x) { return output::printable(x); }) << "\n";
}

void only_lines(std::ostringstream& s, const std::string& what, const std::vector<std::string>& a,
                const std::vector<std::string>& b) {
  list_line(s, what + " only in A", a);
  list_line(s, what + " only in B", b);
}

std::string change_text(const NumberChange& n) {
  std::string t = output::printable(n.name) + " " + a_to_b(n.a, n.b) +
                  output::printable(output::unit_after_number(n.unit));
  if (n.a != 0 && std::isfinite(n.a) && std::isfinite(n.b)) t += std::string(" (") + (n.b > n.a ? "+" : "") + output::percent_text((n.b - n.a) / std::fabs(n.a)) + ")";
  return t;
}

void equation_lines(std::ostringstream& s, const DerivationComparison& c) {
  std::vector<std::string> same;
  std::vector<const EquationComparison*> differ;
  for (const auto& e : c.equations) (e.same ? same.push_back(e.name) : differ.push_back(&e));
  s << "equations: " << c.equations.size() << " in both, each evaluated at " << c.points
    << " random points (the models' symbols matched by name, each model's own constants)\n";
  if (!same.empty())
    s << "  the same function (" << same.size() << "): "
      << output::joined(same, ", ", [](const std::string& x) { return output::printable(x); }) << "\n";
  for (const auto* e : differ) {
    s << "  differs: " << output::printable(e->name) << " (" << e->kind << "), relative difference up to "
      << (std::isnan(e->largest_relative_difference) ? std::string("(not a number at a point)")
                                                      : output::short_number(e->largest_relative_difference));
    if (e->only_in_a.empty() && e->only_in_b.empty()) s << "; the same symbols, other numbers (geometry or constants)";
    const auto names = [](const std::vector<std::string>& v) {
      return output::joined(v, ", ", [](const std::string& x) { return output::printable(x); });
    };
    if (!e->only_in_a.empty()) s << "; symbols only in A: " << names(e->only_in_a);
    if (!e->only_in_b.empty()) s << "; symbols only in B: " << names(e->only_in_b);
    s << "\n";
  }
}

// What differs, counted: "3 of 33 equations, the effects, 2 parameter values".
std::string in_short(const DerivationComparison& c) {
  std::vector<std::string> parts;
  const auto differing = std::count_if(c.equations.begin(), c.equations.end(), [](const EquationComparison& e) { return !e.same; });
  if (differing > 0) parts.push_back(std::to_string(differing) + " of " + std::to_string(c.equations.size()) + " equations");
  const auto count = [&](size_t n, const std::string& one, const std::string& many) {
    if (n > 0) parts.push_back(std::to_string(n) + " " + (n == 1 ? one : many));
  };
  count(c.effects_only_a.size() + c.effects_only_b.size(), "effect", "effects");
  count(c.blocks_only_a.size() + c.blocks_only_b.size() + c.blocks_changed.size(), "block", "blocks");
  count(c.rotors_only_a.size() + c.rotors_only_b.size() + c.rotors_changed.size(), "rotor", "rotors");
  count(c.parameters_only_a.size() + c.parameters_only_b.size(), "parameter of one side", "parameters of one side");
  count(c.parameter_values.size(), "parameter value", "parameter values");
  count(c.parameter_settings.size(), "parameter's bounds or fit flag", "parameters' bounds or fit flags");
  count(c.constants.size(), "constant", "constants");
  count(c.states_only_a.size() + c.states_only_b.size() + c.inputs_only_a.size() + c.inputs_only_b.size(),
        "state or input of one side", "states or inputs of one side");
  return output::joined(parts, ", ");
}

}  // namespace

std::string comparison_text(const DerivationComparison& c, const std::string& label_a, const std::string& label_b) {
  std::ostringstream s;
  s << "A: " << output::printable(label_a) << "\nB: " << output::printable(label_b) << "\n";
  s << "vehicle files and the values derived from them:\n";
  const std::string before = s.str();
  only_lines(s, "effects", c.effects_only_a, c.effects_only_b);
  list_line(s, "blocks changed", c.blocks_changed);
  only_lines(s, "blocks", c.blocks_only_a, c.blocks_only_b);
  list_line(s, "rotors changed", c.rotors_changed);
  only_lines(s, "rotors", c.rotors_only_a, c.rotors_only_b);
  std::vector<std::string> values;
  for (const auto& n : c.parameter_values) values.push_back(change_text(n));
  s << (values.empty() ? "" : "  parameter values (A -> B): " + output::joined(values, "; ") + "\n");
  list_line(s, "parameter settings", c.parameter_settings);
  only_lines(s, "parameters", c.parameters_only_a, c.parameters_only_b);
  std::vector<std::string> constants;
  for (const auto& n : c.constants) constants.push_back(change_text(n));
  s << (constants.empty() ? "" : "  constants (A -> B): " + output::joined(constants, "; ") + "\n");
  only_lines(s, "states", c.states_only_a, c.states_only_b);
  only_lines(s, "inputs", c.inputs_only_a, c.inputs_only_b);
  if (s.str() == before) s << "  nothing differs\n";
  equation_lines(s, c);
  s << "In short: " << (c.same() ? "the two derivations are the same." : "the derivations differ in " + in_short(c) + ".") << "\n";
  return s.str();
}

}  // namespace quadgen
