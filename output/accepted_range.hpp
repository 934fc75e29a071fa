// The values an option accepts, [lo, hi], written once beside its options struct: the
// library's IsValid and the command line's check both read it. Written twice they had drifted
// (diagnose --alpha: 1e-12 passed the library and not the command line; a review, helper-138).
#pragma once
#include <string>

#include "output/numbers.hpp"

namespace quadgen::output {

struct AcceptedRange {
  double lo = 0, hi = 0;
  constexpr bool contains(double v) const { return v >= lo && v <= hi; }  // false for NaN
  // "0.1 to 0.6 s": for a message that says what was expected.
  std::string text(const std::string& unit = "") const {
    return short_number(lo) + " to " + short_number(hi) + (unit.empty() ? "" : " " + unit);
  }
};

}  // namespace quadgen::output
