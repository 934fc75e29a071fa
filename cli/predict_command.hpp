// quadgen predict: its flags, the arguments they land in and the command's run (the pipeline
// itself is a library call: predict/predict_flights.cpp).
#pragma once
#include <set>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "predict/predict_flights.hpp"

namespace quadgen::cli {

struct PredictArgs {
  std::string vehicle, out;
  std::vector<std::string> logs;
  std::string mapping, environment;
  predict::PredictFlightsOptions options;  // the flags land here; defaults are the library's
};
void add_predict(CLI::App& app, PredictArgs& args);
int run_predict(const PredictArgs& args);

}  // namespace quadgen::cli
