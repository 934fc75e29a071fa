#include "codegen/tape_builder.hpp"

#include <map>
#include <stdexcept>

#include "codegen/lowered_model.hpp"

namespace quadgen::codegen {
using runtime::Instruction;
using runtime::TapeOp;

namespace {

using Kind = LoweredPlan::Kind;
using Leaf = LoweredPlan::Leaf;
using Function = LoweredPlan::Function;

// Registers shared by all functions of one tape: x, u, p, constants, precomputed values.
struct Registers {
  runtime::Tape& t;
  int next;
  std::map<double, int> constant;  // keyed by value: +0 and -0 compare equal, see below
  std::vector<int> pre_slot;       // precompute slot -> register

  int fresh() { return next++; }
  int of_constant(double v) {
    // -0.0 == 0.0 as map keys; the plan's constants are magnitudes (signs are
    // subtractions), so a negative zero never reaches here.
    auto it = constant.find(v);
    if (it != constant.end()) return it->second;
    const int r = fresh();
    t.constants.push_back({r, v});
    constant[v] = r;
    return r;
  }
};

// One function of the plan as instructions, following the C++ printer's reading of the
// same plan operation for operation (cpp_printer.cpp): what the printer writes inline the
// lowering computes in place, what it names the lowering keeps in a register.
class FunctionLowering {
 public:
  FunctionLowering(const LoweredPlan& plan, const Function& fn, Registers& regs, std::vector<Instruction>& code)
      : plan_(plan), fn_(fn), regs_(regs), code_(code), temp_reg_(fn.num_temps, -1) {}

  // Runs every step; returns the registers of each group's outputs, in order.
  std::vector<std::vector<int>> lower() {
    std::vector<std::vector<int>> outputs(fn_.groups.size());
    for (size_t g = 0; g < fn_.groups.size(); ++g) outputs[g].assign(fn_.groups[g].outputs.size(), -1);
    for (const auto& s : fn_.steps) {
      switch (s.kind) {
        case Function::StepKind::define: temp_reg_[s.temp] = body(s.node); break;
        case Function::StepKind::store: regs_.pre_slot[s.slot] = value(s.node); break;
        case Function::StepKind::assign: outputs[s.group][s.output] = assignment(s.node, s.sign); break;
        default: break;  // guards: the tape prunes per request instead (TapeModel)
      }
    }
    return outputs;
  }

 private:
  int emit(TapeOp op, int a, int b = 0) {
    const int dst = regs_.fresh();
    code_.push_back({op, dst, a, b});
    return dst;
  }

  int assignment(int id, int sign) {
    const auto& n = plan_.node(id);
    if (sign > 0) return value(id);
    if (n.kind == Kind::sum && n.dynamic && fn_.temp[id] < 0) return sum(id, -1);
    return emit(TapeOp::neg, value(id));  // -x*y is (-x)*y in C++: the same number
  }

  int value(int id) {
    const auto& n = plan_.node(id);
    switch (n.leaf) {
      case Leaf::state: return regs_.t.x_reg(n.index);
      case Leaf::input: return regs_.t.u_reg(n.index);
      case Leaf::param: return regs_.t.p_reg(n.index);
      case Leaf::constant: return regs_.of_constant(n.value);
      case Leaf::none: break;
    }
    if (fn_.temp[id] >= 0) return temp_reg_[fn_.temp[id]];
    if (!fn_.precompute && !n.dynamic) return regs_.pre_slot.at(plan_.precompute_slot(id));
    return body(id);
  }

  int sum(int id, int outer) {
    const auto& n = plan_.node(id);
    int acc = -1;
    for (size_t i : plan_.sum_order(id, outer)) {
      const bool plus = n.sign[i] * outer > 0;
      const int term = value(n.args[i]);
      if (acc < 0) acc = plus ? term : emit(TapeOp::neg, term);
      else acc = emit(plus ? TapeOp::add : TapeOp::sub, acc, term);
    }
    return acc;
  }

