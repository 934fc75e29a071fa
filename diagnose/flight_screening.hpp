// Which flights can inform a diagnosis at all. A flight whose motor commands sit at their
// limit in most of its airborne samples (an exhausted battery, a vehicle too heavy for its
// motors) shows only that the controller asked for more than the motors give: the command
// no longer tells the thrust, and the fit bends the airframe to explain it. In a joint
// diagnosis such a flight is left out, and said so; alone, it is diagnosed with a caution.
#pragma once
#include <string>
#include <vector>

#include "fit/flight_data.hpp"

namespace quadgen::diagnose {

// A command at or above this is at its limit (commands are 0..1).
constexpr double kCommandLimit = 0.999;
// A flight with some command at its limit in more than this share of its samples is unusable.
constexpr double kUnusableSaturatedShare = 0.5;

struct FlightScreening {
  std::string source;
  double saturated_share = 0;  // samples with some command at its limit
  bool usable = true;
  std::string reason;    // why not, in words; "" when usable
  bool left_out = false;  // not diagnosed: unusable, among several flights of which some are usable
};

FlightScreening screen_flight(const fit::Flight& f);

}  // namespace quadgen::diagnose
