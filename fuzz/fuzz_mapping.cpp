// Fuzz target: a column mapping (YAML) applied to a raw log (CSV), the result validated,
// prepared for fitting and turned into equation-error residuals of the FINken 3 model.
// Input: the mapping, a line "%%", the CSV. Only LogError / FitError may come out.
// The mapping's `unit:` entries go through parse_unit (model/units.cpp) and are checked
// against the canonical columns' dimensions; whatever a unit parses to, its conversion
// factor must be a finite positive number (exponents are bounded), else the target traps.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "runtime/dynamic_model.hpp"
#include "fit/equation_error.hpp"
#include "fit/flight_data.hpp"
#include "runtime/flight_log.hpp"
#include "generated/finken3/model.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const size_t cut = text.find("\n%%\n");
  if (cut == std::string::npos) return 0;
  const std::vector<std::string> rotors{"A", "B", "C", "D"};
  try {
    const auto mapping = quadgen::fit::parse_mapping(text.substr(0, cut), "fuzz.yaml");
    for (const auto& e : mapping.entries)
      if (!(std::isfinite(e.unit_scale) && e.unit_scale > 0)) __builtin_trap();
    const auto raw = quadgen::runtime::parse_csv(text.substr(cut + 4), "fuzz.csv");
    const auto table = quadgen::fit::apply_mapping(raw, mapping);
    quadgen::fit::FlightOptions o;
    o.min_samples = 2;
    o.airborne_only = false;
    o.edge_trim = 0;
    const auto flight = quadgen::fit::load_flight(table, rotors, o);
    quadgen::runtime::CompiledModel<quadgen_generated::finken3::Model> model;
    const bool accel = flight.has_accelerometer && !flight.has_pose;
    const quadgen::fit::EquationErrorModel ee(model, flight, accel);
    std::vector<double> r(static_cast<size_t>(ee.num_residuals()));
    ee.evaluate(model.params().data(), r.data(), nullptr);
  } catch (const quadgen::runtime::LogError&) {
  } catch (const quadgen::fit::FitError&) {
  }
  return 0;
}
