#include "audit/dimension_checker.hpp"

#include <sstream>

#include "derive/symbolic_functions.hpp"

namespace quadgen {

void DimensionChecker::declare(const GiNaC::symbol& s, const Dimension& d) { dims_[s] = d; }

Dimension DimensionChecker::infer(const GiNaC::ex& e) const {
  using namespace GiNaC;
  auto fail = [&](const std::string& why) {
    std::ostringstream os;
    os << why << " in " << e;
    throw UnitError(os.str());
  };
  if (is_a<numeric>(e) || is_a<constant>(e)) return Dimension{};
  if (is_a<symbol>(e)) {
    auto it = dims_.find(e);
    if (it == dims_.end()) fail("symbol without a unit");
    return it->second;
  }
  if (is_a<add>(e)) {
    Dimension d = infer(e.op(0));
    for (size_t i = 1; i < e.nops(); ++i) {
      Dimension di = infer(e.op(i));
      if (di != d) {
        std::ostringstream os;
        os << "sum of terms with different units: [" << d.str() << "] " << e.op(0) << " vs ["
           << di.str() << "] " << e.op(i);
        fail(os.str());
      }
    }
    return d;
  }
  if (is_a<mul>(e)) {
    Dimension d;
    for (size_t i = 0; i < e.nops(); ++i) d = d * infer(e.op(i));
    return d;
  }
  if (is_a<power>(e)) {
    Dimension b = infer(e.op(0));
    const ex& x = e.op(1);
    if (b.dimensionless()) {
      if (!infer(x).dimensionless()) fail("exponent with a unit");
      return b;
    }
    if (!is_a<numeric>(x) || !ex_to<numeric>(x).is_rational()) fail("non-rational power of a quantity with a unit");
    const numeric n = ex_to<numeric>(x);
    Dimension r;
    for (int i = 0; i < 4; ++i) {
      numeric v = n * b.exp[i];
      if (!v.is_integer()) fail("fractional power leaves a fractional unit");
      r.exp[i] = v.to_int();
    }
    return r;
  }
  if (is_a<function>(e)) {
    // |x| and sign(x) keep or drop the unit; every other function needs a pure number.
    if (is_ex_the_function(e, abs_value)) return infer(e.op(0));
    if (is_ex_the_function(e, sign_of)) return Dimension{};
    for (size_t i = 0; i < e.nops(); ++i)
      if (!infer(e.op(i)).dimensionless()) fail("function of a quantity with a unit");
    return Dimension{};
  }
  fail("expression type the unit checker does not know");
  return Dimension{};
}

}  // namespace quadgen
