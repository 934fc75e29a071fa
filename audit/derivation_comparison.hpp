// Two derivations side by side, for a reviewer who changed a vehicle (an arm, a block, a
// parameter) and wants to know what that did to the model: which blocks, rotors and values
// differ, and which equations are no longer the same function.
//
// Equations are compared as functions, not as text: each right-hand side, measurement and
// intermediate quantity (each rotor's thrust, drag, F_body, tau) is evaluated at a few random
// points, the two models' symbols matched by name and given the same values, each model's
// constants (rotor geometry) its own. The points are rationals and the evaluation exact (to
// 40 digits where a root or a function leaves an irrational), so a difference of a part in
// 1e15 is seen. Agreement at random points is the polynomial identity test (Schwartz 1980) for
// rational functions; for the rest (|v| in the frame drag, roots) it is evidence, not proof,
// which the random signs of the states make harder to fool. A difference at any point is
// certain. Which parameter values differ is said apart from this, so a changed block reads as
// "mass and J_xx have other values", and a changed arm as "the torque rows differ: the same
// symbols, other numbers".
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
  std::string name;  // plain text: the state's derivative ("dq/dt"), the output, the intermediate ("tau[1]")
  std::string kind;  // "right-hand side", "measurement", "intermediate"
  bool same = false;  // the same value at every point
  double largest_relative_difference = 0;  // over the points; 0 where the same
  int points_not_compared = 0;  // where a side is no number (a pole, a symbol left): counted as differing
  std::vector<std::string> only_in_a, only_in_b;  // symbols one side's expression has and the other's lacks
};

struct DerivationComparison {
  std::string vehicle_name_a, vehicle_name_b;  // the name goes into the generated code
  std::vector<std::string> effects_only_a, effects_only_b;
  std::vector<std::string> blocks_only_a, blocks_only_b, blocks_changed;  // changed: "name: what"
  std::vector<std::string> rotors_only_a, rotors_only_b, rotors_changed;
  std::vector<std::string> parameters_only_a, parameters_only_b;
  std::vector<NumberChange> parameter_values;   // nominal values that differ
  std::vector<std::string> parameter_settings;  // bounds, unit or fit flag that differ: "name: what"
  std::vector<NumberChange> constants;          // rotor geometry and other fixed numbers
  std::vector<std::string> constants_only_a, constants_only_b;
  std::vector<std::string> states_only_a, states_only_b, inputs_only_a, inputs_only_b, outputs_only_a, outputs_only_b;
  // States, inputs, parameters or outputs both have in another order ("inputs: u_M1, u_M2 ->
  // u_M2, u_M1"): the generated code's arrays are laid out in that order.
  std::vector<std::string> order_changes;
  std::vector<EquationComparison> equations;  // those in both models
  std::vector<std::string> equations_only_a, equations_only_b;  // an intermediate one side has
  int points = 0;                             // random points each equation was evaluated at

  bool same() const;
};

struct ComparisonOptions {
  int points = 3;
  unsigned seed = 1;
  // Relative to the larger magnitude of the two values: above the 40-digit evaluation's
  // rounding, far below any change a vehicle file can make.
  double relative_tolerance = 1e-30;
};

DerivationComparison compare_derivations(const DerivationSide& a, const DerivationSide& b, const ComparisonOptions& opt = {});

// The comparison as a person reads it, every name from a file made printable; `label_a` and
// `label_b` say which is which (the files' paths).
std::string comparison_text(const DerivationComparison& c, const std::string& label_a, const std::string& label_b);

}  // namespace quadgen
