#include "fit/grid_mean.hpp"

#include <algorithm>
#include <cmath>

namespace quadgen::fit {

double GridWeights::apply(const std::vector<double>& values) const {
  double sum = 0;
  for (size_t i = 0; i < weight.size(); ++i) sum += weight[i] * values[first_sample + i];
  return sum;
}

GridWeights grid_weights(const std::vector<double>& times, size_t first, size_t last, double t, double half_width) {
  GridWeights g;
  g.first_sample = first;
  if (first == last) {
    g.weight = {1.0};
    return g;
  }
  // Clamped to the stretch: t - (t - times[first]) can round to just below times[first] (a
  // review, helper-92: a topic starting 1.5 ms after boot read as 0).
  const double w = std::max(0.0, std::min({half_width, t - times[first], times[last] - t}));
  const double a = std::clamp(t - w, times[first], times[last]), b = std::clamp(t + w, times[first], times[last]);
  // The sample interval holding x: the last sample at or before it, within [first, last - 1].
  const auto interval_at = [&](double x) {
    const auto begin = times.begin() + static_cast<long>(first), end = times.begin() + static_cast<long>(last) + 1;
    const size_t after = static_cast<size_t>(std::upper_bound(begin, end, x) - times.begin());
    return std::clamp(after, first + 1, last) - 1;
  };
  const size_t k0 = interval_at(a);
  g.first_sample = k0;
  // Weight on samples k and k + 1 of the line between them at x: 1 - s and s.
  const auto at = [&](size_t k, double x, double scale) {
    const double s = (x - times[k]) / (times[k + 1] - times[k]);
    if (g.weight.size() < k + 2 - k0) g.weight.resize(k + 2 - k0, 0.0);
    g.weight[k - k0] += scale * (1 - s);
    g.weight[k + 1 - k0] += scale * s;
  };
  if (!(b > a)) {
    at(k0, a, 1.0);
    return g;
  }
  for (size_t k = k0; k < last && times[k] < b; ++k) {
    const double from = std::max(a, times[k]), to = std::min(b, times[k + 1]);
    if (!(to > from)) continue;
    const double share = 0.5 * (to - from) / (b - a);  // trapezoid: the mean of its two ends
    at(k, from, share);
    at(k, to, share);
  }
  return g;
}

std::vector<double> unwrapped(const std::vector<double>& angles, double period) {
  std::vector<double> out(angles);
  for (size_t k = 1; k < out.size(); ++k) {
    const double step = angles[k] - angles[k - 1];
    out[k] = out[k - 1] + step - period * std::round(step / period);
  }
  return out;
}

void align_quaternion_signs(const std::array<std::vector<double>*, 4>& q) {
  for (size_t k = 1; k < q[0]->size(); ++k) {
    double dot = 0;
    for (const auto* c : q) dot += (*c)[k] * (*c)[k - 1];
    if (dot < 0)
      for (auto* c : q) (*c)[k] = -(*c)[k];
  }
}

double wrapped_to_pi(double radians) {
  const double r = std::remainder(radians, 2 * M_PI);  // in [-pi, pi]
  return r <= -M_PI ? r + 2 * M_PI : r;
}

}  // namespace quadgen::fit
