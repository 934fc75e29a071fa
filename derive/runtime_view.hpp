// The derived vehicle at its nominal parameters, as the runtime takes it: each rotor's thrust
// law (command <-> thrust) and the controller's belief for closed-loop flights. One place, so
// simulation, tests and reports build them alike. Numbers only (the runtime's header-only
// types): derive/ links nothing of the runtime.
#pragma once
#include <vector>

#include "runtime/closed_loop.hpp"
#include "runtime/scenarios.hpp"
#include "runtime/thrust_law.hpp"
#include "derive/symbolic_model.hpp"
#include "model/vehicle.hpp"

namespace quadgen {

std::vector<runtime::ThrustLaw> nominal_thrust_laws(const Vehicle& v, const SymbolicModel& m);
runtime::ControllerModel nominal_controller_belief(const Vehicle& v, const SymbolicModel& m);
// Where each rotor sits relative to the nominal centre of gravity, and its spin: what the
// thesis' tilt and yaw manoeuvres choose their rotors by (runtime/scenarios.hpp).
std::vector<runtime::RotorPlace> rotor_places(const Vehicle& v, const SymbolicModel& m);
// The same, from a belief already built (simulate builds one and reads everything from it).
std::vector<runtime::RotorPlace> rotor_places(const runtime::ControllerModel& b);

}  // namespace quadgen
