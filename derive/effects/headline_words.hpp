// Small helpers the effects' headlines share: numbers as a reader expects them in a
// sentence, and a fitted value looked up by parameter name.
#pragma once
#include <map>
#include <string>

namespace quadgen::headline {

// Two significant digits (three at 100 and above), no exponent between 0.01 and 10,000.
std::string words(double v);

// The value of `name` among `values`; 0 when it is absent (an effect whose parameter the fit
// held at off).
double value_of(const std::map<std::string, double>& values, const std::string& name);

// "motor_gain.C" -> "C".
std::string after_dot(const std::string& name);

constexpr double kDegreesPerRadian = 180.0 / 3.14159265358979323846;

}  // namespace quadgen::headline
