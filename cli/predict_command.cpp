// quadgen predict VEHICLE.yaml LOG.csv... [--mapping M] [--params FIT_OR_DIAGNOSIS.json] --out DIR
// How well a model (nominal, fitted or extended) predicts flights, measured as published
// models report it (predict/prediction.hpp): prediction.json, prediction.csv, prediction.svg.
#include <iostream>

#include "app/predict_job.hpp"
#include "cli/predict_command.hpp"
#include "cli/options.hpp"
#include "fit/log_reader.hpp"
#include "output/output_set.hpp"
#include "output/progress.hpp"
#include "predict/predict_flights.hpp"
#include "output/sinks.hpp"

namespace quadgen::cli {

void add_predict(CLI::App& app, PredictArgs& a) {
  CLI::App* c = app.add_subcommand("predict", "measure how well a model predicts flights (error at horizons, one step)");
  c->add_option("vehicle", a.vehicle, "vehicle description (YAML)")->required();
  c->add_option("logs", a.logs, std::string("flight logs, one or more: ") + kLogFormats)->required()->default_str("");
  c->add_option("--out", a.out, "output directory")->required();
  c->add_option("--mapping", a.mapping, "column mapping (YAML) for logs not in the canonical layout");
  c->add_option("--params", a.options.params,
                "parameter values from a fit.json or diagnosis.json (default: the vehicle file's nominal values)");
  c->add_option("--validation", a.options.validation,
                "fraction of each flight (at its end) evaluated; 1 for flights no fit has seen")
      ->check(finite_range(predict::kPredictValidationRange));
  c->add_option("--resample", a.options.resample, "resample the logs onto a uniform grid at this rate [Hz] first")
      ->check(finite_range(fit::kResampleRange))
      ->default_str(fit::resample_default_text());
  c->add_flag("--calibrate", a.options.calibrate,
              "for a log the --params diagnosis was not fitted to: fit the flight's own parameters (c_t, motor trims, "
              "marker frame, wind) on the part before the evaluated one, the airframe's held");
  c->add_option("--environment", a.environment,
                 "where the flights were flown: indoor, outdoor or unknown (default: the mapping's environment, else "
                 "unknown); with --calibrate, a calibrated value beyond what is plausible there is said")
      ->check(CLI::IsMember(kEnvironmentNames));
  c->add_flag("--linear-correction", a.options.linear_correction,
              "also the one-step errors after a linear correction fitted on the part before the evaluated one (on "
              "the nominal model: a linear-regression baseline on the same split)");
  auto* controller = c->add_option("--controller", a.options.set_point_controller,
                "also fly each log's attitude set points (phi_ref, theta_ref) with a replica of this attitude "
                "controller: crazyflie-pid (the Crazyflie firmware's defaults); the roll and pitch commands come "
                "from it, the collective and yaw from the log")
      ->check(CLI::IsMember(predict::kSetPointControllers));
  c->add_option("--controller-gain", a.options.controller_output_scale,
                "with --controller: logged command counts per count of the loop's output (the firmware's battery "
                "compensation between them; 1: none)")
      ->check(finite_range(predict::kControllerGainRange))
      ->needs(controller);
  c->add_option("--stride", a.options.prediction.start_stride, "seconds between rollout start points")->check(finite_range(predict::kStartStrideRange));
  c->add_option("--disturbance-window", a.options.prediction.disturbance_window,
                "seconds of log before each start whose mean acceleration residual the open loop with the past "
                "disturbance holds (0: that view is not run)")
      ->check(finite_range(predict::kDisturbanceWindowRange));
}

int run_predict(const PredictArgs& a) {
  const Vehicle vehicle = load_vehicle(a.vehicle);  // a bad file is reported before anything is created
  std::vector<std::string> inputs = a.logs;
  inputs.insert(inputs.end(), {a.vehicle, a.mapping, a.options.params});
  output::OutputDirectory out(a.out, "predict", inputs);  // refused before the work, not after
  app::PredictJob job{a.vehicle, a.logs, a.mapping, a.environment, a.options};
  job.options.progress = output::terminal_progress();
  const app::PredictJobResult r = app::run_predict_job(job, vehicle);
  for (const auto& note : r.notes) std::cerr << output::printable_lines(note) << "\n";
  for (const auto& [name, contents] : r.files) out.add(name, contents);
  commit_and_say(out, "predict");
  std::cout << output::printable_lines(r.summary) << "wrote " << output::printable(a.out) << "/prediction.json\n";
  if (!r.failure.empty()) {
    print_error(r.failure);
    return 4;
  }
  return 0;
}

}  // namespace quadgen::cli
