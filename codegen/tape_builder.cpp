#include "codegen/tape_builder.hpp"

#include <cstdlib>
#include <functional>

#include "codegen/expression_graph.hpp"

namespace quadgen::codegen {
using namespace GiNaC;
using runtime::Instruction;
using runtime::TapeOp;

namespace {

struct Builder {
  ExpressionGraph& g;
  runtime::Tape& t;
  std::vector<int> reg;  // node -> register, -1 until emitted
  int next = 0;

  int fresh() { return next++; }

  void emit(int id, std::vector<Instruction>& code) {
    if (reg[id] >= 0) return;
    const Node& n = g.node(id);
    switch (n.op) {
      case Op::state: reg[id] = t.x_reg(n.index); return;
      case Op::input: reg[id] = t.u_reg(n.index); return;
      case Op::param: reg[id] = t.p_reg(n.index); return;
      case Op::constant:
        reg[id] = fresh();
        t.constants.push_back({reg[id], std::strtod(n.literal.c_str(), nullptr)});
        return;
      default: break;
    }
    for (int a : n.args) emit(a, code);
    auto binary_chain = [&](TapeOp op) {
      int acc = reg[n.args[0]];
      for (size_t i = 1; i < n.args.size(); ++i) {
        const int dst = fresh();
        code.push_back({op, dst, acc, reg[n.args[i]], 0});
        acc = dst;
      }
      return acc;
    };
    const int a = reg[n.args[0]];
    const int b = n.args.size() > 1 ? reg[n.args[1]] : 0;
    auto unary = [&](TapeOp op, long k = 0) {
      const int dst = fresh();
      code.push_back({op, dst, a, b, k});
      return dst;
    };
    switch (n.op) {
      case Op::add: reg[id] = binary_chain(TapeOp::add); break;
      case Op::mul: reg[id] = binary_chain(TapeOp::mul); break;
      case Op::div: reg[id] = unary(TapeOp::div); break;
      case Op::ipow: reg[id] = unary(TapeOp::ipow, n.exponent); break;
      case Op::pow: reg[id] = unary(TapeOp::pow); break;
      case Op::sin: reg[id] = unary(TapeOp::sin); break;
      case Op::cos: reg[id] = unary(TapeOp::cos); break;
      case Op::log: reg[id] = unary(TapeOp::log); break;
      case Op::abs: reg[id] = unary(TapeOp::abs); break;
      case Op::sign: reg[id] = unary(TapeOp::sign); break;
      default: break;
    }
  }

  // Parameter-only sub-DAGs first (precompute), then the dynamic nodes into `code`.
  void emit_split(int id, std::vector<Instruction>& code) {
    std::function<void(int)> pre = [&](int k) {
      const Node& n = g.node(k);
      if (!n.dynamic) {
        emit(k, t.precompute);
        return;
      }
      for (int a : n.args) pre(a);
    };
    pre(id);
    emit(id, code);
  }
};

}  // namespace

runtime::Tape build_tape(const SymbolicModel& m) {
  runtime::Tape t;
  t.nx = static_cast<int>(m.states.size());
  t.nu = static_cast<int>(m.inputs.size());
  t.np = static_cast<int>(m.params.size());
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

  ExpressionGraph g;
  declare_model_variables(g, m);
  const lst constants = m.constant_substitution();
  std::vector<int> f_nodes;
  for (unsigned i = 0; i < m.f.rows(); ++i) f_nodes.push_back(g.add(m.f(i, 0).subs(constants)));
  struct Jac {
    const matrix* J;
    runtime::SparseOutputs* out;
    std::vector<Instruction>* code;
    std::vector<int> nodes;
  };
  // Each Jacobian's structural non-zeros (constants substituted already), row-major.
  const auto add_nonzeros = [&](std::vector<Jac>& group) {
    for (auto& j : group)
      for (unsigned r = 0; r < j.J->rows(); ++r)
        for (unsigned c = 0; c < j.J->cols(); ++c)
          if (!(*j.J)(r, c).is_zero()) {
            j.out->row.push_back(static_cast<int>(r));
            j.out->col.push_back(static_cast<int>(c));
            j.nodes.push_back(g.add((*j.J)(r, c)));
          }
  };
  std::vector<Jac> jacs = {{&m.dfdx, &t.dfdx, &t.dfdx_code, {}},
                           {&m.dfdp, &t.dfdp, &t.dfdp_code, {}},
                           {&m.dfdu, &t.dfdu, &t.dfdu_code, {}}};
  add_nonzeros(jacs);
  std::vector<int> h_nodes;
  for (unsigned i = 0; i < m.h.rows(); ++i) h_nodes.push_back(g.add(m.h(i, 0).subs(constants)));
  std::vector<Jac> hjacs = {{&m.dhdx, &t.dhdx, &t.h_code, {}}, {&m.dhdp, &t.dhdp, &t.h_code, {}}};
  add_nonzeros(hjacs);
  Builder b{g, t, std::vector<int>(g.size(), -1), t.nx + t.nu + t.np};
  for (int id : f_nodes) {
    b.emit_split(id, t.f_code);
    t.f_out.push_back(b.reg[id]);
  }
  // Registers of f (and of precomputed nodes) are shared; each Jacobian gets its own code
  // for the rest, starting from the state after f.
  const std::vector<int> after_f = b.reg;
  const auto start_after_f = [&] {
    std::vector<int> own = after_f;
    for (size_t k = 0; k < own.size(); ++k)  // precompute nodes emitted meanwhile stay shared
      if (b.reg[k] >= 0 && !g.node(static_cast<int>(k)).dynamic) own[k] = b.reg[k];
    b.reg = own;
  };
  for (auto& j : jacs) {
    start_after_f();
    for (int id : j.nodes) {
      b.emit_split(id, *j.code);
      j.out->reg.push_back(b.reg[id]);
    }
  }
  // The measurement and its Jacobians: one piece of code, from the registers after f.
  t.ny = static_cast<int>(m.h.rows());
  start_after_f();
  for (int id : h_nodes) {
    b.emit_split(id, t.h_code);
    t.h_out.push_back(b.reg[id]);
  }
  for (auto& j : hjacs)
    for (int id : j.nodes) {
      b.emit_split(id, t.h_code);
      j.out->reg.push_back(b.reg[id]);
    }
  t.num_registers = b.next;
  return t;
}

}  // namespace quadgen::codegen
