#include "diagnose/flight_screening.hpp"

#include <algorithm>
#include <cstdio>

namespace quadgen::diagnose {

FlightScreening screen_flight(const fit::Flight& f) {
  FlightScreening s;
  s.source = f.source;
  size_t at_limit = 0;
  for (const auto& sample : f.samples)
    if (!sample.u.empty() && *std::max_element(sample.u.begin(), sample.u.end()) >= kCommandLimit) ++at_limit;
  s.saturated_share = f.samples.empty() ? 0.0 : static_cast<double>(at_limit) / static_cast<double>(f.samples.size());
  s.usable = s.saturated_share <= kUnusableSaturatedShare;
  if (!s.usable) {
    char text[160];
    std::snprintf(text, sizeof text, "a motor command is at its limit in %.0f %% of the airborne samples",
                  100 * s.saturated_share);
    s.reason = text;
  }
  return s;
}

}  // namespace quadgen::diagnose
