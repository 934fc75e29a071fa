// FNV-1a 64-bit: a fast, stable content hash (output manifests, the generator's options
// hash). Not cryptographic: it detects change, not tampering; a vehicle file's identity, which
// a forgery could abuse, is SHA-256 (model/sha256.hpp).
#pragma once
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

namespace quadgen::output {

// The published offset basis (Fowler, Noll, Vo: 0xcbf29ce484222325).
constexpr uint64_t kFnv1aOffsetBasis = 14695981039346656037ull;
// The basis with a digit dropped, which quadgen used until 2026-11-28: manifests written then
// carry it, and are still recognised (output_set.cpp); nothing new is hashed with it.
constexpr uint64_t kFnv1aLegacyBasis = 1469598103934665603ull;

// Incremental form, for content read in pieces.
class Fnv1a {
 public:
  explicit Fnv1a(uint64_t basis = kFnv1aOffsetBasis) : h_(basis) {}
  void add(const char* bytes, size_t n) {
    for (size_t i = 0; i < n; ++i) {
      h_ ^= static_cast<unsigned char>(bytes[i]);
      h_ *= 1099511628211ull;
    }
  }
  std::string hex() const {
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h_));
    return buf;
  }

 private:
  uint64_t h_;
};

inline std::string fnv1a_hex(const std::string& bytes) {
  Fnv1a h;
  h.add(bytes.data(), bytes.size());
  return h.hex();
}

}  // namespace quadgen::output
