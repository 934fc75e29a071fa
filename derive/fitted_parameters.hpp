// Fitted values back into a model: the fitted_parameters.yaml that `quadgen diagnose` writes
// (effects, and parameter values with their units) read by `quadgen derive --params`, so a
// fitted model can be regenerated from the vehicle file and that file alone.
#pragma once
#include <string>
#include <vector>

#include "derive/symbolic_model.hpp"

namespace quadgen {

struct FittedValue {
  std::string name, unit;
  double value = 0;
  int line = 0;  // in the file, for messages
};

struct FittedParameters {
  std::string path;
  std::string vehicle;               // the vehicle they were fitted for; "" in files written before it was recorded
  std::vector<std::string> effects;  // canonical names, as the file lists them
  std::vector<FittedValue> values;
};

// Reads the file: a fitted_parameters.yaml, or a vehicle file's `fitted:` section (the same
// map); a malformed file, an unknown effect or a non-finite value is a VehicleError
// "path:line: ...".
FittedParameters load_fitted_parameters(const std::string& path);

// Gives `p` a value fitted to data: the vehicle file's value as written (`as_written`, shown in
// derivation.md beside the nominal) no longer describes it, so it goes (helper-104, helper-105).
inline void set_fitted_nominal(Variable& p, double value) {
  p.nominal = value;
  p.as_written.clear();
}

// Sets the model's nominal values to the fitted ones. Each must name a parameter of the
// model, in its unit, within its bounds; otherwise VehicleError "path:line: ...".
void apply_fitted_parameters(SymbolicModel& model, const FittedParameters& fitted);

}  // namespace quadgen
