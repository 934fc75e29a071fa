// quadgen fit: its flags, the arguments they land in and the command's run (the pipeline
// itself is a library call: app/fit_job.cpp).
#pragma once
#include <set>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "fit/fit_pipeline.hpp"

namespace quadgen::cli {

struct FitArgs {
  std::string vehicle, log, out, effects, free, channels;
  std::string profiles = "all";  // all | none | comma-separated parameter names
  fit::FitJobOptions options;    // the other flags land here; defaults are the library's
  std::set<std::string> given;   // options on the command line (each fit kind refuses those it does not use)
};
void add_fit(CLI::App& app, FitArgs& args);
int run_fit(const FitArgs& args);

}  // namespace quadgen::cli
