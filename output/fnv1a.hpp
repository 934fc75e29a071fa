// FNV-1a 64-bit: a fast, stable content hash (vehicle files in generated headers, output
// manifests). Not cryptographic: it detects change, not tampering.
#pragma once
#include <cstdint>
#include <cstdio>
#include <string>

namespace quadgen::output {

inline std::string fnv1a_hex(const std::string& bytes) {
  uint64_t h = 1469598103934665603ull;
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ull;
  }
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

}  // namespace quadgen::output
