// `quadgen fit` as a library call: a vehicle and one log in; the log's columns choose the kind
// of fit (motor steps, a thrust stand or a flight); out, in memory, the files the command
// writes (fit.json, plots) and what it prints. cli/fit_command.cpp turns flags into a FitJob.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "fit/fit_pipeline.hpp"

namespace quadgen::app {

struct FitJob {
  std::string log;      // a flight log, motor steps or a thrust stand
  std::string effects;  // a flight: comma-separated effects to add to the model, or "all"; "": none
  fit::FitJobOptions options;
};

struct FitJobResult {
  std::vector<std::pair<std::string, std::string>> files;  // name, contents: fit.json and plots
  std::string summary;                // what the command prints: the estimates and their intervals
  std::vector<std::string> notes;     // for the terminal after the work: a plot not drawn (raw)
  std::vector<std::string> warnings;  // what to look at before trusting the result (raw)
};

// `vehicle`: the vehicle file as load_vehicle read it; `kind`: fit::log_kind(job.log) (the
// command line reads both first, the kind to refuse the flags it does not take before any
// work). The options are checked before anything is built (IsValidFor: an option set that
// the log's kind does not read, effects on a log that is no flight included, is an error).
// The vehicle's fitted section and the model fitted are said through job.options.progress.
// Throws the layers' own errors (a bad log, with file and line) unchanged.
FitJobResult run_fit_job(const FitJob& job, const Vehicle& vehicle, fit::LogKind kind);

}  // namespace quadgen::app
