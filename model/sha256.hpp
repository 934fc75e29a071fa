// SHA-256 (OpenSSL's libcrypto): the identity of a vehicle file where a forged identity would
// do harm. A generated header is used in place of a fresh derivation when its recorded hash
// equals the vehicle file's (app/model_registry.cpp); with FNV-1a (output/fnv1a.hpp), which detects
// change but not tampering, sixteen bytes appended in a comment could give any file the hash
// of a bundled one and run that vehicle's compiled physics, with its input count, on it.
#pragma once
#include <string>

namespace quadgen {

// The SHA-256 digest of `bytes` as 64 lower-case hex digits.
std::string sha256_hex(const std::string& bytes);

}  // namespace quadgen
