// Two derivations side by side, for a reviewer who changed a vehicle (an arm, a block, a
// parameter) and wants to know what that did to the model: which blocks, rotors and values
// differ, and which equations are no longer the same function.
//
// Equations are compared as functions, not as text: each right-hand side, measurement and
// intermediate quantity (each rotor's thrust, drag, F_body, tau) is evaluated at a few random
// points, the two models' symbols matched by name and given the same values, each model's
// constants (rotor geometry) its own. Two expressions that agree at random points of all
// their symbols are the same function with overwhelming probability (a polynomial identity
// test, Schwartz 1980); a difference at any point is certain. Which parameter values differ is
// said apart from this, so a changed block reads as "mass and J_xx have other values", and a
// changed arm as "the torque rows differ: same symbols, other numbers".
#pragma once
#include <string>
#include <vector>

#include "derive/geometry.hpp"
#include "derive/symbolic_model.hpp"
#include "model/vehicle.hpp"

namespace quadgen {

// One side of the comparison: the vehicle file as read, and what derive made of it.
struct DerivationSide {
  const Vehicle& vehicle;
  const SymbolicModel& model;
};

struct NumberChange {
  std::string name, unit;
  double a = 0, b = 0;
};

// An equation (a row of f or h, or an intermediate quantity) in both models.
struct EquationComparison {
  std::string name;  // the state's derivative ("q_dot"), the output, or the intermediate ("\\tau")
  std::string kind;  // "right-hand side", "measurement", "intermediate"
  bool same = false;
  double largest_relative_difference = 0;  // over the points; 0 where the same
  std::vector<std::string> only_in_a, only_in_b;  // symbols one side's expression has and the other's lacks
};

struct DerivationComparison {
  std::vector<std::string> effects_only_a, effects_only_b;
  std::vector<std::string> blocks_only_a, blocks_only_b, blocks_changed;  // changed: "name: what"
  std::vector<std::string> rotors_only_a, rotors_only_b, rotors_changed;
  std::vector<std::string> parameters_only_a, parameters_only_b;
  std::vector<NumberChange> parameter_values;   // nominal values that differ
  std::vector<std::string> parameter_settings;  // bounds, unit or fit flag that differ: "name: what"
  std::vector<NumberChange> constants;          // rotor geometry and other fixed numbers
  std::vector<std::string> states_only_a, states_only_b, inputs_only_a, inputs_only_b;
  std::vector<EquationComparison> equations;  // those in both models
  int points = 0;                             // random points each equation was evaluated at

  bool same() const;
};

struct ComparisonOptions {
  int points = 3;
  unsigned seed = 1;
  double relative_tolerance = 1e-9;  // relative to the larger magnitude of the two values
};

DerivationComparison compare_derivations(const DerivationSide& a, const DerivationSide& b, const ComparisonOptions& opt = {});

// The comparison as a person reads it, every name from a file made printable; `label_a` and
// `label_b` say which is which (the files' paths).
std::string comparison_text(const DerivationComparison& c, const std::string& label_a, const std::string& label_b);

}  // namespace quadgen
