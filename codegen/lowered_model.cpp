#include "codegen/lowered_model.hpp"

namespace quadgen::codegen {
using namespace GiNaC;

SparsePattern nonzeros(const matrix& J) {
  SparsePattern s;
  for (unsigned i = 0; i < J.rows(); ++i)
    for (unsigned j = 0; j < J.cols(); ++j)
      if (!J(i, j).is_zero()) {
        s.rows.push_back(static_cast<int>(i));
        s.cols.push_back(static_cast<int>(j));
        s.values.push_back(J(i, j));
      }
  return s;
}

LoweredModel lower_model(const SymbolicModel& m) {
  LoweredModel lm;
  lm.graph = std::make_unique<ExpressionGraph>();
  ExpressionGraph& g = *lm.graph;
  declare_model_variables(g, m);
  const lst constants = m.constant_substitution();
  // f and h carry the constants as symbols (for the unit audit and the report); the
  // Jacobians have them substituted already (SymbolicModel).
  auto nodes = [&](const std::string& target, const std::vector<ex>& values, bool substitute) {
    std::vector<Output> out;
    for (size_t i = 0; i < values.size(); ++i)
      out.push_back({target + "[" + std::to_string(i) + "]", g.add(substitute ? values[i].subs(constants) : values[i])});
    return out;
  };
  std::vector<ex> f, h;
  for (unsigned i = 0; i < m.f.rows(); ++i) f.push_back(m.f(i, 0));
  for (unsigned i = 0; i < m.h.rows(); ++i) h.push_back(m.h(i, 0));
  lm.dfdx = nonzeros(m.dfdx);
  lm.dfdu = nonzeros(m.dfdu);
  lm.dfdp = nonzeros(m.dfdp);
  lm.dhdx = nonzeros(m.dhdx);
  lm.dhdp = nonzeros(m.dhdp);
  const std::vector<OutputGroup> rhs = {{"", nodes("f", f, true)},
                                        {"dfdx", nodes("dfdx", lm.dfdx.values, false)},
                                        {"dfdu", nodes("dfdu", lm.dfdu.values, false)},
                                        {"dfdp", nodes("dfdp", lm.dfdp.values, false)}};
  const std::vector<OutputGroup> meas = {{"", nodes("h", h, true)},
                                         {"dhdx", nodes("dhdx", lm.dhdx.values, false)},
                                         {"dhdp", nodes("dhdp", lm.dhdp.values, false)}};
  std::vector<OutputGroup> all = rhs;
  all.insert(all.end(), meas.begin(), meas.end());
  lm.plan = std::make_unique<LoweredPlan>(g, all);
  lm.precompute = lm.plan->precompute_function();
  lm.rhs_f = lm.plan->function({rhs[0]});
  lm.rhs = lm.plan->function(rhs);
  lm.rotor_speed_rates =
      lm.plan->part_of(lm.rhs, 0, std::vector<int>(m.rotor_speed_states.begin(), m.rotor_speed_states.end()));
  lm.measurement = lm.plan->function(meas);
  return lm;
}

}  // namespace quadgen::codegen
