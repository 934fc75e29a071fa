#include "diagnose/draft_signature.hpp"

#include "diagnose/residual_analysis.hpp"
#include "fit/flight_data.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>

namespace quadgen::diagnose {

namespace {

// Means of the values in [g, g + kWindow) for g every kGrid from the first time; nullopt
// where no sample lies in the window (a gap).
std::vector<std::optional<double>> grid_means(const std::vector<double>& t, const std::vector<double>& y) {
  std::vector<std::optional<double>> out;
  if (t.empty()) return out;
  double total = 0;
  size_t start = 0, end = 0;
  for (size_t i = 0;; ++i) {
    const double g = t.front() + static_cast<double>(i) * DraftSignature::kGrid;  // not accumulated: no drift
    if (g + DraftSignature::kWindow > t.back() + 1e-9) break;
    while (end < t.size() && t[end] < g + DraftSignature::kWindow) total += y[end++];
    while (start < end && t[start] < g) total -= y[start++];
    out.push_back(end > start ? std::optional<double>(total / static_cast<double>(end - start)) : std::nullopt);
  }
  return out;
}

std::vector<double> centred(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m += x / static_cast<double>(v.size());
  std::vector<double> c;
  for (double x : v) c.push_back(x - m);
  return c;
}

double dot(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0;
  for (size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}

// y minus its least-squares fit on x and a constant.
std::vector<double> partial_out(const std::vector<double>& y, const std::vector<double>& x) {
  const auto xc = centred(x), yc = centred(y);
  const double sxx = dot(xc, xc), b = sxx > 0 ? dot(xc, yc) / sxx : 0.0;
  std::vector<double> out;
  for (size_t i = 0; i < yc.size(); ++i) out.push_back(yc[i] - b * xc[i]);
  return out;
}

// SplitMix64 (Steele, Lea & Flood, OOPSLA 2014): a fixed, portable stream of random bits,
// so that a p-value is the same on every machine, in every order of the tests, and in
// scripts/air_draft_check.py.
class SplitMix64 {
 public:
  explicit SplitMix64(uint64_t seed) : state_(seed) {}
  uint64_t next() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }

 private:
  uint64_t state_;
};

// cos(pi j / (2n)) for j = 0 .. 4n-1: every cosine the DCT-II of n samples needs.
std::vector<double> cosine_table(size_t n) {
  constexpr double kPi = 3.14159265358979323846;
  std::vector<double> table(4 * n);
  for (size_t j = 0; j < table.size(); ++j) table[j] = std::cos(kPi * static_cast<double>(j) / (2.0 * static_cast<double>(n)));
  return table;
}

// Orthonormal DCT-II coefficients of z for k = 1 .. n-1 (k = 0, the mean, left out):
// sqrt(2/n) sum_t z_t cos(pi k (2t + 1) / (2n)), the cosines from cosine_table(n).
std::vector<double> cosine_coefficients(const std::vector<double>& z, const std::vector<double>& table) {
  const size_t n = z.size(), period = table.size();
  std::vector<double> c(n > 0 ? n - 1 : 0);
  for (size_t k = 1; k < n; ++k) {
    double s = 0;
    for (size_t t = 0; t < n; ++t) s += z[t] * table[(k * (2 * t + 1)) % period];
    c[k - 1] = std::sqrt(2.0 / static_cast<double>(n)) * s;
  }
  return c;
}

// One-sided p of the partial correlation of the moment means `moment` with `force_res` (the
// force means turned so that a draft correlates positively, the velocity and a constant
// partialled out), the velocity `velocity` partialled out of the moment too. Under no draft,
// the moment's cosine coefficients, nearly uncorrelated for a slow series (Ahmed, Natarajan
// & Rao 1974), are as likely to have either sign relative to the force's: the test draws
// kSignFlips random signs for them (Ebisuzaki's 1997 surrogate with cosines instead of
// Fourier modes, whose ends do not match on a short part) and counts the surrogate
// correlations at or above the measured one. Bartlett's effective sample size with n_eff - 3
// degrees of freedom gave 6-11 % false alarms at the 5 % level on short parts once the
// slow velocity was partialled out; this test 4-6 % (docs/history.md, the fourteenth session).
double sign_flip_p(const std::vector<double>& moment, const std::vector<double>& force_res,
                   const std::vector<double>& velocity) {
  constexpr int kSignFlips = 1999;
  constexpr uint64_t kSeed = 0x5EED0001ULL;
  auto u = centred(velocity);
  const double uu = std::sqrt(dot(u, u));
  for (double& x : u) x = uu > 0 ? x / uu : 0.0;
  const auto table = cosine_table(moment.size());
  const auto c = cosine_coefficients(moment, table), d = cosine_coefficients(force_res, table),
             e = cosine_coefficients(u, table);
  std::vector<double> w(c.size()), g(c.size());
  for (size_t k = 0; k < c.size(); ++k) w[k] = c[k] * d[k], g[k] = c[k] * e[k];
  const double cc = dot(c, c), ff = dot(force_res, force_res);
  const auto correlation = [&](const std::vector<double>& signs) {
    double num = 0, projection = 0;
    for (size_t k = 0; k < w.size(); ++k) num += signs[k] * w[k], projection += signs[k] * g[k];
    const double den = (cc - projection * projection) * ff;
    return den > 0 ? num / std::sqrt(den) : 0.0;
  };
  const double measured = correlation(std::vector<double>(w.size(), 1.0));
  SplitMix64 bits(kSeed);
  std::vector<double> signs(w.size());
  int at_or_above = 0;
  for (int b = 0; b < kSignFlips; ++b) {
    uint64_t word = 0;
    for (size_t k = 0; k < signs.size(); ++k) {
      if (k % 64 == 0) word = bits.next();
      signs[k] = (word >> (k % 64)) & 1U ? -1.0 : 1.0;
    }
    at_or_above += correlation(signs) >= measured - 1e-12 ? 1 : 0;
  }
  return (1.0 + at_or_above) / (kSignFlips + 1.0);
}

DraftSignature::Pair measure_pair(const char* force_name, const char* moment_name, double draft_slope,
                                  const std::vector<double>& moment, const std::vector<double>& force,
                                  const std::vector<double>& velocity) {
  DraftSignature::Pair p;
  p.force = force_name, p.moment = moment_name, p.draft_slope = draft_slope;
  const auto correlation = [](const std::vector<double>& a, const std::vector<double>& b) {
    const double aa = dot(a, a), bb = dot(b, b);
    return aa > 0 && bb > 0 ? dot(a, b) / std::sqrt(aa * bb) : 0.0;
  };
  p.raw_r = correlation(centred(moment), centred(force));
  const auto m = partial_out(moment, velocity), f = partial_out(force, velocity);
  p.r = correlation(m, f);
  const double mm = dot(m, m), ff = dot(f, f), mf = dot(m, f);
  p.slope = mm > 0 ? mf / mm : 0.0;
  p.reverse_slope = mf != 0 ? ff / mf : 0.0;
  const int lag = static_cast<int>(m.size() / 4);  // reported: how slow the two series are
  p.effective_n = bartlett_effective_n(autocorrelation(m, lag), autocorrelation(f, lag), m.size(), lag);
  std::vector<double> f_draft = f;  // turned so that a draft correlates positively
  if (draft_slope < 0)
    for (double& x : f_draft) x = -x;
  p.p = sign_flip_p(moment, f_draft, velocity);
  return p;
}

double rms(const std::vector<double>& v) {
  return v.empty() ? 0.0 : std::sqrt(dot(v, v) / static_cast<double>(v.size()));
}

}  // namespace

std::vector<std::string> DraftSignature::axes_showing_it() const {
  bool y = !parts.empty(), x = !parts.empty();
  for (const auto& p : parts) y = y && p.y_roll.shows_draft(), x = x && p.x_pitch.shows_draft();
  std::vector<std::string> out;
  if (y) out.push_back("y (roll)");
  if (x) out.push_back("x (pitch)");
  return out;
}

std::vector<DraftSignatureInput> split_by_flight(const DraftSignatureInput& in, const std::vector<double>& starts) {
  std::vector<DraftSignatureInput> out(starts.size());
  for (auto& f : out) {
    f = in;
    f.t.clear(), f.residual.clear(), f.velocity.clear(), f.heading.clear(), f.held_out.clear();
  }
  for (size_t k = 0; k < in.t.size(); ++k) {
    const int flight = fit::joined_flight_at(starts, in.t[k]);
    if (flight < 0) continue;  // before the first flight
    auto& f = out[static_cast<size_t>(flight)];
    f.t.push_back(in.t[k]), f.heading.push_back(in.heading[k]), f.held_out.push_back(in.held_out[k]);
    f.residual.insert(f.residual.end(), in.residual.begin() + 6 * static_cast<long>(k),
                      in.residual.begin() + 6 * static_cast<long>(k + 1));
    f.velocity.insert(f.velocity.end(), in.velocity.begin() + 2 * static_cast<long>(k),
                      in.velocity.begin() + 2 * static_cast<long>(k + 1));
  }
  return out;
}

DraftSignature draft_signature(const DraftSignatureInput& in) {
  DraftSignature d;
  if (!(in.rotor_drag_k > 0) || !(in.blade_flapping_k > 0) || !(in.mass > 0) || !(in.J_xx > 0) || !(in.J_yy > 0)) {
    d.why_not = "needs rotor drag and blade flapping, both positive, in the final model (and its mass and inertia)";
    return d;
  }
  const double ratio_y = -in.rotor_drag_k * in.J_xx / (in.blade_flapping_k * in.mass);
  const double ratio_x = in.rotor_drag_k * in.J_yy / (in.blade_flapping_k * in.mass);
  for (const bool held_out : {false, true}) {
    // The part's samples, world vectors turned into the heading frame.
    std::vector<double> t, series[6];  // ax, ay, pdot, qdot, vx, vy
    for (size_t k = 0; k < in.t.size(); ++k) {
      if (in.held_out[k] != held_out) continue;
      const double* r = &in.residual[6 * k];
      const double c = std::cos(in.heading[k]), s = std::sin(in.heading[k]);
      const double fc = in.force_in_world ? c : 1.0, fs = in.force_in_world ? s : 0.0;
      const double vx = in.velocity[2 * k], vy = in.velocity[2 * k + 1];
      t.push_back(in.t[k]);
      const double values[6] = {fc * r[0] + fs * r[1], -fs * r[0] + fc * r[1], r[3], r[4], c * vx + s * vy, -s * vx + c * vy};
      for (int i = 0; i < 6; ++i) series[i].push_back(values[i]);
    }
    std::vector<std::optional<double>> slow[6];
    for (int i = 0; i < 6; ++i) slow[i] = grid_means(t, series[i]);
    std::vector<double> means[6];  // where every series has a window
    for (size_t g = 0; g < slow[0].size(); ++g) {
      bool all = true;
      for (int i = 0; i < 6; ++i) all = all && slow[i][g].has_value();
      if (all)
        for (int i = 0; i < 6; ++i) means[i].push_back(*slow[i][g]);
    }
    if (means[0].size() < 20) {  // 2 s of means: nothing to test
      d.why_not = std::string("the ") + (held_out ? "held-out" : "training") + " part is too short";
      d.parts.clear();
      return d;
    }
    DraftSignature::Part part;
    part.name = held_out ? "held-out" : "training";
    part.means = means[0].size();
    part.y_roll = measure_pair("a_y", "pdot", ratio_y, means[2], means[1], means[5]);
    part.x_pitch = measure_pair("a_x", "qdot", ratio_x, means[3], means[0], means[4]);
    if (in.hover_speeds_sum > 0)
      part.implied_speed =
          std::hypot(rms(means[2]) * in.J_xx, rms(means[3]) * in.J_yy) / (in.blade_flapping_k * in.hover_speeds_sum);
    d.parts.push_back(part);
  }
  d.measured = true;
  return d;
}

}  // namespace quadgen::diagnose
