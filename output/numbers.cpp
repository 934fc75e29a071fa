#include "output/numbers.hpp"

#include <cmath>
#include <cstdlib>
#include <sstream>

namespace quadgen::output {

std::string short_number(double v) {
  std::ostringstream os;
  os.precision(3);
  os << v;
  return os.str();
}

std::string six_digits(double v) {
  std::ostringstream os;
  os.precision(6);
  os << v;
  return os.str();
}

std::string full_number(double v) {
  std::ostringstream os;
  os.precision(17);
  os << v;
  return os.str();
}

std::string one_then_other(double a, double b) {
  for (int digits = 6;; ++digits) {
    std::ostringstream x, y;
    x.precision(digits);
    y.precision(digits);
    x << a;
    y << b;
    if (x.str() != y.str() || a == b || digits >= 17) return x.str() + " then " + y.str();
  }
}

NumberText read_number(const std::string& text, double* value) {
  if (text.find_first_of("xX") != std::string::npos) return NumberText::not_a_number;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  // The whole text: strtod stops at a NUL ("1\0junk") or any other character.
  if (end == text.c_str() || end != text.c_str() + text.size()) return NumberText::not_a_number;
  if (!std::isfinite(v)) return NumberText::not_finite;
  // 0 from a mantissa with a digit other than 0 is a number below a double's smallest.
  const std::string mantissa = text.substr(0, text.find_first_of("eE"));
  if (v == 0 && mantissa.find_first_of("123456789") != std::string::npos) return NumberText::underflow;
  *value = v;
  return NumberText::finite;
}

std::string number_text_problem(NumberText kind) {
  switch (kind) {
    case NumberText::finite: return "is a finite number";
    case NumberText::not_a_number: return "is not a number";
    case NumberText::not_finite: return "is not finite";
    case NumberText::underflow: return "is below the smallest number a double holds, so it would read as 0";
  }
  return "is not a number";
}

}  // namespace quadgen::output
