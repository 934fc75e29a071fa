#include "diagnose_job.hpp"

#include <iostream>
#include <sstream>
#include <stdexcept>

#include "diagnosis_report.hpp"
#include "dynamics.hpp"
#include "effect_catalogue.hpp"
#include "extended_model.hpp"
#include "geometry.hpp"
#include "json_document.hpp"
#include "log_reader.hpp"
#include "model_registry.hpp"
#include "vehicle.hpp"

namespace quadgen::app {

bool DiagnoseJob::IsValid(std::string* error) const {
  const auto fail = [&](const std::string& why) {
    if (error) *error = why;
    return false;
  };
  if (vehicle.empty()) return fail("no vehicle file");
  if (logs.empty()) return fail("no flight log");
  if (!fit::valid_resample_rate(resample)) return fail("resample: 0 or 0.1 to 1e5 Hz");
  if (!environment.empty() && environment != "indoor" && environment != "outdoor" && environment != "unknown")
    return fail("environment: indoor, outdoor or unknown");
  return options.IsValid(error);
}

namespace {

std::vector<fit::Flight> load_flights(const DiagnoseJob& job, const Vehicle& v, const fit::ColumnMapping& mapping) {
  std::vector<std::string> rotors;
  for (const auto& r : v.rotors) rotors.push_back(r.name);
  std::vector<fit::Flight> flights;
  for (const auto& path : job.logs)
    flights.push_back(fit::load_flight(fit::read_log(path, job.mapping.empty() ? nullptr : &mapping, job.resample), rotors, {}));
  return flights;
}

}  // namespace

DiagnoseJobResult run_diagnose_job(const DiagnoseJob& job) {
  std::string error;
  if (!job.IsValid(&error)) throw std::invalid_argument("diagnose: " + error);
  const Vehicle v = load_vehicle(job.vehicle);
  const fit::ColumnMapping mapping = job.mapping.empty() ? fit::ColumnMapping{} : fit::load_mapping(job.mapping);
  const std::vector<fit::Flight> flights = load_flights(job, v, mapping);
  std::string logs_label;  // what the outputs say was diagnosed
  for (const auto& path : job.logs) logs_label += (logs_label.empty() ? "" : ", ") + path;
  size_t samples = 0;
  for (const auto& f : flights) samples += f.samples.size();
  diagnose::DiagnoseOptions o = job.options;
  if (!job.candidates.empty()) o.search.candidates = parse_effect_list(job.candidates);
  o.environment = parse_environment(job.environment.empty() ? mapping.environment : job.environment);

  std::cerr << "[diagnose] " << samples << " airborne samples in " << flights.size()
            << (flights.size() > 1 ? " flights (diagnosed jointly)" : " flight") << "; deriving the full-catalogue model\n";
  const MassProperties mp = derive_mass_properties(v);
  DeriveOptions all_opt;
  all_opt.effects = parse_effect_list("all");
  const SymbolicModel all = derive_model(v, mp, all_opt);
  bool compiled = false;
  const auto model = make_model(all, &compiled);
  std::cerr << "[diagnose] model: " << (compiled ? "compiled header from generated/" : "interpreted tape") << "\n";
  fit::Flight valid;
  const diagnose::Diagnosis d = diagnose::diagnose_flights(v, all, *model, flights, o, &valid);

  std::cerr << "[diagnose] generating the extended model\n";
  const diagnose::ExtendedModelFiles ext = diagnose::extended_model(v, mp, d, job.vehicle, logs_label);
  std::string err;
  std::vector<std::pair<std::string, std::string>> plot_data;
  const auto plots = diagnose::diagnosis_plots(d, valid, &err, &plot_data);
  if (plots.empty()) std::cerr << "no plots: " << err << "\n";
  DiagnoseJobResult r;
  r.files = {{"diagnosis.json", output::json_document(diagnose::diagnosis_json(d, logs_label))},
             {"report.html", diagnose::diagnosis_html(d, logs_label, plots)},
             {"extended_model.hpp", ext.header},
             {"extended_model.json", ext.model_json},
             {"extended_derivation.md", ext.derivation_markdown},
             {"fitted_parameters.yaml", ext.fitted_parameters_yaml}};
  if (!diagnose::proposed_terms(d.discovered).empty()) {  // the extended model plus the proposed terms
    const diagnose::ExtendedModelFiles disc = diagnose::extended_model(v, mp, d, job.vehicle, logs_label, true);
    r.files.push_back({"discovered_model.hpp", disc.header});
    r.files.push_back({"discovered_derivation.md", disc.derivation_markdown});
  }
  for (const auto& [name, svg] : plots) r.files.push_back({name, svg});
  for (const auto& [name, csv] : plot_data) r.files.push_back({name, csv});  // every plotted series, for Python or MATLAB
  std::ostringstream summary;
  summary << diagnose::diagnosis_summary(d) << "diagnosed in " << d.seconds << " s";
  r.summary = summary.str();
  return r;
}

}  // namespace quadgen::app
