// Fills the file skeleton in templates/model.hpp.mustache with the emitted code.
#pragma once
#include <string>

#include "symbolic_model.hpp"

namespace quadgen::emission {

struct EmitOptions {
  std::string vehicle_file;  // as named on the command line, for the regenerate comment
  std::string effects_flag;  // "--effects ..." or ""
};

struct GeneratedHeader {
  std::string name;     // namespace and folder name, e.g. "finken3_with_motor_lag"
  std::string content;
  double ops_before = 0, ops_after = 0, ops_f_before = 0, ops_f_after = 0, pre_ops = 0;
  int pre_count = 0;
};

GeneratedHeader generate_header(const SymbolicModel& m, const EmitOptions& opt);

// The model's name: vehicle, plus effects.
std::string model_name(const SymbolicModel& m);

}  // namespace quadgen::emission
