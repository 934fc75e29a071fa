// The fastest model for a derived vehicle: the compiled header from generated/ when it was
// generated from the same vehicle file (SHA-256) and effects and has the derivation's
// states, inputs, parameters and nominal values, else the interpreted tape.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "runtime/dynamic_model.hpp"
#include "derive/symbolic_model.hpp"
#include "model/vehicle.hpp"

namespace quadgen::app {
std::unique_ptr<runtime::DynamicModel> make_model(const SymbolicModel& m, bool* compiled = nullptr);
// The model of this vehicle with these effects: the compiled header when generated/ has it,
// else the tape of a fresh derivation. `how` (optional) says which, for the progress line.
std::unique_ptr<runtime::DynamicModel> model_for(const Vehicle& v, const std::vector<std::string>& effects,
                                                 std::string* how = nullptr);
}
