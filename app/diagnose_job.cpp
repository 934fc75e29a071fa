#include "app/diagnose_job.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "diagnose/diagnosis_report.hpp"
#include "derive/dynamics.hpp"
#include "derive/effects/effect_catalogue.hpp"
#include "app/extended_model.hpp"
#include "derive/geometry.hpp"
#include "output/nearest_word.hpp"
#include "output/numbers.hpp"
#include "output/joined.hpp"
#include "output/names.hpp"
#include "output/json_document.hpp"
#include "output/sinks.hpp"
#include "fit/log_reader.hpp"
#include "fit/read_flight.hpp"
#include "app/model_registry.hpp"
#include "model/vehicle.hpp"
#include "runtime/log_file.hpp"
#include "runtime/parameter.hpp"

namespace quadgen::app {

bool DiagnoseJob::IsValid(std::string* error) const {
  const auto fail = [&](const std::string& why) {
    if (error) *error = why;
    return false;
  };
  if (vehicle.empty()) return fail("no vehicle file");
  if (logs.empty()) return fail("no flight log");
  if (!fit::valid_resample_rate(resample)) return fail("resample: 0 or " + fit::kResampleRange.text("Hz"));
  if (!airframe.empty() && logs.size() != 1)
    return fail("airframe: checks one flight against an airframe; several logs are diagnosed jointly instead");
  if (!environment.empty() && !output::is_one_of(environment, kEnvironmentNames))
    return fail("environment: " + output::joined(kEnvironmentNames));
  return options.IsValid(error);
}

namespace {

std::vector<fit::Flight> load_flights(const DiagnoseJob& job, const Vehicle& v, const fit::ColumnMapping& mapping) {
  std::vector<fit::Flight> flights;
  for (const auto& path : job.logs)
    flights.push_back(fit::read_flight(path, job.mapping.empty() ? nullptr : &mapping, job.resample, v));
  return flights;
}

std::runtime_error airframe_error(const std::string& path, const std::string& what) {
  return std::runtime_error(output::printable(path) + ": " + what);
}

// Names and numbers of an airframe's diagnosis.json, each refused where it is not what
// quadgen writes for this vehicle.
struct AirframeReader {
  const std::string& path;
  const SymbolicModel& all;

