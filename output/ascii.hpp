// Letters folded to lower case the same way in every locale: only A-Z change (std::tolower
// follows the C locale a program may change, and is undefined for a negative char).
#pragma once
#include <string>

namespace quadgen::output {

constexpr char ascii_lower(char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; }

inline std::string ascii_lower(std::string s) {
  for (char& c : s) c = ascii_lower(c);
  return s;
}

}  // namespace quadgen::output
