// Whether one residual evaluation may be split over the machine's cores. A diagnosis fits
// most candidates side by side, one fit per core (CandidateSearch, profiles); there, splitting
// each evaluation again would only make the threads fight for the same cores. The fits that
// run alone (the base fit, the refit after each selection, the intervals) are a third of a
// joint diagnosis' time, and they use every core only if their evaluations split.
#pragma once
#include <atomic>
#include <cstddef>
#include <functional>

namespace quadgen::fit {

// While one lives, evaluations on this thread are split into exactly `parts` parts
// (1: they stay on this thread, as in a pool that runs one fit per core; 0: as before it).
class EvaluationParts {
 public:
  explicit EvaluationParts(size_t parts);
  ~EvaluationParts();
  EvaluationParts(const EvaluationParts&) = delete;
  EvaluationParts& operator=(const EvaluationParts&) = delete;

 private:
  size_t previous_;
};

// A thread of a pool that runs one fit per core; `in_pool` false: a pool of one thread,
// whose fit may split its evaluations.
class OneCorePerFit : public EvaluationParts {
 public:
  explicit OneCorePerFit(bool in_pool = true) : EvaluationParts(in_pool ? 1 : 0) {}
};

// How many parts an evaluation over `items` independent items should be split into on this
// thread: what an EvaluationParts in scope says; else one per core (at most 8) for long work.
size_t evaluation_parts(size_t items);

// The one way quadgen runs work on several threads (a split evaluation, a pool of candidate
// fits, the profile sides): body(w, stopped) for each worker w < workers, worker 0 on the calling
// thread, the others each on a thread of its own (or after worker 0 on the calling thread when
// no thread can be started). Returns when all are done; the first failure is rethrown then,
// and `stopped` turns true as soon as one worker fails, so that workers taking jobs from a shared
// queue stop taking them.
void run_workers(size_t workers, const std::function<void(size_t worker, const std::atomic<bool>& stopped)>& body);

}  // namespace quadgen::fit
