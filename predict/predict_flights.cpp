#include "predict/predict_flights.hpp"

#include <algorithm>
#include <optional>
#include <sstream>
#include <utility>

#include "derive/effects/effect_catalogue.hpp"
#include "fit/log_reader.hpp"
#include "fit/read_flight.hpp"
#include "output/joined.hpp"
#include "output/numbers.hpp"
#include "output/sinks.hpp"
#include "predict/parameter_source.hpp"

namespace quadgen::predict {

namespace {

fit::Flight load(const std::string& path, const Vehicle& v, const PredictFlightsOptions& o) {
  const fit::Flight flight =
      fill_missing_signals(fit::read_flight(path, o.mapping ? &*o.mapping : nullptr, o.resample, v), param(v, "vbat_ref").nominal);
  for (const auto& note : flight.notes) o.progress.say(note);  // why a logged pose is not read
  if (!flight.has_pose)
    o.progress.say(path + (flight.pose_partly_logged ? "" : ": no pose logged") +
                   ": one-step errors only (rollouts need a measured state)");
  if (!o.set_point_controller.empty() && !flight.has_attitude_ref)
    throw fit::FitError(path + ":1: --controller " + o.set_point_controller +
                        " flies the log's attitude set points, but it has no phi_ref and theta_ref columns "
                        "(docs/formats.md; data/mappings/nanobench.yaml maps them for the NanoBench logs)");
  return flight;
}

// The controller of --controller, mixed by the vehicle's rotor positions.
std::optional<SetPointFlying> set_point_flying(const Vehicle& v, const std::string& controller, double output_scale) {
  if (controller.empty()) return std::nullopt;
  if (std::find(kSetPointControllers.begin(), kSetPointControllers.end(), controller) == kSetPointControllers.end()) {
    throw std::invalid_argument("--controller: unknown controller '" + output::printable(controller) +
                                "' (expected one of: " + output::joined(kSetPointControllers) + ")");
  }
  std::vector<std::array<double, 3>> positions;
  std::vector<int> spins;
  for (const auto& r : v.rotors) positions.push_back(r.position), spins.push_back(spin_sign(r));
  runtime::AttitudePidOptions pid;
  pid.output_scale = output_scale;
  try {
    return SetPointFlying{pid, runtime::AttitudeMixer::quad_x(positions, spins)};
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("--controller " + controller + ": " + e.what() + " (vehicle " + v.name + ")");
  }
}

// "indoors", "outdoors", "in any environment".
std::string where_words(Environment e) {
  return e == Environment::kUnknown ? "in any environment" : environment_name(e) + "s";
}

// Calibrated values beyond what the flight's environment makes plausible (a steady wind of
// 0.8 m/s indoors): the flight's own quantities then stand in for something the airframe's
// held values miss on this flight, and the prediction says so rather than scoring it silently.
nlohmann::ordered_json implausible_calibration(const Vehicle& v, const runtime::DynamicModel& model,
                                               const std::vector<double>& values, const std::vector<int>& calibrated,
                                               const std::vector<fit::FitParameter>& bounds,
                                               const PredictFlightsOptions& o) {
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (int k : calibrated) {
    const std::string& name = model.param_names()[k];
    double lower = 0, upper = 0;
    std::string why;
    if (!outside_plausible_range(name, values[k], o.environment, vehicle_scales(v), &lower, &upper, &why)) continue;
    const std::string unit = output::unit_after_number(bounds[k].unit);
    o.progress.say("  note: calibrated " + name + " = " + output::short_number(values[k]) + unit +
                   " lies outside what is plausible " + where_words(o.environment) + " (" +
                   output::short_number(lower) + " to " + output::short_number(upper) + unit + ": " + why +
                   "): this flight's own quantities stand in for something the airframe's values miss here; "
                   "quadgen diagnose of this flight with --airframe tests which of them it rejects");
    out.push_back({{"parameter", name}, {"value", values[k]}, {"plausible", {lower, upper}}, {"why", why}});
  }
  return out;
}

}  // namespace

bool PredictFlightsOptions::IsValid(std::string* error) const {
  const auto fail = [&](const std::string& why) {
    if (error) *error = why;
    return false;
  };
  if (!fit::valid_resample_rate(resample)) return fail("resample: 0 or " + fit::kResampleRange.text("Hz"));
  if (!kPredictValidationRange.contains(validation)) return fail("validation fraction: " + kPredictValidationRange.text());
  if (!kControllerGainRange.contains(controller_output_scale))
    return fail("controller gain: " + kControllerGainRange.text());
  if (!kStartStrideRange.contains(prediction.start_stride)) return fail("start stride: " + kStartStrideRange.text("s"));
  if (!kDisturbanceWindowRange.contains(prediction.disturbance_window))
    return fail("disturbance window: " + kDisturbanceWindowRange.text("s"));
  return true;
}

PredictedFlights predict_flights(const Vehicle& v, runtime::DynamicModel& model, const std::vector<fit::FitParameter>& bounds,
                                 const std::vector<std::string>& logs, const PredictFlightsOptions& o) {
  if (std::string error; !o.IsValid(&error)) throw std::invalid_argument("predict: " + error);
  if (o.calibrate && o.params.empty()) throw std::invalid_argument("--calibrate needs --params (a diagnosis.json)");
  if (o.calibrate && o.validation >= 1.0)
    throw std::invalid_argument("--calibrate needs a part before the evaluated one: --validation below 1");
  if (o.linear_correction && o.validation >= 1.0)
    throw std::invalid_argument("--linear-correction needs a part before the evaluated one to fit on: --validation below 1");
  PredictionOptions prediction = o.prediction;
  prediction.set_points = set_point_flying(v, o.set_point_controller, o.controller_output_scale);
  const std::vector<double> nominal = model.params();  // before any calibration moves the model's
  std::optional<ParameterSource> source;
  if (!o.params.empty()) source.emplace(o.params);
  // Values of another vehicle file may still be what the user wants (the same airframe under
  // another name), but never silently: the parameter names alone cannot tell.
  if (source && !source->vehicle().empty() && source->vehicle() != v.name)
    o.progress.say("note: " + o.params + " was fitted for the vehicle '" + source->vehicle() +
               "', not '" + v.name + "'; its values are applied by parameter name");
  PredictedFlights out;
  nlohmann::ordered_json flights = nlohmann::ordered_json::array();
  for (size_t i = 0; i < logs.size(); ++i) {
    o.progress.say("[" + std::to_string(i + 1) + "/" + std::to_string(logs.size()) + "] " + logs[i]);
    const fit::Flight whole = load(logs[i], v, o);
    const auto [before, evaluated] = o.validation >= 1.0 ? std::pair<fit::Flight, fit::Flight>{{}, whole}
                                                         : fit::split_by_time(whole, 1.0 - o.validation);
    ParameterSource::ForLog values;
    values.values = nominal;
    values.origin = "vehicle file (nominal)";
    if (source) values = source->for_log(model, logs[i]);
    nlohmann::ordered_json calibrated = nlohmann::ordered_json::object();
    nlohmann::ordered_json implausible = nlohmann::ordered_json::array();
    if (o.calibrate && values.flight == 0 && !values.flight_params.empty()) {
      o.progress.say("  calibrating " + std::to_string(values.flight_params.size()) + " flight parameters on the first " +
                 output::percent_text(1.0 - o.validation));
      values.values = calibrate(model, values.values, values.flight_params, bounds, before);
      for (int k : values.flight_params) calibrated[model.param_names()[k]] = values.values[k];
      values.origin += ", flight parameters calibrated on the part before";
      implausible = implausible_calibration(v, model, values.values, values.flight_params, bounds, o);
    }
    Prediction p = evaluate_prediction(model, values.values, evaluated, prediction);
    if (o.linear_correction) p.one_step_corrected = linearly_corrected_one_step(model, values.values, before, evaluated);
    auto j = prediction_json(p);
    j["log"] = logs[i];
    j["parameters_from"] = values.origin;
    if (!calibrated.empty()) j["calibrated"] = calibrated;
    if (!implausible.empty()) j["calibrated_implausible"] = implausible;
    j["evaluated_from_s"] = evaluated.samples.empty() ? 0.0 : evaluated.samples.front().t;
    if (!whole.notes.empty()) j["notes"] = whole.notes;  // what reading the log noticed, said on the terminal too
    flights.push_back(j);
    out.pooled.merge(p);
  }
  out.json = prediction_json(out.pooled);
  out.json["vehicle"] = v.name;
  out.json["parameters_from"] = o.params.empty() ? "vehicle file (nominal)" : o.params;
  if (source && !source->vehicle().empty()) out.json["parameters_vehicle"] = source->vehicle();
  out.json["evaluated_fraction"] = o.validation;
  out.json["environment"] = environment_name(o.environment);
  out.json["flights"] = flights;
  return out;
}

}  // namespace quadgen::predict
