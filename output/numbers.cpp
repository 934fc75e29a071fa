#include "output/numbers.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include <nlohmann/json.hpp>

#include "output/sinks.hpp"

namespace quadgen::output {

namespace {
// v with `digits` significant digits (as %g). -0 (a vehicle file's "-0", a product of 0 and a
// negative number) is printed as 0: "-0" in a message or a report reads as a sign that
// matters, and nothing here tells the two apart.
std::string with_digits(double v, int digits) {
  std::ostringstream os;
  os.precision(digits);
  os << (v == 0 ? 0.0 : v);
  return os.str();
}
}  // namespace

std::string short_number(double v) { return with_digits(v, 3); }

std::string percent_text(double fraction) { return short_number(100 * fraction) + " %"; }

std::string six_digits(double v) { return with_digits(v, 6); }

namespace {
constexpr double kSmallestPrintedP = 1e-300;
bool below_printed(double p) { return p >= 0 && p < kSmallestPrintedP; }
}  // namespace

std::string p_value_cell(double p) {
  if (!std::isfinite(p)) return "–";
  return below_printed(p) ? "< " + short_number(kSmallestPrintedP) : short_number(p);
}

std::string p_is(double p) { return (below_printed(p) ? "p " : "p = ") + p_value_cell(p); }

bool equal_but_for_rounding(double a, double b) {
  return std::fabs(a - b) <= 1e-12 * std::max(std::fabs(a), std::fabs(b));
}

std::string full_number(double v) {
  // std::to_chars without a format gives the shortest text that reads back as v, plain or
  // scientific, whichever is shorter ("100", "0.1", "1e+22"); %g with the fewest digits
  // that read back would give "1e+02" for 100 (a review, helper-112).
  if (!std::isfinite(v)) return with_digits(v, 17);
  char text[32];
  const auto written = std::to_chars(text, text + sizeof text, v == 0 ? 0.0 : v);
  return std::string(text, written.ptr);
}

std::string unit_for_reading(const std::string& unit) {
  static const char* const kRaised[] = {"⁰", "¹", "²", "³", "⁴", "⁵", "⁶", "⁷", "⁸", "⁹"};
  std::string out;
  for (size_t at = 0; at < unit.size(); ++at) {
    if (unit[at] != '^') {
      out += unit[at];
      continue;
    }
    const size_t digits = at + 1 + (unit.compare(at + 1, 1, "-") == 0 ? 1 : 0);
    size_t end = digits;
    while (end < unit.size() && unit[end] >= '0' && unit[end] <= '9') ++end;
    if (end == digits) {  // not a power: "^T", a '^' at the end, a name's '^'
      out += unit[at];
      continue;
    }
    if (digits > at + 1) out += "⁻";
    for (size_t k = digits; k < end; ++k) out += kRaised[unit[k] - '0'];
    at = end - 1;
  }
  return out;
}

std::string unit_after_number(const std::string& unit) {
  return unit.empty() || unit == "1" ? "" : " " + unit_for_reading(unit);
}

std::string one_then_other(double a, double b, const std::string& separator) {
  for (int digits = 6;; ++digits) {
    const std::string x = with_digits(a, digits), y = with_digits(b, digits);
    if (x != y || a == b || digits >= 17) return x + separator + y;
  }
}

NumberText read_number(const std::string& text, double* value) {
  if (text.find_first_of("xX") != std::string::npos) return NumberText::not_a_number;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  // The whole text: strtod stops at a NUL ("1\0junk") or any other character.
  if (end == text.c_str() || end != text.c_str() + text.size()) return NumberText::not_a_number;
  if (!std::isfinite(v)) return NumberText::not_finite;
  // 0 from a mantissa with a digit other than 0 is a number below a double's smallest (looked
  // at only for a 0: a log's every cell passes here).
  if (v == 0 && text.find_first_of("123456789") < text.find_first_of("eE")) return NumberText::underflow;
  *value = v;
  return NumberText::finite;
}

std::string hexadecimal_hint(const std::string& text) {
  size_t i = text.find_first_not_of(" \t\n\v\f\r");
  if (i != std::string::npos && (text[i] == '+' || text[i] == '-')) ++i;
  const bool hexadecimal = i != std::string::npos && i + 1 < text.size() && text[i] == '0' &&
                           (text[i + 1] == 'x' || text[i + 1] == 'X');
  return hexadecimal ? "; hexadecimal is not read, write it in decimal" : "";
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

namespace {

// Walks JSON text and keeps the first floating-point number's text that underflows; a SAX pass
// sees each number as written, which the parsed document no longer does.
struct UnderflowFinder : nlohmann::json::json_sax_t {
  std::string found;
  bool null() override { return true; }
  bool boolean(bool) override { return true; }
  bool number_integer(number_integer_t) override { return true; }
  bool number_unsigned(number_unsigned_t) override { return true; }
  bool number_float(number_float_t, const string_t& text) override {
    double v = 0;
    if (read_number(text, &v) == NumberText::underflow) found = text;
    return found.empty();  // stop at the first
  }
  bool string(string_t&) override { return true; }
  bool binary(binary_t&) override { return true; }
  bool start_object(std::size_t) override { return true; }
  bool key(string_t&) override { return true; }
  bool end_object() override { return true; }
  bool start_array(std::size_t) override { return true; }
  bool end_array() override { return true; }
  bool parse_error(std::size_t, const std::string&, const nlohmann::json::exception&) override { return false; }
};

}  // namespace

std::string json_number_below_a_double(const std::string& json_text) {
  UnderflowFinder finder;
  nlohmann::json::sax_parse(json_text, &finder);
  return finder.found;
}

std::string json_number_problem(const std::string& json_text) {
  const std::string tiny = json_number_below_a_double(json_text);
  return tiny.empty() ? "" : "the number " + printable(tiny) + " " + number_text_problem(NumberText::underflow);
}

}  // namespace quadgen::output
