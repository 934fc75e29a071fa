// `quadgen derive` as a library call: a vehicle file (and the fitted values to give it) in;
// out, in memory, the files the command writes (model.hpp, model.json, derivation.md) and
// what it prints. The command line writes the files as one output set.
#pragma once
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "model/vehicle.hpp"

namespace quadgen::app {

struct DeriveJob {
  std::string vehicle;  // vehicle file (YAML)
  std::string effects;  // comma-separated effects, or "all"; "": none (or the fitted ones)
  std::string params;   // fitted_parameters.yaml from diagnose: its effects and values; "": none
  // Called before each step with its description ("mass properties of 13 blocks", "audit"):
  // kDeriveJobSteps times.
  std::function<void(const std::string&)> progress;
};
inline constexpr int kDeriveJobSteps = 4;

struct DeriveJobResult {
  std::vector<std::pair<std::string, std::string>> files;  // name, contents
  std::string summary;  // what the command prints: the model's size, the audit, op counts, mass properties
  std::string note;     // for the terminal: parameters fitted for another vehicle; "" if none
  bool audit_passed = false;
};

// `vehicle`: job.vehicle as load_vehicle read it (the command line reads it first, so that a bad
// vehicle file is reported before anything is created). Throws the layers' own errors (a bad
// parameter file, with file and line) unchanged.
DeriveJobResult run_derive_job(const DeriveJob& job, const Vehicle& vehicle);

}  // namespace quadgen::app
