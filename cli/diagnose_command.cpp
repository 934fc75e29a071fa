// quadgen diagnose VEHICLE.yaml LOG.csv [LOG2.csv ...] --out DIR
// Fits the base model, shows what it gets wrong, names the cause from the effect catalogue,
// regenerates the model with it and measures the gain on the held-out end of the flight
// (of each flight, when several flights of the vehicle are diagnosed jointly).
#include <algorithm>
#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "diagnosis.hpp"
#include "diagnosis_report.hpp"
#include "dynamics.hpp"
#include "effects.hpp"
#include "geometry.hpp"
#include "extended_model.hpp"
#include "json_document.hpp"
#include "log_reader.hpp"
#include "options.hpp"
#include "output_set.hpp"
#include "sinks.hpp"
#include "model_registry.hpp"
#include "vehicle.hpp"

namespace quadgen::cli {

void add_diagnose(CLI::App& app, DiagnoseArgs& a) {
  CLI::App* c = app.add_subcommand("diagnose", "find what the model gets wrong in a flight, name the cause, extend the model");
  c->add_option("vehicle", a.vehicle, "vehicle description (YAML)")->required();
  c->add_option("logs", a.logs,
                std::string("flight log(s): ") + kLogFormats +
                    ". Several flights of the same vehicle are diagnosed jointly, with one set of vehicle parameters "
                    "and the end of each flight held out")
      ->required();
  c->add_option("--out", a.out, "output directory")->required();
  c->add_option("--mapping", a.mapping, "column mapping (YAML) for logs not in the canonical layout");
  c->add_option("--resample", a.resample, "resample the log onto a uniform grid at this rate [Hz] first")
      ->check(finite_range(0.1, 1e5));
  c->add_option("--validation", a.validation, "fraction of the flight (at its end) held out")->check(finite_range(0.1, 0.6));
  c->add_option("--alpha", a.alpha, "family-wise significance level of each selection step")->check(finite_range(1e-9, 0.2));
  c->add_option("--max-effects", a.max_effects, "stop after this many effects")->check(CLI::Range(1, 10));
  std::string effect_names;  // the catalogue, so --help lists what --candidates accepts
  for (const Effect& e : effect_catalogue()) effect_names += (effect_names.empty() ? "" : ", ") + e.name;
  c->add_option("--candidates", a.candidates,
                "comma-separated effects to consider (default: all the log supports): " + effect_names);
  c->add_option("--translational", a.translational, "translational channels: auto, pose or accelerometer")
      ->check(CLI::IsMember({"auto", "pose", "accelerometer"}));
  c->add_option("--environment", a.environment,
                 "where the flights were flown: indoor, outdoor or unknown (default: the mapping's environment, else "
                 "unknown); a finding beyond what is plausible there is reported as a stand-in for missing physics")
      ->check(CLI::IsMember({"indoor", "outdoor", "unknown"}));
  c->add_option("--window", a.window, "validation simulation window [s]")->check(finite_range(0.1, 10.0));
}

int run_diagnose(const DiagnoseArgs& a) {
  const Vehicle v = load_vehicle(a.vehicle);
  std::vector<std::string> rotors;
  for (const auto& r : v.rotors) rotors.push_back(r.name);
  std::vector<fit::Flight> flights;
  const fit::ColumnMapping mapping = a.mapping.empty() ? fit::ColumnMapping{} : fit::load_mapping(a.mapping);
  for (const auto& path : a.logs)
    flights.push_back(fit::load_flight(fit::read_log(path, a.mapping.empty() ? nullptr : &mapping, a.resample), rotors, {}));
  std::string logs_label;  // what the outputs say was diagnosed
  for (const auto& path : a.logs) logs_label += (logs_label.empty() ? "" : ", ") + path;
  size_t samples = 0;
  for (const auto& f : flights) samples += f.samples.size();
  diagnose::DiagnoseOptions o;
  if (!a.candidates.empty()) o.search.candidates = parse_effect_list(a.candidates);
  // Fail before the long work if the results could not be written.
  std::vector<std::string> inputs = a.logs;
  inputs.push_back(a.vehicle);
  inputs.push_back(a.mapping);
  output::OutputDirectory out(a.out, inputs);
  std::cerr << "[diagnose] " << samples << " airborne samples in " << flights.size()
            << (flights.size() > 1 ? " flights (diagnosed jointly)" : " flight") << "; deriving the full-catalogue model\n";
  const MassProperties mp = derive_mass_properties(v);
  DeriveOptions all_opt;
  all_opt.effects = parse_effect_list("all");
  const SymbolicModel all = derive_model(v, mp, all_opt);
  bool compiled = false;
  const auto model = make_model(all, &compiled);
  std::cerr << "[diagnose] model: " << (compiled ? "compiled header from generated/" : "interpreted tape") << "\n";
  o.validation_fraction = a.validation;
  o.window = a.window;
  o.translational = a.translational;
  o.environment = parse_environment(a.environment.empty() ? mapping.environment : a.environment);
  o.search.alpha = a.alpha;
  o.search.max_effects = a.max_effects;
  fit::Flight valid;
  const diagnose::Diagnosis d = diagnose::diagnose_flights(v, all, *model, flights, o, &valid);
  std::cerr << "[diagnose] generating the extended model\n";
  const diagnose::ExtendedModelFiles ext = diagnose::extended_model(v, mp, d, a.vehicle, logs_label);
  std::string err;
  std::vector<std::pair<std::string, std::string>> plot_data;
  const auto plots = diagnose::diagnosis_plots(d, valid, &err, &plot_data);
  if (plots.empty()) std::cerr << "no plots: " << err << "\n";
  out.add("diagnosis.json", output::json_document(diagnose::diagnosis_json(d, logs_label)));
  out.add("report.html", diagnose::diagnosis_html(d, logs_label, plots));
  out.add("extended_model.hpp", ext.header);
  out.add("extended_model.json", ext.model_json);
  out.add("extended_derivation.md", ext.derivation_markdown);
  out.add("fitted_parameters.yaml", ext.fitted_parameters_yaml);
  if (!diagnose::proposed_terms(d.discovered).empty()) {  // the extended model plus the proposed terms
    const diagnose::ExtendedModelFiles disc = diagnose::extended_model(v, mp, d, a.vehicle, logs_label, true);
    out.add("discovered_model.hpp", disc.header);
    out.add("discovered_derivation.md", disc.derivation_markdown);
  }
  for (const auto& [name, svg] : plots) out.add(name, svg);
  for (const auto& [name, csv] : plot_data) out.add(name, csv);  // every plotted series, for Python or MATLAB
  out.commit();
  std::cout << diagnose::diagnosis_summary(d) << "diagnosed in " << d.seconds << " s; wrote " << a.out << "/report.html\n";
  return 0;
}

}  // namespace quadgen::cli
