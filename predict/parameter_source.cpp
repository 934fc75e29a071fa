#include "predict/parameter_source.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "fit/equation_error.hpp"
#include "runtime/flight_log.hpp"
#include "runtime/log_file.hpp"
#include "runtime/per_flight_model.hpp"
#include "output/json_document.hpp"
#include "output/numbers.hpp"
#include "output/sinks.hpp"

namespace quadgen::predict {

namespace {

// Logs are matched by their canonical path (as given to diagnose, from the same directory).
std::string canonical(const std::string& path) {
  std::error_code ec;
  const auto c = std::filesystem::weakly_canonical(path, ec);
  return ec ? path : c.string();
}

}  // namespace

ParameterSource::ParameterSource(const std::string& path) : path_(path) {
  std::string text;
  try {  // opened as a log is: a FIFO or a device is refused, not waited on; size-limited
    text = runtime::LogFile(path, "a diagnosis.json or fit.json").read_all();
  } catch (const runtime::LogError& e) {
    throw std::invalid_argument(e.what());
  }
  if (const std::string problem = output::parse_json_input(
          text, &json_,
          "--params takes the diagnosis.json or fit.json a diagnose or fit run writes (the fitted_parameters.yaml "
          "beside it is for derive --params)");
      !problem.empty())
    throw std::invalid_argument(path + ": " + problem);
  if (!json_.is_object()) throw std::invalid_argument(path + ": expected a diagnosis.json or fit.json object");
  if (json_.value("kind", nlohmann::json()) == "thrust_stand")
    throw std::invalid_argument(path + ": a thrust-stand fit describes the motors (thrust_vs_speed, speed_vs_command), "
                                "not a flight model's values; its k and motor map go into the vehicle file's rotor_model "
                                "and motor_map (docs/formats.md, fit.json)");
  key_ = json_.contains("final_fit") ? "final_fit" : json_.contains("estimates") ? "estimates" : nullptr;
  if (!key_ || !json_[key_].is_object())
    throw std::invalid_argument(path + ": expected a diagnosis.json (final_fit) or fit.json (estimates)");
  const auto strings = [&](const char* key) {
    std::vector<std::string> out;
    if (!json_.contains(key)) return out;
    if (!json_[key].is_array()) throw std::invalid_argument(path + ": " + key + " is not a list");
    for (const auto& s : json_[key]) {
      if (!s.is_string()) throw std::invalid_argument(path + ": " + key + " holds a non-text entry");
      out.push_back(s.get<std::string>());
    }
    return out;
  };
  // flight_paths (absolute) where the diagnosis wrote them; flights as given otherwise.
  for (const auto& f : strings(json_.contains("flight_paths") ? "flight_paths" : "flights"))
    flights_.push_back(canonical(f));
  flight_params_ = strings("flight_parameters");
  if (json_.contains("airframe_fit") && !json_["airframe_fit"].is_object())
    throw std::invalid_argument(path + ": airframe_fit is not an object");
}

void ParameterSource::set(const runtime::DynamicModel& model, const nlohmann::json& entries, const char* key,
                          std::vector<double>& p) const {
  const std::vector<runtime::Parameter> declared = model.parameters();
  // The value an entry gives the model's parameter `index` (its own, or one flight's copy).
  const auto checked = [&](const std::string& name, const nlohmann::json& entry, int index) {
    const double value = entry["value"].get<double>();
    const runtime::Parameter& p = declared[static_cast<size_t>(index)];
    // A unit the file gives is the model's, as derive --params requires: kappa in mm was read as
    // metres (a review, helper-135). A hand-written entry without one is taken as declared.
    if (entry.contains("unit")) {
      const std::string given = entry["unit"].is_string() ? entry["unit"].get<std::string>() : entry["unit"].dump();
      if (const std::string u = runtime::unit_problem(p, given); !u.empty())
        throw std::invalid_argument(path_ + ": " + key + "." + output::printable(name) + " " + u);
    }
    const std::string problem = runtime::value_problem(p, value, true);
    if (!problem.empty()) throw std::invalid_argument(path_ + ": " + key + "." + output::printable(name) + " " + problem);
    return value;
  };
  for (const auto& [name, entry] : entries.items()) {
    if (!entry.is_object() || !entry.contains("value") || !entry["value"].is_number())
      throw std::invalid_argument(path_ + ": " + key + "." + output::printable(name) + " has no numeric value");
    const int i = model.param_index(name);
    if (i >= 0) {
      p[static_cast<size_t>(i)] = checked(name, entry, i);
      continue;
    }
    // Another flight's copy (name@k, k = 2 .. the number of flights) of a per-flight
    // parameter: applied by for_log.
    const auto at = name.rfind('@');
    const std::string suffix = at == std::string::npos ? "" : name.substr(at + 1);
    const bool digits = !suffix.empty() && suffix.size() <= 6 &&
                        std::all_of(suffix.begin(), suffix.end(), [](char c) { return c >= '0' && c <= '9'; });
    const int k = digits ? std::stoi(suffix) : 0;
    if (at == std::string::npos || model.param_index(name.substr(0, at)) < 0)
      throw std::invalid_argument(path_ + ": parameter '" + output::printable(name) + "' is not in the model");
    if (k < 2 || (!flights_.empty() && k > static_cast<int>(flights_.size())))
      throw std::invalid_argument(path_ + ": '" + output::printable(name) + "': a flight's copy is name@k with k from 2 to " +
                                  std::to_string(flights_.size()) + ", the number of flights");
    checked(name, entry, model.param_index(name.substr(0, at)));  // applied by for_log
  }
}

std::string ParameterSource::vehicle() const {
  return json_.contains("vehicle") && json_["vehicle"].is_string() ? json_["vehicle"].get<std::string>() : "";
}

ParameterSource::ForLog ParameterSource::for_log(const runtime::DynamicModel& model, const std::string& log) const {
  ForLog out;
  out.values = model.params();
  const auto it = std::find(flights_.begin(), flights_.end(), canonical(log));
  out.flight = it == flights_.end() ? 0 : static_cast<int>(it - flights_.begin()) + 1;
  const bool airframe = out.flight == 0 && json_.contains("airframe_fit");
  const char* key = airframe ? "airframe_fit" : key_;
  set(model, json_[key], key, out.values);
  if (out.flight > 1)  // this flight's own copies replace flight 1's (the plain names)
    for (const auto& [name, entry] : json_[key].items())
      if (runtime::flight_of_name(name) == out.flight)
        out.values[static_cast<size_t>(model.param_index(runtime::shared_name(name)))] = entry["value"].get<double>();
  for (const auto& n : flight_params_) {
    const int i = model.param_index(n);
    if (i < 0) throw std::invalid_argument(path_ + ": flight parameter '" + output::printable(n) + "' is not in the model");
    out.flight_params.push_back(i);
  }
  if (flights_.empty() && key_ == std::string("estimates"))
    out.origin = path_ + " (fit estimates)";
  else if (out.flight > 0)
    out.origin = path_ + " (flight " + std::to_string(out.flight) + " of " + std::to_string(flights_.size()) + ")";
  else
    out.origin = path_ + (airframe ? " (airframe values: a log it was not fitted to)"
                          : flights_.size() > 1 ? " (a log it was not fitted to; no airframe_fit in the file: flight 1's values)"
                                                : " (a log it was not fitted to)");
  return out;
}

std::vector<double> calibrate(runtime::DynamicModel& model, const std::vector<double>& start,
                              const std::vector<int>& free, const std::vector<fit::FitParameter>& bounds,
                              const fit::Flight& part) {
  if (bounds.size() != start.size()) throw std::invalid_argument("calibrate: one bound per parameter expected");
  std::vector<fit::FitParameter> ps = bounds;
  for (size_t i = 0; i < ps.size(); ++i) {
    ps[i].value = std::clamp(start[i], ps[i].lower, ps[i].upper);
    ps[i].free = std::find(free.begin(), free.end(), static_cast<int>(i)) != free.end();
    if (!ps[i].free) ps[i].lower = ps[i].upper = ps[i].value = start[i];
  }
  const std::vector<double> entry = model.params();  // restored after: the fit leaves its last trial
  model.set_params(start);
  const fit::EquationErrorModel residuals(model, part, !part.has_pose);
  fit::FitOptions o;
  o.max_iterations = 100;
  const fit::FitResult r = fit::fit_least_squares(residuals, ps, o);
  model.set_params(entry);
  return fit::parameter_values(r.parameters);
}

}  // namespace quadgen::predict
