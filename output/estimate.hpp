// One shape for an estimate in every JSON output (fit.json, diagnosis.json, prediction
// sources): {"value", "unit", "ci95": [lower, upper], "identifiability", "at_bound"}.
// A side of the interval that is open (the profile never crossed the threshold) or was not
// computed is null; identifiability is null when it was not assessed. Outputs add fields of
// their own after these five (standard error, bounds, how the interval was found).
#pragma once
#include <cmath>
#include <string>

#include <nlohmann/json.hpp>

namespace quadgen::output {

struct Estimate {
  double value = 0;
  std::string unit;
  double lower = NAN, upper = NAN;  // 95 % interval; NaN: open, or not computed
  std::string identifiability;      // "identifiable", "practically non-identifiable", ...; "": not assessed
  bool at_bound = false;            // ended on a bound of the fit
};

// A number in JSON, or null for NaN and infinities (an open interval side, a missing value).
nlohmann::ordered_json number_or_null(double v);

nlohmann::ordered_json estimate_json(const Estimate& e);

}  // namespace quadgen::output
