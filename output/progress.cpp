#include "output/progress.hpp"

#include <unistd.h>

#include <iostream>
#include <memory>
#include <mutex>

#include "output/sinks.hpp"

namespace quadgen::output {

namespace {

// What is on the terminal's last line: a counter's length, so that the next report blanks
// exactly what it does not overwrite. Reports may come from worker threads.
struct Terminal {
  std::mutex mutex;
  size_t counter_length = 0;  // 0: the line is empty

  std::string over_counter(const std::string& text) {
    const std::string blanks(counter_length > text.size() ? counter_length - text.size() : 0, ' ');
    return (counter_length ? "\r" : "") + text + blanks;
  }
};

}  // namespace

Progress terminal_progress() {
  const bool terminal = ::isatty(2) != 0;
  const auto state = std::make_shared<Terminal>();
  Progress p;
  p.line = [state](const std::string& text) {
    const std::lock_guard<std::mutex> lock(state->mutex);
    std::cerr << state->over_counter(printable(text)) << "\n";
    state->counter_length = 0;
  };
  if (terminal)
    p.counter = [state](const std::string& text) {
      const std::lock_guard<std::mutex> lock(state->mutex);
      const std::string shown = printable(text);
      std::cerr << state->over_counter(shown) << std::flush;
      state->counter_length = shown.size();
    };
  return p;
}

}  // namespace quadgen::output
