// Which parameter values predict a log: read from quadgen's own outputs (a diagnosis.json or
// a fit.json), per log. A diagnosis of several flights holds some parameters per flight
// (motor trims, the marker frame, wind: `flight_parameters`); a log it was fitted to is
// predicted with that flight's own values, any other log with the airframe's values (the
// per-flight ones at their mean). For a log no fit has seen, the flight's own parameters
// can be calibrated on its first part, the airframe's held: the honest way to carry a model
// fitted on some flights to another ("fit on some, predict the others").
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "runtime/dynamic_model.hpp"
#include "fit/flight_data.hpp"
#include "fit/least_squares.hpp"

namespace quadgen::predict {

class ParameterSource {
 public:
  // Reads and checks the file (path in every error message).
  explicit ParameterSource(const std::string& path);
  const std::string& path() const { return path_; }
  // The vehicle the file was fitted for (its "vehicle" field), "" if it names none.
  std::string vehicle() const;

  struct ForLog {
    std::vector<double> values;      // the model's whole parameter vector
    std::string origin;              // where they come from, for the user
    int flight = 0;                  // 1-based flight of the diagnosis this log is; 0: none
    std::vector<int> flight_params;  // indices of the parameters that belong to a flight
  };
  // The values for `log` on top of the model's nominal ones. Every name must be a parameter
  // of the model.
  ForLog for_log(const runtime::DynamicModel& model, const std::string& log) const;

 private:
  std::string path_;
  nlohmann::json json_;
  const char* key_ = nullptr;                // "final_fit" or "estimates"
  std::vector<std::string> flights_;         // the logs a diagnosis was fitted to, canonical
  std::vector<std::string> flight_params_;   // names (without @k) that belong to a flight
  void set(const runtime::DynamicModel& model, const nlohmann::json& entries, const char* key,
           std::vector<double>& p) const;
};

// Fits the parameters `free` (indices into `start`; everything else held) on `part` with the
// equation error (pose-differentiated, or the accelerometer when no pose is logged).
// `bounds` gives each parameter's name, unit and bounds (its value is ignored).
std::vector<double> calibrate(runtime::DynamicModel& model, const std::vector<double>& start,
                              const std::vector<int>& free, const std::vector<fit::FitParameter>& bounds,
                              const fit::Flight& part);

}  // namespace quadgen::predict
