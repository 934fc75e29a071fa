#pragma once
// Uniform and normal random numbers whose algorithm is written here, not left to the
// standard library.
//
// std::mt19937's output is fixed by the C++ standard, but the distributions that turn it into
// doubles are not: libstdc++, libc++ and MSVC each use their own, so one `--seed` flew a
// different flight with each. These two follow libstdc++'s algorithms (GCC 12,
// bits/random.tcc) step for step: a double from two 32-bit draws (generate_canonical), and
// Marsaglia's polar method, which makes two normal numbers at a time and keeps the second.
// The flights generated so far stay as they were, and now come out the same with any standard
// library. What is left to the platform is libm's log and sqrt (sqrt is exactly rounded by
// IEEE 754; log is not required to be); the golden flight test would show a difference.
// Arithmetic as written: the project builds with -ffp-contract=off, so nothing is fused.
// C++26 changes std::generate_canonical (P0952R2); should libstdc++ follow, the check against
// it (PortableRandom.GivesTheNumbersOfTheLibstdcxxAlgorithms...) fails while the flights,
// drawn through this file, stay as they are.

#include <cmath>

namespace quadgen::runtime {

// A double in [0, 1) from a 32-bit engine (std::mt19937): two draws, the first the low bits.
// From a 64-bit one (std::mt19937_64): one draw. Either way the sum rounds to 53 bits and can
// reach 1, for which the largest double below 1 stands in.
template <class Engine>
double canonical_double(Engine& engine) {
  static_assert(Engine::min() == 0, "an engine whose numbers start at 0");
  double u;
  if constexpr (Engine::max() == 0xffffffffu) {
    const double low = static_cast<double>(engine());
    const double high = static_cast<double>(engine()) * 4294967296.0;  // 2^32
    u = (low + high) / 18446744073709551616.0;                          // 2^64
  } else {
    static_assert(Engine::max() == 0xffffffffffffffffu, "a 32- or 64-bit engine");
    u = static_cast<double>(engine()) / 18446744073709551616.0;
  }
  return u < 1.0 ? u : std::nextafter(1.0, 0.0);
}

// Uniform on [low, high).
class UniformReal {
 public:
  UniformReal(double low, double high) : low_(low), high_(high) {}
  template <class Engine>
  double operator()(Engine& engine) const { return canonical_double(engine) * (high_ - low_) + low_; }

 private:
  double low_, high_;
};

// Normal with the given mean and standard deviation. Keeps the polar method's second value
// for the next call, whichever engine that call passes (the closed loop's disturbance relies
// on this sharing; see UnmodelledForces).
class Normal {
 public:
  Normal(double mean, double standard_deviation) : mean_(mean), sd_(standard_deviation) {}
  template <class Engine>
  double operator()(Engine& engine) { return standard(engine) * sd_ + mean_; }

 private:
  template <class Engine>
  double standard(Engine& engine) {
    if (has_kept_) {
      has_kept_ = false;
      return kept_;
    }
    double x, y, r2;
    do {
      x = 2.0 * canonical_double(engine) - 1.0;
      y = 2.0 * canonical_double(engine) - 1.0;
      r2 = x * x + y * y;
    } while (r2 > 1.0 || r2 == 0.0);
    const double scale = std::sqrt(-2 * std::log(r2) / r2);
    kept_ = x * scale;
    has_kept_ = true;
    return y * scale;
  }
  double mean_, sd_;
  double kept_ = 0.0;
  bool has_kept_ = false;
};

}  // namespace quadgen::runtime
