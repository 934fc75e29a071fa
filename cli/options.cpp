#include "cli/options.hpp"

#include "derive/dynamics.hpp"
#include "derive/effects/effect_catalogue.hpp"
#include "output/joined.hpp"

namespace quadgen::cli {

std::string parameter_names_help() {
  const std::string base = output::joined(base_parameter_names());
  // vbat_ref is the vehicle file's, but a model has it only with battery_sag.
  return "the vehicle's (" + base + "; in a model with battery_sag also vbat_ref; model.json lists a model's) and the effects' (" +
         catalogue_parameter_names() + ")";
}

}  // namespace quadgen::cli
