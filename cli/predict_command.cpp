// quadgen predict VEHICLE.yaml LOG.csv... [--mapping M] [--params FIT_OR_DIAGNOSIS.json] --out DIR
// How well a model (nominal, fitted or extended) predicts flights, measured as published
// models report it (predict/prediction.hpp): prediction.json, prediction.csv, prediction.svg.
#include <fstream>
#include <iostream>
#include <optional>

#include "log_reader.hpp"
#include "commands.hpp"
#include "dynamics.hpp"
#include "effects.hpp"
#include "geometry.hpp"
#include "json_document.hpp"
#include "model_registry.hpp"
#include "options.hpp"
#include "output_set.hpp"
#include "parameter_source.hpp"
#include "prediction.hpp"
#include "sinks.hpp"
#include "vehicle.hpp"

namespace quadgen::cli {

void add_predict(CLI::App& app, PredictArgs& a) {
  CLI::App* c = app.add_subcommand("predict", "measure how well a model predicts flights (error at horizons, one step)");
  c->add_option("vehicle", a.vehicle, "vehicle description (YAML)")->required();
  c->add_option("logs", a.logs, "flight logs (CSV), one or more")->required()->default_str("");
  c->add_option("--out", a.out, "output directory")->required();
  c->add_option("--mapping", a.mapping, "column mapping (YAML) for logs not in the canonical layout");
  c->add_option("--params", a.params,
                "parameter values from a fit.json or diagnosis.json (default: the vehicle file's nominal values)");
  c->add_option("--validation", a.validation,
                "fraction of each flight (at its end) evaluated; 1 for flights no fit has seen (default 0.3)")
      ->check(finite_range(0.05, 1.0));
  c->add_option("--resample", a.resample, "resample the logs onto a uniform grid at this rate [Hz] first")
      ->check(finite_range(0.1, 1e5));
  c->add_flag("--calibrate", a.calibrate,
              "for a log the --params diagnosis was not fitted to: fit the flight's own parameters (motor trims, "
              "marker frame, wind) on the part before the evaluated one, the airframe's held");
  c->add_option("--stride", a.stride, "seconds between rollout start points (default 0.05)")->check(finite_range(0.001, 10));
}

namespace {

fit::Flight load(const PredictArgs& a, const std::string& log_path, const std::vector<std::string>& rotors,
                 double vbat_ref) {
  const runtime::CsvTable log = fit::read_log(log_path, a.mapping, a.resample);
  const fit::Flight flight = predict::fill_missing_signals(fit::load_flight(log, rotors, {}), vbat_ref);
  if (!flight.has_pose)
    std::cerr << output::printable(log_path) << ": no pose logged: one-step errors only (rollouts need a measured state)\n";
  return flight;
}

// Name, unit and bounds of every parameter, for calibration.
std::vector<fit::FitParameter> parameter_bounds(const SymbolicModel& model) {
  std::vector<fit::FitParameter> out;
  for (const auto& p : model.params) out.push_back({p.name, p.unit, p.nominal, p.lower, p.upper, false});
  return out;
}

}  // namespace

int run_predict(const PredictArgs& a) {
  if (a.calibrate && a.params.empty()) throw std::invalid_argument("--calibrate needs --params (a diagnosis.json)");
  if (a.calibrate && a.validation >= 1.0)
    throw std::invalid_argument("--calibrate needs a part before the evaluated one: --validation below 1");
  const Vehicle v = load_vehicle(a.vehicle);
  std::vector<std::string> inputs = a.logs;
  inputs.insert(inputs.end(), {a.vehicle, a.mapping, a.params});
  output::OutputDirectory out(a.out, inputs);  // refused before the work, not after
  DeriveOptions all;
  all.effects = parse_effect_list("all");  // effects at neutral values unless --params sets them
  const SymbolicModel model = derive_model(v, derive_mass_properties(v), all);
  bool compiled = false;
  const auto m = make_model(model, &compiled);
  const std::vector<double> nominal = m->params();  // before any calibration moves the model's
  std::optional<predict::ParameterSource> source;
  if (!a.params.empty()) source.emplace(a.params);
  std::vector<std::string> rotors;
  for (const auto& r : v.rotors) rotors.push_back(r.name);
  const double vbat_ref = param(v, "vbat_ref").value;
  predict::PredictionOptions o;
  o.start_stride = a.stride;
  predict::Prediction pooled;
  nlohmann::ordered_json flights = nlohmann::ordered_json::array();
  for (size_t i = 0; i < a.logs.size(); ++i) {
    std::cerr << "[" << i + 1 << "/" << a.logs.size() << "] " << output::printable(a.logs[i]) << " ("
              << (compiled ? "compiled model" : "interpreted model") << ")\n";
    const fit::Flight whole = load(a, a.logs[i], rotors, vbat_ref);
    const auto [before, f] = a.validation >= 1.0 ? std::pair<fit::Flight, fit::Flight>{{}, whole}
                                                 : fit::split_by_time(whole, 1.0 - a.validation);
    predict::ParameterSource::ForLog values;
    values.values = nominal;
    values.origin = "vehicle file (nominal)";
    if (source) values = source->for_log(*m, a.logs[i]);
    nlohmann::ordered_json calibrated = nlohmann::ordered_json::object();
    if (a.calibrate && values.flight == 0 && !values.flight_params.empty()) {
      std::cerr << "  calibrating " << values.flight_params.size() << " flight parameters on the first "
                << 100 * (1.0 - a.validation) << " %\n";
      values.values = predict::calibrate(*m, values.values, values.flight_params, parameter_bounds(model), before);
      for (int k : values.flight_params) calibrated[m->param_names()[k]] = values.values[k];
      values.origin += ", flight parameters calibrated on the part before";
    }
    const std::vector<double>& params = values.values;
    const predict::Prediction p = predict::evaluate_prediction(*m, params, f, o);
    auto j = predict::prediction_json(p);
    j["log"] = a.logs[i];
    j["parameters_from"] = values.origin;
    if (!calibrated.empty()) j["calibrated"] = calibrated;
    j["evaluated_from_s"] = f.samples.empty() ? 0.0 : f.samples.front().t;
    flights.push_back(j);
    pooled.merge(p);
  }
  auto j = predict::prediction_json(pooled);
  j["vehicle"] = v.name;
  j["parameters_from"] = a.params.empty() ? "vehicle file (nominal)" : a.params;
  j["evaluated_fraction"] = a.validation;
  j["flights"] = flights;
  out.add("prediction.json", output::json_document(j));
  out.add("prediction.csv", predict::prediction_csv(pooled));
  std::string svg, err;
  if (runtime::render_svg(v.name + ": prediction error against horizon", predict::horizon_panels({{"this model", &pooled}}), &svg, &err))
    out.add("prediction.svg", svg);
  else
    std::cerr << "no plot: " << err << "\n";
  out.commit();
  for (const auto& h : pooled.open_loop)
    std::cout << "open loop, " << h.horizon << " s: position " << h.position.mean() << " m (mean), tilt " << h.tilt.mean()
              << " rad, heading " << h.heading.mean() << " rad\n";
  std::cout << "wrote " << output::printable(a.out) << "/prediction.json\n";
  return 0;
}

}  // namespace quadgen::cli
