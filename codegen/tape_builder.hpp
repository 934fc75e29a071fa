// Builds the runtime's interpreted model (runtime/tape.hpp) from a symbolic model by
// lowering the same plan (lowered_model) that header_writer prints as C++.
#pragma once
#include "derive/symbolic_model.hpp"
#include "runtime/tape.hpp"

namespace quadgen::codegen {
runtime::Tape build_tape(const SymbolicModel& m);
}
