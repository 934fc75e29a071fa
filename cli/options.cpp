#include "cli/options.hpp"

#include "derive/dynamics.hpp"
#include "derive/effects/effect_catalogue.hpp"

namespace quadgen::cli {

std::string parameter_names_help() {
  std::string base;
  for (const std::string& name : base_parameter_names()) base += name + ", ";
  return "the vehicle's (" + base + "and vbat_ref with battery_sag; model.json lists a model's) and the effects' (" +
         catalogue_parameter_names() + ")";
}

}  // namespace quadgen::cli
