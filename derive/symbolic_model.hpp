// The symbolic flight model handed from the derivation to the code generator,
// the audit and the report: named variables with units, f(x,u,p), the measurement
// h(x,p), and their Jacobians, all as GiNaC expressions.
#pragma once
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <ginac/ginac.h>

#include "model/parameter_spec.hpp"
#include "model/units.hpp"

namespace quadgen {

// A state, input, output, constant or parameter of the symbolic model: its record (for
// states and inputs only name, unit, dimension and doc mean anything) and its symbol.
struct Variable : ParameterSpec {
  GiNaC::symbol sym;
};

struct SymbolicModel {
  std::string vehicle_name;
  std::string vehicle_hash;
  std::vector<std::string> effects;  // canonical order
  std::vector<Variable> states, inputs, params;
  // Fixed numbers with units (rotor geometry): symbols in the derivation so that the
  // unit audit sees their units, replaced by their exact values in generated code.
  std::vector<Variable> constants;

  GiNaC::matrix f;  // dx/dt, states.size() x 1
  // The states that are rotor speeds (motor_lag's w_<rotor>), in rotor order; empty when the
  // rotors follow their commands at once. Their rows of f have a generated function of their
  // own (a fit that filters the commands through the lag needs only them at every sample).
  std::vector<size_t> rotor_speed_states;
  std::vector<Variable> outputs;  // what is measured (pose), names and units
  GiNaC::matrix h;  // outputs.size() x 1, depends on x and p

  // The Jacobians of f and h with the constants already replaced by their values, as the
  // generated code has them: differentiated after the substitution, the rotor geometry folds
  // into numeric coefficients and the trees to differentiate shrink (an octocopter's f by
  // about half), which is most of the time a derive takes.
  GiNaC::matrix dfdx, dfdu, dfdp, dhdx, dhdp;
  // f once more, with dω/dt in the translation rows (the origin's transport acceleration)
  // kept as the symbols `omega_dot`: the chain rule then differentiates dω/dt once, in rows
  // 10-12, instead of once for each of its copies in rows 3-5 (derive time; see
  // differentiate()). Equal to f once omega_dot is replaced by rows 10-12.
  GiNaC::matrix f_split;
  std::vector<GiNaC::symbol> omega_dot;

  // Set when the input_delay effect is on: the runtime feeds u(t - delay) and uses
  // dfdu * du/dt for the delay's sensitivity (a pure delay is not an ODE term).
  std::optional<size_t> input_delay_param;

  // Intermediate quantities written out in full (thrust of each rotor, drag, body force,
  // torque), for checks that compare them with other derivations (the thesis comparison).
  std::vector<std::pair<std::string, GiNaC::ex>> intermediates;

  // The same quantities as the report prints them, in reading order, each written with the
  // ones before it as named symbols: rotor speed ω_i, thrust F_i and moment τ_i of each rotor,
  // the air velocity v_a in body axes, drag, then F_body and τ as sums of those. A reviewer
  // checks one small step at a time instead of one expanded tree. When `rhs_tex` is set it is
  // the right-hand side (a sum over rotors, written as such) and `rhs` is unused.
  struct NamedEquation {
    std::string lhs;  // TeX
    GiNaC::ex rhs;
    std::string rhs_tex;
  };
  std::vector<NamedEquation> named_equations;

  // Each effect's own formula for the report: what it does to the model's intermediate
  // quantities, derived by applying it alone to the base model (TeX left-hand side, value).
  struct EffectFormula {
    std::string effect;
    std::vector<std::pair<std::string, GiNaC::ex>> lines;
    std::string note;  // what the lines leave out (a delay is no ODE term; the other rotors)
  };
  std::vector<EffectFormula> effect_formulas;

  size_t state_index(const std::string& name) const;
  size_t param_index(const std::string& name) const;
  size_t input_index(const std::string& name) const;
  // The entry of `intermediates` named `name` (TeX: "\\tau", "F_{drag}"); std::out_of_range
  // when the model has none (every derived model has each rotor's thrust, drag, F_body and τ).
  const GiNaC::ex& intermediate(const std::string& name) const;
  GiNaC::lst nominal_substitution() const;  // params == nominal values
  GiNaC::lst constant_substitution() const;  // constants == exact values
  // The effects in canonical order joined by `separator` ("motor_gain,motor_lag"): the
  // --effects flag that regenerates this model, and a generated header's kEffects.
  std::string effect_list(const std::string& separator = ",") const;
};

}  // namespace quadgen
