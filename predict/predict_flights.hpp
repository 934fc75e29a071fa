// `quadgen predict` as a pipeline: logs in, prediction errors out (per flight and pooled),
// with the parameter values each log is predicted with (predict/parameter_source.hpp) and,
// for a log the diagnosis has not seen, its own parameters calibrated on the part before
// the evaluated one. The command line only turns flags into PredictFlightsOptions.
#pragma once
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "runtime/dynamic_model.hpp"
#include "fit/flight_data.hpp"
#include "fit/least_squares.hpp"
#include "output/accepted_range.hpp"
#include "output/progress.hpp"
#include "predict/prediction.hpp"
#include "model/effect.hpp"
#include "model/vehicle.hpp"

namespace quadgen::predict {

// The controllers PredictFlightsOptions::set_point_controller may name (the CLI's choices too).
inline const std::vector<std::string> kSetPointControllers = {"crazyflie-pid"};

// The values PredictFlightsOptions accepts (its IsValid and the command line's checks).
inline constexpr output::AcceptedRange kPredictValidationRange{0.05, 1};  // fraction evaluated
inline constexpr output::AcceptedRange kControllerGainRange{0.05, 20};
inline constexpr output::AcceptedRange kStartStrideRange{0.001, 10};      // s
inline constexpr output::AcceptedRange kDisturbanceWindowRange{0, 10};    // s

struct PredictFlightsOptions {
  // The column mapping for logs not in the canonical layout, read once (fit::load_mapping).
  std::optional<fit::ColumnMapping> mapping;
  double resample = 0;   // resample each log onto a uniform grid at this rate [Hz] first (0: no)
  double validation = 0.3;  // fraction of each flight (at its end) evaluated; 1: all of it
  std::string params;    // a fit.json or diagnosis.json; empty: the vehicle file's nominal values
  bool calibrate = false;   // fit an unseen log's own parameters on the part before (needs params)
  // Where the flights were flown: a calibrated value outside what is plausible there (a
  // steady wind indoors) is said, as diagnose says a stand-in.
  Environment environment = Environment::kUnknown;
  // Also the one-step errors left after a linear correction fitted on the part before
  // (linearly_corrected_one_step; needs validation below 1).
  bool linear_correction = false;
  // Also fly each log's attitude set points (phi_ref, theta_ref) with this controller: "" (not
  // run) or one of kSetPointControllers (crazyflie-pid: runtime::AttitudePidOptions' defaults,
  // mixed by the vehicle's rotor positions). Sets prediction.set_points; a log without set
  // points is refused.
  std::string set_point_controller;
  double controller_output_scale = 1;  // runtime::AttitudePidOptions::output_scale
  PredictionOptions prediction;
  output::Progress progress;  // which log, calibration, notes; nowhere by default

  // Ceres-style: false with a reason for a value no prediction can use (predict_flights
  // throws it).
  bool IsValid(std::string* error) const;
};

struct PredictedFlights {
  Prediction pooled;             // every flight's errors together
  nlohmann::ordered_json json;   // prediction.json: pooled errors and one entry per flight
};

// `bounds`: every parameter of `model` with its name, unit and bounds (for calibration).
// Throws std::invalid_argument for options that contradict each other.
PredictedFlights predict_flights(const Vehicle& v, runtime::DynamicModel& model,
                                 const std::vector<fit::FitParameter>& bounds, const std::vector<std::string>& logs,
                                 const PredictFlightsOptions& o);

}  // namespace quadgen::predict
