// quadgen diagnose VEHICLE.yaml LOG.csv [LOG2.csv ...] --out DIR: flags into an
// app::DiagnoseJob (defaults are the library's), the job's files written as one output set.
// The pipeline itself: app/diagnose_job.cpp.
#include <iostream>

#include "cli/diagnose_command.hpp"
#include "app/diagnose_job.hpp"
#include "derive/effects/effect_catalogue.hpp"
#include "cli/options.hpp"
#include "fit/log_reader.hpp"
#include "output/output_set.hpp"
#include "output/progress.hpp"
#include "output/sinks.hpp"

namespace quadgen::cli {

void add_diagnose(CLI::App& app, DiagnoseArgs& a) {
  app::DiagnoseJob& j = a.job;
  diagnose::DiagnoseOptions& o = j.options;
  CLI::App* c = app.add_subcommand("diagnose", "find what the model gets wrong in a flight, name the cause, extend the model");
  c->add_option("vehicle", j.vehicle, "vehicle description (YAML)")->required();
  c->add_option("logs", j.logs,
                std::string("flight log(s): ") + kLogFormats +
                    ". Several flights of the same vehicle are diagnosed jointly, with one set of vehicle parameters "
                    "and the end of each flight held out")
      ->required();
  c->add_option("--out", a.out,
                "output directory (created; an earlier diagnose output there is replaced, a folder holding anything "
                "else is refused)")
      ->required();
  c->add_option("--mapping", j.mapping, "column mapping (YAML) for logs not in the canonical layout");
  c->add_option("--resample", j.resample, "resample the log onto a uniform grid at this rate [Hz] first")
      ->check(finite_range(fit::kResampleRange))
      ->default_str(fit::resample_default_text());
  c->add_option("--validation", o.validation_fraction, "fraction of the flight (at its end) held out")
      ->check(finite_range(diagnose::kDiagnoseValidationRange));
  c->add_option("--alpha", o.search.alpha, "family-wise significance level of each selection step")
      ->check(finite_range(diagnose::kAlphaRange));
  c->add_option("--max-effects", o.search.max_effects,
                "effects the search may select at most, named or carried (each forward step adds one; one the backward pass "
                "drops gives its place back; the held-out tests may then turn effects down)")
      ->check(whole_number_in(1, static_cast<long long>(diagnose::kMaxEffectsAllowed)));
  const std::string effect_names = catalogue_names();  // --help lists what --effects accepts
  c->add_option("--candidates", j.candidates,
                "comma-separated effects to consider (default: all the log supports): " + effect_names);
  c->add_option("--translational", o.translational, "translational channels: the differentiated velocity of the pose, or the accelerometer's specific "
                "force; auto: the pose where the log has one, else the accelerometer")
      ->check(CLI::IsMember(diagnose::kTranslationalChoices));
  c->add_option("--environment", j.environment,
                 "where the flights were flown: indoor, outdoor or unknown (default: the mapping's environment, else "
                 "unknown); a finding beyond what is plausible there is reported as a stand-in for missing physics")
      ->check(CLI::IsMember(kEnvironmentNames));
  c->add_option("--window", o.window, "length of each open-loop simulation the held-out position error is scored over [s]")->check(finite_range(diagnose::kDiagnoseWindowRange));
  c->add_option("--window-stride", o.window_stride,
                "time between the starts of the validation windows the held-out position error is taken over [s]: "
                "0 (consecutive windows) or from " + output::short_number(diagnose::kSmallestWindowStride) + " to below --window")
      ->check(finite_range(0.0, diagnose::kDiagnoseWindowRange.hi));  // the rest: DiagnoseOptions::IsValid
  c->add_option("--airframe", j.airframe,
                "diagnosis.json of an earlier diagnosis of this vehicle (best a joint one: its airframe is what several "
                "flights share): also refit its named effects on this one flight and say whether the flight agrees with it");
}

int run_diagnose(const DiagnoseArgs& a) {
  app::DiagnoseJob j = a.job;
  j.options.progress = output::terminal_progress();
  std::string error;
  if (!j.IsValid(&error)) throw std::invalid_argument(error);
  // Fail before the long work if the results could not be written.
  std::vector<std::string> inputs = j.logs;
  inputs.push_back(j.vehicle);
  inputs.push_back(j.mapping);
  inputs.push_back(j.airframe);
  output::OutputDirectory out(a.out, "diagnose", inputs);
  const app::DiagnoseJobResult r = app::run_diagnose_job(j);
  for (const auto& note : r.notes) std::cerr << output::printable(note) << "\n";
  for (const auto& [name, contents] : r.files) out.add(name, contents);
  commit_and_say(out, "diagnose");
  std::cout << output::printable_lines(r.summary) << "; wrote " << output::printable(a.out) << "/report.html\n";
  return 0;
}

}  // namespace quadgen::cli
