#include "derive/effects/headline_words.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>

namespace quadgen::headline {

std::string words(double v) {
  std::ostringstream os;
  const double a = std::fabs(v);
  if (a != 0 && (a < 0.01 || a >= 1e4)) os << std::setprecision(2) << v;
  else os << std::fixed << std::setprecision(a >= 100 ? 0 : a >= 10 ? 1 : a >= 1 ? 1 : 2) << v;
  return os.str();
}

double value_of(const std::map<std::string, double>& values, const std::string& name) {
  const auto it = values.find(name);
  return it == values.end() ? 0.0 : it->second;
}

std::string after_dot(const std::string& name) { return name.substr(name.find('.') + 1); }

std::string motor_comparison(const std::map<std::string, double>& values, const std::string& reference,
                             const MotorComparisonWords& w) {
  std::ostringstream os;
  bool first = true;
  for (const auto& [name, v] : values) {
    os << (first ? "Motor " : "; motor ") << after_dot(name) << (first ? w.first_lead : w.lead)
       << words(100 * std::fabs(v)) << " % " << (v < 0 ? w.less : w.more) << (first ? w.first_tail : "");
    if (first && !reference.empty()) os << " than motor " << after_dot(reference) << w.reference_tail;
    first = false;
  }
  return os.str() + ".";
}

}  // namespace quadgen::headline
