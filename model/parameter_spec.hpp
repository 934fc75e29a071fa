// What a model parameter is, one record from the vehicle file through the symbolic model to
// the generated header (kParamUnits, kParamLower, kParamUpper, kParamFit): the vehicle's
// Parameter adds the file line, the symbolic model's Variable adds the GiNaC symbol. At run
// time a parameter is a value with its bounds and fit flag (runtime::Parameter, which the
// installed runtime headers carry without this project's model library).
#pragma once
#include <string>

#include "model/units.hpp"
#include "runtime/parameter.hpp"

namespace quadgen {

struct ParameterSpec {
  std::string name;
  std::string unit;  // SI unit text, e.g. "m/s^2"
  Dimension dim;
  double nominal = 0;           // SI
  double lower = 0, upper = 0;  // bounds in SI; equal: held at the nominal value
  bool fit = false;
  std::string doc;  // what it is
  // The value as the vehicle file wrote it where its unit is not the SI one ("1674 rpm"), for a
  // reviewer who compares the derivation with the file; empty otherwise.
  std::string as_written;
};

// The run-time record of `p` (the one conversion): at `value`, freed by a fit or not.
inline runtime::Parameter runtime_parameter(const ParameterSpec& p, double value, bool free) {
  return {p.name, p.unit, value, p.lower, p.upper, free};
}

// ... at its nominal value, freed as the vehicle file says.
inline runtime::Parameter runtime_parameter(const ParameterSpec& p) { return runtime_parameter(p, p.nominal, p.fit); }

}  // namespace quadgen
