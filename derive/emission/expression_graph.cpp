#include "expression_graph.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "symbolic_functions.hpp"

namespace quadgen::emission {
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

// Shortest decimal that reads back as the same double.
std::string double_literal(double v) {
  char buf[40];
  for (int prec = 1; prec <= 17; ++prec) {
    std::snprintf(buf, sizeof buf, "%.*g", prec, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  std::string s(buf);
  if (s.find_first_of(".e") == std::string::npos) s += ".0";
  return s;
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

int ExpressionGraph::convert_power(const ex& base, const ex& exponent) {
  const int b = add(base);
  if (is_a<numeric>(exponent) && ex_to<numeric>(exponent).is_integer()) {
    Node n{Op::ipow, {b}, ex_to<numeric>(exponent).to_long(), "", -1};
    return intern(n);
  }
  return intern(Node{Op::pow, {b, add(exponent)}, 0, "", -1});
}

// Products split into numerator and denominator so that x^-1 becomes a division.
int ExpressionGraph::convert_mul(const ex& e) {
  std::vector<int> num, den;
  for (size_t i = 0; i < e.nops(); ++i) {
    const ex f = e.op(i);
    if (is_a<power>(f) && is_a<numeric>(f.op(1)) && ex_to<numeric>(f.op(1)).is_integer() &&
        ex_to<numeric>(f.op(1)).is_negative()) {
      const long k = -ex_to<numeric>(f.op(1)).to_long();
      den.push_back(k == 1 ? add(f.op(0)) : intern(Node{Op::ipow, {add(f.op(0))}, k, "", -1}));
    } else {
      num.push_back(add(f));
    }
  }
  const int top = num.empty() ? constant(1) : make_sorted(Op::mul, num);
  if (den.empty()) return top;
  return intern(Node{Op::div, {top, make_sorted(Op::mul, den)}, 0, "", -1});
}

int ExpressionGraph::add(const ex& e) {
  auto m = memo_.find(e);
  if (m != memo_.end()) return m->second;
  int id;
  if (is_a<numeric>(e)) {
    id = constant(ex_to<numeric>(e));
  } else if (is_a<GiNaC::constant>(e)) {
    id = constant(ex_to<numeric>(e.evalf()));
  } else if (is_a<symbol>(e)) {
    auto v = vars_.find(e);
    if (v == vars_.end()) throw std::runtime_error("emission: undeclared symbol " + ex_to<symbol>(e).get_name());
    const Op op = v->second.first == VarKind::state ? Op::state : v->second.first == VarKind::input ? Op::input : Op::param;
    id = intern(Node{op, {}, 0, names_[e], v->second.second});
  } else if (is_a<GiNaC::add>(e)) {
    std::vector<int> args;
    for (size_t i = 0; i < e.nops(); ++i) args.push_back(add(e.op(i)));
    id = make_sorted(Op::add, args);
  } else if (is_a<GiNaC::mul>(e)) {
    id = convert_mul(e);
  } else if (is_a<power>(e)) {
    if (is_a<numeric>(e.op(1)) && ex_to<numeric>(e.op(1)).is_integer() && ex_to<numeric>(e.op(1)).is_negative()) {
      const long k = -ex_to<numeric>(e.op(1)).to_long();
      const int den = k == 1 ? add(e.op(0)) : intern(Node{Op::ipow, {add(e.op(0))}, k, "", -1});
      id = intern(Node{Op::div, {constant(1), den}, 0, "", -1});
    } else
      id = convert_power(e.op(0), e.op(1));
  } else if (is_ex_the_function(e, sin)) {
    id = intern(Node{Op::sin, {add(e.op(0))}, 0, "", -1});
  } else if (is_ex_the_function(e, cos)) {
    id = intern(Node{Op::cos, {add(e.op(0))}, 0, "", -1});
  } else if (is_ex_the_function(e, log)) {
    id = intern(Node{Op::log, {add(e.op(0))}, 0, "", -1});
  } else if (is_ex_the_function(e, abs_value)) {
    id = intern(Node{Op::abs, {add(e.op(0))}, 0, "", -1});
  } else if (is_ex_the_function(e, sign_of)) {
    id = intern(Node{Op::sign, {add(e.op(0))}, 0, "", -1});
  } else {
    std::ostringstream os;
    os << e;
    throw std::runtime_error("emission: unsupported expression " + os.str());
  }
  memo_[e] = id;
  return id;
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

}  // namespace quadgen::emission
