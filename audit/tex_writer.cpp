#include "audit/tex_writer.hpp"

#include <algorithm>
#include <sstream>

#include "output/joined.hpp"
#include "output/sinks.hpp"

namespace quadgen {
using namespace GiNaC;

namespace {

// GiNaC's own printing, for leaves only (a symbol's TeX name, a number): deterministic.
std::string ginac_tex(const ex& e) {
  std::ostringstream os;
  os << latex << e;
  return os.str();
}

// The sum with every term negated, built term by term (-sum may come back as the product
// (-1) sum, which would be turned around again without end).
ex negated_sum(const ex& sum) {
  exvector terms;
  for (const auto& t : sum) terms.push_back(-t);
  return add(terms);
}

}  // namespace

void TexWriter::sort(std::vector<Written>& v) {
  std::stable_sort(v.begin(), v.end(), [](const Written& a, const Written& b) {  // ties only between equal texts
    if (term_order::before(a.support, b.support)) return true;
    if (term_order::before(b.support, a.support)) return false;
    return a.text < b.text;
  });
}

std::string TexWriter::tex(const ex& e) {
  const auto it = cache_.find(e);
  if (it != cache_.end()) return it->second;
  std::string text = uncached(e);
  cache_.emplace(e, text);
  return text;
}

std::string TexWriter::matrix(const GiNaC::matrix& m) {
  std::ostringstream os;
  os << "\\begin{pmatrix}";
  for (unsigned i = 0; i < m.rows(); ++i) {
    for (unsigned j = 0; j < m.cols(); ++j) os << (j ? " & " : "") << tex(m(i, j));
    os << (i + 1 < m.rows() ? " \\\\ " : "");
  }
  os << "\\end{pmatrix}";
  return os.str();
}

std::string TexWriter::uncached(const ex& e) {
  if (is_a<add>(e)) return sum(e);
  if (is_a<mul>(e)) return product(e);
  if (is_a<GiNaC::power>(e)) return power(e);
  if (is_a<GiNaC::function>(e)) return function(e);
  return ginac_tex(e);  // symbols and numbers
}

// Wrapped in parentheses when it would otherwise bind wrongly as a factor or a base.
std::string TexWriter::operand(const ex& e, bool as_base) {
  const bool wrap = is_a<add>(e) || (as_base && (is_a<mul>(e) || is_a<GiNaC::power>(e))) ||
                    (is_a<numeric>(e) && (ex_to<numeric>(e).is_negative() || !ex_to<numeric>(e).is_integer()));
  return wrap ? "\\left(" + tex(e) + "\\right)" : tex(e);
}

// A sum's terms in the shared order, each as its text without sign and its sign.
std::vector<TexWriter::Written> TexWriter::sorted_terms(const ex& sum) {
  std::vector<Written> terms;
  for (const auto& t : sum) {
    const std::string text = tex(t);  // a term's sign is what its own canonical text shows
    const bool negative = !text.empty() && text[0] == '-';
    terms.push_back({places_.support(t), negative ? text.substr(1) : text, negative});
  }
  sort(terms);
  return terms;
}

// Terms in the shared order, starting with the first one that is added (as the generated
// code writes a sum), a sign in front of each.
std::string TexWriter::sum(const ex& e) {
  std::vector<Written> terms = sorted_terms(e);
  term_order::first_added_first(terms.begin(), terms.end(), [](const Written& w) { return !w.negative; });
  std::string out;
  for (size_t i = 0; i < terms.size(); ++i)
    out += (terms[i].negative ? (i ? " - " : "-") : (i ? " + " : "")) + terms[i].text;
  return out;
}

// GiNaC may keep -(a - b) c as (b - a) c, depending on the process: a sum that is a factor
// is written with its first term (in the shared order) positive, the sign moved to the product.
bool TexWriter::leading_term_negative(const ex& sum) {
  const std::vector<Written> terms = sorted_terms(sum);
  return !terms.empty() && terms.front().negative;
}

// The text of a factor of a product with any sum in it in its canonical sign; flips *sign
// when that text is the factor's negative. Text only: a GiNaC power of the negated sum would
// be evaluated back into the original.
std::string TexWriter::factor_text(const ex& f, bool* sign) {
  if (is_a<add>(f)) {
    const bool negative = leading_term_negative(f);
    if (negative) *sign = !*sign;
    return "\\left(" + tex(negative ? negated_sum(f) : f) + "\\right)";
  }
  if (is_a<GiNaC::power>(f) && is_a<add>(f.op(0)) && is_a<numeric>(f.op(1)) && ex_to<numeric>(f.op(1)).is_integer()) {
    const bool negative = leading_term_negative(f.op(0));
    if (negative && ex_to<numeric>(f.op(1)).is_odd()) *sign = !*sign;
    return "\\left(" + tex(negative ? negated_sum(f.op(0)) : f.op(0)) + "\\right)^{" + tex(f.op(1)) + "}";
  }
  return operand(f, false);
}

// A product: its number first, then the factors in the shared order; factors with negative
// exponents go below a fraction bar.
std::string TexWriter::product(const ex& e) {
  numeric coefficient = 1;
  std::vector<Written> above, below;
  bool flipped = false;
  for (const auto& f : e) {
    if (is_a<numeric>(f)) {
      coefficient *= ex_to<numeric>(f);
    } else if (is_a<GiNaC::power>(f) && is_a<numeric>(f.op(1)) && ex_to<numeric>(f.op(1)).is_negative()) {
      const ex positive = pow(f.op(0), -f.op(1));
      below.push_back({places_.support(positive), factor_text(positive, &flipped)});
    } else {
      above.push_back({places_.support(f), factor_text(f, &flipped)});
    }
  }
  sort(above);
  sort(below);
  const auto join = [](const std::vector<Written>& v) {
    return v.empty() ? std::string("1") : output::joined(v, " ", [](const Written& x) { return x.text; });
  };
  if (flipped) coefficient = -coefficient;
  std::string sign = coefficient.is_negative() ? "-" : "";
  const numeric c = abs(coefficient);
  const numeric num = c.numer(), den = c.denom();
  if (num != 1) above.insert(above.begin(), Written{{}, ginac_tex(num)});
  if (den != 1) below.insert(below.begin(), Written{{}, ginac_tex(den)});
  if (below.empty()) return sign + join(above);
  return sign + "\\frac{" + join(above) + "}{" + join(below) + "}";
}

std::string TexWriter::power(const ex& e) {
  const ex base = e.op(0), exponent = e.op(1);
  if (exponent.is_equal(numeric(1, 2))) return "\\sqrt{" + tex(base) + "}";
  if (is_a<numeric>(exponent) && ex_to<numeric>(exponent).is_negative())
    return "\\frac{1}{" + tex(pow(base, -exponent)) + "}";
  return operand(base, true) + "^{" + tex(exponent) + "}";
}

std::string TexWriter::function(const ex& e) {
  const std::string name = ex_to<GiNaC::function>(e).get_name();
  const bool even = name == "abs_value" || name == "abs";
  const std::string args = output::joined(e, ", ", [&](const ex& a) {
    const bool flip = even && is_a<add>(a) && leading_term_negative(a);  // |-x| = |x|
    return tex(flip ? negated_sum(a) : a);
  });
  if (even) return "\\left|" + args + "\\right|";
  if (name == "sign_of") return "\\operatorname{sgn}\\left(" + args + "\\right)";
  const bool known = name == "sin" || name == "cos" || name == "tan" || name == "exp" || name == "log";
  return (known ? "\\" + name : "\\operatorname{" + output::latex_math_text(name) + "}") + "\\left(" + args + "\\right)";
}

}  // namespace quadgen
