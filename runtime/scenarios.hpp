// The manoeuvres of the thesis, section 2.3, as per-rotor thrust profiles, turned into
// motor commands through the inverse of the thrust law and motor map.
#pragma once
#include <string>
#include <vector>

#include "runtime/thrust_law.hpp"

namespace quadgen::runtime {

struct Scenario {
  std::string name;
  std::string description;
  // Thrust per rotor [N] at time t; rotors in vehicle order.
  std::vector<double> (*thrust)(double t, double hover, const std::vector<std::string>& rotors);
  // Gives the thesis' rotor roles A..D to rotors 1..4 (a tilt or yaw manoeuvre): flown only on
  // a vehicle with four rotors. The others change every rotor alike and fly any vehicle.
  bool rotor_roles = false;
};

const std::vector<Scenario>& scenario_catalogue();
const Scenario& find_scenario(const std::string& name);  // throws std::invalid_argument

}  // namespace quadgen::runtime
