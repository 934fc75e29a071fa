// The one lowered plan that both back ends read: the C++ printer (cpp_printer) and the
// runtime's tape (tape_builder). Neither decides anything about the code on its own; both
// walk the same nodes, temporaries, precompute slots and statements, so a tape evaluates
// exactly the operations, in exactly the order, of the header generated from the same model.
//
// The canonical DAG (expression_graph) is rewritten into an emission form first:
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
// Then parameter-only nodes go to a precompute step, and each function is planned: shared
// nodes become numbered temporaries, single-use nodes are inlined into their user.
// Deterministic: every id of the emission form is assigned in a traversal that follows
// output order and the canonical operand order of the graph, and every tie is broken by
// those ids.
#pragma once
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "codegen/expression_graph.hpp"
#include "derive/term_order.hpp"

namespace quadgen::codegen {

struct Output {
  std::string target;  // e.g. "f[3]", "dfdx[17]"
  int node;            // graph node
};

struct OutputGroup {
  std::string guard;  // "" for always; else a pointer tested for nullptr, e.g. "dfdx"
  std::vector<Output> outputs;
};

class LoweredPlan {
 public:
  // Emission-form node kinds.
  enum class Kind { leaf, sum, prod, recip, call };
  enum class Leaf { none, constant, state, input, param };

  struct Node {
    Kind kind;
    std::vector<int> args;          // sum: terms; prod: factors (sorted, repeats = powers); recip/call: args
    std::vector<signed char> sign;  // sum: +1/-1 per term
    std::string text;               // leaf: C++ text; call: function name
    bool dynamic = false;           // depends on x or u
    Leaf leaf = Leaf::none;         // leaf: what it reads
    int index = -1;                 // leaf: x/u/p index
    double value = 0;               // leaf constant
  };
  struct Signed {
    int sign;
    int id;
  };

  // One function's straight-line program. A node is a temporary (temp[id] >= 0) when used
  // more than once; a reciprocal used once by a product becomes a division there (a
  // back end reads that from `uses`).
  struct Function {
    bool precompute = false;         // the parameter-only region (precompute())
    std::vector<int> uses, temp;     // per node
    int num_temps = 0;
    enum class StepKind {
      define,      // const t<temp> = node
      assign,      // groups[group].outputs[output].target = sign * node
      store,       // pre->c[slot] = node (precompute only)
      open_any,    // if (guard || guard ...) {   the guarded groups' shared temporaries
      open_group,  // if (groups[group].guard) {
      close,
    };
    struct Step {
      StepKind kind;
      int node = -1, temp = -1, group = -1, output = -1, slot = -1;
      int sign = 1;  // assign: the output is sign * node
    };
    std::vector<Step> steps;
    std::vector<OutputGroup> groups;
    double ops_before = 0;  // tree operation count of the outputs (no sharing)
  };

  // Builds the emission form of every output of every group jointly and plans the
  // precompute step; every function planned later must draw from these groups.
  LoweredPlan(ExpressionGraph& g, const std::vector<OutputGroup>& all_groups);

  Function precompute_function() const;
  Function function(const std::vector<OutputGroup>& groups) const;
  // Outputs `outputs` of `full`'s unguarded group `group`, alone: `full`'s steps that they
  // need, with `full`'s use counts and temporaries. Planned on its own (function()), a part
  // would count its uses afresh, and a reciprocal or a negated sum that `full` names as a
  // temporary could be written inline, in other operations; taken out of `full`, every value
  // is computed exactly as `full` computes it.
  Function part_of(const Function& full, int group, const std::vector<int>& outputs) const;

  // Rules both back ends follow to the letter, so that they compute the same operations:
  // the operands of a sum or product are written in the shared reading order
  // (derive/term_order.hpp: by the variables they depend on, then by node id); a sum starts
  // with its first term that is added (sign * outer > 0), then the others in that order; a
  // reciprocal used once by a product, and not a temporary, is a division in that product.
  std::vector<size_t> operand_order(int id) const;
  std::vector<size_t> sum_order(int id, int outer) const;
  bool is_inline_division(const Function& fn, int id) const;

  const Node& node(int id) const { return ir_[id]; }
  size_t size() const { return ir_.size(); }
  Signed output(int graph_node) const { return out_.at(graph_node); }
  int precompute_slot(int id) const { return pre_slot_[id]; }
  int precompute_count() const { return static_cast<int>(pre_order_.size()); }

 private:
  struct Mono {  // coeff * prod(base^exp), factors sorted by id
    double coeff = 1;
    std::vector<std::pair<int, int>> f;
  };

  int intern(Node n);
  int leaf(Leaf kind, int index, const std::string& text, bool dynamic);
  int constant(double v);
  int prod(std::vector<int> factors);
  int sum(std::vector<std::pair<int, int>> terms);  // (id, sign)
  int recip(int id);
  int call(const std::string& name, std::vector<int> args);
  int negate(int id);
  Mono convert(int gid);
  Mono make_sum(std::vector<Mono> terms);
  // make_sum's steps (lowered_plan.cpp): a dynamic base or a parameter-only part shared by
  // terms taken out of them while any is shared, and whether a term has no dynamic base.
  void factor_greedily(std::vector<Mono>& terms);
  bool is_static(const Mono& t) const;
  Signed materialize(const Mono& m);
  int materialize_positive(const Mono& m);
  void extract_pairs(Kind kind);
  int rebuild(int id, const std::vector<std::vector<int>>& args, const std::vector<std::vector<signed char>>& sign,
              std::vector<int>& memo);
  std::vector<int> reachable(Kind kind) const;
  void plan_precompute_slots(const std::vector<OutputGroup>& all_groups);
  void find_supports();
  bool inside(const Function& fn, int id) const;
  void count_use(Function& fn, int id, std::vector<char>& seen) const;
  void define_temporaries(Function& fn, int id, std::vector<char>& done) const;

  ExpressionGraph& g_;
  std::vector<Node> ir_;
  std::map<std::tuple<int, std::vector<int>, std::vector<signed char>, std::string>, int> unique_;
  std::map<int, Mono> memo_;                 // graph node -> monomial
  std::map<int, Signed> out_;                // graph output node -> emission node with sign
  std::vector<Signed> roots_;                // every output, in order
  std::vector<int> pre_slot_;                // emission node -> precompute slot, or -1
  std::vector<int> pre_order_;
  std::vector<term_order::Support> support_;  // emission node -> what it depends on (reachable nodes)
};

}  // namespace quadgen::codegen
