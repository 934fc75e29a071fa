#include "extended_model.hpp"

#include <algorithm>
#include <sstream>
#include <vector>

#include "audit.hpp"
#include "dynamics.hpp"
#include "header_writer.hpp"
#include "report.hpp"
#include "sinks.hpp"

namespace quadgen::diagnose {

namespace {

bool selected(const Diagnosis& d, const std::string& effect) {
  return std::find(d.search.selected.begin(), d.search.selected.end(), effect) != d.search.selected.end();
}

std::string fitted_parameters_yaml(const Vehicle& v, const Diagnosis& d) {
  std::ostringstream y;
  y.precision(17);  // round-trips: derive --params regenerates the same values
  y << "# Parameters of " << output::printable(v.name) << " fitted by quadgen diagnose; effects: ";
  for (const auto& e : d.search.selected) y << e << " ";
  for (const auto& e : d.per_flight_effects)
    if (selected(d, e))
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

ExtendedModelFiles extended_model(const Vehicle& v, const MassProperties& mass, const Diagnosis& d,
                                  const std::string& vehicle_file, const std::string& logs_label,
                                  bool with_proposed_terms) {
  DeriveOptions options;
  options.effects = d.search.selected;
  if (with_proposed_terms) options.terms = proposed_terms(d.discovered);
  SymbolicModel ext = derive_model(v, mass, options);
  for (const auto& p : d.airframe_fit)  // the header's nominal values are the estimates
    if (p.free) ext.params[ext.param_index(p.name)].nominal = p.value;
  emission::EmitOptions eo;
  eo.vehicle_file = vehicle_file;
  eo.effects_flag = ext.effects.empty() ? "" : " --effects " + ext.effect_list();
  eo.parameter_source = "fitted by quadgen diagnose to " + logs_label +
                        " (fitted_parameters.yaml); regenerating with derive gives the vehicle file's values";
  if (with_proposed_terms)
    eo.parameter_source += "; term_* parameters: terms proposed beyond the catalogue (diagnosis.json discovered_terms), "
                           "not named causes";
  const std::vector<ThesisItem> no_thesis;  // the thesis comparison belongs to the FINken 3 derivation
  const AuditResult ext_audit = audit(ext, mass);
  const Derivation der{v, mass, ext, ext_audit, no_thesis};
  return {emission::generate_header(ext, eo).content, model_json(der), derivation_markdown(der), fitted_parameters_yaml(v, d)};
}

}  // namespace quadgen::diagnose
