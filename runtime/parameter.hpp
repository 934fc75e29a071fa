// A model parameter as it travels from the vehicle file to the outputs: name, SI unit, value,
// the bounds a fit keeps it in, and whether a fit frees it by default (the vehicle file's
// `fit`; an effect's parameters are freed by the effect search). The generated header and the
// tape carry all of it, so a fit needs no symbolic derivation when a compiled header matches.
// fit::FitParameter is this record.
#pragma once
#include <string>

namespace quadgen::runtime {

struct Parameter {
  std::string name, unit;
  double value = 0, lower = 0, upper = 0;
  bool free = true;
};

}  // namespace quadgen::runtime
