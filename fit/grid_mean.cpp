#include "fit/grid_mean.hpp"

#include <algorithm>

namespace quadgen::fit {

namespace {

// The line through samples k and k + 1, at x.
double on_line(const std::vector<double>& times, const std::vector<double>& values, size_t k, double x) {
  const double w = (x - times[k]) / (times[k + 1] - times[k]);
  return values[k] + w * (values[k + 1] - values[k]);
}

}  // namespace

double grid_mean(const std::vector<double>& times, const std::vector<double>& values, size_t first, size_t last,
                 double t, double half_width) {
  const double w = std::min({half_width, t - times[first], times[last] - t});
  // The sample interval holding a: the last sample at or before it, never the stretch's last.
  const auto interval_at = [&](double a) {
    const auto it = std::upper_bound(times.begin() + static_cast<long>(first), times.begin() + static_cast<long>(last) + 1, a);
    return std::min(static_cast<size_t>(it - times.begin()) - 1, last - 1);
  };
  if (first == last) return values[first];
  if (!(w > 0)) return on_line(times, values, interval_at(t), t);
  const double a = t - w, b = t + w;
  double area = 0;
  for (size_t k = interval_at(a); k < last && times[k] < b; ++k) {
    const double from = std::max(a, times[k]), to = std::min(b, times[k + 1]);
    if (to > from) area += 0.5 * (on_line(times, values, k, from) + on_line(times, values, k, to)) * (to - from);
  }
  return area / (b - a);
}

}  // namespace quadgen::fit
