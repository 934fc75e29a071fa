// Subcommands of the quadgen executable (README "What each command writes").
#pragma once
#include <set>
#include <string>

#include <CLI/CLI.hpp>

#include "derive_command.hpp"
#include "diagnose_job.hpp"
#include "fit_pipeline.hpp"
#include "predict_flights.hpp"

namespace quadgen::cli {

struct SimulateArgs {
  std::string vehicle, scenario, inputs, out, effects;
  double duration = 0;
  std::string integrator = "rk4";
  double step = 1e-3;
  double rate = 100;
  std::string interpolation = "hold";
  // Closed-loop flight generator.
  bool closed_loop = false;
  unsigned seed = 1;
  std::vector<std::string> set;  // NAME=VALUE overrides of the true model's parameters
  double pose_noise = 1e-3, gyro_noise = 0, gyro_bias = 0, accel_noise = 0, accel_bias = 0;
  double amplitude = 0.8, height = 1.0, height_amplitude = 0.3, yaw_amplitude = 0.8, excitation = 0, tether = 0,
         yaw_per_speed = 0;
  bool no_size_limit = false;
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
  predict::PredictFlightsOptions options;  // the flags land here; defaults are the library's
};
void add_predict(CLI::App& app, PredictArgs& args);
int run_predict(const PredictArgs& args);

}  // namespace quadgen::cli
