// Turns the expression DAG into C++ statements. The canonical DAG (expression_graph) is
// rewritten into an emission form first:
//   - products and quotients become monomials c * prod(base^e); the parameter-only part of
//     every mixed product (constants, parameters, their quotients) is one precomputed
//     value, so divisions by parameters (mass, det J, ...) happen in precompute() only;
//   - dynamic denominators become shared reciprocals (one division per distinct
//     denominator);
//   - common factors of all terms of a sum are factored out, parameter-only terms of a
//     sum are one precomputed value;
//   - greedy pair extraction: the operand pair (of products, and the signed term pair of
//     sums) shared by the most nodes becomes a node of its own, repeatedly;
//   - signs become subtractions instead of multiplications by -1.
// Then parameter-only nodes go to a precompute step, shared nodes become named
// temporaries, single-use nodes are inlined. Deterministic: every id of the emission form
// is assigned in a traversal that follows output order and the canonical operand order
// of the graph, and every tie is broken by those ids.
#pragma once
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "codegen/expression_graph.hpp"

namespace quadgen::codegen {

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
  // Must be called with every function's outputs before emitting any of them: it builds
  // the emission form of all outputs jointly and plans the precompute step.
  void plan_precompute(const std::vector<OutputGroup>& all_groups);
  EmittedPrecompute emit_precompute();
  // Emits the given groups (each must have been passed to plan_precompute).
  EmittedFunction emit_function(const std::vector<OutputGroup>& groups);

  // Emission-form node kinds.
  enum class Kind { leaf, sum, prod, recip, call };

 private:
  struct INode {
    Kind kind;
    std::vector<int> args;          // sum: terms; prod: factors (sorted, repeats = powers); recip/call: args
    std::vector<signed char> sign;  // sum: +1/-1 per term
    std::string text;               // leaf: C++ text; call: function name
    bool dynamic = false;           // depends on x or u
  };
  struct Mono {  // coeff * prod(base^exp), factors sorted by id
    double coeff = 1;
    std::vector<std::pair<int, int>> f;
  };
  struct Signed {
    int sign;
    int id;
  };

  int intern(INode n);
  int leaf(const std::string& text, bool dynamic);
  int constant(double v);
  int prod(std::vector<int> factors);
  int sum(std::vector<std::pair<int, int>> terms);  // (id, sign)
  int recip(int id);
  int call(const std::string& name, std::vector<int> args);
  int negate(int id);
  Mono convert(int gid);
  Mono make_sum(std::vector<Mono> terms);
  Signed materialize(const Mono& m);
  int materialize_positive(const Mono& m);
  void extract_pairs(Kind kind);
  int rebuild(int id, const std::vector<std::vector<int>>& args, const std::vector<std::vector<signed char>>& sign,
              std::vector<int>& memo);
  std::vector<int> reachable(Kind kind) const;

  std::string render(int id, const std::vector<int>& temp, const std::vector<int>& uses, bool pre_region,
                     double& ops, bool as_operand) const;
  std::string render_sum(int id, int outer_sign, const std::vector<int>& temp, const std::vector<int>& uses,
                         bool pre_region, double& ops) const;

  ExpressionGraph& g_;
  std::vector<INode> ir_;
  std::map<std::tuple<int, std::vector<int>, std::vector<signed char>, std::string>, int> unique_;
  std::map<int, Mono> memo_;                 // graph node -> monomial
  std::map<int, Signed> out_;                // graph output node -> emission node with sign
  std::vector<Signed> roots_;                // every output, in order
  std::vector<int> pre_slot_;                // emission node -> precompute slot, or -1
  std::vector<int> pre_order_;
};

}  // namespace quadgen::codegen
