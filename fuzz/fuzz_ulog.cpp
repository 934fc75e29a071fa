// Fuzz target: the PX4 ULog reader. Only LogError may come out, and a parsed log must be
// consistent: every topic has `timestamp` as its first column and every row as many values
// as the topic has columns.
#include <cstddef>
#include <cstdint>
#include <string>

#include "runtime/ulog.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  try {
    const auto log = quadgen::runtime::parse_ulog(bytes, "fuzz.ulg");
    for (const auto& t : log.topics) {
      if (t.fields.empty() || t.fields[0] != "timestamp") __builtin_trap();
      for (const auto& row : t.rows)
        if (row.size() != t.fields.size()) __builtin_trap();
    }
    if (log.truncated && log.truncated_at >= size) __builtin_trap();
  } catch (const quadgen::runtime::LogError&) {
  }
  return 0;
}
