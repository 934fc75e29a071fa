// Prints a function of the lowered plan as C++ statements (the bodies that
// templates/model.hpp.mustache wraps): temporaries as `const Scalar tN`, precomputed
// values as `pre.c[k]`, sums with their first positive term first, and a reciprocal used
// once as a division.
#pragma once
#include <string>

#include "codegen/lowered_plan.hpp"

namespace quadgen::codegen {

struct PrintedFunction {
  std::string body;       // statements, indented by two spaces
  double ops_before = 0;  // tree operation count (no sharing)
  double ops_after = 0;   // operations actually printed (after CSE, excluding precompute)
};

PrintedFunction print_cpp(const LoweredPlan& plan, const LoweredPlan::Function& fn);

}  // namespace quadgen::codegen
