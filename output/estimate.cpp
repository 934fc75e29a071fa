#include "output/estimate.hpp"

namespace quadgen::output {

nlohmann::ordered_json number_or_null(double v) {
  return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(nullptr);
}

nlohmann::ordered_json estimate_json(const Estimate& e) {
  using J = nlohmann::ordered_json;
  return J{{"value", number_or_null(e.value)},
           {"unit", e.unit},
           {"ci95", J::array({number_or_null(e.lower), number_or_null(e.upper)})},
           {"identifiability", e.identifiability.empty() ? J(nullptr) : J(e.identifiability)},
           {"at_bound", e.at_bound}};
}

}  // namespace quadgen::output
