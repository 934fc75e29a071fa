// quadgen predict VEHICLE.yaml LOG.csv... [--mapping M] [--params FIT_OR_DIAGNOSIS.json] --out DIR
// How well a model (nominal, fitted or extended) predicts flights, measured as published
// models report it (predict/prediction.hpp): prediction.json, prediction.csv, prediction.svg.
#include <cmath>
#include <fstream>
#include <iostream>

#include "cli/commands.hpp"
#include "derive/dynamics.hpp"
#include "derive/effects/effect_catalogue.hpp"
#include "derive/geometry.hpp"
#include "output/json_document.hpp"
#include "app/model_registry.hpp"
#include "cli/options.hpp"
#include "output/output_set.hpp"
#include "fit/fit_pipeline.hpp"
#include "predict/predict_flights.hpp"
#include "predict/prediction.hpp"
#include "output/sinks.hpp"
#include "model/vehicle.hpp"

namespace quadgen::cli {

void add_predict(CLI::App& app, PredictArgs& a) {
  CLI::App* c = app.add_subcommand("predict", "measure how well a model predicts flights (error at horizons, one step)");
  c->add_option("vehicle", a.vehicle, "vehicle description (YAML)")->required();
  c->add_option("logs", a.logs, std::string("flight logs, one or more: ") + kLogFormats)->required()->default_str("");
  c->add_option("--out", a.out, "output directory")->required();
  c->add_option("--mapping", a.options.mapping, "column mapping (YAML) for logs not in the canonical layout");
  c->add_option("--params", a.options.params,
                "parameter values from a fit.json or diagnosis.json (default: the vehicle file's nominal values)");
  c->add_option("--validation", a.options.validation,
                "fraction of each flight (at its end) evaluated; 1 for flights no fit has seen")
      ->check(finite_range(0.05, 1.0));
  c->add_option("--resample", a.options.resample, "resample the logs onto a uniform grid at this rate [Hz] first")
      ->check(finite_range(0.1, 1e5));
  c->add_flag("--calibrate", a.options.calibrate,
              "for a log the --params diagnosis was not fitted to: fit the flight's own parameters (motor trims, "
              "marker frame, wind) on the part before the evaluated one, the airframe's held");
  c->add_flag("--linear-correction", a.options.linear_correction,
              "also the one-step errors after a linear correction fitted on the part before the evaluated one (on "
              "the nominal model: a linear-regression baseline on the same split)");
  c->add_option("--stride", a.options.prediction.start_stride, "seconds between rollout start points")->check(finite_range(0.001, 10));
  c->add_option("--disturbance-window", a.options.prediction.disturbance_window,
                "seconds of log before each start whose mean acceleration residual the open loop with the past "
                "disturbance holds (0: that view is not run)")
      ->check(finite_range(0.0, 10));
}

int run_predict(const PredictArgs& a) {
  const Vehicle v = load_vehicle(a.vehicle);
  std::vector<std::string> inputs = a.logs;
  inputs.insert(inputs.end(), {a.vehicle, a.options.mapping, a.options.params});
  output::OutputDirectory out(a.out, "predict", inputs);  // refused before the work, not after
  // Every effect, at its neutral value unless --params sets it.
  std::string how;
  const std::unique_ptr<runtime::DynamicModel> model = app::model_for(v, parse_effect_list("all"), &how);
  std::cerr << "model: " << how << "\n";
  predict::PredictFlightsOptions o = a.options;
  o.progress = [](const std::string& line) { std::cerr << line << "\n"; };
  const predict::PredictedFlights p = predict::predict_flights(v, *model, model->parameters(), a.logs, o);
  out.add("prediction.json", output::json_document(p.json));
  out.add("prediction.csv", predict::prediction_csv(p.pooled));
  std::string svg, err;
  if (runtime::render_svg(v.name + ": prediction error against horizon", predict::horizon_panels({{"this model", &p.pooled}}), &svg, &err))
    out.add("prediction.svg", svg);
  else
    std::cerr << "no plot: " << err << "\n";
  out.commit();
  for (const auto& h : p.pooled.open_loop)
    std::cout << "open loop, " << h.horizon << " s: position " << h.position.mean() << " m (mean), tilt " << h.tilt.mean()
              << " rad, heading " << h.heading.mean() << " rad\n";
  if (const std::string limits = predict::what_limits_prediction(p.pooled); !limits.empty()) std::cout << limits << "\n";
  std::cout << "wrote " << output::printable(a.out) << "/prediction.json\n";
  // A non-finite error is a model that left its range (commands, units or parameters wrong):
  // the files are written for a look, but the run did not succeed.
  for (const auto& h : p.pooled.open_loop)
    if (!std::isfinite(h.position.mean())) {
      std::cerr << "quadgen: error: the open-loop position error " << h.horizon
                << " s ahead is not finite: the model left its range on this log (check the commands' scale, the "
                   "units and --params); the output is kept for inspection\n";
      return 4;
    }
  return 0;
}

}  // namespace quadgen::cli
