#include "fit/evaluation_threads.hpp"

#include <algorithm>
#include <thread>

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

}  // namespace quadgen::fit
