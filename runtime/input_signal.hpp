// Inputs between samples: held (zero-order, as a flight controller applies them) or
// linearly interpolated; optionally delayed (the input_delay effect).
#pragma once
#include <stdexcept>
#include <string>
#include <vector>

namespace quadgen::runtime {

enum class Interpolation { hold, linear };

class InputSignal {
 public:
  InputSignal(std::vector<double> times, std::vector<std::vector<double>> values, Interpolation mode)
      : t_(std::move(times)), v_(std::move(values)), mode_(mode) {
    if (t_.empty() || t_.size() != v_.size()) throw std::invalid_argument("input signal: times and values differ in length");
    for (size_t i = 1; i < t_.size(); ++i)
      if (!(t_[i] > t_[i - 1]))
        throw std::invalid_argument("input signal: time not strictly increasing at sample " + std::to_string(i));
  }
  size_t width() const { return v_.front().size(); }
  double start() const { return t_.front(); }
  double end() const { return t_.back(); }

  // u(t - delay); before the first sample the first value holds, after the last the last.
  void at(double t, double* u, double delay = 0.0) const {
    t -= delay;
    const size_t n = t_.size();
    if (t <= t_.front()) return copy(0, u);
    if (t >= t_.back()) return copy(n - 1, u);
    size_t lo = 0, hi = n - 1;
    while (hi - lo > 1) {
      const size_t mid = (lo + hi) / 2;
      (t_[mid] <= t ? lo : hi) = mid;
    }
    if (mode_ == Interpolation::hold) return copy(lo, u);
    const double w = (t - t_[lo]) / (t_[hi] - t_[lo]);
    for (size_t k = 0; k < width(); ++k) u[k] = (1 - w) * v_[lo][k] + w * v_[hi][k];
  }

 private:
  void copy(size_t i, double* u) const {
    for (size_t k = 0; k < width(); ++k) u[k] = v_[i][k];
  }
  std::vector<double> t_;
  std::vector<std::vector<double>> v_;
  Interpolation mode_;
};

}  // namespace quadgen::runtime
