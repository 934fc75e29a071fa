#include "derive/exact_number.hpp"

#include <cstdio>
#include <cstdlib>
#include <string>

namespace quadgen {

GiNaC::numeric exact(double v) {
  // Decimal with 15 significant digits: what a person wrote in the file.
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.14e", v);
  std::string s(buf);
  const auto e = s.find('e');
  const int exponent = std::atoi(s.c_str() + e + 1);
  std::string mantissa = s.substr(0, e);
  const bool negative = mantissa[0] == '-';
  if (negative) mantissa.erase(0, 1);
  std::string digits;
  for (char c : mantissa)
    if (c != '.') digits += c;
  while (digits.size() > 1 && digits.back() == '0') digits.pop_back();
  // value = 0.digits... scaled: digits[0].digits[1..] * 10^exponent
  GiNaC::numeric n(digits.c_str());
  const int shift = exponent - static_cast<int>(digits.size() - 1);
  GiNaC::numeric ten(10);
  const GiNaC::numeric scale = ten.power(shift >= 0 ? shift : -shift);
  GiNaC::numeric result = shift >= 0 ? n * scale : n / scale;
  return negative ? -result : result;
}

std::string shortest_text(double v) {
  char buf[40];
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  return buf;
}

}  // namespace quadgen
