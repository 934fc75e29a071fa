// The manoeuvres of the thesis, section 2.3, as per-rotor thrust profiles, turned into
// motor commands through the inverse of the thrust law and motor map.
#pragma once
#include <string>
#include <vector>

#include "runtime/thrust_law.hpp"

namespace quadgen::runtime {

// What it takes to turn a thrust into a command for one rotor:
// F = k w^2 with k = c_t rho A_p r_p^2, and w = a0 + a1 u + a2 u^2.
struct ThrustLaw {
  double k = 0;
  double a0 = 0, a1 = 0, a2 = 0;
  double command_for(double thrust) const;  // throws if unreachable for u in [0, 1]
};

struct Scenario {
  std::string name;
  std::string description;
  // Thrust per rotor [N] at time t; rotors in vehicle order.
  std::vector<double> (*thrust)(double t, double hover, const std::vector<std::string>& rotors);
};

const std::vector<Scenario>& scenario_catalogue();
const Scenario& find_scenario(const std::string& name);  // throws std::invalid_argument

}  // namespace quadgen::runtime
