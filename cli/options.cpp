#include "cli/options.hpp"

#include "derive/dynamics.hpp"
#include "derive/effects/effect_catalogue.hpp"

namespace quadgen::cli {

std::string parameter_names_help() {
  std::string base;
  for (const std::string& name : base_parameter_names()) base += (base.empty() ? "" : ", ") + name;
  // vbat_ref is the vehicle file's, but a model has it only with battery_sag.
  return "the vehicle's (" + base + "; in a model with battery_sag also vbat_ref; model.json lists a model's) and the effects' (" +
         catalogue_parameter_names() + ")";
}

}  // namespace quadgen::cli
