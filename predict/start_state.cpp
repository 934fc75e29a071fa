#include "predict/start_state.hpp"

#include <algorithm>
#include <cmath>

#include "runtime/attitude.hpp"
#include "runtime/rigid_body_state.hpp"

namespace quadgen::predict {

using namespace runtime::rigid_body;

size_t held_sample(const fit::Flight& f, double t) {
  const auto& S = f.samples;
  const auto it = std::upper_bound(S.begin(), S.end(), t, [](double v, const fit::FlightSample& s) { return v < s.t; });
  return it == S.begin() ? 0 : static_cast<size_t>(it - S.begin()) - 1;
}

size_t command_sample(const fit::Flight& f, double t, double delay, size_t first) {
  return std::max(held_sample(f, t - delay + 1e-12), first);
}

StartStates::StartStates(runtime::DynamicModel& model, std::vector<double> params, const fit::Flight& flight)
    : model_(model), params_(std::move(params)), flight_(flight), data_side_(model) {
  const auto& S = flight_.samples;
  std::vector<double> times;
  for (const auto& s : S) times.push_back(s.t);
  stretch_ = runtime::stretch_starts(times);
  settled_.assign(S.size(), false);
  rotors_ = model_.rotor_speed_states().size();
  speeds_.assign(S.size() * rotors_, 0.0);
  std::vector<double> c(rotors_);
  double restarted = 0;  // s, time of the last restart
  for (size_t k = 0; k < S.size(); ++k) {
    const runtime::DataSideEffects e = effects_at(k);
    double* w = rotors_ ? &speeds_[k * rotors_] : nullptr;
    if (k == 0 || S[k].t - S[k - 1].t > runtime::kRotorRestartGap) {  // steady state with the commands
      restarted = S[k].t;
      if (rotors_) {
        commanded_speeds(S[k].t, e.delay, stretch_[k], e.tau, c);
        std::copy(c.begin(), c.end(), w);
      }
    } else if (rotors_) {
      // From the previous sample's speeds through the lag, one piece per held command: the
      // delayed command changes where a logged sample's time plus the delay falls inside.
      std::copy(&speeds_[(k - 1) * rotors_], &speeds_[k * rotors_], w);
      double t = S[k - 1].t;
      while (t < S[k].t) {
        const size_t j = command_sample(flight_, t, e.delay, 0);  // command in force from t on
        const double next_change = j + 1 < S.size() ? S[j + 1].t + e.delay : S[k].t;
        const double t_end = std::min(S[k].t, std::max(next_change, t + 1e-9));
        commanded_speeds(t, e.delay, stretch_[k - 1], e.tau, c);
        for (size_t i = 0; i < rotors_; ++i) {
          const double tau = rotor_tau(S[k].t, i, e.tau);
          const double a = tau > 0 && t_end - t < 700 * tau ? std::exp(-(t_end - t) / tau) : 0.0;
          w[i] = c[i] + (w[i] - c[i]) * a;
        }
        t = t_end;
      }
    }
    settled_[k] = S[k].t - restarted >= kSettle - 1e-9;
  }
}

runtime::DataSideEffects StartStates::effects_at(size_t k) const {
  return data_side_.at(model_, params_.data(), flight_.samples[k].t);
}

void StartStates::commanded_speeds(double t, double delay, size_t first, double tau, std::vector<double>& c) const {
  const int n = model_.num_states();
  std::vector<double> x(n, 0.0), u(model_.num_inputs(), 0.0), f(n);
  const auto& s = flight_.samples[held_sample(flight_, t)];
  std::copy(s.x.begin(), s.x.end(), x.begin());
  const auto& cmd = flight_.samples[command_sample(flight_, t, delay, first)].u;
  std::copy(cmd.begin(), cmd.end(), u.begin());
  runtime::ExtraInputs(model_).fill(t, s.vbat, u.data());
  const std::vector<int>& speed = model_.rotor_speed_states();
  model_.rhs_rows(x.data(), u.data(), speed, f.data());  // dw/dt = (w_cmd - w) / tau_i
  for (size_t i = 0; i < rotors_; ++i) c[i] = rotor_tau(t, i, tau) * f[speed[i]];
}

double StartStates::rotor_tau(double t, size_t i, double tau_all) const {
  return data_side_.rotor_tau(model_, params_.data(), t, i, tau_all);
}

std::vector<double> StartStates::at(size_t k) const {
  std::vector<double> x(model_.num_states(), 0.0);
  const auto& s = flight_.samples[k];
  std::copy(s.x.begin(), s.x.end(), x.begin());
  const runtime::DataSideEffects e = effects_at(k);
  runtime::unbias_attitude(&s.x[kAttitude], e.roll, e.pitch, &x[kAttitude]);
  const std::vector<int>& speed = model_.rotor_speed_states();
  for (size_t i = 0; i < rotors_; ++i) x[speed[i]] = speeds_[k * rotors_ + i];
  return x;
}

}  // namespace quadgen::predict
