#include "derive/symbolic_functions.hpp"

namespace quadgen {
using namespace GiNaC;

static ex abs_value_eval(const ex& x) {
  if (is_exactly_a<numeric>(x)) return abs(ex_to<numeric>(x));
  return abs_value(x).hold();
}
static ex abs_value_evalf(const ex& x) {
  if (is_exactly_a<numeric>(x)) return abs(ex_to<numeric>(x));
  return abs_value(x).hold();
}
static ex abs_value_deriv(const ex& x, unsigned) { return sign_of(x); }
static void abs_value_latex(const ex& x, const print_context& c) {
  c.s << "\\left|";
  x.print(c);
  c.s << "\\right|";
}

static ex sign_of_eval(const ex& x) {
  if (is_exactly_a<numeric>(x) && ex_to<numeric>(x).is_real()) {
    const numeric& n = ex_to<numeric>(x);
    return n.is_zero() ? ex(0) : ex(n.csgn());
  }
  return sign_of(x).hold();
}
static ex sign_of_deriv(const ex&, unsigned) { return 0; }
static void sign_of_latex(const ex& x, const print_context& c) {
  c.s << "\\operatorname{sgn}\\left(";
  x.print(c);
  c.s << "\\right)";
}

REGISTER_FUNCTION(abs_value, eval_func(abs_value_eval)
                                 .evalf_func(abs_value_evalf)
                                 .derivative_func(abs_value_deriv)
                                 .print_func<print_latex>(abs_value_latex)
                                 .set_name("abs_value", "\\left|\\cdot\\right|"))
REGISTER_FUNCTION(sign_of, eval_func(sign_of_eval)
                               .evalf_func(sign_of_eval)
                               .derivative_func(sign_of_deriv)
                               .print_func<print_latex>(sign_of_latex)
                               .set_name("sign_of", "\\operatorname{sgn}"))
}  // namespace quadgen
