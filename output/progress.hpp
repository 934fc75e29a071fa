// How long work tells a person how far it has got, kept apart from where the words go: the
// command line sends them to the terminal (terminal_progress), a library caller wherever it
// likes, and by default they go nowhere. Text is passed as it is; the terminal escapes it.
#pragma once
#include <chrono>
#include <functional>
#include <string>

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

// Where a long job spends its time, phase by phase: "[diagnose] base model fitted (12 s)"
// counts from where the last phase ended.
class PhaseTimer {
 public:
  explicit PhaseTimer(const Progress& progress) : progress_(progress) {}
  // Seconds since the last phase ended (or the timer started).
  double seconds() const { return seconds_since(start_); }
  // Says "[diagnose] <what> (N s)" and starts the next phase.
  void done(const std::string& what) {
    progress_.say("[diagnose] " + what + " (" + std::to_string(static_cast<int>(seconds())) + " s)");
    restart();
  }
  void restart() { start_ = Clock::now(); }

 private:
  using Clock = std::chrono::steady_clock;
  const Progress& progress_;
  Clock::time_point start_ = Clock::now();
};

// Standard error, one report at a time: lines as they come, every control character shown as
// an escape; counters rewritten in place where standard error is a terminal (a line blanks
// what is left of one), left out where it is a file (a CI log would keep every one of them).
Progress terminal_progress();

}  // namespace quadgen::output
