// Dimensional analysis of GiNaC expressions, for the audit of a derivation.
#pragma once
#include <map>

#include <ginac/ginac.h>

#include "model/units.hpp"

namespace quadgen {

// Dimensional analysis: maps every symbol to its dimension and infers the dimension
// of an expression, requiring every term of a sum to agree and every function
// argument and symbolic exponent to be dimensionless.
class DimensionChecker {
 public:
  void declare(const GiNaC::symbol& s, const Dimension& d);
  // Returns the dimension or throws UnitError naming the offending sub-expression.
  Dimension infer(const GiNaC::ex& e) const;

 private:
  std::map<GiNaC::ex, Dimension, GiNaC::ex_is_less> dims_;
};

}  // namespace quadgen
