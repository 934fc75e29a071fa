#include "validation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "attitude.hpp"
#include "integrator.hpp"

namespace quadgen::diagnose {

namespace {
// Index of the last sample at or before t (commands are held between samples).
size_t held_index(const fit::Flight& f, double t) {
  const auto& S = f.samples;
  const auto it = std::upper_bound(S.begin(), S.end(), t, [](double v, const fit::FlightSample& s) { return v < s.t; });
  return it == S.begin() ? 0 : static_cast<size_t>(it - S.begin()) - 1;
}
}  // namespace

WindowedSimulation simulate_windows(runtime::DynamicModel& model, const std::vector<double>& params,
                                    const fit::Flight& f, double window) {
  // A rotor lag below 1 ms (the equation error's "no lag") would make RK4 at 1 ms steps
  // unstable; over 1 s windows 1 ms of lag is invisible, so it is simulated as 1 ms.
  std::vector<double> sim_params = params;
  const int lag = model.param_index("motor_lag.tau");
  if (lag >= 0 && sim_params[lag] < 1e-3) sim_params[lag] = 1e-3;
  model.set_params(sim_params);
  auto param = [&](const char* n) {
    const int i = model.param_index(n);
    return i >= 0 ? sim_params[i] : 0.0;
  };
  const double delay = param("input_delay.seconds"), roll = param("attitude_bias.roll"),
               pitch = param("attitude_bias.pitch"), tau = param("motor_lag.tau");
  const int n = model.num_states(), nu = model.num_inputs();
  const int t_in = model.input_index("t"), v_in = model.input_index("vbat");
  const size_t nr = f.samples.front().u.size();
  auto inputs = [&](double t, double* u) {
    const auto& s = f.samples[held_index(f, t - delay)];
    for (size_t i = 0; i < nr; ++i) u[i] = s.u[i];
    if (t_in >= 0) u[t_in] = t;
    if (v_in >= 0) u[v_in] = f.samples[held_index(f, t)].vbat;
  };
  runtime::IntegratorOptions io;
  io.step = 1e-3;  // well inside RK4's stability limit for rotor lags down to 0.4 ms
  io.divergence_bound = 1e6;
  WindowedSimulation out;
  double se = 0;
  size_t count = 0;
  const auto& S = f.samples;
  std::vector<double> u(nu), fx(n);
  for (size_t k0 = 0; k0 + 1 < S.size();) {
    std::vector<double> x(n, 0.0);
    std::copy(S[k0].x.begin(), S[k0].x.end(), x.begin());
    runtime::unbias_attitude(&S[k0].x[6], roll, pitch, &x[6]);
    if (n > 13) {  // rotor speeds in steady state with the commands (model's dw/dt at w = 0, times tau)
      inputs(S[k0].t, u.data());
      model.rhs(x.data(), u.data(), fx.data(), nullptr, nullptr, nullptr);
      for (int i = 13; i < n; ++i) x[i] = tau * fx[i];
    }
    size_t k = k0;
    bool lost = false;
    for (; k + 1 < S.size() && S[k + 1].t - S[k0].t <= window + 1e-9; ++k) {
      if (S[k + 1].t - S[k].t > 0.1) break;  // a gap (trimmed ground contact): new window
      try {
        x = runtime::integrate_rk4(model, x, inputs, S[k].t, S[k + 1].t, io).x.back();
      } catch (const std::exception&) {
        lost = true;
        break;
      }
      double e2 = 0;
      for (int a = 0; a < 3; ++a) e2 += std::pow(x[a] - S[k + 1].x[a], 2);
      se += e2;
      ++count;
      out.t.push_back(S[k + 1].t);
      out.x.push_back(x[0]);
      out.y.push_back(x[1]);
      out.z.push_back(x[2]);
    }
    if (lost) {  // diverged: count the rest of the window at the last error
      out.position_rmse = std::numeric_limits<double>::infinity();
      return out;
    }
    const double nan = std::numeric_limits<double>::quiet_NaN();
    out.t.push_back(S[k].t);
    out.x.push_back(nan);
    out.y.push_back(nan);
    out.z.push_back(nan);
    k0 = std::max(k, k0 + 1);
  }
  out.position_rmse = count ? std::sqrt(se / static_cast<double>(count)) : 0.0;
  return out;
}

}  // namespace quadgen::diagnose
