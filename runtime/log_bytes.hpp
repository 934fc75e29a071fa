// What the binary log readers (runtime/ulog, runtime/usd_log) share: little-endian integers
// read byte by byte whatever the host, and text taken from a log quoted in a one-line message.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace quadgen::runtime {

// The n-byte (n <= 8) little-endian unsigned integer at p.
inline std::uint64_t little_endian(const char* p, unsigned n) {
  std::uint64_t v = 0;
  for (unsigned i = n; i-- > 0;) v = (v << 8) | static_cast<unsigned char>(p[i]);
  return v;
}

// Text from a log in a one-line message: control characters as '?', cut short after `max`.
inline std::string text_from_log(std::string_view s, std::size_t max) {
  std::string out;
  for (char c : s.substr(0, max)) out += (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) ? '?' : c;
  return s.size() > max ? out + "..." : out;
}

// The same in quotes, at most 40 characters.
inline std::string quoted_from_log(std::string_view s) { return "'" + text_from_log(s, 40) + "'"; }

}  // namespace quadgen::runtime
