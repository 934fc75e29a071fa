// JSON as it leaves the program: indented, one trailing newline, and bytes that are not UTF-8
// (a path from the command line may hold any) replaced instead of aborting the write.
#pragma once
#include <string>

#include <nlohmann/json.hpp>

namespace quadgen::output {

template <typename Json>
std::string json_document(const Json& j) {
  return j.dump(2, ' ', false, Json::error_handler_t::replace) + "\n";
}

}  // namespace quadgen::output
