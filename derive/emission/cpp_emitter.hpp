// Turns the expression DAG into C++ statements: parameter-only nodes go to a precompute
// step, shared nodes become named temporaries, single-use nodes are inlined, integer
// powers become products. Deterministic: traversal follows output order and the
// canonical operand order of the graph.
#pragma once
#include <string>
#include <vector>

#include "expression_graph.hpp"

namespace quadgen::emission {

struct Output {
  std::string target;  // e.g. "f[3]", "dfdx[17]"
  int node;
};

struct OutputGroup {
  std::string guard;  // "" for always; else a pointer tested for nullptr, e.g. "dfdx"
  std::vector<Output> outputs;
};

struct EmittedFunction {
  std::string body;       // statements, indented by two spaces
  double ops_before = 0;  // tree operation count (no sharing)
  double ops_after = 0;   // operations actually emitted (after CSE, excluding precompute)
};

struct EmittedPrecompute {
  std::string body;
  int count = 0;  // number of precomputed values
  double ops = 0;
};

class CppEmitter {
 public:
  explicit CppEmitter(ExpressionGraph& g) : g_(g) {}
  // Must be called with every function's outputs before emitting any of them, so the
  // precompute step covers all parameter-only subexpressions.
  void plan_precompute(const std::vector<OutputGroup>& all_groups);
  EmittedPrecompute emit_precompute();
  EmittedFunction emit_function(const std::vector<OutputGroup>& groups);

 private:
  std::string render(int id, const std::vector<int>& temp_id, bool as_operand) const;
  std::string leaf(int id) const;
  double node_ops(int id) const;

  ExpressionGraph& g_;
  std::vector<int> pre_slot_;  // node -> slot in the precompute array, or -1
  std::vector<int> pre_order_;
};

}  // namespace quadgen::emission
