// The manoeuvres of the thesis, section 2.3, as per-rotor thrust profiles, turned into
// motor commands through the inverse of the thrust law and motor map.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "runtime/thrust_law.hpp"

namespace quadgen::runtime {

// Where a rotor sits relative to the centre of gravity (body frame) and which way it spins:
// what the tilt and yaw manoeuvres choose their rotors by.
struct RotorPlace {
  double x = 0, y = 0;  // m
  bool ccw = true;
};

struct Scenario {
  std::string name;
  std::string description;
  // Thrust per rotor [N] at time t; rotors in vehicle order. The tilt and yaw manoeuvres raise
  // the rotors on one side of the centre of gravity, or those of one spin, wherever they are
  // listed: the thesis' rotor roles on the FINken 3 (A, D on -x; C, D on +y; A, C ccw), and
  // the same manoeuvre on any layout.
  std::vector<double> (*thrust)(double t, double hover, const std::vector<RotorPlace>& rotors);
  // What the manoeuvre means to change of (thrust, roll, pitch, yaw), the rows of the
  // allocation matrix. On a vehicle whose rotors carry different trims (a CoG off the centre)
  // the raised rotors' steps also turn it about the other axes: simulate takes that part out.
  std::array<bool, 4> changes{};
};

const std::vector<Scenario>& scenario_catalogue();
const Scenario& find_scenario(const std::string& name);  // throws std::invalid_argument

}  // namespace quadgen::runtime
