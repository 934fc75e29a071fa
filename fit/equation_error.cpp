#include "equation_error.hpp"

#include "attitude.hpp"

#include <algorithm>
#include <cmath>

namespace quadgen::fit {

EquationErrorModel::EquationErrorModel(runtime::DynamicModel& model, Flight flight, bool use_accelerometer,
                                       std::vector<std::string> use)
    : model_(model), flight_(std::move(flight)), accel_(use_accelerometer), g_index_(model.param_index("g")) {
  const auto names = all_names();
  if (use.empty()) use = names;
  for (const auto& u : use) {
    const int c = runtime::index_in(names, u);
    if (c < 0) throw FitError("unknown residual channel '" + u + "'");
    used_.push_back(c);
  }
  lag_ = model.param_index("motor_lag.tau");
  delay_ = model.param_index("input_delay.seconds");
  roll_ = model.param_index("attitude_bias.roll");
  pitch_ = model.param_index("attitude_bias.pitch");
  for (int i = 13; i < model.num_states(); ++i) {
    const std::string& s = model.state_names()[i];
    if (lag_ < 0 || s.rfind("w_", 0) != 0)
      throw FitError("equation error needs every state measured or filtered from the commands; this model has state " + s);
    speed_states_.push_back(i);
  }
  if (!flight_.samples.empty() && speed_states_.size() > flight_.samples.front().u.size())
    throw FitError("more rotor-speed states than logged commands");
  if (accel_ && !flight_.has_accelerometer) throw FitError(flight_.source + ": no accelerometer columns ax, ay, az");
  if (!accel_ && !flight_.has_pose) throw FitError(flight_.source + ": no pose to differentiate");
}

std::vector<std::string> EquationErrorModel::all_names() const {
  if (accel_) return {"ax", "ay", "az", "pdot", "qdot", "rdot"};
  return {"ax", "ay", "az", "pdot", "qdot", "rdot"};  // world-frame accelerations when no accelerometer
}

void EquationErrorModel::set_free(const std::vector<bool>& free) const {
  free_ = free;
  std::vector<int> cols;
  for (size_t j = 0; j < free.size(); ++j)
    if (free[j]) cols.push_back(static_cast<int>(j));
  model_.restrict_param_jacobian(cols);
}

std::vector<std::string> EquationErrorModel::channels() const {
  const auto names = all_names();
  std::vector<std::string> out;
  for (int c : used_) out.push_back(names[c]);
  return out;
}

void EquationErrorModel::evaluate(const double* p, double* r, double* J) const {
  if (used_.size() == 6) return evaluate6(p, r, J);
  const int np = model_.num_params();
  const size_t ns = flight_.samples.size();
  std::vector<double> r6(ns * 6), J6(J ? ns * 6 * np : 0);
  evaluate6(p, r6.data(), J ? J6.data() : nullptr);
  const size_t nu = used_.size();
  for (size_t k = 0; k < ns; ++k)
    for (size_t c = 0; c < nu; ++c) {
      r[k * nu + c] = r6[k * 6 + used_[c]];
      if (J)
        for (int j = 0; j < np; ++j) J[(k * nu + c) * np + j] = J6[(k * 6 + used_[c]) * np + j];
    }
}

void EquationErrorModel::all_channels(const double* p, std::vector<double>& r6) const {
  r6.resize(flight_.samples.size() * 6);
  evaluate6(p, r6.data(), nullptr);
}

void EquationErrorModel::commands_at(double t, double* u) const {
  const auto& S = flight_.samples;
  const auto it = std::lower_bound(S.begin(), S.end(), t, [](const FlightSample& s, double v) { return s.t < v; });
  if (it == S.begin() || it == S.end()) {
    const FlightSample& s = it == S.end() ? S.back() : S.front();
    std::copy(s.u.begin(), s.u.end(), u);
    return;
  }
  const FlightSample &b = *it, &a = *(it - 1);
  const double w = (t - a.t) / (b.t - a.t);
  for (size_t i = 0; i < a.u.size(); ++i) u[i] = a.u[i] + w * (b.u[i] - a.u[i]);
}

void EquationErrorModel::prepare(const double* p, std::vector<double>& X, std::vector<double>& U) const {
  const int n = model_.num_states(), nu = model_.num_inputs();
  const size_t ns = flight_.samples.size();
  X.assign(ns * n, 0.0);
  U.assign(ns * nu, 0.0);
  const int t_in = model_.input_index("t"), v_in = model_.input_index("vbat");
  const double delay = delay_ >= 0 ? p[delay_] : 0.0;
  const double roll = roll_ >= 0 ? p[roll_] : 0.0, pitch = pitch_ >= 0 ? p[pitch_] : 0.0;
  for (size_t k = 0; k < ns; ++k) {
    const FlightSample& s = flight_.samples[k];
    double* x = &X[k * n];
    double* u = &U[k * nu];
    std::copy(s.x.begin(), s.x.end(), x);
    runtime::unbias_attitude(&s.x[6], roll, pitch, x + 6);
    // Commands are held until the next sample (zero-order hold), so the smoothed
    // derivative centred on t_k sees them half a sample late on average.
    const double hold = k > 0 ? 0.5 * (s.t - flight_.samples[k - 1].t) : 0.0;
    commands_at(s.t - delay - hold, u);
    if (t_in >= 0) u[t_in] = s.t;
    if (v_in >= 0) u[v_in] = s.vbat;
  }
  if (speed_states_.empty()) return;
  // Rotor speeds: the commanded speed (the model's dw/dt at w = 0, times tau) through the
  // first-order lag, exact for commands held between samples, started in steady state.
  const double tau = p[lag_];
  std::vector<double> f(n), prev(speed_states_.size());
  for (size_t k = 0; k < ns; ++k) {
    double* x = &X[k * n];
    model_.rhs(x, &U[k * nu], f.data(), nullptr, nullptr, nullptr);
    for (size_t i = 0; i < speed_states_.size(); ++i) {
      const double w_cmd = tau * f[speed_states_[i]];
      if (k == 0) {
        x[speed_states_[i]] = w_cmd;
      } else {
        const double a = std::exp(-(flight_.samples[k].t - flight_.samples[k - 1].t) / tau);
        x[speed_states_[i]] = a * X[(k - 1) * n + speed_states_[i]] + (1 - a) * prev[i];
      }
      prev[i] = w_cmd;
    }
  }
}

void EquationErrorModel::evaluate6(const double* p, double* r, double* J) const {
  const int np = model_.num_params();
  residuals(p, r, J);
  if (!J) return;
  // Columns of the parameters applied to the data: central differences.
  std::vector<double> pp(p, p + np), rp(flight_.samples.size() * 6), rm(rp.size());
  for (int c : {lag_, delay_, roll_, pitch_}) {
    if (c < 0 || (!free_.empty() && !free_[c])) continue;
    const double h = 1e-6 * std::max(std::abs(p[c]), 1e-2);
    pp[c] = p[c] + h;
    residuals(pp.data(), rp.data(), nullptr);
    pp[c] = p[c] - h;
    residuals(pp.data(), rm.data(), nullptr);
    pp[c] = p[c];
    for (size_t i = 0; i < rp.size(); ++i) J[i * np + c] = (rp[i] - rm[i]) / (2 * h);
  }
  model_.set_params(pp);
}

void EquationErrorModel::residuals(const double* p, double* r, double* J) const {
  const int n = model_.num_states(), np = model_.num_params(), nu = model_.num_inputs();
  model_.set_params(std::vector<double>(p, p + np));
  std::vector<double> X, U;
  prepare(p, X, U);
  std::vector<double> f(n), B(J ? n * np : 0);
  for (size_t k = 0; k < flight_.samples.size(); ++k) {
    const FlightSample& s = flight_.samples[k];
    const double* xk = &X[k * n];
    model_.rhs(xk, &U[k * nu], f.data(), nullptr, J ? B.data() : nullptr, nullptr);
    double* rk = r + 6 * k;
    // Body -> world rotation of the (true) attitude.
    const double w = xk[6], x = xk[7], y = xk[8], z = xk[9];
    const double R[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                            {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                            {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
    const double g = p[g_index_];
    for (int i = 0; i < 3; ++i) {
      if (accel_) {  // specific force in body axes: R^T (a + g e_z)
        double sf = 0;
        for (int j = 0; j < 3; ++j) sf += R[j][i] * (f[3 + j] + (j == 2 ? g : 0.0));
        rk[i] = sf - s.specific_force[i];
      } else {
        rk[i] = f[3 + i] - s.acc_world[i];
      }
      rk[3 + i] = f[10 + i] - s.rate_dot[i];
    }
    if (!J) continue;
    double* Jk = J + static_cast<size_t>(6 * k) * np;
    for (int c = 0; c < np; ++c) {
      for (int i = 0; i < 3; ++i) {
        double d;
        if (accel_) {
          d = 0;
          for (int j = 0; j < 3; ++j) d += R[j][i] * (B[(3 + j) * np + c] + (j == 2 && c == g_index_ ? 1.0 : 0.0));
        } else {
          d = B[(3 + i) * np + c];
        }
        Jk[i * np + c] = d;
        Jk[(3 + i) * np + c] = B[(10 + i) * np + c];
      }
    }
  }
}

}  // namespace quadgen::fit
