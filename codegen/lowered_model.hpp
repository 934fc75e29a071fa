// A symbolic model lowered once for every back end: its canonical DAG, the one lowered
// plan, and the five functions a model has (precompute, rhs for f only, the rotor speeds'
// rates, rhs with its Jacobians, the measurement with its Jacobians). header_writer prints
// all five; tape_builder turns precompute, rhs and measurement into the runtime's
// instructions (a tape prunes its rhs to f, or to a few rows, by itself).
#pragma once
#include <memory>
#include <vector>

#include "codegen/expression_graph.hpp"
#include "codegen/lowered_plan.hpp"
#include "derive/symbolic_model.hpp"

namespace quadgen::codegen {

// Jacobian entries that are not structurally zero, row-major.
struct SparsePattern {
  std::vector<int> rows, cols;
  std::vector<GiNaC::ex> values;
};
SparsePattern nonzeros(const GiNaC::matrix& J);

struct LoweredModel {
  std::unique_ptr<ExpressionGraph> graph;  // the plan refers to it
  std::unique_ptr<LoweredPlan> plan;
  SparsePattern dfdx, dfdu, dfdp, dhdx, dhdp;
  LoweredPlan::Function precompute;
  LoweredPlan::Function rhs_f;        // groups: f
  LoweredPlan::Function rotor_speed_rates;  // rhs's steps for f's rotor-speed rows (part_of)
  LoweredPlan::Function rhs;          // groups: f, dfdx, dfdu, dfdp
  LoweredPlan::Function measurement;  // groups: h, dhdx, dhdp
};

LoweredModel lower_model(const SymbolicModel& m);

}  // namespace quadgen::codegen
