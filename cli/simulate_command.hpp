// quadgen simulate: its flags, the arguments they land in and the command's run (the pipeline
// itself is a library call: app/simulate_job.cpp).
#pragma once
#include <set>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "app/simulate_job.hpp"

namespace quadgen::cli {

struct SimulateArgs {
  app::SimulateJob job;          // the flags land here
  std::string out;
  std::vector<std::string> set;  // NAME=VALUE overrides of the true model's parameters, parsed into job.set
  std::string ground;            // "start" or a height [m], parsed into job.ground_*; "": none
};

void add_simulate(CLI::App& app, SimulateArgs& args);
int run_simulate(const SimulateArgs& args);

}  // namespace quadgen::cli
