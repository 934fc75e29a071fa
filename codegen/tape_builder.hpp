// Builds the runtime's interpreted model (runtime/tape.hpp) from a symbolic model, through
// the same canonical expression DAG the C++ emitter uses.
#pragma once
#include "derive/symbolic_model.hpp"
#include "runtime/tape.hpp"

namespace quadgen::codegen {
runtime::Tape build_tape(const SymbolicModel& m);
}
