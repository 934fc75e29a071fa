#include "runtime/integrator.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "runtime/attitude.hpp"

namespace quadgen::runtime {

namespace {

using Vec = std::vector<double>;

// After a step from `before`: the state's quaternion (at opt.quaternion_offset, none if < 0)
// back on the unit sphere, then the options' constraint.
void finish_step(const Vec& before, Vec& x, const IntegratorOptions& opt) {
  if (opt.quaternion_offset >= 0) runtime::normalize_quaternion(&x[opt.quaternion_offset]);
  if (opt.constrain) opt.constrain(before, x);
}

struct Rhs {
  const DynamicModel& m;
  const InputFunction& u;
  Stats* stats;
  mutable Vec ubuf;
  void operator()(double t, const Vec& x, Vec& f) const {
    ubuf.resize(m.num_inputs());
    u(t, ubuf.data());
    f.resize(x.size());
    m.rhs(x.data(), ubuf.data(), f.data(), nullptr, nullptr, nullptr);
    if (stats) ++stats->rhs_evaluations;
  }
};

Vec axpy(const Vec& x, double h, const Vec& k) {
  Vec r(x.size());
  for (size_t i = 0; i < x.size(); ++i) r[i] = x[i] + h * k[i];
  return r;
}

// One classical Runge-Kutta step of dz/dt = deriv(t, z) (shared by states and sensitivities).
template <class Deriv>
void rk4_step(const Deriv& deriv, double t, Vec& z, double h) {
  Vec k1, k2, k3, k4;
  deriv(t, z, k1);
  deriv(t + h / 2, axpy(z, h / 2, k1), k2);
  deriv(t + h / 2, axpy(z, h / 2, k2), k3);
  deriv(t + h, axpy(z, h, k3), k4);
  for (size_t i = 0; i < z.size(); ++i) z[i] += h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
}

}  // namespace

void check_finite(const DynamicModel& m, const Vec& x, double t, double bound) {
  for (size_t i = 0; i < x.size(); ++i)
    if (!std::isfinite(x[i]) || std::fabs(x[i]) > bound) {
      std::ostringstream os;
      os << "simulation diverged at t = " << t << " s: state " << m.state_names()[i] << " = " << x[i];
      throw DivergenceError(os.str());
    }
}

Trajectory integrate_rk4(const DynamicModel& m, Vec x, const InputFunction& u, double t0, double t1,
                         const IntegratorOptions& opt, Stats* stats) {
  Rhs f{m, u, stats, {}};
  Trajectory tr;
  tr.t.push_back(t0);
  tr.x.push_back(x);
  const long steps = std::max(1L, std::lround((t1 - t0) / opt.step));
  const double h = (t1 - t0) / static_cast<double>(steps);
  for (long s = 0; s < steps; ++s) {
    const double t = t0 + static_cast<double>(s) * h;
    const Vec before = opt.constrain ? x : Vec();
    rk4_step(f, t, x, h);
    finish_step(before, x, opt);
    check_finite(m, x, t + h, opt.divergence_bound);
    if (stats) ++stats->accepted_steps;
    tr.t.push_back(t0 + static_cast<double>(s + 1) * h);
    tr.x.push_back(x);
  }
  return tr;
}

namespace {

// Dormand & Prince (1980) RK5(4)7M coefficients, with the continuous extension of
// Hairer, Nørsett & Wanner, Solving ODEs I, section II.6 (dense output of order 4).
namespace dp {
constexpr double c2 = 1.0 / 5, c3 = 3.0 / 10, c4 = 4.0 / 5, c5 = 8.0 / 9;
constexpr double a21 = 1.0 / 5, a31 = 3.0 / 40, a32 = 9.0 / 40, a41 = 44.0 / 45, a42 = -56.0 / 15,
                 a43 = 32.0 / 9, a51 = 19372.0 / 6561, a52 = -25360.0 / 2187, a53 = 64448.0 / 6561,
                 a54 = -212.0 / 729, a61 = 9017.0 / 3168, a62 = -355.0 / 33, a63 = 46732.0 / 5247,
                 a64 = 49.0 / 176, a65 = -5103.0 / 18656, a71 = 35.0 / 384, a73 = 500.0 / 1113,
                 a74 = 125.0 / 192, a75 = -2187.0 / 6784, a76 = 11.0 / 84;
constexpr double e1 = 71.0 / 57600, e3 = -71.0 / 16695, e4 = 71.0 / 1920, e5 = -17253.0 / 339200,
                 e6 = 22.0 / 525, e7 = -1.0 / 40;
constexpr double d1 = -12715105075.0 / 11282082432, d3 = 87487479700.0 / 32700410799,
                 d4 = -10690763975.0 / 1880347072, d5 = 701980252875.0 / 199316789632,
                 d6 = -1453857185.0 / 822651844, d7 = 69997945.0 / 29380423;
}  // namespace dp

// The seven stages of one step; k1 is the derivative at the step's start (the last step's k7:
// first same as last).
struct Dopri5Stages {
  Vec k1, k2, k3, k4, k5, k6, k7;
};

// Attempts a step of h from (t, x): the fifth-order result into y, the stages into k (k1
// given), and returns the RMS of the embedded error estimate over the tolerances (1 or less:
// accept).
double dopri5_attempt(const Rhs& f, double t, const Vec& x, double h, const IntegratorOptions& opt, Dopri5Stages& k,
                      Vec& y, Vec& ytmp) {
  using namespace dp;
  const size_t n = x.size();
  for (size_t i = 0; i < n; ++i) ytmp[i] = x[i] + h * a21 * k.k1[i];
  f(t + c2 * h, ytmp, k.k2);
  for (size_t i = 0; i < n; ++i) ytmp[i] = x[i] + h * (a31 * k.k1[i] + a32 * k.k2[i]);
  f(t + c3 * h, ytmp, k.k3);
  for (size_t i = 0; i < n; ++i) ytmp[i] = x[i] + h * (a41 * k.k1[i] + a42 * k.k2[i] + a43 * k.k3[i]);
  f(t + c4 * h, ytmp, k.k4);
  for (size_t i = 0; i < n; ++i) ytmp[i] = x[i] + h * (a51 * k.k1[i] + a52 * k.k2[i] + a53 * k.k3[i] + a54 * k.k4[i]);
  f(t + c5 * h, ytmp, k.k5);
  for (size_t i = 0; i < n; ++i)
    ytmp[i] = x[i] + h * (a61 * k.k1[i] + a62 * k.k2[i] + a63 * k.k3[i] + a64 * k.k4[i] + a65 * k.k5[i]);
  f(t + h, ytmp, k.k6);
  for (size_t i = 0; i < n; ++i)
    y[i] = x[i] + h * (a71 * k.k1[i] + a73 * k.k3[i] + a74 * k.k4[i] + a75 * k.k5[i] + a76 * k.k6[i]);
  f(t + h, y, k.k7);
  double err = 0;
  for (size_t i = 0; i < n; ++i) {
    const double sc = opt.atol + opt.rtol * std::max(std::fabs(x[i]), std::fabs(y[i]));
    const double e = h * (e1 * k.k1[i] + e3 * k.k3[i] + e4 * k.k4[i] + e5 * k.k5[i] + e6 * k.k6[i] + e7 * k.k7[i]);
    err += (e / sc) * (e / sc);
  }
  return std::sqrt(err / static_cast<double>(n));
}

// The dense output of an accepted step from x to y at the fraction th of it.
Vec dopri5_dense(const Dopri5Stages& k, const Vec& x, const Vec& y, double h, double th) {
  using namespace dp;
  const double th1 = 1 - th;
  Vec xo(x.size());
  for (size_t i = 0; i < x.size(); ++i) {
    const double r1 = x[i], ydiff = y[i] - x[i], bspl = h * k.k1[i] - ydiff;
    const double r5 = h * (d1 * k.k1[i] + d3 * k.k3[i] + d4 * k.k4[i] + d5 * k.k5[i] + d6 * k.k6[i] + d7 * k.k7[i]);
    xo[i] = r1 + th * (ydiff + th1 * (bspl + th * ((ydiff - h * k.k7[i] - bspl) + th1 * r5)));
  }
  return xo;
}

}  // namespace

Trajectory integrate_dopri5(const DynamicModel& m, Vec x, const InputFunction& u, const std::vector<double>& out_t,
                            const IntegratorOptions& opt, Stats* stats) {
  if (out_t.empty()) throw std::invalid_argument("dopri5: no output times");
  Rhs f{m, u, stats, {}};
  const size_t n = x.size();
  Trajectory tr;
  double t = out_t.front();
  const double t_end = out_t.back();
  size_t next_out = 0;
  tr.t.push_back(t);
  tr.x.push_back(x);
  ++next_out;
  Dopri5Stages k;
  Vec y(n), ytmp(n);
  f(t, x, k.k1);
  double h = std::min(opt.max_step, 1e-3);
  while (t < t_end && next_out < out_t.size()) {
    if (t + h > t_end) h = t_end - t;
    double err = dopri5_attempt(f, t, x, h, opt, k, y, ytmp);
    if (!std::isfinite(err)) check_finite(m, y, t + h, opt.divergence_bound), err = 1e10;
    if (err <= 1.0) {
      // Dense output on [t, t + h] for every requested time inside it.
      while (next_out < out_t.size() && out_t[next_out] <= t + h + 1e-15) {
        Vec xo = dopri5_dense(k, x, y, h, (out_t[next_out] - t) / h);
        finish_step(x, xo, opt);
        tr.t.push_back(out_t[next_out]);
        tr.x.push_back(xo);
        ++next_out;
      }
      t += h;
      std::swap(x, y);  // y holds the step's start until the constraint has seen it
      finish_step(y, x, opt);
      check_finite(m, x, t, opt.divergence_bound);
      k.k1 = k.k7;
      if (opt.quaternion_offset >= 0 || opt.constrain) f(t, x, k.k1);  // x changed by normalisation or the constraint
      if (stats) ++stats->accepted_steps;
    } else if (stats) {
      ++stats->rejected_steps;
    }
    const double factor = err == 0 ? 5.0 : std::clamp(0.9 * std::pow(err, -0.2), 0.2, 5.0);
    h = std::min(opt.max_step, h * factor);
    if (h < opt.min_step) {
      std::ostringstream os;
      os << "simulation step size fell below " << opt.min_step << " s at t = " << t << " s (stiff or diverging)";
      throw DivergenceError(os.str());
    }
  }
  return tr;
}

SensitivityTrajectory integrate_rk4_sensitivities(const DynamicModel& m, Vec x, const InputFunction& u, double t0,
                                                  double t1, const IntegratorOptions& opt, const std::vector<int>* subset) {
  const int n = m.num_states(), np_all = m.num_params();
  std::vector<int> all(np_all);
  for (int j = 0; j < np_all; ++j) all[j] = j;
  const std::vector<int>& pcols = subset ? *subset : all;
  const int np = static_cast<int>(pcols.size()), cols = n + np;
  Vec ubuf(m.num_inputs()), A(n * n), B(n * np_all);
  // z = [x, S] with S row-major n x cols; S(0) = [I | 0].
  auto deriv = [&](double t, const Vec& z, Vec& dz) {
    u(t, ubuf.data());
    dz.assign(z.size(), 0.0);
    m.rhs(z.data(), ubuf.data(), dz.data(), A.data(), B.data(), nullptr);
    const double* S = z.data() + n;
    double* dS = dz.data() + n;
    for (int i = 0; i < n; ++i) {
      for (int k = 0; k < n; ++k) {
        const double a = A[i * n + k];
        if (a == 0) continue;
        for (int j = 0; j < cols; ++j) dS[i * cols + j] += a * S[k * cols + j];
      }
      for (int j = 0; j < np; ++j) dS[i * cols + n + j] += B[i * np_all + pcols[j]];
    }
  };
  Vec z(n + n * cols, 0.0);
  for (int i = 0; i < n; ++i) z[i] = x[i];
  for (int i = 0; i < n; ++i) z[n + i * cols + i] = 1.0;
  SensitivityTrajectory out;
  auto record = [&](double t) {
    out.states.t.push_back(t);
    out.states.x.push_back(Vec(z.begin(), z.begin() + n));
    out.S.push_back(Vec(z.begin() + n, z.end()));
  };
  record(t0);
  const long steps = std::max(1L, std::lround((t1 - t0) / opt.step));
  const double h = (t1 - t0) / static_cast<double>(steps);
  for (long s = 0; s < steps; ++s) {
    const double t = t0 + static_cast<double>(s) * h;
    rk4_step(deriv, t, z, h);
    check_finite(m, Vec(z.begin(), z.begin() + n), t + h, opt.divergence_bound);
    record(t + h);
  }
  return out;
}

}  // namespace quadgen::runtime
