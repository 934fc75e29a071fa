#include "app/extended_model.hpp"

#include <algorithm>
#include <iterator>
#include <sstream>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "app/derive_pipeline.hpp"
#include "derive/fitted_parameters.hpp"
#include "output/numbers.hpp"
#include "output/joined.hpp"
#include "output/sinks.hpp"

namespace quadgen::diagnose {

namespace {

bool selected(const Diagnosis& d, const std::string& effect) {
  return std::find(d.search.selected.begin(), d.search.selected.end(), effect) != d.search.selected.end();
}

std::string fitted_parameters_yaml(const Vehicle& v, const Diagnosis& d) {
  std::ostringstream y;
  y << "# Parameters of " << output::printable(v.name) << " fitted by quadgen diagnose; effects: ";
  for (const auto& e : d.search.selected) y << e << " ";
  for (const auto& e : d.per_flight_effects)
    if (selected(d, e))
      y << "\n# " << e << ": one value per flight in diagnosis.json; here their mean over the " << d.flights.size()
        << " flights";
  y << "\nvehicle: " << v.name << "\neffects: [" << output::joined(d.search.selected) << "]\nparameters:\n";
  for (const auto& p : d.airframe_fit)
    // The shortest text that reads back as the same double: derive --params regenerates the
    // same values, and a fitted 0.05 reads "0.05".
    if (p.free) y << "  " << p.name << ": {value: " << output::full_number(p.value) << ", unit: \"" << p.unit << "\"}\n";
  return y.str();
}

}  // namespace

std::string fitted_vehicle_yaml(const Vehicle& v, const std::string& fitted_parameters) {
  if (v.fitted_line > 0) return "";
  std::string text = v.source_text;
  if (!text.empty() && text.back() != '\n') text += '\n';
  std::ostringstream y;
  y << text << "\n# Written by quadgen diagnose: the effects it named and the values it fitted. `quadgen derive`\n"
    << "# on this file builds the fitted model (the same as extended_model.hpp).\nfitted:\n";
  std::istringstream lines(fitted_parameters);
  for (std::string line; std::getline(lines, line);) y << "  " << line << "\n";
  try {  // a flow-style top level ({name: ...}) cannot take a block key after it
    const YAML::Node node = YAML::Load(y.str());
    if (!node.IsMap() || !node["fitted"] || !node["fitted"]["parameters"]) return "";
  } catch (const YAML::Exception&) {
    return "";
  }
  return y.str();
}

ExtendedModelFiles extended_model(const Vehicle& v, const MassProperties& mass, const Diagnosis& d,
                                  const std::string& vehicle_file, const std::string& logs_label,
                                  bool with_proposed_terms) {
  DeriveRequest request;
  request.derive.effects = d.search.selected;
  if (with_proposed_terms) request.derive.terms = proposed_terms(d.discovered);
  request.set_nominal = [&](SymbolicModel& ext) {  // the header's nominal values are the estimates
    for (const auto& p : d.airframe_fit)
      if (p.free) set_fitted_nominal(ext.params[ext.param_index(p.name)], p.value);
  };
  request.thesis_comparison = false;  // the thesis comparison belongs to the FINken 3's own derivation
  request.emit.vehicle_file = vehicle_file;
  request.regenerate_flags_from_model = true;
  request.emit.parameter_source = "fitted by quadgen diagnose to " + logs_label +
                                  " (fitted_parameters.yaml); regenerating with derive gives the vehicle file's values";
  if (with_proposed_terms)
    request.emit.parameter_source +=
        "; term_* parameters: terms proposed beyond the catalogue (diagnosis.json discovered_terms), not named causes";
  const DerivedModel ext = run_derive_pipeline(v, mass, request);
  const std::string fitted = fitted_parameters_yaml(v, d);
  return {ext.header.content, ext.model_json, ext.derivation_md, fitted, fitted_vehicle_yaml(v, fitted)};
}

}  // namespace quadgen::diagnose
