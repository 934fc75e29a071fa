#include "cpp_emitter.hpp"

#include <cstdlib>
#include <functional>
#include <set>
#include <sstream>

namespace quadgen::emission {

namespace {
bool is_leaf(const Node& n) {
  return n.op == Op::constant || n.op == Op::state || n.op == Op::input || n.op == Op::param;
}
}  // namespace

double CppEmitter::node_ops(int id) const {
  const Node& n = g_.node(id);
  switch (n.op) {
    case Op::constant: case Op::state: case Op::input: case Op::param: return 0;
    case Op::add: case Op::mul: return static_cast<double>(n.args.size() - 1);
    case Op::ipow: return static_cast<double>(std::labs(n.exponent) - 1);
    default: return 1;
  }
}

// Parameter-only nodes that dynamic code (or an output) reads get a precompute slot.
void CppEmitter::plan_precompute(const std::vector<OutputGroup>& all_groups) {
  pre_slot_.assign(g_.size(), -1);
  std::vector<char> seen(g_.size(), 0);
  std::function<void(int)> visit = [&](int id) {
    if (seen[id]) return;
    seen[id] = 1;
    const Node& n = g_.node(id);
    for (int a : n.args) {
      visit(a);
      const Node& c = g_.node(a);
      if (n.dynamic && !c.dynamic && !is_leaf(c) && pre_slot_[a] < 0) {
        pre_slot_[a] = static_cast<int>(pre_order_.size());
        pre_order_.push_back(a);
      }
    }
  };
  for (const auto& grp : all_groups)
    for (const auto& o : grp.outputs) {
      visit(o.node);
      const Node& n = g_.node(o.node);
      if (!n.dynamic && !is_leaf(n) && pre_slot_[o.node] < 0) {
        pre_slot_[o.node] = static_cast<int>(pre_order_.size());
        pre_order_.push_back(o.node);
      }
    }
}

std::string CppEmitter::leaf(int id) const {
  const Node& n = g_.node(id);
  switch (n.op) {
    case Op::constant: return "Scalar(" + n.literal + ")";
    case Op::state: return "x[" + std::to_string(n.index) + "]";
    case Op::input: return "u[" + std::to_string(n.index) + "]";
    case Op::param: return "p[" + std::to_string(n.index) + "]";
    default: return "";
  }
}

std::string CppEmitter::render(int id, const std::vector<int>& temp_id, bool as_operand) const {
  const Node& n = g_.node(id);
  if (is_leaf(n)) return leaf(id);
  if (temp_id[id] >= 0) return "t" + std::to_string(temp_id[id]);
  if (pre_slot_[id] >= 0 && !n.dynamic && temp_id.size() == g_.size() && temp_id[id] != -2)
    return "pre.c[" + std::to_string(pre_slot_[id]) + "]";
  auto sub = [&](int a) { return render(a, temp_id, true); };
  std::string s;
  switch (n.op) {
    case Op::add:
      for (size_t i = 0; i < n.args.size(); ++i) s += (i ? " + " : "") + render(n.args[i], temp_id, false);
      return as_operand ? "(" + s + ")" : s;
    case Op::mul:
      for (size_t i = 0; i < n.args.size(); ++i) s += (i ? "*" : "") + sub(n.args[i]);
      return s;
    case Op::div: return sub(n.args[0]) + "/" + (g_.node(n.args[1]).op == Op::mul ? "(" + sub(n.args[1]) + ")" : sub(n.args[1]));
    case Op::ipow: {
      const std::string b = sub(n.args[0]);
      for (long i = 0; i < n.exponent; ++i) s += (i ? "*" : "") + b;
      return n.exponent > 1 && as_operand ? "(" + s + ")" : s;
    }
    case Op::pow: return "pow(" + render(n.args[0], temp_id, false) + ", " + render(n.args[1], temp_id, false) + ")";
    case Op::sin: return "sin(" + render(n.args[0], temp_id, false) + ")";
    case Op::cos: return "cos(" + render(n.args[0], temp_id, false) + ")";
    case Op::log: return "log(" + render(n.args[0], temp_id, false) + ")";
    case Op::abs: return "abs_value(" + render(n.args[0], temp_id, false) + ")";
    case Op::sign: return "sign_of(" + render(n.args[0], temp_id, false) + ")";
    default: return "";
  }
}

EmittedPrecompute CppEmitter::emit_precompute() {
  // Inside the precompute step every slot is computed from parameters; shared interior
  // nodes become locals, the rest is inlined.
  std::vector<int> uses(g_.size(), 0), temp(g_.size(), -1);
  std::vector<char> seen(g_.size(), 0);
  std::function<void(int)> count = [&](int id) {
    const Node& n = g_.node(id);
    for (int a : n.args) {
      uses[a] += n.op == Op::ipow ? static_cast<int>(n.exponent) : 1;
      if (!seen[a]) {
        seen[a] = 1;
        count(a);
      }
    }
  };
  for (int id : pre_order_) {
    uses[id] += 2;  // stored: always named
    if (!seen[id]) {
      seen[id] = 1;
      count(id);
    }
  }
  EmittedPrecompute out;
  std::ostringstream os;
  int next = 0;
  std::vector<char> done(g_.size(), 0);
  std::function<void(int)> emit = [&](int id) {
    if (done[id] || is_leaf(g_.node(id))) return;
    done[id] = 1;
    for (int a : g_.node(id).args) emit(a);
    out.ops += node_ops(id);
    if (uses[id] > 1) {
      // Render the node itself with temp[id] = -2 so it is not replaced by its own slot.
      temp[id] = -2;
      const std::string expr = render(id, temp, false);
      temp[id] = next++;
      os << "  const Scalar t" << temp[id] << " = " << expr << ";\n";
    }
  };
  for (int id : pre_order_) {
    emit(id);
    os << "  pre->c[" << pre_slot_[id] << "] = t" << temp[id] << ";\n";
  }
  out.body = os.str();
  out.count = static_cast<int>(pre_order_.size());
  return out;
}

EmittedFunction CppEmitter::emit_function(const std::vector<OutputGroup>& groups) {
  // Use counts over the dynamic part of the graph reachable from these outputs.
  std::vector<int> uses(g_.size(), 0), temp(g_.size(), -1);
  std::vector<char> seen(g_.size(), 0);
  EmittedFunction out;
  std::function<void(int)> count = [&](int id) {
    const Node& n = g_.node(id);
    if (!n.dynamic) return;
    for (int a : n.args) {
      uses[a] += n.op == Op::ipow ? static_cast<int>(n.exponent) : 1;
      if (!seen[a]) {
        seen[a] = 1;
        count(a);
      }
    }
  };
  for (const auto& grp : groups)
    for (const auto& o : grp.outputs) {
      out.ops_before += g_.tree_ops(o.node);
      uses[o.node]++;
      if (!seen[o.node]) {
        seen[o.node] = 1;
        count(o.node);
      }
    }
  std::ostringstream os;
  int next = 0;
  std::vector<char> done(g_.size(), 0);
  std::string indent = "  ";
  std::function<void(int)> emit = [&](int id) {
    const Node& n = g_.node(id);
    if (done[id] || is_leaf(n) || !n.dynamic) return;
    done[id] = 1;
    for (int a : n.args) emit(a);
    out.ops_after += node_ops(id);
    if (uses[id] > 1) {
      const std::string expr = render(id, temp, false);
      temp[id] = next++;
      os << indent << "const Scalar t" << temp[id] << " = " << expr << ";\n";
    }
  };
  // Unguarded groups (f) first; guarded groups (Jacobians) share one outer block in
  // which all their temporaries are computed, each group then written under its guard.
  std::string outer;
  for (const auto& grp : groups) {
    if (grp.guard.empty()) {
      for (const auto& o : grp.outputs) {
        emit(o.node);
        os << indent << o.target << " = " << render(o.node, temp, false) << ";\n";
      }
    } else {
      outer += (outer.empty() ? "" : " || ") + grp.guard;
    }
  }
  if (!outer.empty()) {
    os << "  if (" << outer << ") {\n";
    indent = "    ";
    for (const auto& grp : groups)
      if (!grp.guard.empty())
        for (const auto& o : grp.outputs) emit(o.node);
    for (const auto& grp : groups) {
      if (grp.guard.empty()) continue;
      os << "    if (" << grp.guard << ") {\n";
      for (const auto& o : grp.outputs) os << "      " << o.target << " = " << render(o.node, temp, false) << ";\n";
      os << "    }\n";
    }
    os << "  }\n";
  }
  out.body = os.str();
  return out;
}

}  // namespace quadgen::emission
