// `quadgen predict` as a library call: a vehicle and its logs in; out, in memory, the files
// the command writes (prediction.json, prediction.csv, prediction.svg) and what it prints.
// The model is the vehicle's with every effect, at its neutral value unless --params sets it.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "predict/predict_flights.hpp"

namespace quadgen::app {

struct PredictJob {
  std::string vehicle;            // vehicle file (YAML)
  std::vector<std::string> logs;  // one or more flights of it
  std::string mapping;            // column mapping (YAML) for logs not in the canonical layout
  // "indoor", "outdoor" or "unknown"; empty: the mapping's environment, else unknown.
  std::string environment;
  predict::PredictFlightsOptions options;
};

struct PredictJobResult {
  std::vector<std::pair<std::string, std::string>> files;  // name, contents
  std::string summary;             // what the command prints: error at each horizon, what limits it
  std::vector<std::string> notes;  // for the terminal: a plot that could not be drawn
  // Non-empty when the run did not succeed although its files were made: an open-loop error
  // that is not finite is a model that left its range (commands, units or parameters wrong).
  std::string failure;
};

// `vehicle`: job.vehicle as load_vehicle read it (the command line reads it first). Throws
// std::invalid_argument for contradicting options, and the layers' own errors (a bad log,
// with file and line) unchanged.
PredictJobResult run_predict_job(const PredictJob& job, const Vehicle& vehicle);

// What the command prints of a prediction (PredictJobResult::summary): the error at each
// horizon, the views without a model's parts, what limits it, the one-step errors.
std::string prediction_summary(const predict::Prediction& pooled);

}  // namespace quadgen::app
