#include "diagnose/residual_analysis.hpp"

#include <algorithm>
#include <cmath>

#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/students_t.hpp>

#include "runtime/attitude.hpp"
#include "runtime/rigid_body_state.hpp"

namespace quadgen::diagnose {

namespace {

double mean(const std::vector<double>& x) {
  double s = 0;
  for (double v : x) s += v;
  return x.empty() ? 0 : s / static_cast<double>(x.size());
}

double tau_from_acf(const std::vector<double>& acf) {
  double tau = 1;
  for (size_t k = 1; k < acf.size() && acf[k] > 0; ++k) tau += 2 * acf[k];
  return tau;
}

}  // namespace

std::vector<double> autocorrelation(const std::vector<double>& x, int max_lag) {
  const size_t n = x.size();
  const double m = mean(x);
  double c0 = 0;
  for (double v : x) c0 += (v - m) * (v - m);
  std::vector<double> acf(static_cast<size_t>(max_lag) + 1, 0.0);
  if (c0 <= 0) return acf;
  for (int k = 0; k <= max_lag && static_cast<size_t>(k) < n; ++k) {
    double c = 0;
    for (size_t i = 0; i + k < n; ++i) c += (x[i] - m) * (x[i + k] - m);
    acf[k] = c / c0;
  }
  return acf;
}

double bartlett_effective_n(const std::vector<double>& acf_x, const std::vector<double>& acf_y, size_t n, int lag) {
  double inflate = 1;
  for (int k = 1; k <= lag; ++k) inflate += 2 * acf_x[k] * acf_y[k];
  const double ns = static_cast<double>(n);
  return std::clamp(ns / std::max(1.0, inflate), 3.0, ns);
}

double integrated_autocorrelation_time(const std::vector<double>& x, int max_lag) {
  return tau_from_acf(autocorrelation(x, max_lag));
}

SignalSet physical_signals(const fit::Flight& f, const std::vector<std::string>& rotors) {
  SignalSet s;
  const size_t ns = f.samples.size(), nr = rotors.size();
  auto add = [&](const std::string& name, auto fn) {
    s.names.push_back(name);
    std::vector<double> v(ns);
    for (size_t k = 0; k < ns; ++k) v[k] = fn(k);
    s.values.push_back(std::move(v));
  };
  for (size_t i = 0; i < nr; ++i) add("u_" + rotors[i], [&](size_t k) { return f.samples[k].u[i]; });
  add("total command", [&](size_t k) {
    double sum = 0;
    for (double u : f.samples[k].u) sum += u * u;  // thrust ~ speed^2 ~ command^2 near hover
    return sum;
  });
  for (int a = 0; a < 3; ++a)
    add(std::string("body velocity ") + "xyz"[a],
        [&](size_t k) { return runtime::rigid_body::body_velocity(f.samples[k].x.data())[a]; });
  if (f.has_pose) {
    using runtime::rigid_body::kPosition;
    add("position x", [&](size_t k) { return f.samples[k].x[kPosition]; });
    add("position y", [&](size_t k) { return f.samples[k].x[kPosition + 1]; });
    add("height", [&](size_t k) { return f.samples[k].x[kPosition + 2]; });
  }
  add("time", [&](size_t k) { return f.samples[k].t; });
  if (f.has_vbat) add("battery voltage", [&](size_t k) { return f.samples[k].vbat; });
  for (size_t i = 0; i < nr; ++i)
    add("du_" + rotors[i] + "/dt", [&](size_t k) {
      const size_t a = k == 0 ? 0 : k - 1, b = std::min(ns - 1, k + 1);
      const double dt = f.samples[b].t - f.samples[a].t;
      return dt > 0 ? (f.samples[b].u[i] - f.samples[a].u[i]) / dt : 0.0;
    });
  return s;
}

namespace {

// Slow structure: the residual's means over 1 s windows against what the high-passed noise
// would give them (a chi-squared test of the means), the worst window, and how much of the
// autocorrelation beyond the noise's correlation length lies outside the white-noise band.
// Needs three windows; fewer leave the fields at their defaults.
void analyse_slow_structure(ChannelAnalysis& a, const std::vector<double>& x, const std::vector<double>& t, double dt) {
  const size_t ns = x.size();
  const size_t w = std::max<size_t>(10, static_cast<size_t>(std::lround(1.0 / dt)));
  std::vector<double> means, highpass;
  std::vector<size_t> starts;
  for (size_t k0 = 0; k0 + w <= ns; k0 += w) {
    double m = 0;
    for (size_t k = k0; k < k0 + w; ++k) m += x[k];
    m /= static_cast<double>(w);
    means.push_back(m);
    starts.push_back(k0);
    for (size_t k = k0; k < k0 + w; ++k) highpass.push_back(x[k] - m);
  }
  if (means.size() < 3) return;
  // The noise's correlation length, read from the high-passed residual's short lags.
  auto hp_acf = autocorrelation(highpass, static_cast<int>(std::min<size_t>(w / 2, highpass.size() / 4)));
  const double tau = tau_from_acf(hp_acf);
  double hv = 0;
  for (double v : highpass) hv += v * v;
  // Within-window variance is biased low by 1 - tau/w; undo it.
  hv = hv / static_cast<double>(highpass.size()) / std::max(0.05, 1.0 - tau / static_cast<double>(w));
  const double var_mean = hv * tau / static_cast<double>(w);
  double S = 0, worst = 0;
  for (size_t j = 0; j < means.size(); ++j) {
    S += means[j] * means[j] / var_mean;
    if (std::abs(means[j]) > std::abs(worst)) {
      worst = means[j];
      a.worst_window_t0 = t[starts[j]];
      a.worst_window_t1 = t[starts[j] + w - 1];
    }
  }
  double ms = 0;
  for (double m : means) ms += m * m;
  a.slow_rms = std::sqrt(ms / static_cast<double>(means.size()));
  a.worst_window_mean = worst;
  const double J = static_cast<double>(means.size());
  a.slow_ratio = S / J;
  a.slow_p_value = boost::math::cdf(boost::math::complement(boost::math::chi_squared(J), S));
  int outside = 0, counted = 0;
  for (size_t k = static_cast<size_t>(std::ceil(tau)) + 1; k < a.acf.size(); ++k, ++counted)
    if (std::abs(a.acf[k]) > a.acf_band) ++outside;
  a.acf_outside = counted ? static_cast<double>(outside) / counted : 0.0;
}

// Correlations of the residual with each signal, strongest first; the effective n by
// Bartlett's formula for two autocorrelated series, n / (1 + 2 sum rho_x rho_y).
std::vector<Correlation> correlations_with(const ChannelAnalysis& a, const std::vector<double>& x, const SignalSet& signals,
                                           const std::vector<std::vector<double>>& signal_acf, int lag) {
  const size_t ns = x.size();
  const double sx = a.sigma;
  std::vector<Correlation> out;
  for (size_t s = 0; s < signals.names.size(); ++s) {
    const auto& y = signals.values[s];
    const double my = mean(y);
    double sy = 0, cxy = 0;
    for (size_t k = 0; k < ns; ++k) {
      sy += (y[k] - my) * (y[k] - my);
      cxy += (x[k] - a.bias) * (y[k] - my);
    }
    sy = std::sqrt(sy / static_cast<double>(ns));
    if (!(sx > 0 && sy > 0)) continue;  // also a NaN, which would break the sort below
    Correlation cr;
    cr.signal = signals.names[s];
    cr.r = cxy / static_cast<double>(ns) / (sx * sy);
    const double n_eff = bartlett_effective_n(a.acf, signal_acf[s], ns, lag);
    const double r2 = std::min(cr.r * cr.r, 1 - 1e-12);
    const double tstat = std::abs(cr.r) * std::sqrt((n_eff - 2) / (1 - r2));
    cr.p_value = 2 * boost::math::cdf(boost::math::complement(boost::math::students_t(n_eff - 2), tstat));
    out.push_back(cr);
  }
  // Stable: signals of equal |r| keep the signal set's order, not the sort's (which the
  // standard leaves open, so another library could print them the other way round).
  std::stable_sort(out.begin(), out.end(),
                   [](const Correlation& p, const Correlation& q) { return std::abs(p.r) > std::abs(q.r); });
  return out;
}

}  // namespace

ResidualAnalysis analyse_residuals(const std::vector<double>& r6, const std::vector<std::string>& names,
                                   const std::vector<std::string>& units, const std::vector<double>& t,
                                   const SignalSet& signals) {
  constexpr int kMaxLag = 300;
  const size_t ns = t.size();
  const int lag = static_cast<int>(std::min<size_t>(kMaxLag, ns / 4));
  std::vector<std::vector<double>> signal_acf;
  for (const auto& v : signals.values) signal_acf.push_back(autocorrelation(v, lag));
  const double dt = ns > 1 ? (t.back() - t.front()) / static_cast<double>(ns - 1) : 0.01;
  ResidualAnalysis out;
  for (size_t c = 0; c < names.size(); ++c) {
    ChannelAnalysis a;
    a.name = names[c];
    a.unit = units[c];
    a.samples = static_cast<int>(ns);
    std::vector<double> x(ns);
    for (size_t k = 0; k < ns; ++k) x[k] = r6[k * 6 + c];
    a.bias = mean(x);
    double ss = 0;
    for (double v : x) ss += v * v;
    a.rms = std::sqrt(ss / std::max<size_t>(1, ns));
    a.sigma = std::sqrt(std::max(0.0, a.rms * a.rms - a.bias * a.bias));
    a.acf = autocorrelation(x, lag);
    a.tau_int = tau_from_acf(a.acf);
    a.acf_band = 1.96 / std::sqrt(static_cast<double>(std::max<size_t>(ns, 1)));
    analyse_slow_structure(a, x, t, dt);
    a.correlations = correlations_with(a, x, signals, signal_acf, lag);
    out.channels.push_back(std::move(a));
  }
  return out;
}

}  // namespace quadgen::diagnose
