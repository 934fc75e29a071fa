// A hash-consed expression DAG built from GiNaC expressions, in a canonical form that
// does not depend on the order symbols were created in: commutative operands are sorted
// by a structural key computed from variable names and exact constants. Identical
// subexpressions anywhere in f, ∂f/∂x, ∂f/∂u and ∂f/∂p become one node (CSE).
#pragma once
#include <cstdint>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include <ginac/ginac.h>

#include "derive/symbolic_model.hpp"

namespace quadgen::codegen {

enum class Op { constant, state, input, param, add, mul, div, ipow, pow, sin, cos, log, abs, sign };

struct Node {
  Op op;
  std::vector<int> args;  // child node ids
  long exponent = 0;      // ipow
  std::string literal;    // constant: decimal text, round-trip exact for double
  int index = -1;         // state/input/param index
  uint64_t key = 0;       // structural hash, independent of symbol creation order
  bool dynamic = false;   // depends on x or u (else: parameters only -> precompute)
};

enum class VarKind { state, input, param };

class ExpressionGraph {
 public:
  // Registers the symbols of each kind; their names feed the structural keys.
  void declare(VarKind kind, const std::vector<std::pair<GiNaC::symbol, std::string>>& vars);
  int add(const GiNaC::ex& e);  // returns the node id of e
  const Node& node(int id) const { return nodes_[id]; }
  size_t size() const { return nodes_.size(); }
  // Operation count of e written out as a tree (no sharing): the "before CSE" count.
  double tree_ops(int id);

 private:
  int intern(Node n);
  int constant(const GiNaC::numeric& v);
  int make_sorted(Op op, std::vector<int> args);
  // e = coefficient * node, with the node's sign canonical: GiNaC writes a sum as
  // (a - b) or -(b - a) depending on its internal term order, so signs of sums are
  // pulled out into the coefficient of the enclosing product.
  std::pair<GiNaC::numeric, int> canon(const GiNaC::ex& e);
  std::pair<GiNaC::numeric, int> canon_add(const GiNaC::ex& e);
  std::pair<GiNaC::numeric, int> canon_mul(const GiNaC::ex& e);
  std::pair<GiNaC::numeric, int> canon_function(const GiNaC::ex& e);
  int scaled(const GiNaC::numeric& c, int id);  // node for c * node

  std::vector<Node> nodes_;
  std::map<std::tuple<int, std::vector<int>, long, std::string, int>, int> unique_;
  std::map<GiNaC::ex, std::pair<GiNaC::numeric, int>, GiNaC::ex_is_less> memo_;
  std::map<GiNaC::ex, std::pair<VarKind, int>, GiNaC::ex_is_less> vars_;
  std::map<GiNaC::ex, std::string, GiNaC::ex_is_less> names_;
  std::map<int, double> tree_ops_;
};

// A graph with the model's states, inputs and parameters declared.
void declare_model_variables(ExpressionGraph& g, const SymbolicModel& m);

// The text of a constant in generated code and in the graph's keys: the shortest decimal
// that reads back as the same double.
std::string double_literal(double v);

}  // namespace quadgen::codegen
