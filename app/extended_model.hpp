// The diagnosis' last step: the model regenerated with exactly the effects it found, its
// nominal values set to the estimates, so the header a user compiles is the fitted model.
// Written beside the report as extended_model.hpp, its derivation and fitted_parameters.yaml
// (which `quadgen derive --params` reads back).
#pragma once
#include <string>

#include "diagnose/diagnosis.hpp"
#include "derive/geometry.hpp"
#include "model/vehicle.hpp"

namespace quadgen::diagnose {

struct ExtendedModelFiles {
  std::string header;                   // extended_model.hpp
  std::string model_json;               // extended_model.json
  std::string derivation_markdown;      // extended_derivation.md
  std::string fitted_parameters_yaml;   // fitted_parameters.yaml
  std::string fitted_vehicle_yaml;      // fitted_vehicle.yaml: the vehicle file plus `fitted:` ("": not written)
};

// The vehicle file as it was read (v.source_text, comments kept; not read again, so a file
// edited during the diagnosis does not mix into it), with the fitted values appended as its
// `fitted:` section: `quadgen derive` on it builds the fitted model. Empty when the file has
// a `fitted:` section already, or is not a block map a key can be appended to.
std::string fitted_vehicle_yaml(const Vehicle& v, const std::string& fitted_parameters);

// `vehicle_file` and `logs_label` say in the header where the model and its values came from.
// With `with_proposed_terms`, the terms proposed beyond the catalogue are added too (written
// as discovered_model.hpp: a lead, not the named causes' model).
ExtendedModelFiles extended_model(const Vehicle& v, const MassProperties& mass, const Diagnosis& d,
                                  const std::string& vehicle_file, const std::string& logs_label,
                                  bool with_proposed_terms = false);

}  // namespace quadgen::diagnose
