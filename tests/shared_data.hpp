// The real measurements beside the clone (../shared/data: the NanoBench flights, the ARPL log,
// the thrust stand). Where they are absent, a test that needs them is skipped; where the run
// says they must be there (QUADGEN_REQUIRE_SHARED_DATA=1, which .ci/run sets when
// ../shared/data exists), a missing file fails the test instead of skipping it silently.
#pragma once
#include <cstdlib>
#include <filesystem>
#include <string>

namespace quadgen::test {

inline std::filesystem::path shared_data(const std::string& relative) {
  return std::filesystem::path(QUADGEN_SOURCE_DIR) / "../shared/data" / relative;
}

inline bool shared_data_required() {
  const char* v = std::getenv("QUADGEN_REQUIRE_SHARED_DATA");
  return v && std::string(v) == "1";
}

}  // namespace quadgen::test

// In a test body: skip (or fail, where required) unless `path` exists.
#define QUADGEN_NEEDS_SHARED_DATA(path)                                                              \
  do {                                                                                              \
    if (!std::filesystem::exists(path)) {                                                           \
      if (quadgen::test::shared_data_required()) FAIL() << "missing " << (path)                     \
                                                        << " (QUADGEN_REQUIRE_SHARED_DATA=1)";      \
      GTEST_SKIP() << "needs the shared data beside the clone: " << (path);                         \
    }                                                                                               \
  } while (0)
