// quadgen fit VEHICLE.yaml LOG --out DIR: flags into an app::FitJob (defaults are the
// library's), the job's files written as one output set. The kind of fit follows the log's
// layout; an option that kind does not use is refused. The pipeline itself: app/fit_job.cpp.
#include <iostream>

#include "app/fit_job.hpp"
#include "cli/fit_command.hpp"
#include "cli/options.hpp"
#include "derive/effects/effect_catalogue.hpp"
#include "fit/log_reader.hpp"
#include "model/vehicle.hpp"
#include "output/names.hpp"
#include "output/output_set.hpp"
#include "output/progress.hpp"
#include "output/sinks.hpp"

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
      ->check(CLI::IsMember(kFitFormulations));
  c->add_option("--window", a.options.window, "multiple shooting: window length [s]")->check(finite_range(kFitWindowRange));
  c->add_option("--resample", a.options.resample, "resample the log onto a uniform grid at this rate [Hz] first")
      ->check(finite_range(kResampleRange))
      ->default_str(fit::resample_default_text());
  c->add_option("--channels", a.channels, "residual channels to fit (default all): ax,ay,az,pdot,qdot,rdot");
  c->add_option("--translational", a.options.translational,
                "equation error: ax, ay, az from the accelerometer (body specific force at each sample) or from the "
                "pose (world acceleration, the differentiated velocity, exact for commands held between samples)")
      ->check(CLI::IsMember(kTranslationalSources))
      ->default_str("the accelerometer where logged, else the pose");
  c->add_option("--free", a.free,
                std::string("parameters to fit (comma-separated), overriding the vehicle file's fit flags: ") +
                    parameter_names_help());
  c->add_option("--profiles", a.profiles,
                "profile likelihood of: all free parameters, none (estimates and standard errors only), or "
                "comma-separated names (as for --free)")
      ->capture_default_str();
  c->add_option("--threads", a.options.threads, "threads for the profiles (0: one per core)")
      ->check(whole_number_in(0, kMaxThreads))
      ->capture_default_str();
}

namespace {

FitJobOptions job_options(const FitArgs& a) {
  FitJobOptions o = a.options;
  o.profile_all_free = a.profiles != "none";
  if (a.profiles != "all" && a.profiles != "none") o.profiles = output::split_name_list(a.profiles, "--profiles");
  o.channels = output::split_name_list(a.channels, "--channels");
  o.free = output::split_name_list(a.free, "--free");
  o.progress = output::terminal_progress().line;  // escapes what a line quotes (a name, a path)
  return o;
}

// The kind of fit follows the log's columns; a flag given that this kind does not read is an
// error, never silently dropped (even at its default value). The rule is the library's.
void refuse_unused_flags(const FitArgs& a, LogKind kind) {
  for (const auto& flag : a.given) {
    if (flag == "--out") continue;
    if (const std::string why = why_unused(flag.substr(2), kind, a.options.formulation, "--"); !why.empty())
      throw std::invalid_argument(flag + ": " + why);
  }
}

}  // namespace

int run_fit(const FitArgs& a) {
  const Vehicle v = load_vehicle(a.vehicle);  // a bad file is reported before anything is created
  const LogKind kind = log_kind(a.log);
  refuse_unused_flags(a, kind);
  output::OutputDirectory out(a.out, "fit", {a.vehicle, a.log, a.options.mapping});  // refused before the work, not after
  const app::FitJobResult r = app::run_fit_job({a.log, a.effects, job_options(a)}, v, kind);
  for (const auto& [name, contents] : r.files) out.add(name, contents);
  for (const auto& note : r.notes) std::cerr << output::printable_lines(note) << "\n";
  commit_and_say(out, "fit");
  std::cout << output::printable_lines(r.summary);
  for (const auto& w : r.warnings) std::cerr << "quadgen: warning: " << output::printable(w) << "\n";
  return 0;
}

}  // namespace quadgen::cli
