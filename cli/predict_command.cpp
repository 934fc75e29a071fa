// quadgen predict VEHICLE.yaml LOG.csv... [--mapping M] [--params FIT_OR_DIAGNOSIS.json] --out DIR
// How well a model (nominal, fitted or extended) predicts flights, measured as published
// models report it (predict/prediction.hpp): prediction.json, prediction.csv, prediction.svg.
#include <fstream>
#include <iostream>

#include "log_reader.hpp"
#include "commands.hpp"
#include "dynamics.hpp"
#include "effects.hpp"
#include "geometry.hpp"
#include "json_document.hpp"
#include "model_registry.hpp"
#include "options.hpp"
#include "output_set.hpp"
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
  c->add_option("--stride", a.stride, "seconds between rollout start points (default 0.05)")->check(finite_range(0.001, 10));
}

namespace {

// Parameter values by name from quadgen's own outputs: diagnosis.json (final_fit) or
// fit.json (estimates). Every name must be a parameter of the model.
std::vector<double> read_params(const std::string& path, const runtime::DynamicModel& m) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::invalid_argument(path + ": cannot open the parameter file");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::parse_error& e) {
    throw std::invalid_argument(path + ": not JSON (" + e.what() + ")");
  }
  const char* key = j.contains("final_fit") ? "final_fit" : j.contains("estimates") ? "estimates" : nullptr;
  if (!key || !j[key].is_object())
    throw std::invalid_argument(path + ": expected a diagnosis.json (final_fit) or fit.json (estimates)");
  std::vector<double> p = m.params();
  for (const auto& [name, entry] : j[key].items()) {
    const int i = m.param_index(name);
    if (i < 0) throw std::invalid_argument(path + ": parameter '" + output::printable(name) + "' is not in the model");
    if (!entry.is_object() || !entry.contains("value") || !entry["value"].is_number())
      throw std::invalid_argument(path + ": " + key + "." + output::printable(name) + " has no numeric value");
    p[static_cast<size_t>(i)] = entry["value"].get<double>();
  }
  return p;
}

fit::Flight held_out_flight(const PredictArgs& a, const std::string& log_path, const std::vector<std::string>& rotors,
                            double vbat_ref) {
  const runtime::CsvTable log = fit::read_log(log_path, a.mapping, a.resample);
  const fit::Flight flight = predict::fill_missing_signals(fit::load_flight(log, rotors, {}), vbat_ref);
  if (!flight.has_pose)
    std::cerr << output::printable(log_path) << ": no pose logged: one-step errors only (rollouts need a measured state)\n";
  return a.validation >= 1.0 ? flight : fit::split_by_time(flight, 1.0 - a.validation).second;
}

}  // namespace

int run_predict(const PredictArgs& a) {
  const Vehicle v = load_vehicle(a.vehicle);
  std::vector<std::string> inputs = a.logs;
  inputs.insert(inputs.end(), {a.vehicle, a.mapping, a.params});
  output::OutputDirectory out(a.out, inputs);  // refused before the work, not after
  DeriveOptions all;
  all.effects = parse_effect_list("all");  // effects at neutral values unless --params sets them
  const SymbolicModel model = derive_model(v, derive_mass_properties(v), all);
  bool compiled = false;
  const auto m = make_model(model, &compiled);
  const std::vector<double> params = a.params.empty() ? m->params() : read_params(a.params, *m);
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
    const fit::Flight f = held_out_flight(a, a.logs[i], rotors, vbat_ref);
    const predict::Prediction p = predict::evaluate_prediction(*m, params, f, o);
    auto j = predict::prediction_json(p);
    j["log"] = a.logs[i];
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
