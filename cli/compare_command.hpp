// quadgen compare: its flags (two vehicle files, the effects to derive both with).
#pragma once
#include <string>

#include <CLI/CLI.hpp>

namespace quadgen::cli {

struct CompareArgs {
  std::string vehicle_a, vehicle_b;
  std::string effects;
  bool exit_code = false;  // --exit-code: 1 where the derivations differ
};

void add_compare(CLI::App& app, CompareArgs& args);
// 0: compared (every subcommand exits 0 on success); with --exit-code, 1 where the two
// derivations differ (as `git diff --exit-code` has it); 2: an error.
int run_compare(const CompareArgs& args);

}  // namespace quadgen::cli