  int body(int id) {
    const auto& n = plan_.node(id);
    switch (n.kind) {
      case Kind::sum: return sum(id, 1);
      case Kind::prod: {  // the factors multiplied left to right, then the divisions
        int acc = -1;
        std::vector<int> divisors;
        for (size_t i : plan_.operand_order(id)) {
          const int a = n.args[i];
          if (plan_.is_inline_division(fn_, a)) {
            divisors.push_back(value(plan_.node(a).args[0]));
          } else {
            const int r = value(a);
            acc = acc < 0 ? r : emit(TapeOp::mul, acc, r);
          }
        }
        if (acc < 0) acc = regs_.of_constant(1.0);
        for (int d : divisors) acc = emit(TapeOp::div, acc, d);
        return acc;
      }
      case Kind::recip: {
        // Operands first, each in a statement of its own (and in GCC's order, which the
        // arguments of one call had): a call's argument order is the compiler's, and it
        // numbers registers and orders instructions.
        const int divisor = value(n.args[0]);
        const int one = regs_.of_constant(1.0);
        return emit(TapeOp::div, one, divisor);
      }
      case Kind::call: return call(n);
      case Kind::leaf: break;
    }
    throw std::logic_error("tape_builder: a leaf has no body");
  }

  int call(const LoweredPlan::Node& n) {
    if (n.text == "pow") {
      const int exponent = value(n.args[1]);  // GCC's order, as at Kind::recip
      const int base = value(n.args[0]);
      return emit(TapeOp::pow, base, exponent);
    }
    static const std::map<std::string, TapeOp> unary = {{"sin", TapeOp::sin},       {"cos", TapeOp::cos},
                                                        {"log", TapeOp::log},       {"abs_value", TapeOp::abs},
                                                        {"sign_of", TapeOp::sign}};
    const auto it = unary.find(n.text);
    if (it == unary.end()) throw std::logic_error("tape_builder: no instruction for " + n.text);
    return emit(it->second, value(n.args[0]));
  }

  const LoweredPlan& plan_;
  const Function& fn_;
  Registers& regs_;
  std::vector<Instruction>& code_;
  std::vector<int> temp_reg_;
};

// Group 0 (f or h) as a column; the Jacobians in their sparse pattern.
runtime::TapeFunction lower_function(const LoweredPlan& plan, const Function& fn, Registers& regs,
                                     const std::vector<const SparsePattern*>& patterns) {
  runtime::TapeFunction out;
  const auto regs_of = FunctionLowering(plan, fn, regs, out.code).lower();
  for (size_t g = 0; g < regs_of.size(); ++g) {
    runtime::SparseOutputs s;
    for (size_t k = 0; k < regs_of[g].size(); ++k) {
      s.row.push_back(g == 0 ? static_cast<int>(k) : patterns[g - 1]->rows[k]);
      s.col.push_back(g == 0 ? 0 : patterns[g - 1]->cols[k]);
      s.reg.push_back(regs_of[g][k]);
    }
    out.groups.push_back(std::move(s));
  }
  return out;
}

}  // namespace

runtime::Tape build_tape(const SymbolicModel& m) {
  runtime::Tape t;
  t.nx = static_cast<int>(m.states.size());
  t.nu = static_cast<int>(m.inputs.size());
  t.np = static_cast<int>(m.params.size());
  t.ny = static_cast<int>(m.h.rows());
  for (const auto& v : m.states) t.state_names.push_back(v.name);
  for (const auto& v : m.inputs) t.input_names.push_back(v.name);
  for (const auto& v : m.params) {
    t.param_names.push_back(v.name);
    t.nominal.push_back(v.nominal);
    t.param_units.push_back(v.unit);
    t.param_lower.push_back(v.lower);
    t.param_upper.push_back(v.upper);
    t.param_fit.push_back(v.fit ? 1 : 0);
  }
  t.input_delay_param = m.input_delay_param ? static_cast<int>(*m.input_delay_param) : -1;
  t.rotor_speed_states.assign(m.rotor_speed_states.begin(), m.rotor_speed_states.end());

  const LoweredModel lm = lower_model(m);
  Registers regs{t, t.nx + t.nu + t.np, {}, std::vector<int>(lm.plan->precompute_count(), -1)};
  FunctionLowering(*lm.plan, lm.precompute, regs, t.precompute).lower();
  t.rhs = lower_function(*lm.plan, lm.rhs, regs, {&lm.dfdx, &lm.dfdu, &lm.dfdp});
  t.measurement = lower_function(*lm.plan, lm.measurement, regs, {&lm.dhdx, &lm.dhdp});
  t.num_registers = regs.next;
  return t;
}

}  // namespace quadgen::codegen
