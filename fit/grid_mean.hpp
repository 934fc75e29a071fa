// Putting a signal onto a uniform time grid without folding: each grid value is the mean of
// the signal, drawn as straight lines between its samples, over the grid interval around the
// grid point. Read at the grid point alone (as both resamplers did until 2026-12-04), a signal
// logged faster than the grid folds what it holds above half the grid rate into every band,
// the slow one included: a 1 kHz motor command read at 200 Hz gives the model moments the
// rotors never made (docs/history.md, "Could the logged commands make the slow moment?"). A
// signal slower than the grid keeps its value: the mean of a straight line is its middle.
#pragma once
#include <cstddef>
#include <vector>

namespace quadgen::fit {

// The mean over [t - half_width, t + half_width] of the line through (times[k], values[k]) for
// k in [first, last], a stretch with no gap; the window is narrowed equally on both sides to
// stay inside it (at its ends the value at t). Needs times[first] <= t <= times[last] and
// times strictly increasing.
double grid_mean(const std::vector<double>& times, const std::vector<double>& values, size_t first, size_t last,
                 double t, double half_width);

}  // namespace quadgen::fit
