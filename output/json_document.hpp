// JSON as it leaves the program: indented, one trailing newline, and bytes that are not UTF-8
// (a path from the command line may hold any) replaced instead of aborting the write. The line
// and paragraph separators U+2028 and U+2029 are valid in a JSON string but end a line in
// JavaScript before ES2019 and in some editors: they are written as \u2028 and \u2029 (JSON
// emits them only inside strings, so the bytes are replaced wherever they stand).
#pragma once
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "output/numbers.hpp"
#include "output/sinks.hpp"

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

// JSON as it comes in (a --params or --airframe file): parsed into `out`, or why not in words
// to follow "path: " (empty when it parsed). nlohmann's parser takes 1e-400 as 0
// (json_number_problem), throws its own bare "number overflow" for 1e400, naming no file, and
// keeps the last of a key given twice without a word (a review, helper-135): each said here.
// `expected` ends the message of text that is no JSON ("expected the diagnosis.json of ...").
inline std::string parse_json_input(const std::string& text, nlohmann::json* out, const std::string& expected) {
  std::vector<std::set<std::string>> keys;  // the keys of each object open at this point
  std::string twice;
  const nlohmann::json::parser_callback_t each = [&](int, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
    if (event == nlohmann::json::parse_event_t::object_start) keys.emplace_back();
    if (event == nlohmann::json::parse_event_t::object_end && !keys.empty()) keys.pop_back();
    if (event == nlohmann::json::parse_event_t::key && !keys.empty() && !keys.back().insert(parsed.get<std::string>()).second &&
        twice.empty())
      twice = parsed.get<std::string>();
    return true;
  };
  try {
    *out = nlohmann::json::parse(text, each);
  } catch (const nlohmann::json::parse_error& e) {
    return "not JSON (the text stops parsing at byte " + std::to_string(e.byte) + "); " + expected;
  } catch (const nlohmann::json::out_of_range&) {
    return "a number in it is beyond a double's range (about ±1.8e308)";
  }
  if (!twice.empty()) return "the key '" + printable(twice) + "' is given twice in one object (which value is meant?)";
  return json_number_problem(text);
}

}  // namespace quadgen::output
