// The fastest model for a derived vehicle: the compiled header from generated/ when it was
// generated from the same vehicle file and effects, else the interpreted tape.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "runtime/dynamic_model.hpp"
#include "derive/symbolic_model.hpp"
#include "model/vehicle.hpp"

namespace quadgen::app {
std::unique_ptr<runtime::DynamicModel> make_model(const SymbolicModel& m, bool* compiled = nullptr);
// The compiled header generated from this vehicle file (its bytes' hash) with these effects,
// found without deriving; nullptr when generated/ has none. Its parameters carry units,
// bounds and fit flags, so fit and predict then need no symbolic derivation.
std::unique_ptr<runtime::DynamicModel> compiled_model_for(const Vehicle& v, const std::vector<std::string>& effects);
// The model of this vehicle with these effects: the compiled header when generated/ has it,
// else the tape of a fresh derivation. `how` (optional) says which, for the progress line.
std::unique_ptr<runtime::DynamicModel> model_for(const Vehicle& v, const std::vector<std::string>& effects,
                                                 std::string* how = nullptr);
}
