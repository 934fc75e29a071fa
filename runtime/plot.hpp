// Plots through gnuplot (Debian's gnuplot-nox): a person would rather look at a flight than
// read it. gnuplot runs without a shell; the script and the data go to its standard input and
// the SVG comes back on its standard output, so no path and no temporary file is ever part of
// the script, and every label is passed as an escaped, non-enhanced string (output/sinks.hpp).
#pragma once
#include <string>
#include <utility>
#include <vector>

namespace quadgen::runtime {

struct Series {
  std::string label;
  std::vector<double> x, y;
  bool points = false;  // markers instead of a line (measurements)
  std::string color = {};  // "#rrggbb", so that one model has one colour in every plot; empty: gnuplot's
  // gnuplot's point type for markers (7 a filled circle, 5 a square, 9 a triangle, 13 a
  // diamond, 3 a star): two series of one colour stay two (a user trial, helper-106).
  int marker = 7;
};

struct Panel {
  std::string title, xlabel, ylabel;
  std::vector<Series> series;
  std::vector<double> marks = {};  // x values marked by a dashed vertical line (e.g. where validation starts)
  // Text written at the top of the panel from an x value on (e.g. which flight a stretch of
  // joined flights is); escaped like every label.
  std::vector<std::pair<double, std::string>> labels = {};
};

// At most this many points of one series reach gnuplot; longer series are thinned to the
// minimum and maximum of each bucket, which keeps spikes visible (a 1e6-sample log would
// otherwise give a 200 MB SVG).
inline constexpr size_t kMaxPlotPointsPerSeries = 4000;

// Renders the panels, stacked vertically, as one SVG document into `svg`. Returns false (and
// says why in `error`) when gnuplot is missing, fails, or returns something that is not a
// whole SVG document; the caller decides whether that is fatal.
bool render_svg(const std::string& title, const std::vector<Panel>& panels, std::string* svg, std::string* error);

// Whether `svg` is one whole SVG document with no tag that would run as script inlined into a
// page: a <script> (any namespace), a javascript: URL or an on...= event handler in a tag.
// Text is not searched (a label may say "javascript:"). render_svg's second line of defence.
bool whole_inert_svg(const std::string& svg);

// The gnuplot script render_svg sends (exposed for tests and the fuzz target).
std::string gnuplot_script(const std::string& title, const std::vector<Panel>& panels);

// Every point of every series, as one CSV table for Python, MATLAB or a spreadsheet (long
// format, one row per point: plot,panel,x_label,y_label,series,x,y; a non-finite value is an
// empty field). Unthinned; text fields through output::csv_field.
std::string panels_csv(const std::string& title, const std::vector<Panel>& panels);

// `s` thinned to at most kMaxPlotPointsPerSeries points (bucket minimum and maximum, in order).
Series decimated(const Series& s);

}  // namespace quadgen::runtime
