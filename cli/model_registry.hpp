// The fastest model for a derived vehicle: the compiled header from generated/ when it was
// generated from the same vehicle file and effects, else the interpreted tape.
#pragma once
#include <memory>

#include "dynamic_model.hpp"
#include "symbolic_model.hpp"

namespace quadgen::cli {
std::unique_ptr<runtime::DynamicModel> make_model(const SymbolicModel& m, bool* compiled = nullptr);
}
