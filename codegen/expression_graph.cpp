#include "codegen/expression_graph.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "derive/symbolic_functions.hpp"
#include "output/sinks.hpp"

namespace quadgen::codegen {
using namespace GiNaC;

namespace {

uint64_t mix(uint64_t h, uint64_t v) {
  // FNV-1a over the 8 bytes of v.
  for (int i = 0; i < 8; ++i) {
    h ^= (v >> (8 * i)) & 0xff;
    h *= 1099511628211ull;
  }
  return h;
}
uint64_t mix(uint64_t h, const std::string& s) {
  for (unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return mix(h, s.size());
}

}  // namespace

void ExpressionGraph::declare(VarKind kind, const std::vector<std::pair<symbol, std::string>>& vars) {
  for (size_t i = 0; i < vars.size(); ++i) {
    vars_[vars[i].first] = {kind, static_cast<int>(i)};
    names_[vars[i].first] = vars[i].second;
  }
}

int ExpressionGraph::intern(Node n) {
  uint64_t h = mix(1469598103934665603ull, static_cast<uint64_t>(n.op));
  h = mix(h, static_cast<uint64_t>(n.exponent));
  h = mix(h, n.literal);
  bool dynamic = n.op == Op::state || n.op == Op::input;
  for (int a : n.args) {
    h = mix(h, nodes_[a].key);
    dynamic = dynamic || nodes_[a].dynamic;
  }
  n.key = h;
  n.dynamic = dynamic;
  auto id = std::make_tuple(static_cast<int>(n.op), n.args, n.exponent, n.literal, n.index);
  auto it = unique_.find(id);
  if (it != unique_.end()) return it->second;
  nodes_.push_back(n);
  unique_[id] = static_cast<int>(nodes_.size() - 1);
  return static_cast<int>(nodes_.size() - 1);
}

int ExpressionGraph::constant(const numeric& v) {
  Node n{Op::constant, {}, 0, double_literal(v.to_double()), -1};
  return intern(n);
}

int ExpressionGraph::make_sorted(Op op, std::vector<int> args) {
  if (args.size() == 1) return args[0];
  // Canonical operand order: by structural key, then by node text-independent id as a
  // tie-break only between identical keys (which are then identical nodes).
  std::sort(args.begin(), args.end(), [&](int a, int b) {
    if (nodes_[a].key != nodes_[b].key) return nodes_[a].key < nodes_[b].key;
    return a < b;
  });
  return intern(Node{op, args, 0, "", -1});
}

int ExpressionGraph::scaled(const numeric& c, int id) {
  if (c.is_equal(numeric(1))) return id;
  if (nodes_[id].op == Op::constant) return constant(c * numeric(std::strtod(nodes_[id].literal.c_str(), nullptr)));
  std::vector<int> args{constant(c)};
  if (nodes_[id].op == Op::mul) args.insert(args.end(), nodes_[id].args.begin(), nodes_[id].args.end());
  else args.push_back(id);
  return make_sorted(Op::mul, args);
}

int ExpressionGraph::add(const ex& e) {
  const auto [c, id] = canon(e);
  return scaled(c, id);
}

std::pair<numeric, int> ExpressionGraph::canon(const ex& e) {
  auto m = memo_.find(e);
  if (m != memo_.end()) return m->second;
  std::pair<numeric, int> r;
  if (is_a<numeric>(e)) {
    r = {ex_to<numeric>(e), constant(1)};
  } else if (is_a<GiNaC::constant>(e)) {
    r = {1, constant(ex_to<numeric>(e.evalf()))};
  } else if (is_a<symbol>(e)) {
    auto v = vars_.find(e);
    if (v == vars_.end()) throw std::runtime_error("emission: undeclared symbol " + output::printable(ex_to<symbol>(e).get_name()));
    const Op op = v->second.first == VarKind::state ? Op::state : v->second.first == VarKind::input ? Op::input : Op::param;
    r = {1, intern(Node{op, {}, 0, names_[e], v->second.second})};
  } else if (is_a<GiNaC::add>(e)) {
    r = canon_add(e);
  } else if (is_a<GiNaC::mul>(e) || is_a<power>(e)) {
    r = canon_mul(e);
  } else if (is_a<function>(e)) {
    r = canon_function(e);
  } else {
    std::ostringstream os;
    os << e;
    throw std::runtime_error("emission: unsupported expression " + os.str());
  }
  memo_[e] = r;
  return r;
}

// Terms as (coefficient, unit node); sorted by the unit's key; the first coefficient is
// made positive and its sign returned to the caller.
std::pair<numeric, int> ExpressionGraph::canon_add(const ex& e) {
  std::vector<std::pair<numeric, int>> terms;
  for (size_t i = 0; i < e.nops(); ++i) terms.push_back(canon(e.op(i)));
  std::sort(terms.begin(), terms.end(), [&](const auto& a, const auto& b) {
    if (nodes_[a.second].key != nodes_[b.second].key) return nodes_[a.second].key < nodes_[b.second].key;
    return a.first < b.first;
  });
  const numeric sign = terms.front().first.is_negative() ? numeric(-1) : numeric(1);
  std::vector<int> args;
  for (const auto& [c, id] : terms) args.push_back(scaled(c * sign, id));
  return {sign, make_sorted(Op::add, args)};
}

// Products and integer powers: coefficients of all factors multiply into one; negative
// powers go to a denominator.
std::pair<numeric, int> ExpressionGraph::canon_mul(const ex& e) {
  numeric coeff = 1;
  std::vector<int> num, den;
  auto factor = [&](const ex& f) {
    ex base = f, expo = 1;
    if (is_a<power>(f)) {
      base = f.op(0);
      expo = f.op(1);
    }
    if (!(is_a<numeric>(expo) && ex_to<numeric>(expo).is_integer())) {
      num.push_back(intern(Node{Op::pow, {add(base), add(expo)}, 0, "", -1}));
      return;
    }
    const long k = ex_to<numeric>(expo).to_long();
    const auto [c, id] = canon(base);
    coeff *= c.power(k);
    if (nodes_[id].op == Op::constant && nodes_[id].literal == "1.0") return;
    const long a = std::labs(k);
    const int node = a == 1 ? id : intern(Node{Op::ipow, {id}, a, "", -1});
    (k > 0 ? num : den).push_back(node);
  };
  if (is_a<GiNaC::mul>(e))
    for (size_t i = 0; i < e.nops(); ++i) factor(e.op(i));
  else
    factor(e);
  int top = num.empty() ? constant(1) : make_sorted(Op::mul, num);
  if (!den.empty()) top = intern(Node{Op::div, {top, make_sorted(Op::mul, den)}, 0, "", -1});
  return {coeff, top};
}

std::pair<numeric, int> ExpressionGraph::canon_function(const ex& e) {
  const auto [c, id] = canon(e.op(0));
  auto unary = [&](Op op, int arg) { return intern(Node{op, {arg}, 0, "", -1}); };
  if (is_ex_the_function(e, abs_value)) return {abs(c), unary(Op::abs, id)};          // |cA| = |c||A|
  if (is_ex_the_function(e, sign_of)) return {numeric(c.csgn()), unary(Op::sign, id)};  // sgn(cA)
  if (is_ex_the_function(e, cos) && c.is_equal(numeric(-1))) return {1, unary(Op::cos, id)};
  if (is_ex_the_function(e, sin) && c.is_equal(numeric(-1))) return {-1, unary(Op::sin, id)};
  const int arg = scaled(c, id);
  if (is_ex_the_function(e, sin)) return {1, unary(Op::sin, arg)};
  if (is_ex_the_function(e, cos)) return {1, unary(Op::cos, arg)};
  if (is_ex_the_function(e, log)) return {1, unary(Op::log, arg)};
  std::ostringstream os;
  os << e;
  throw std::runtime_error("emission: unsupported function " + os.str());
}

void declare_model_variables(ExpressionGraph& g, const SymbolicModel& m) {
  auto decl = [](const std::vector<Variable>& vs) {
    std::vector<std::pair<symbol, std::string>> out;
    for (const auto& v : vs) out.push_back({v.sym, v.name});
    return out;
  };
  g.declare(VarKind::state, decl(m.states));
  g.declare(VarKind::input, decl(m.inputs));
  g.declare(VarKind::param, decl(m.params));
}

double ExpressionGraph::tree_ops(int id) {
  auto it = tree_ops_.find(id);
  if (it != tree_ops_.end()) return it->second;
  const Node& n = nodes_[id];
  double ops = 0;
  switch (n.op) {
    case Op::constant: case Op::state: case Op::input: case Op::param: ops = 0; break;
    case Op::add: case Op::mul: ops = static_cast<double>(n.args.size() - 1); break;
    case Op::ipow: ops = static_cast<double>(std::labs(n.exponent) - 1) + (n.exponent < 0); break;
    default: ops = 1;
  }
  for (int a : n.args) ops += tree_ops(a);
  tree_ops_[id] = ops;
  return ops;
}

// Shortest decimal that reads back as the same double; ".0" appended to an integer, so that
// C++ reads it as a double. A constant that is not finite (a vehicle's numbers overflowing)
// is refused: "inf" or "nan" in the code would be an identifier the including project may define.
std::string double_literal(double v) {
  if (!std::isfinite(v))
    throw std::domain_error("generated code: a constant of the model is not finite (" + std::to_string(v) +
                            "): the vehicle's numbers overflow a double");
  char buf[40];
  for (int prec = 1; prec <= 17; ++prec) {
    std::snprintf(buf, sizeof buf, "%.*g", prec, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  std::string s(buf);
  if (s.find_first_of(".en") == std::string::npos) s += ".0";
  return s;
}

}  // namespace quadgen::codegen