  void known(const std::string& name) const {
    std::vector<std::string> names;
    for (const auto& p : all.params) {
      if (p.name == name) return;
      names.push_back(p.name);
    }
    throw airframe_error(path, "'" + output::printable(name) + "' is no parameter of this vehicle's model" +
                                   output::did_you_mean(name, names));
  }
  // The unit an entry gives is the model's (kappa in mm was read as metres by predict --params;
  // a review, helper-135); an entry without one is taken as declared.
  void same_unit(const nlohmann::json& entry, const std::string& where, const std::string& name) const {
    if (!entry.is_object() || !entry.contains("unit")) return;
    const std::string given = entry["unit"].is_string() ? entry["unit"].get<std::string>() : entry["unit"].dump();
    const std::string problem = runtime::unit_problem(runtime_parameter(all.params[all.param_index(name)]), given);
    if (!problem.empty()) throw airframe_error(path, where + output::printable(name) + " " + problem);
  }
  double number(const nlohmann::json& v, const std::string& what) const {
    if (!v.is_number()) throw airframe_error(path, what + ": expected a number");
    return v.get<double>();
  }
  // A parameter's standard error: as written, else from its 95 % interval; 0 where neither is.
  static double standard_error(const nlohmann::json& p) {
    double se = p.contains("standard_error") && p["standard_error"].is_number() ? p["standard_error"].get<double>() : NAN;
    if (!std::isfinite(se)) se = NAN;
    if (!(se > 0) && p.contains("ci95") && p["ci95"].is_array() && p["ci95"].size() == 2 && p["ci95"][0].is_number() &&
        p["ci95"][1].is_number())
      se = (p["ci95"][1].get<double>() - p["ci95"][0].get<double>()) / (2 * fit::kZ95);
    return se > 0 && std::isfinite(se) ? se : 0.0;
  }
  // A finding's airframe effect with its values (no parameters: a flight's state, or only the
  // reference rotor's).
  diagnose::AirframeReference::Effect effect(const nlohmann::json& f) const {
    const std::string name = f.value("effect", "");
    if (name.empty() || !f.contains("parameters")) throw airframe_error(path, "a finding without effect or parameters");
    const Effect* described = effect_named(name);
    if (!described) throw airframe_error(path, "findings: unknown effect '" + output::printable(name) + "'");
    diagnose::AirframeReference::Effect e{name, {}, {}, {}, {}};
    if (described->per_flight) return e;  // a flight's state, freed by read_airframe
    for (const auto& [parameter, p] : f["parameters"].items()) {
      if (p.value("reference", false)) continue;
      known(parameter);
      same_unit(p, "findings: ", parameter);
      const double v = number(p.value("value", nlohmann::json()), parameter);
      // Compared with this flight's estimate: a value outside the parameter's bounds is no
      // estimate quadgen could have written, and an infinite one broke the comparison's test.
      const auto& declared = all.params[all.param_index(parameter)];
      const std::string problem = runtime::value_problem(runtime_parameter(declared), v, true);
      if (!problem.empty()) throw airframe_error(path, "findings: " + output::printable(parameter) + " " + problem);
      e.parameters.push_back(parameter);
      e.value.push_back(v);
      e.standard_error.push_back(standard_error(p));
      e.off.push_back(diagnose::neutral_value(declared));
    }
    return e;
  }
};

diagnose::AirframeReference read_airframe(const nlohmann::json& j, const std::string& path, const SymbolicModel& all) {
  if (!j.is_object() || !j.contains("airframe_fit") || !j.contains("findings") || !j.contains("flight_parameters"))
    throw airframe_error(path, "not a diagnosis.json of quadgen (expected airframe_fit, findings, flight_parameters)");
  const AirframeReader read{path, all};
  diagnose::AirframeReference ref;
  ref.source = path;
  ref.flights = j.contains("flights") && j["flights"].is_array() ? j["flights"].size() : 0;
  for (const auto& p : all.params)
    ref.values.push_back(runtime_parameter(p, is_effect_parameter(p.name) ? diagnose::neutral_value(p) : p.nominal, false));
  for (const auto& [name, e] : j["airframe_fit"].items()) {
    read.known(name);
    read.same_unit(e, "airframe_fit.", name);
    for (auto& p : ref.values)
      if (p.name == name) p.value = std::clamp(read.number(e.value("value", nlohmann::json()), name), p.lower, p.upper);
  }
  for (const auto& n : j["flight_parameters"]) {
    if (!n.is_string()) throw airframe_error(path, "flight_parameters: expected names");
    read.known(n.get<std::string>());
    ref.flight_parameters.push_back(n.get<std::string>());
  }
  for (const auto& f : j["findings"]) {
    diagnose::AirframeReference::Effect e = read.effect(f);
    if (!e.parameters.empty()) ref.effects.push_back(std::move(e));
  }
  return ref;
}

// The airframe an earlier diagnosis found, from its diagnosis.json: its fitted values
// (airframe_fit; parameters it did not fit at the model's nominal or "off" values), the
// parameters each flight has its own value of, and its named airframe effects with their
// values and standard errors. Every name must be a parameter of `all` (the same vehicle).
diagnose::AirframeReference load_airframe(const std::string& path, const SymbolicModel& all) {
  std::string text;
  try {  // opened as a log is: a FIFO or a directory is refused, not waited on; size-limited
    text = runtime::LogFile(path, "a diagnosis.json").read_all();
  } catch (const runtime::LogError& e) {
    throw std::runtime_error(e.what());
  }
  nlohmann::json j;
  if (const std::string problem =
          output::parse_json_input(text, &j, "expected the diagnosis.json of an earlier diagnose run");
      !problem.empty())
    throw airframe_error(path, problem);
  try {
    return read_airframe(j, path, all);
  } catch (const nlohmann::json::exception& e) {  // an entry of another type than quadgen writes
    const std::string what = e.what();
    const size_t bracket = what.find("] ");
    throw airframe_error(path, "not the diagnosis.json layout quadgen writes (" +
                                   output::printable(bracket == std::string::npos ? what : what.substr(bracket + 2)) + ")");
  }
}

}  // namespace

std::string logs_label(const std::vector<std::string>& paths) {
  if (paths.size() == 1 && paths[0].find(", ") == std::string::npos) return paths[0];
  return output::joined(paths, ", ", [](const std::string& p) { return output::shell_path(p); });
}

std::vector<std::string> plot_notes(const std::vector<std::string>& errors, bool none_drawn) {
  std::set<std::string> reasons;
  for (const std::string& e : errors) reasons.insert(e.substr(e.find(": ") + 2));
  if (none_drawn && reasons.size() == 1) return {"no plots: " + *reasons.begin()};
  std::vector<std::string> notes;
  for (const std::string& e : errors) notes.push_back("no plot " + e);
  return notes;
}

namespace {

// The options the job's flags give beyond its DiagnoseOptions: the candidates, the environment.
// A refinement among the candidates without the effect it refines is refused here.
diagnose::DiagnoseOptions options_of(const DiagnoseJob& job, const fit::ColumnMapping& mapping) {
  diagnose::DiagnoseOptions o = job.options;
  if (!job.candidates.empty()) o.search.candidates = parse_effect_list(job.candidates);
  for (const auto& e : refinements_without_their_effect(o.search.candidates)) {  // only ever tested beside it
    const std::string& refined = find_effect(e).refines;
    throw std::invalid_argument("--candidates: " + e + " scales " + refined + "'s terms and is only tested beside it: add " +
                                refined + " too");
  }
  o.search.environment = parse_environment(job.environment.empty() ? mapping.environment : job.environment);
  return o;
}

// Why a diagnosis writes no fitted_vehicle.yaml, and what to do instead.
std::string no_fitted_vehicle_note(const Vehicle& v) {
  return v.fitted_line > 0
             ? "note: no fitted_vehicle.yaml: the vehicle file has a fitted: section already; to build "
               "this fitted model, put fitted_parameters.yaml's lines in its place (or remove it and "
               "run quadgen derive VEHICLE --params fitted_parameters.yaml)"
             : "note: no fitted_vehicle.yaml: a fitted: section cannot be added to this vehicle file's "
               "YAML (a flow-style or indented top level); fitted_parameters.yaml holds the values "
               "(quadgen derive VEHICLE --params fitted_parameters.yaml)";
}

// What a diagnosis writes: the report, the extended model (and the model with the proposed
// terms), the plots and their data.
DiagnoseJobResult diagnosis_files(const DiagnoseJob& job, const Vehicle& v, const MassProperties& mp,
                                  const diagnose::Diagnosis& d, const fit::Flight& valid, const output::Progress& progress) {
  progress.say("[diagnose] generating the extended model");
  const std::string diagnosed = logs_label(job.logs);  // what the outputs say was diagnosed
  const std::string fitted_to = logs_label(d.flights);  // a left-out log is not one of them
  const diagnose::ExtendedModelFiles ext = diagnose::extended_model(v, mp, d, job.vehicle, fitted_to);
  std::vector<std::string> plot_errors;
  std::vector<std::pair<std::string, std::string>> plot_data;
  const auto plots = diagnose::diagnosis_plots(d, valid, &plot_errors, &plot_data);
  DiagnoseJobResult r;
  r.notes = plot_notes(plot_errors, plots.empty());
  r.files = {{"diagnosis.json", output::json_document(diagnose::diagnosis_json(d, diagnosed))},
             {"report.html", diagnose::diagnosis_html(d, diagnosed, plots)},
             {"extended_model.hpp", ext.header},
             {"extended_model.json", ext.model_json},
             {"extended_derivation.md", ext.derivation_markdown},
             {"fitted_parameters.yaml", ext.fitted_parameters_yaml}};
  if (!ext.fitted_vehicle_yaml.empty()) r.files.push_back({"fitted_vehicle.yaml", ext.fitted_vehicle_yaml});
  else r.notes.push_back(no_fitted_vehicle_note(v));
  if (!diagnose::proposed_terms(d.discovered).empty()) {  // the extended model plus the proposed terms
    const diagnose::ExtendedModelFiles disc = diagnose::extended_model(v, mp, d, job.vehicle, fitted_to, true);
    r.files.push_back({"discovered_model.hpp", disc.header});
    r.files.push_back({"discovered_derivation.md", disc.derivation_markdown});
  }
  for (const auto& [name, svg] : plots) r.files.push_back({name, svg});
  for (const auto& [name, csv] : plot_data) r.files.push_back({name, csv});  // every plotted series, for Python or MATLAB
  std::ostringstream summary;
  summary << diagnose::diagnosis_summary(d) << "diagnosed in " << output::short_number(d.seconds) << " s";
  r.summary = summary.str();
  return r;
}

}  // namespace

DiagnoseJobResult run_diagnose_job(const DiagnoseJob& job) {
  std::string error;
  if (!job.IsValid(&error)) throw std::invalid_argument("diagnose: " + error);
  runtime::refuse_repeated_files(job.logs, "flight log");
  const Vehicle v = load_vehicle(job.vehicle);
  const fit::ColumnMapping mapping = job.mapping.empty() ? fit::ColumnMapping{} : fit::load_mapping(job.mapping);
  diagnose::DiagnoseOptions o = options_of(job, mapping);
  // The model and the airframe first: a wrong --airframe file is said before the logs are read.
  if (const std::string note = fitted_section_note(v, "diagnose"); !note.empty()) o.progress.say("[diagnose] " + note);
  o.progress.say("[diagnose] deriving the full-catalogue model's equations (its parameters, units and structure)");
  const MassProperties mp = derive_mass_properties(v);
  DeriveOptions all_opt;
  all_opt.effects = parse_effect_list("all");
  const SymbolicModel all = derive_model(v, mp, all_opt);
  if (!job.airframe.empty()) o.airframe = load_airframe(job.airframe, all);

  const std::vector<fit::Flight> flights = load_flights(job, v, mapping);
  for (const auto& f : flights)  // said before the long work, not after it
    for (const auto& note : f.notes) o.progress.say("[diagnose] " + note);
  size_t samples = 0;
  for (const auto& f : flights) samples += f.samples.size();
  o.progress.say("[diagnose] " + std::to_string(samples) + " airborne samples in " + std::to_string(flights.size()) +
                 (flights.size() > 1 ? " logs (diagnosed jointly)" : " log"));
  bool compiled = false;
  const auto model = make_model(all, &compiled);
  o.progress.say(std::string("[diagnose] evaluating it with ") +
                 (compiled ? "the compiled header in generated/, derived from the same equations"
                           : "the equations interpreted (no header compiled into quadgen matches this vehicle: normal for "
                             "your own vehicle, the same numbers, slower; README, \"the tape\")"));
  fit::Flight valid;
  const diagnose::Diagnosis d = diagnose::diagnose_flights(v, all, *model, flights, o, &valid);
  return diagnosis_files(job, v, mp, d, valid, o.progress);
}

}  // namespace quadgen::app
