#include "model/units.hpp"
#include "output/joined.hpp"

#include <cmath>
#include <sstream>

namespace quadgen {

Dimension Dimension::operator*(const Dimension& o) const {
  Dimension r;
  for (int i = 0; i < 4; ++i) r.exp[i] = exp[i] + o.exp[i];
  return r;
}
Dimension Dimension::operator/(const Dimension& o) const {
  Dimension r;
  for (int i = 0; i < 4; ++i) r.exp[i] = exp[i] - o.exp[i];
  return r;
}
Dimension Dimension::pow(int n) const {
  Dimension r;
  for (int i = 0; i < 4; ++i) r.exp[i] = exp[i] * n;
  return r;
}
std::string Dimension::str() const {
  static const char* names[] = {"m", "kg", "s", "A"};
  std::ostringstream os;
  bool first = true;
  for (int i = 0; i < 4; ++i) {
    if (exp[i] == 0) continue;
    if (!first) os << ' ';
    first = false;
    os << names[i];
    if (exp[i] != 1) os << '^' << exp[i];
  }
  return first ? "1" : os.str();
}

namespace {

Unit base(double scale, int m, int kg, int s, int a) {
  Unit u;
  u.scale = scale;
  u.dim.exp = {m, kg, s, a};
  return u;
}

const std::map<std::string, Unit>& unit_table() {
  const double pi = 3.14159265358979323846;
  static const std::map<std::string, Unit> table = {
      {"1", base(1, 0, 0, 0, 0)},        {"rad", base(1, 0, 0, 0, 0)},
      {"deg", base(pi / 180, 0, 0, 0, 0)}, {"m", base(1, 1, 0, 0, 0)},
      {"mm", base(1e-3, 1, 0, 0, 0)},    {"cm", base(1e-2, 1, 0, 0, 0)},
      {"kg", base(1, 0, 1, 0, 0)},       {"g", base(1e-3, 0, 1, 0, 0)},
      {"s", base(1, 0, 0, 1, 0)},        {"ms", base(1e-3, 0, 0, 1, 0)},
      {"min", base(60, 0, 0, 1, 0)},     {"A", base(1, 0, 0, 0, 1)},
      {"N", base(1, 1, 1, -2, 0)},       {"V", base(1, 2, 1, -3, -1)},
      {"W", base(1, 2, 1, -3, 0)},
      {"rev", base(2 * pi, 0, 0, 0, 0)},        // one revolution = 2 pi rad
      {"rpm", base(2 * pi / 60, 0, 0, -1, 0)},  // revolutions per minute -> rad/s
  };
  return table;
}

// Units that are refused rather than given one of two meanings (see units.hpp).
const std::map<std::string, std::string>& refused_units() {
  static const std::map<std::string, std::string> refused = {
      {"Hz", "is ambiguous here (rad is dimensionless, so 1 Hz could be 1/s or 2 pi rad/s): write '1/s' for a rate "
             "or 'rev/s' for a rotation rate (2 pi rad/s)"},
  };
  return refused;
}

// The exponent after '^': an optional sign and decimal digits, at most kMaxUnitExponent in
// magnitude. Parsed by hand: std::stoi would overflow (UB in the multiplication later) or
// throw out_of_range for long digit strings.
int parse_exponent(const std::string& p, const std::string& whole) {
  size_t i = 0;
  bool negative = false;
  if (i < p.size() && (p[i] == '+' || p[i] == '-')) negative = p[i++] == '-';
  if (i == p.size()) throw UnitError("unit '" + whole + "': exponent '" + p + "' is not an integer");
  int value = 0;
  for (; i < p.size(); ++i) {
    if (p[i] < '0' || p[i] > '9') throw UnitError("unit '" + whole + "': exponent '" + p + "' is not an integer");
    value = value * 10 + (p[i] - '0');
    if (value > kMaxUnitExponent) break;  // stop before the digits can overflow
  }
  if (value > kMaxUnitExponent)
    throw UnitError("unit '" + whole + "': exponent '" + p + "' is out of range (expected |n| <= " +
                    std::to_string(kMaxUnitExponent) + ")");
  return negative ? -value : value;
}

// One factor "name" or "name^k".
Unit parse_factor(const std::string& tok, const std::string& whole) {
  std::string name = tok;
  int power = 1;
  auto caret = tok.find('^');
  if (caret != std::string::npos) {
    name = tok.substr(0, caret);
    power = parse_exponent(tok.substr(caret + 1), whole);
  }
  const auto refused = refused_units().find(name);
  if (refused != refused_units().end()) throw UnitError("unit '" + whole + "': '" + name + "' " + refused->second);
  auto it = unit_table().find(name);
  if (it == unit_table().end()) {
    const std::string known = output::joined(unit_table(), ", ", [](const auto& entry) { return entry.first; });
    throw UnitError("unit '" + whole + "': unknown unit '" + name + "' (known: " + known + ", combined as in \"kg m^2\", \"N s/m\")");
  }
  Unit u;
  u.scale = std::pow(it->second.scale, power);
  u.dim = it->second.dim.pow(power);
  return u;
}

}  // namespace

Unit parse_unit(const std::string& text) {
  // Grammar: factors separated by spaces or '*'; one optional '/' after which all
  // factors are in the denominator ("N s/m", "kg/m^3", "1/s").
  Unit result;
  bool denominator = false;
  int before_slash = 0, after_slash = 0;  // factors on each side
  std::string tok;
  auto flush = [&]() {
    if (tok.empty()) return;
    ++(denominator ? after_slash : before_slash);
    Unit f = parse_factor(tok, text);
    if (denominator) {
      result.scale /= f.scale;
      result.dim = result.dim / f.dim;
    } else {
      result.scale *= f.scale;
      result.dim = result.dim * f.dim;
    }
    tok.clear();
    // Many bounded factors could still add up ("m^12 m^12 ..."): bound the whole unit too.
    for (int e : result.dim.exp)
      if (e > kMaxUnitExponent || e < -kMaxUnitExponent)
        throw UnitError("unit '" + text + "': combined exponent " + std::to_string(e) + " is out of range (expected |n| <= " +
                        std::to_string(kMaxUnitExponent) + ")");
  };
  if (text.empty()) throw UnitError("empty unit (write \"1\" for dimensionless)");
  for (char c : text) {
    if (c == ' ' || c == '*') {
      flush();
    } else if (c == '/') {
      flush();
      if (denominator) throw UnitError("unit '" + text + "': more than one '/'");
      denominator = true;
    } else {
      tok += c;
    }
  }
  flush();
  // Separators alone (" ", "/", "** mm*/") read as 1 or as mm (a review, helper-135).
  if (before_slash + after_slash == 0) throw UnitError("unit '" + text + "' holds no unit, only separators (write \"1\" for dimensionless)");
  if (denominator && (before_slash == 0 || after_slash == 0))
    throw UnitError("unit '" + text + "': nothing " + (before_slash == 0 ? "before" : "after") + " '/' (write 1/s for per second)");
  return result;
}

}  // namespace quadgen
