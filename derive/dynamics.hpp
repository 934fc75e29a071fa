// Assembles the rigid-body flight model of a multirotor from its vehicle description,
// mass properties and a set of effects: forces and torques, translation (Newton /
// D'Alembert for the centre of gravity, expressed for the body origin), rotation
// (angular-momentum balance J dω/dt = τ − ω × Jω), quaternion kinematics.
#pragma once
#include <string>
#include <vector>

#include "derive/added_terms.hpp"
#include "derive/geometry.hpp"
#include "derive/symbolic_model.hpp"
#include "model/vehicle.hpp"

namespace quadgen {

// Intermediate quantities an effect may change before the equations are closed.
struct ModelContext {
  ModelContext(const Vehicle& v, SymbolicModel& m) : vehicle(v), model(m) {}
  const Vehicle& vehicle;
  SymbolicModel& model;

  // Body-frame geometry and state pieces.
  GiNaC::matrix position{3, 1}, velocity{3, 1}, q{4, 1}, omega{3, 1};
  GiNaC::matrix R{3, 3};  // body -> world
  GiNaC::matrix cog{3, 1};
  GiNaC::matrix air_velocity_world{3, 1};
  GiNaC::matrix extra_body_force{3, 1};
  GiNaC::matrix extra_body_torque{3, 1};  // body-frame moment about the CoG from effects
  std::vector<GiNaC::ex> rotor_speed;   // rad/s, per rotor
  std::vector<GiNaC::ex> thrust_scale;  // multiplies each rotor's thrust
  // Each rotor's thrust is thrust_scale c_t rho A_p r_p^2 w (w - thrust_speed_loss): an
  // effect that lowers the thrust in proportion to w (inflow) sets the loss [rad/s].
  std::vector<GiNaC::ex> thrust_speed_loss;
  // Multiplies motor_lag's time constant for each rotor (1 unless motor_lag_spread sets it;
  // without motor_lag there is no lag to scale).
  std::vector<GiNaC::ex> lag_factor;
  std::vector<GiNaC::matrix> rotor_position;  // m, body frame, each rotor's hub (named constants)
  std::vector<GiNaC::ex> rotor_radius;        // m, r_p
  std::vector<GiNaC::ex> rotor_disc_area;     // m^2, A_p
  std::vector<GiNaC::ex> commanded_speed;  // motor map of the command, per rotor
  GiNaC::matrix measured_q{4, 1};       // attitude as logged

  // A parameter as its record says (a vehicle file's, with its name as the model calls it).
  GiNaC::symbol add_param(const ParameterSpec& spec);
  GiNaC::symbol add_param(const std::string& name, const std::string& unit, double nominal,
                          double lower, double upper, bool fit, const std::string& doc);
  GiNaC::symbol add_state(const std::string& name, const std::string& unit, const std::string& doc);
  GiNaC::symbol add_input(const std::string& name, const std::string& unit, const std::string& doc);
  GiNaC::symbol add_constant(const std::string& name, const std::string& unit, double value, const std::string& doc);
  GiNaC::ex p(const std::string& name) const;  // symbol of a declared parameter
  std::vector<GiNaC::ex> extra_rates;          // d/dt of states added by effects, in order
};

struct DeriveOptions {
  std::vector<std::string> effects;  // any order; duplicates rejected
  std::vector<AddedTerm> terms;      // beyond the catalogue, applied after the effects
};

SymbolicModel derive_model(const Vehicle& v, const MassProperties& mp, const DeriveOptions& opt);

// Computes dfdx, dfdu, dfdp, dhdx, dhdp from f and h.
void differentiate(SymbolicModel& m);

// The names of the parameters every model has (the vehicle file's scalars as the model calls
// them, then the quantities the blocks give), in the order derive_model declares them;
// motor_slope only where the file gives a slope.
std::vector<std::string> base_parameter_names();

// The TeX name of rotor `rotor`'s thrust among SymbolicModel::intermediates ("F_{\mathrm{A}}").
std::string rotor_thrust_name(const std::string& rotor);

// A derived total (mass, J_*, A_*) far beyond its `derived:` bounds, as a unit slip in the
// blocks would give it: the likely slip in words, to append to the error; "" when none fits.
std::string unit_slip(const Vehicle& v, const std::string& name, double value, const Parameter& declared);

}  // namespace quadgen
