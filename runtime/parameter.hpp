// A model parameter as it travels from the vehicle file to the outputs: name, SI unit, value,
// the bounds a fit keeps it in, and whether a fit frees it by default (the vehicle file's
// `fit`; an effect's parameters are freed by the effect search). The generated header and the
// tape carry all of it, so a fit needs no symbolic derivation when a compiled header matches.
// fit::FitParameter is this record.
#pragma once
#include <cmath>
#include <sstream>
#include <string>

namespace quadgen::runtime {

struct Parameter {
  std::string name, unit;
  double value = 0, lower = 0, upper = 0;
  bool free = true;
};

// Why `value` cannot be given to `p` from outside (predict --params, simulate --set), or ""
// when it can: not finite; with `within_bounds`, outside p's bounds where it has any (lower <
// upper; `derive --params` holds values to the same); the rigid body's mass and principal
// moments of inertia not positive, which the model would integrate without a word (a test
// flight's truth may lie outside what a fit searches, so simulate checks no bounds).
inline std::string value_problem(const Parameter& p, double value, bool within_bounds) {
  std::ostringstream os;
  if (!std::isfinite(value)) {
    os << "is not finite";
  } else if (within_bounds && p.lower < p.upper && (value < p.lower || value > p.upper)) {
    os << "= " << value << " is outside its bounds [" << p.lower << ", " << p.upper << "]";
  } else if ((p.name == "mass" || p.name == "J_xx" || p.name == "J_yy" || p.name == "J_zz") && !(value > 0)) {
    os << "= " << value << ": a mass and a principal moment of inertia must be positive";
  }
  return os.str();
}

}  // namespace quadgen::runtime
