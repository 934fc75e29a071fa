#include "runtime/parameter.hpp"

#include <cmath>

#include "output/numbers.hpp"
#include "output/sinks.hpp"

namespace quadgen::runtime {

std::string unit_problem(const Parameter& p, const std::string& unit) {
  if (unit == p.unit) return "";
  return "is in " + output::printable(p.unit) + ", the file says '" + output::printable(unit) + "'";
}

std::string value_problem(const Parameter& p, double value, bool within_bounds) {
  using output::short_number;
  if (!std::isfinite(value)) return "is not finite";
  if (within_bounds && p.lower < p.upper && (value < p.lower || value > p.upper))
    return "= " + short_number(value) + " is outside its bounds [" + short_number(p.lower) + ", " + short_number(p.upper) + "]";
  // The names the vehicle file's derived section gives them (model/vehicle.hpp).
  const bool must_be_positive = p.name == "mass" || p.name == "J_xx" || p.name == "J_yy" || p.name == "J_zz";
  if (must_be_positive && !(value > 0))
    return "= " + short_number(value) + ": a mass and a principal moment of inertia must be positive";
  const bool area = p.name == "A_x" || p.name == "A_y" || p.name == "A_z";
  if (area && value < 0) return "= " + short_number(value) + ": an exposed area cannot be negative";
  // Battery sag scales the thrust by (vbat / vbat_ref)^exponent (a review, helper-88: 0 divided
  // by zero in derive's hover check, -3 was flown).
  if (p.name == "vbat_ref" && !(value > 0))
    return "= " + short_number(value) + ": a battery voltage must be positive (the thrust scales with vbat / vbat_ref)";
  return "";
}

}  // namespace quadgen::runtime
