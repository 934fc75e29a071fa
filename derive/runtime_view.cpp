#include "derive/runtime_view.hpp"

namespace quadgen {

namespace {
double nominal(const SymbolicModel& m, const char* name) { return m.params[m.param_index(name)].nominal; }
}  // namespace

// The map as the model has it (derive/dynamics.cpp, commanded_rotor_speed): turned about the
// pivot command by the slope where the vehicle file gives one. Turned, it is still a
// quadratic in u: w = (1 - s) map(pivot) + s map(u).
std::vector<runtime::ThrustLaw> nominal_thrust_laws(const Vehicle& v, const SymbolicModel& m) {
  double a0 = nominal(m, "motor_a0"), a1 = nominal(m, "motor_a1"), a2 = nominal(m, "motor_a2");
  if (v.params.count("slope")) {
    const double s = nominal(m, "motor_slope"), pivot = param(v, "pivot").nominal;
    const double at_pivot = a0 + a1 * pivot + a2 * pivot * pivot;
    a0 = (1 - s) * at_pivot + s * a0, a1 *= s, a2 *= s;
  }
  std::vector<runtime::ThrustLaw> laws;
  for (const Rotor& r : v.rotors)
    laws.push_back({runtime::rotor_thrust_coefficient(nominal(m, "c_t"), nominal(m, "rho"), r.disc_area, r.radius), a0, a1, a2});
  return laws;
}

runtime::ControllerModel nominal_controller_belief(const Vehicle& v, const SymbolicModel& m) {
  runtime::ControllerModel b;
  b.mass = nominal(m, "mass");
  b.g = nominal(m, "g");
  b.J[0] = nominal(m, "J_xx");
  b.J[1] = nominal(m, "J_yy");
  b.J[2] = nominal(m, "J_zz");
  b.kappa = nominal(m, "kappa");
  for (const Rotor& r : v.rotors) {
    b.rotor_x.push_back(r.position[0] - nominal(m, "cog_x"));
    b.rotor_y.push_back(r.position[1] - nominal(m, "cog_y"));
    b.spin.push_back(spin_sign(r));
  }
  b.thrust_laws = nominal_thrust_laws(v, m);
  return b;
}

std::vector<runtime::RotorPlace> rotor_places(const runtime::ControllerModel& b) {
  std::vector<runtime::RotorPlace> out;
  for (size_t i = 0; i < b.rotor_x.size(); ++i) out.push_back({b.rotor_x[i], b.rotor_y[i], b.spin[i] > 0});
  return out;
}

std::vector<runtime::RotorPlace> rotor_places(const Vehicle& v, const SymbolicModel& m) {
  return rotor_places(nominal_controller_belief(v, m));
}

}  // namespace quadgen
