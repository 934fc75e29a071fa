#include "fit/evaluation_threads.hpp"

#include <algorithm>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace quadgen::fit {

namespace {
thread_local size_t parts_in_scope = 0;  // 0: none set, decide by the work's size
// Below this many samples a part is not worth a thread (a sample's model evaluation with
// its Jacobian takes microseconds; starting a thread, tens of them).
constexpr size_t kMinItemsPerPart = 1000;
}  // namespace

EvaluationParts::EvaluationParts(size_t parts) : previous_(parts_in_scope) {
  if (parts > 0) parts_in_scope = parts;
}
EvaluationParts::~EvaluationParts() { parts_in_scope = previous_; }

size_t evaluation_parts(size_t items) {
  if (parts_in_scope > 0) return std::min(parts_in_scope, std::max<size_t>(1, items));
  const size_t cores = std::clamp<size_t>(std::thread::hardware_concurrency(), 1, 8);
  return std::max<size_t>(1, std::min(cores, items / kMinItemsPerPart));
}

void run_workers(size_t workers, const std::function<void(size_t, const std::atomic<bool>&)>& body) {
  std::atomic<bool> stopped{false};
  std::mutex failing;
  std::exception_ptr failure;
  const auto run = [&](size_t w) {
    try {
      body(w, stopped);
    } catch (...) {
      const std::lock_guard<std::mutex> lock(failing);
      if (!failure) failure = std::current_exception();
      stopped = true;
    }
  };
  std::vector<std::thread> threads;
  std::vector<size_t> here;  // workers without a thread of their own
  for (size_t w = 1; w < workers; ++w) {
    try {
      threads.emplace_back(run, w);
    } catch (...) {
      here.push_back(w);
    }
  }
  run(0);
  for (size_t w : here) run(w);
  for (auto& t : threads) t.join();
  if (failure) std::rethrow_exception(failure);
}

}  // namespace quadgen::fit
