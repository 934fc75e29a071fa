// Fuzz target: the flight-log reader, canonical-layout validation, resampling and the
// preparation for fitting. Only LogError / FitError may come out.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fit/flight_data.hpp"
#include "runtime/flight_log.hpp"
#include "fit/least_squares.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const auto table = quadgen::runtime::parse_csv(text, "fuzz.csv");
    quadgen::runtime::validate_canonical(table, {"A", "B", "C", "D"});
    quadgen::fit::FlightOptions o;
    o.min_samples = 2;
    o.airborne_only = false;
    const auto flight = quadgen::fit::load_flight(table, {"A", "B", "C", "D"}, o);
    if (flight.samples.empty()) __builtin_trap();
    const auto resampled = quadgen::fit::resample(table, 50.0);
    (void)resampled;
  } catch (const quadgen::runtime::LogError&) {
  } catch (const quadgen::fit::FitError&) {
  }
  return 0;
}
