// JSON as it leaves the program: indented, one trailing newline, and bytes that are not UTF-8
// (a path from the command line may hold any) replaced instead of aborting the write. The line
// and paragraph separators U+2028 and U+2029 are valid in a JSON string but end a line in
// JavaScript before ES2019 and in some editors: they are written as \u2028 and \u2029 (JSON
// emits them only inside strings, so the bytes are replaced wherever they stand).
#pragma once
#include <string>

#include <nlohmann/json.hpp>

namespace quadgen::output {

template <typename Json>
std::string json_document(const Json& j) {
  std::string out = j.dump(2, ' ', false, Json::error_handler_t::replace);
  for (size_t at = out.find("\xE2\x80"); at != std::string::npos; at = out.find("\xE2\x80", at + 1)) {
    if (at + 2 >= out.size()) break;
    const char last = out[at + 2];
    if (last == '\xA8' || last == '\xA9') out.replace(at, 3, last == '\xA8' ? "\\u2028" : "\\u2029");
  }
  return out + "\n";
}

}  // namespace quadgen::output
