// quadgen fit VEHICLE.yaml LOG --out DIR: flags to options; the fits are fit/fit_pipeline.
// The kind of fit follows the log's layout; an option that kind does not use is refused.
#include <algorithm>
#include <iostream>
#include <set>
#include <sstream>

#include "cli/commands.hpp"
#include "derive/effects/effect_catalogue.hpp"
#include "fit/fit_pipeline.hpp"
#include "output/joined.hpp"
#include "output/json_document.hpp"
#include "output/sinks.hpp"
#include "app/model_registry.hpp"
#include "cli/options.hpp"
#include "fit/log_reader.hpp"
#include "output/output_set.hpp"
#include "model/vehicle.hpp"

namespace quadgen::cli {

using namespace quadgen::fit;

void add_fit(CLI::App& app, FitArgs& a) {
  CLI::App* c = app.add_subcommand("fit", "estimate parameters from measured data, with profile likelihood");
  c->add_option("vehicle", a.vehicle, "vehicle description (YAML)")->required();
  c->add_option("log", a.log, std::string("measurements: a flight log (") + kLogFormats +
                                  "), motor steps or a thrust stand (CSV)")
      ->required();
  c->add_option("--out", a.out, "output directory")->required();
  c->add_flag("--robust", a.options.robust,
              "Huber loss instead of squares (quadratic up to 1 in the weighted residuals, about one noise "
              "standard deviation of each channel; linear beyond)");
  c->add_option("--mapping", a.options.mapping, "column mapping (YAML) for logs not in the canonical layout, e.g. data/mappings/nanobench.yaml");
  const std::string effect_names = catalogue_names();  // --help lists what --effects accepts
  c->add_option("--effects", a.effects, "comma-separated effects to add, or 'all': " + effect_names);
  c->add_option("--validation", a.options.validation, "fraction of the flight (at its end) held out for validation")
      ->check(finite_range(kFitValidationRange));
  c->add_option("--formulation", a.options.formulation, "equation_error (IMU, accelerations) or multiple_shooting (pose, windows)")
      ->check(CLI::IsMember({"equation_error", "multiple_shooting"}));
  c->add_option("--window", a.options.window, "multiple shooting: window length [s]")->check(finite_range(kFitWindowRange));
  c->add_option("--resample", a.options.resample, "resample the log onto a uniform grid at this rate [Hz] first")
      ->check(finite_range(kResampleRange))
      ->default_str("none for a CSV, 100 Hz for a ULog or uSD log");
  c->add_option("--channels", a.channels, "residual channels to fit (default all): ax,ay,az,pdot,qdot,rdot");
  c->add_option("--translational", a.options.translational,
                "equation error: ax, ay, az from the accelerometer (body specific force at each sample) or from the "
                "pose (world acceleration, the differentiated velocity, exact for commands held between samples)")
      ->check(CLI::IsMember({"pose", "accelerometer"}))
      ->default_str("the accelerometer where logged, else the pose");
  c->add_option("--free", a.free,
                std::string("parameters to fit (comma-separated), overriding the vehicle file's fit flags: ") +
                    parameter_names_help());
  c->add_option("--profiles", a.profiles,
                "profile likelihood of: all free parameters, none (estimates and standard errors only), or "
                "comma-separated names (as for --free)")
      ->capture_default_str();
  c->add_option("--threads", a.options.threads, "threads for the profiles (0: one per core)")
      ->check(CLI::Range(0, 256))
      ->capture_default_str();
}

namespace {

// A comma-separated option value; a name given twice is refused (a channel listed twice was
// weighted twice in the fit), as --candidates and --effects refuse one.
std::vector<std::string> split_list(const std::string& s, const std::string& option) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (item.empty()) continue;
    if (std::find(out.begin(), out.end(), item) != out.end())
      throw std::invalid_argument(option + ": '" + output::printable(item) + "' is given twice");
    out.push_back(item);
  }
  return out;
}

FitJobOptions job_options(const FitArgs& a) {
  FitJobOptions o = a.options;
  o.profile_all_free = a.profiles != "none";
  if (a.profiles != "all" && a.profiles != "none") o.profiles = split_list(a.profiles, "--profiles");
  o.channels = split_list(a.channels, "--channels");
  o.free = split_list(a.free, "--free");
  o.progress = [](const std::string& line) { std::cerr << line << "\n"; };
  return o;
}

// The kind of fit follows the log's columns; an option that kind does not use is an error,
// never silently dropped.
void refuse_options(const FitArgs& a, const std::string& kind, const std::set<std::string>& used) {
  for (const auto& opt : a.given)
    if (!used.count(opt)) {
      throw std::invalid_argument(opt + ": not used when fitting " + kind +
                                  " (the log's columns choose the kind of fit); this kind takes " + output::joined(used));
    }
}

void check_flight_options(const FitArgs& a) {
  const bool shooting = a.options.formulation == "multiple_shooting";
  if (a.given.count("--window") && !shooting) throw std::invalid_argument("--window: only with --formulation multiple_shooting");
  if (a.given.count("--translational") && shooting)
    throw std::invalid_argument("--translational: only with --formulation equation_error (multiple shooting fits the pose)");
  if (a.given.count("--channels") && shooting)
    throw std::invalid_argument("--channels: only with --formulation equation_error (multiple shooting fits the pose)");
}

}  // namespace

int run_fit(const FitArgs& a) {
  const Vehicle v = load_vehicle(a.vehicle);
  if (const std::string note = fitted_section_note(v, "fit"); !note.empty()) std::cerr << note << "\n";
  const LogKind kind = log_kind(a.log);
  output::OutputDirectory out(a.out, "fit", {a.vehicle, a.log, a.options.mapping});  // refused before the work, not after
  const FitJobOptions o = job_options(a);
  FitOutputs result;
  if (kind == LogKind::kMotorSteps) {
    refuse_options(a, "a motor-step log", {"--out", "--robust", "--profiles", "--threads"});
    result = fit_motor_steps_log(a.log, v, o);
  } else if (kind == LogKind::kThrustStand) {
    refuse_options(a, "a thrust-stand log", {"--out", "--robust", "--threads"});
    result = fit_thrust_stand_log(a.log, v, o);
  } else {
    check_flight_options(a);
    std::string how;
    const std::unique_ptr<runtime::DynamicModel> model = app::model_for(v, parse_effect_list(a.effects), &how);
    std::cerr << "model: " << how << "\n";
    result = fit_flight_log(a.log, v, *model, o);
  }
  out.add("fit.json", output::json_document(result.json));
  for (const auto& [file, svg] : result.plots) out.add(file, svg);
  for (const auto& err : result.plot_errors) std::cerr << "no plot " << output::printable_lines(err) << "\n";
  commit_and_say(out, "fit");
  std::cout << output::printable_lines(result.summary);
  for (const auto& w : result.warnings) std::cerr << "quadgen: warning: " << output::printable(w) << "\n";
  return 0;
}

}  // namespace quadgen::cli
