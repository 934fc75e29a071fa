// Subcommands of the quadgen executable (docs/formats.md, "What each command writes").
#pragma once
#include <set>
#include <string>

#include <CLI/CLI.hpp>

#include "cli/derive_command.hpp"
#include "app/diagnose_job.hpp"
#include "fit/fit_pipeline.hpp"
#include "predict/predict_flights.hpp"
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

struct FitArgs {
  std::string vehicle, log, out, effects, free, channels;
  std::string profiles = "all";  // all | none | comma-separated parameter names
  fit::FitJobOptions options;    // the other flags land here; defaults are the library's
  std::set<std::string> given;   // options on the command line (each fit kind refuses those it does not use)
};
void add_fit(CLI::App& app, FitArgs& args);
int run_fit(const FitArgs& args);

struct DiagnoseArgs {
  app::DiagnoseJob job;  // the flags land here; defaults are the library's
  std::string out;
};
void add_diagnose(CLI::App& app, DiagnoseArgs& args);
int run_diagnose(const DiagnoseArgs& args);

struct PredictArgs {
  std::string vehicle, out;
  std::vector<std::string> logs;
  std::string mapping, environment;
  predict::PredictFlightsOptions options;  // the flags land here; defaults are the library's
};
void add_predict(CLI::App& app, PredictArgs& args);
int run_predict(const PredictArgs& args);

}  // namespace quadgen::cli
