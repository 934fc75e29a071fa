#include "output/progress.hpp"

#include <unistd.h>

#include <iostream>

#include "output/sinks.hpp"

namespace quadgen::output {

Progress terminal_progress() {
  const bool terminal = ::isatty(2) != 0;
  Progress p;
  // "\r" and trailing blanks overwrite a counter still on the line.
  p.line = [terminal](const std::string& text) {
    std::cerr << (terminal ? "\r" : "") << printable(text) << (terminal ? "        " : "") << "\n";
  };
  if (terminal)
    p.counter = [](const std::string& text) { std::cerr << "\r" << printable(text) << "        " << std::flush; };
  return p;
}

}  // namespace quadgen::output
