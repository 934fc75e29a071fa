#include "codegen/cpp_printer.hpp"

#include <sstream>

#include "output/joined.hpp"

namespace quadgen::codegen {

namespace {

using Kind = LoweredPlan::Kind;

class Printer {
 public:
  Printer(const LoweredPlan& plan, const LoweredPlan::Function& fn) : plan_(plan), fn_(fn) {}

  PrintedFunction print() {
    using StepKind = LoweredPlan::Function::StepKind;
    std::ostringstream os;
    std::string indent = "  ";
    for (const auto& s : fn_.steps) {
      switch (s.kind) {
        case StepKind::define:
          os << indent << "const Scalar t" << s.temp << " = " << body(s.node, false) << ";\n";
          break;
        case StepKind::store:
          os << indent << "pre->c[" << s.slot << "] = " << expr(s.node, false) << ";\n";
          break;
        case StepKind::assign:
          os << indent << fn_.groups[s.group].outputs[s.output].target << " = " << assignment(s.node, s.sign) << ";\n";
          break;
        case StepKind::open_any: {
          std::string guards;
          for (const auto& g : fn_.groups)
            if (!g.guard.empty()) guards += (guards.empty() ? "" : " || ") + g.guard;
          os << indent << "if (" << guards << ") {\n";
          indent += "  ";
          break;
        }
        case StepKind::open_group:
          os << indent << "if (" << fn_.groups[s.group].guard << ") {\n";
          indent += "  ";
          break;
        case StepKind::close:
          indent.resize(indent.size() - 2);
          os << indent << "}\n";
          break;
      }
    }
    out_.body = os.str();
    out_.ops_before = fn_.ops_before;
    return out_;
  }

 private:
  // An output: sign * node, a negated sum written as the subtraction it is.
  std::string assignment(int id, int sign) {
    const auto& n = plan_.node(id);
    if (sign > 0) return expr(id, false);
    if (n.kind == Kind::sum && n.dynamic && fn_.temp[id] < 0) return sum(id, -1);
    out_.ops_after += 1;
    return "-" + expr(id, true);
  }

  // A node where it is used: its temporary, its precompute slot, or its text inline.
  std::string expr(int id, bool as_operand) {
    const auto& n = plan_.node(id);
    if (n.kind == Kind::leaf) return n.text;
    if (fn_.temp[id] >= 0) return "t" + std::to_string(fn_.temp[id]);
    if (!fn_.precompute && !n.dynamic) return "pre.c[" + std::to_string(plan_.precompute_slot(id)) + "]";
    return body(id, as_operand);
  }

  // Sums parenthesise themselves as operands; inline products and reciprocals are
  // parenthesised by the product they are a factor of.
  std::string factor(int a) {
    const std::string s = expr(a, true);
    const auto& c = plan_.node(a);
    const bool inline_node = c.kind != Kind::leaf && fn_.temp[a] < 0 && (fn_.precompute || c.dynamic);
    return inline_node && (c.kind == Kind::prod || c.kind == Kind::recip) ? "(" + s + ")" : s;
  }

  std::string sum(int id, int outer) {
    const auto& n = plan_.node(id);
    std::string s;
    bool first = true;
    for (size_t i : plan_.sum_order(id, outer)) {
      const bool plus = n.sign[i] * outer > 0;
      const std::string term = expr(n.args[i], true);
      if (first) s += plus ? term : "-" + term;
      else s += (plus ? " + " : " - ") + term;
      if (!first || !plus) out_.ops_after += 1;
      first = false;
    }
    return s;
  }

  std::string body(int id, bool as_operand) {
    const auto& n = plan_.node(id);
    switch (n.kind) {
      case Kind::sum: {
        const std::string s = sum(id, 1);
        return as_operand ? "(" + s + ")" : s;
      }
      case Kind::prod: {
        std::string num, den;
        int nn = 0;
        for (size_t i : plan_.operand_order(id)) {
          const int a = n.args[i];
          if (plan_.is_inline_division(fn_, a)) {
            den += "/" + factor(plan_.node(a).args[0]);
            out_.ops_after += 1;
          } else {
            num += (nn ? "*" : "") + factor(a);
            if (nn) out_.ops_after += 1;
            ++nn;
          }
        }
        if (nn == 0) num = "Scalar(1.0)";
        return num + den;
      }
      case Kind::recip:
        out_.ops_after += 1;
        return "Scalar(1.0)/" + factor(n.args[0]);
      case Kind::call: {
        out_.ops_after += 1;
        return n.text + "(" + output::joined(n.args, ", ", [&](const auto& a) { return expr(a, false); }) + ")";
      }
      case Kind::leaf: return n.text;
    }
    return "";
  }

  const LoweredPlan& plan_;
  const LoweredPlan::Function& fn_;
  PrintedFunction out_;
};

}  // namespace

PrintedFunction print_cpp(const LoweredPlan& plan, const LoweredPlan::Function& fn) { return Printer(plan, fn).print(); }

}  // namespace quadgen::codegen
