// quadgen diagnose VEHICLE.yaml LOG.csv [LOG2.csv ...] --out DIR
// Fits the base model, shows what it gets wrong, names the cause from the effect catalogue,
// regenerates the model with it and measures the gain on the held-out end of the flight
// (of each flight, when several flights of the vehicle are diagnosed jointly).
#include <algorithm>
#include <iostream>
#include <sstream>

#include "audit.hpp"
#include "commands.hpp"
#include "diagnosis.hpp"
#include "diagnosis_report.hpp"
#include "dynamics.hpp"
#include "effects.hpp"
#include "geometry.hpp"
#include "header_writer.hpp"
#include "json_document.hpp"
#include "log_reader.hpp"
#include "options.hpp"
#include "output_set.hpp"
#include "sinks.hpp"
#include "model_registry.hpp"
#include "report.hpp"
#include "vehicle.hpp"

namespace quadgen::cli {

void add_diagnose(CLI::App& app, DiagnoseArgs& a) {
  CLI::App* c = app.add_subcommand("diagnose", "find what the model gets wrong in a flight, name the cause, extend the model");
  c->add_option("vehicle", a.vehicle, "vehicle description (YAML)")->required();
  c->add_option("logs", a.logs,
                "flight log(s) (CSV): several flights of the same vehicle are diagnosed jointly, with one set of "
                "vehicle parameters and the end of each flight held out")
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

namespace {

std::string fitted_parameters_yaml(const Vehicle& v, const diagnose::Diagnosis& d) {
  std::ostringstream y;
  y.precision(17);  // round-trips: derive --params regenerates the same values
  y << "# Parameters of " << output::printable(v.name) << " fitted by quadgen diagnose; effects: ";
  for (const auto& e : d.search.selected) y << e << " ";
  for (const auto& e : d.per_flight_effects)
    if (std::find(d.search.selected.begin(), d.search.selected.end(), e) != d.search.selected.end())
      y << "\n# " << e << ": one value per flight in diagnosis.json; here their mean over the " << d.flights.size()
        << " flights";
  y << "\neffects: [";
  for (size_t i = 0; i < d.search.selected.size(); ++i) y << (i ? ", " : "") << d.search.selected[i];
  y << "]\nparameters:\n";
  for (const auto& p : d.airframe_fit)
    if (p.free) y << "  " << p.name << ": {value: " << p.value << ", unit: \"" << p.unit << "\"}\n";
  return y.str();
}

}  // namespace

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
  // The extended model, regenerated with exactly the effects found.
  std::cerr << "[diagnose] generating the extended model\n";
  DeriveOptions ext_opt;
  ext_opt.effects = d.search.selected;
  SymbolicModel ext = derive_model(v, mp, ext_opt);
  // The extended header is the fitted model: its nominal values are the estimates.
  for (const auto& p : d.airframe_fit)
    if (p.free) ext.params[ext.param_index(p.name)].nominal = p.value;
  emission::EmitOptions eo;
  eo.vehicle_file = a.vehicle;
  eo.effects_flag = ext.effects.empty() ? "" : " --effects " + ext.effect_list();
  eo.parameter_source = "fitted by quadgen diagnose to " + logs_label +
                        " (fitted_parameters.yaml); regenerating with derive gives the vehicle file's values";
  const auto header = emission::generate_header(ext, eo);
  const AuditResult ext_audit = audit(ext, mp);
  const std::vector<ThesisItem> no_thesis;
  const Derivation der{v, mp, ext, ext_audit, no_thesis};
  std::string err;
  std::vector<std::pair<std::string, std::string>> plot_data;
  const auto plots = diagnose::diagnosis_plots(d, valid, &err, &plot_data);
  if (plots.empty()) std::cerr << "no plots: " << err << "\n";
  out.add("diagnosis.json", output::json_document(diagnose::diagnosis_json(d, logs_label)));
  out.add("report.html", diagnose::diagnosis_html(d, logs_label, plots));
  out.add("extended_model.hpp", header.content);
  out.add("extended_model.json", model_json(der));
  out.add("extended_derivation.md", derivation_markdown(der));
  out.add("fitted_parameters.yaml", fitted_parameters_yaml(v, d));
  for (const auto& [name, svg] : plots) out.add(name, svg);
  for (const auto& [name, csv] : plot_data) out.add(name, csv);  // every plotted series, for Python or MATLAB
  out.commit();
  std::cout << diagnose::diagnosis_summary(d) << "diagnosed in " << d.seconds << " s; wrote " << a.out << "/report.html\n";
  return 0;
}

}  // namespace quadgen::cli
