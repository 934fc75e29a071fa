#include "atomic_output.hpp"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <unistd.h>

namespace quadgen {
namespace fs = std::filesystem;

OutputSet::OutputSet(std::string dir) : dir_(std::move(dir)) {
  std::error_code ec;
  fs::create_directories(dir_, ec);
  if (ec || !fs::is_directory(dir_)) throw OutputError(dir_ + ": cannot create output directory");
}

OutputSet::~OutputSet() {
  if (committed_) return;
  for (const auto& p : pending_) std::remove(p.first.c_str());
}

void OutputSet::add(const std::string& filename, const std::string& content) {
  const std::string final_path = (fs::path(dir_) / filename).string();
  const std::string temp = final_path + ".tmp." + std::to_string(getpid());
  {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    if (!out) throw OutputError(final_path + ": cannot write");
    out << content;
    out.flush();
    if (!out) throw OutputError(final_path + ": write failed");
  }
  pending_.push_back({temp, final_path});
}

void OutputSet::commit() {
  // Test hook: die here, after the temporaries are written and before anything is renamed,
  // as a killed process would (tests/test_robustness.cpp).
  if (std::getenv("QUADGEN_TEST_DIE_BEFORE_COMMIT")) _exit(70);
  for (const auto& p : pending_) {
    std::error_code ec;
    fs::rename(p.first, p.second, ec);
    if (ec) throw OutputError(p.second + ": cannot move into place: " + ec.message());
    // Temporaries an earlier, interrupted run left beside this file.
    const fs::path final_path(p.second);
    for (const auto& e : fs::directory_iterator(final_path.parent_path(), ec))
      if (e.path().filename().string().rfind(final_path.filename().string() + ".tmp.", 0) == 0)
        fs::remove(e.path(), ec);
  }
  committed_ = true;
}

}  // namespace quadgen
