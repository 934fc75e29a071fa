// How long work tells a person how far it has got, kept apart from where the words go: the
// command line sends them to the terminal (terminal_progress), a library caller wherever it
// likes, and by default they go nowhere. Text is passed as it is; the terminal escapes it.
#pragma once
#include <chrono>
#include <functional>
#include <string>

#include "output/numbers.hpp"

namespace quadgen::output {

struct Progress {
  // A finished line: "[diagnose] base model fitted (12 s)".
  std::function<void(const std::string&)> line;
  // A counter the next report replaces: "[diagnose] step 1: 3/12 candidates (wind)".
  std::function<void(const std::string&)> counter;
  // Either may be called from worker threads at once (a diagnosis fits its candidates on
  // every core): a caller's functions must be safe for that, as the terminal's are.

  void say(const std::string& text) const {
    if (line) line(text);
  }
  void count(const std::string& text) const {
    if (counter) counter(text);
  }
};

// Seconds on the steady clock since `start`: what a job's timings and progress lines report.
inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// " (12.3 s)", " (0.41 s)": how long something begun at `since` took. Not whole seconds, which
// read "(0 s)" for every step of a short flight (a user trial, helper-106).
inline std::string took_since(std::chrono::steady_clock::time_point since) {
  return " (" + short_number(seconds_since(since)) + " s)";
}

// Where a long job spends its time, in one voice: "[diagnose] 5 s: validation ..." says how far
// into the job a stage begins, "[diagnose] base model fitted (0.41 s)" how long a phase took,
// counted from where the last one ended.
class JobClock {
 public:
  using Clock = std::chrono::steady_clock;
  JobClock(const Progress& progress, std::string job) : progress_(progress), job_(std::move(job)) {}
  // Seconds since the job began.
  double seconds() const { return seconds_since(start_); }
  // "[job] N s: <what>": a stage begins.
  void say(const std::string& what) const {
    progress_.say("[" + job_ + "] " + std::to_string(static_cast<int>(seconds())) + " s: " + what);
  }
  // "[job] <what> (x s)": a phase ended; the next one starts.
  void done(const std::string& what) {
    progress_.say("[" + job_ + "] " + what + took_since(phase_start_));
    restart_phase();
  }
  // The next phase starts now (work before it, e.g. a parallel step's own counter, not counted).
  void restart_phase() { phase_start_ = Clock::now(); }

 private:
  const Progress& progress_;
  std::string job_;
  Clock::time_point start_ = Clock::now(), phase_start_ = start_;
};

// Standard error, one report at a time: lines as they come, every control character shown as
// an escape; counters rewritten in place where standard error is a terminal (a line blanks
// what is left of one), left out where it is a file (a CI log would keep every one of them).
Progress terminal_progress();

}  // namespace quadgen::output
