// Small helpers the effects' headlines share: numbers as a reader expects them in a
// sentence, and a fitted value looked up by parameter name.
#pragma once
#include <map>
#include <string>

#include "runtime/attitude.hpp"

namespace quadgen::headline {

// A number for a sentence: between 0.01 and 10,000 with fixed decimals, none from 100 ("208"),
// one from 1 ("37.5", "8.0"), two below 1 ("0.35", "0.05"); outside that range two significant
// digits with an exponent ("1.4e-06").
std::string words(double v);

// The value of `name` among `values`; 0 when it is absent (an effect whose parameter the fit
// held at off).
double value_of(const std::map<std::string, double>& values, const std::string& name);

// "motor_gain.C" -> "C".
std::string after_dot(const std::string& name);

// How one motor is said to differ from the reference motor, e.g. for thrust
// {" gives ", " ", "less", "more", " thrust", ""}:
// "Motor C gives 8.0 % less thrust than motor A; motor D 3.1 % more."
struct MotorComparisonWords {
  const char* first_lead;      // after the first motor's letter
  const char* lead;            // after every later motor's letter
  const char* less;
  const char* more;
  const char* first_tail;      // after the first motor's amount
  const char* reference_tail;  // after the reference motor's letter
};

// One sentence over the per-motor values (a fraction each, e.g. -0.08 for 8 % less), each
// against `reference` (left out when empty).
std::string motor_comparison(const std::map<std::string, double>& values, const std::string& reference,
                             const MotorComparisonWords& w);

using runtime::kDegreesPerRadian;

}  // namespace quadgen::headline
