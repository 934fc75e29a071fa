// `quadgen compare` as a library call: two vehicle files, each derived as `quadgen derive`
// would (its `fitted:` section's effects and values included), and what differs between the
// two derivations (audit/derivation_comparison.hpp).
#pragma once
#include <functional>
#include <string>
#include <vector>

namespace quadgen::app {

struct CompareJob {
  std::string vehicle_a, vehicle_b;
  std::string effects;  // for both: comma-separated, or "all"; "": none (or each file's fitted ones)
  std::function<void(const std::string&)> progress;  // before each derivation and the comparison
};

struct CompareJobResult {
  std::string text;  // what the command prints
  std::vector<std::string> notes;  // "A: ..." or "B: ...": a file's fitted values for another vehicle
  bool same = false;
};

// Throws the layers' own errors (a bad vehicle file, with file and line) unchanged.
CompareJobResult run_compare_job(const CompareJob& job);

}  // namespace quadgen::app
