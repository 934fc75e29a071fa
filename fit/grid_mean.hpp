// Putting a signal onto a uniform time grid without folding: each grid value is the mean of
// the signal, drawn as straight lines between its samples, over the grid interval around the
// grid point. Read at the grid point alone (as both resamplers did until 2026-12-04), a signal
// logged faster than the grid folds what it holds above half the grid rate into every band,
// the slow one included: a 1 kHz motor command read at 200 Hz gives the model moments the
// rotors never made (docs/history.md, "Could the logged commands make the slow moment?"). A
// signal slower than the grid keeps its values but for the corners at its samples (a window
// holding a sample moves by at most a quarter of the window times the change of slope there).
#pragma once
#include <array>
#include <cstddef>
#include <vector>

namespace quadgen::fit {

// The window's mean as weights on the samples: mean = sum over i of weight[i] * values[first_sample + i].
struct GridWeights {
  size_t first_sample = 0;
  std::vector<double> weight;
  double apply(const std::vector<double>& values) const;
};

// The weights of the mean over [t - half_width, t + half_width] of the line through
// (times[k], values[k]) for k in [first, last], a stretch with no gap; the window is narrowed
// equally on both sides to stay inside it (at its ends: the value at t). Needs
// times[first] <= t <= times[last] and times strictly increasing. Found once per grid point,
// they serve every column logged at those times.
GridWeights grid_weights(const std::vector<double>& times, size_t first, size_t last, double t, double half_width);

// An angle logged wrapped (a yaw jumping from pi to -pi) would be averaged across the jump to
// something in between: it is averaged unwrapped (each step taken the short way round, `period`
// in the log's unit), and a roll is wrapped back into (-pi, pi] after (a review, helper-92).
std::vector<double> unwrapped(const std::vector<double>& angles, double period);
double wrapped_to_pi(double radians);

// q and -q are one attitude, so a quaternion's component averaged or interpolated across a
// sign flip would pass through zero: each sample is negated where its dot product with the one
// before is negative. The four vectors are one quaternion's components (w, x, y, z) on one clock.
void align_quaternion_signs(const std::array<std::vector<double>*, 4>& components);

}  // namespace quadgen::fit
