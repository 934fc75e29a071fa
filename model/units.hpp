// Physical units: parsing unit strings into a scale to SI and a dimension vector (no
// GiNaC: the vehicle file and the log mappings read units; audit/dimension_checker.hpp
// checks the dimensions of expressions).
#pragma once
#include <array>
#include <map>
#include <stdexcept>
#include <string>

namespace quadgen {

// Exponents of the SI base dimensions the models use: length, mass, time, current.
// Angles (rad) are dimensionless, as in SI.
struct Dimension {
  std::array<int, 4> exp{0, 0, 0, 0};  // m, kg, s, A

  bool dimensionless() const { return exp == std::array<int, 4>{0, 0, 0, 0}; }
  bool operator==(const Dimension& o) const { return exp == o.exp; }
  bool operator!=(const Dimension& o) const { return exp != o.exp; }
  Dimension operator*(const Dimension& o) const;
  Dimension operator/(const Dimension& o) const;
  Dimension pow(int n) const;
  std::string str() const;  // e.g. "kg m s^-2", "1"
};

// Standard gravity [m/s^2] (CGPM 1901): a gram-force in newtons is 1e-3 of it, and an
// accelerometer logged in g reads in m/s^2 times it.
inline constexpr double kStandardGravity = 9.80665;

// A parsed unit: value_in_SI = value_in_unit * scale.
struct Unit {
  double scale = 1.0;
  Dimension dim;
};

struct UnitError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Exponents ("m^n") are bounded, per factor and per base dimension of the whole unit.
constexpr int kMaxUnitExponent = 12;

// Parses "kg m^2", "N s/m", "m/s^2", "rpm", "rev/s", "deg", "1". Throws UnitError.
//
// Angles: rad is dimensionless (as in SI), so "rad/s" and "1/s" are the same unit, deg is
// pi/180 and rev is 2 pi; rpm is rev/min = 2 pi/60 rad/s. "Hz" is refused with a hint
// ("1/s" or "rev/s"): with rad dimensionless it would have to mean either 1/s or 2 pi rad/s,
// and whichever were chosen, a value written with the other meaning in mind would pass
// the dimension check and be off by 2 pi. Exponents beyond kMaxUnitExponent are refused.
Unit parse_unit(const std::string& text);

}  // namespace quadgen
