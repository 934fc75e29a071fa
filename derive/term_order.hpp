// The one order in which quadgen writes the operands of a sum or a product: the derivation
// report (audit/tex_writer) prints them in it, and the generated code (codegen/lowered_plan)
// emits them in it, so that a reviewer reads a term of the report and the same term of the
// header in the same order.
//
// An operand's support is the set of the model's variables it depends on, each at its place in
// reading order: the vehicle's fixed numbers (rotor geometry), the parameters, the inputs, the
// states, each group in the model's declaration order (the tables of the report), then any
// other symbol (the report's named quantities such as the rotor speed, by name). Operands
// compare by their supports, place by place: numbers (no support) first, then what depends on
// earlier variables, a support that begins another one before it. So the coefficient comes
// before what it multiplies and a polynomial is written by rising powers:
//   omega = a0 + a1 u + a2 u^2,   F = rho c_t omega^2.
// Operands with equal supports keep an order each writer breaks deterministically (the
// report by their text, the code generator by its node ids); the code generator's sums and
// products are also grouped for speed (common factors, shared pairs), so the order holds
// within each sum and product as emitted.
#pragma once
#include <algorithm>
#include <map>
#include <string>
#include <vector>

#include <ginac/ginac.h>

#include "derive/symbolic_model.hpp"

namespace quadgen::term_order {

enum class Group { constant, parameter, input, state, other };

// A variable's place in reading order; `name` orders the symbols outside the model.
struct Place {
  Group group;
  int index = 0;
  std::string name;
};
bool operator<(const Place& a, const Place& b);
bool operator==(const Place& a, const Place& b);

using Support = std::vector<Place>;  // sorted, without repeats

Support merged(const Support& a, const Support& b);
// True when an operand with support a is written before one with support b.
bool before(const Support& a, const Support& b);

// A sum is written from its first added term (no leading minus where the sum has a plus),
// the others after it in the order above: moves the first element of [begin, end) for which
// added(element) holds to the front, keeping the order of the rest.
template <class It, class Added>
void first_added_first(It begin, It end, Added added) {
  const It first = std::find_if(begin, end, added);
  if (first != end) std::rotate(begin, first, first + 1);
}

// The supports of a symbolic model's expressions (memoised per subexpression).
class SymbolPlaces {
 public:
  explicit SymbolPlaces(const SymbolicModel& m);
  const Support& support(const GiNaC::ex& e);

 private:
  std::map<GiNaC::ex, Place, GiNaC::ex_is_less> places_;
  std::map<GiNaC::ex, Support, GiNaC::ex_is_less> memo_;
};

}  // namespace quadgen::term_order
