// quadgen compare: its flags (two vehicle files, the effects to derive both with).
#pragma once
#include <string>

#include <CLI/CLI.hpp>

namespace quadgen::cli {

struct CompareArgs {
  std::string vehicle_a, vehicle_b;
  std::string effects;
};

void add_compare(CLI::App& app, CompareArgs& args);
// 0: the two derivations are the same; 1: they differ (as diff(1) has it); 2: an error.
int run_compare(const CompareArgs& args);

}  // namespace quadgen::cli
