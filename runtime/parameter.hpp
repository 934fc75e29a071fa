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

// Why `value` cannot be given to `p` from outside (predict --params, derive --params, a
// diagnosis read by --airframe, simulate --set), or "" when it can: not finite; with
// `within_bounds`, outside p's bounds where it has any (lower < upper; equal bounds hold a
// parameter fixed, and any value may replace it); the rigid body's mass and principal moments
// of inertia not positive, or an exposed area negative, which the model would integrate
// without a word. (The vehicle file's `derived:` values are judged by it too.) (A test flight's
// truth may lie outside what a fit searches, so simulate checks no bounds.)
std::string value_problem(const Parameter& p, double value, bool within_bounds);

// Why a file's `unit` for `p` is not p's, or "" when it is: "is in m, the file says 'mm'". The
// units quadgen writes (diagnosis.json, fit.json, fitted_parameters.yaml) are the declared
// ones character for character, so a file of its own always passes; one rule for derive
// --params, predict --params and diagnose --airframe (kappa in mm was read as metres by the
// last two: a review, helper-135).
std::string unit_problem(const Parameter& p, const std::string& unit);

}  // namespace quadgen::runtime
