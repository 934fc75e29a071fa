// Checks shared by the subcommands' flags: numbers that are finite and in range (CLI11's Range
// lets NaN through), NAME=VALUE pairs, and which options a command line actually gave.
#pragma once
#include <cmath>
#include <cstdlib>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>

#include <CLI/CLI.hpp>

namespace quadgen::cli {

// A finite number of the whole text, or nothing.
inline bool parse_finite(const std::string& text, double* value) {
  if (text.empty()) return false;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size() || !std::isfinite(v)) return false;
  *value = v;
  return true;
}

inline std::string range_text(double lo, double hi) {
  std::ostringstream os;
  os << "[" << lo << ", " << hi << "]";
  return os.str();
}

// A finite number within [lo, hi]; the message names the accepted range.
inline CLI::Validator finite_range(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& s) -> std::string {
        double v = 0;
        if (!parse_finite(s, &v)) return "'" + s + "' is not a finite number (accepted: " + range_text(lo, hi) + ")";
        if (v < lo || v > hi) return s + " is outside the accepted range " + range_text(lo, hi);
        return {};
      },
      "in " + range_text(lo, hi));
}

// The long names of the options of `sub` that the command line gave.
inline std::set<std::string> given_options(const CLI::App* sub) {
  std::set<std::string> given;
  for (const CLI::Option* o : sub->get_options())
    if (o->count() > 0 && !o->get_lnames().empty()) given.insert("--" + o->get_lnames().front());
  return given;
}

}  // namespace quadgen::cli
