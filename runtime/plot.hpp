// Plots through gnuplot (Debian's gnuplot-nox): a person would rather look at a flight
// than read it. Writes SVG; the data goes through a temporary file.
#pragma once
#include <string>
#include <vector>

namespace quadgen::runtime {

struct Series {
  std::string label;
  std::vector<double> x, y;
  bool points = false;  // markers instead of a line (measurements)
};

struct Panel {
  std::string title, xlabel, ylabel;
  std::vector<Series> series;
};

// Stacks the panels vertically in one SVG. Returns false (and says why in `error`) when
// gnuplot is missing or fails; the caller decides whether that is fatal.
bool plot_svg(const std::string& path, const std::string& title, const std::vector<Panel>& panels, std::string* error);

}  // namespace quadgen::runtime
