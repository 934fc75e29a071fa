// Fuzz target: the vehicle-file parser. Any input must either parse or raise one of the
// documented errors (VehicleError, UnitError); crashes, hangs and other exceptions are bugs.
#include <cstddef>
#include <cstdint>
#include <string>

#include "model/vehicle.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const quadgen::Vehicle v = quadgen::parse_vehicle(text, "fuzz.yaml");
    // A parsed vehicle must satisfy what the parser promised.
    for (const auto& b : v.blocks)
      if (!(b.mass > 0) || !(b.size[0] > 0) || !(b.size[1] > 0) || !(b.size[2] > 0)) __builtin_trap();
    for (const char* p : {"g", "rho", "c_w", "c_t", "kappa", "a0", "a1", "a2"}) (void)quadgen::param(v, p);
  } catch (const quadgen::VehicleError&) {
  } catch (const quadgen::UnitError&) {
  }
  return 0;
}
