// The effects that act on the logged data rather than in the ODE, and the one place their
// parameters are looked up by name:
//  - input_delay: the commands logged at t - delay act at t;
//  - attitude_bias: the logged attitude is the true one rotated by roll and pitch;
//  - motor_lag: the commanded rotor speeds reach the rotors through a first-order lag, each
//    rotor's time constant scaled by motor_lag_spread's factor (1 + value) where the model
//    has it.
// A fit or a simulation against a log applies them to the log (the equation error, the
// validation windows, the prediction rollouts); their values may differ by flight, so they
// are read through DynamicModel::param_column at the sample's time.
#pragma once
#include <algorithm>
#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "runtime/dynamic_model.hpp"
#include "runtime/per_flight_model.hpp"

namespace quadgen::runtime {

// Their values in effect at one time (0 for an effect the model lacks).
struct DataSideEffects {
  double delay = 0;  // s
  double roll = 0;   // rad
  double pitch = 0;  // rad
  double tau = 0;    // s
};

// Where they sit in a model's parameter vector (-1: the model lacks the effect).
struct DataSideParams {
  int delay = -1, roll = -1, pitch = -1, tau = -1;

  // motor_lag_spread.<rotor> of each rotor-speed state w_<rotor>, in the order of
  // DynamicModel::rotor_speed_states() (-1: none).
  std::vector<int> lag_spread;

  explicit DataSideParams(const DynamicModel& model)
      : delay(model.input_delay_param()),
        roll(model.param_index("attitude_bias.roll")),
        pitch(model.param_index("attitude_bias.pitch")),
        tau(model.param_index("motor_lag.tau")) {
    for (int s : model.rotor_speed_states())
      lag_spread.push_back(model.param_index("motor_lag_spread." + model.state_names()[s].substr(2)));
  }

  std::array<int, 4> indices() const { return {delay, roll, pitch, tau}; }

  // The values in effect at time t, read from parameter vector p.
  DataSideEffects at(const DynamicModel& model, const double* p, double t) const {
    const auto value = [&](int index) { return index >= 0 ? p[model.param_column(index, t)] : 0.0; };
    return {value(delay), value(roll), value(pitch), value(tau)};
  }

  // Rotor `i`'s time constant at time t: motor_lag.tau times motor_lag_spread's (1 + value).
  double rotor_tau(const DynamicModel& model, const double* p, double t, size_t i, double tau_all) const {
    const int s = i < lag_spread.size() ? lag_spread[i] : -1;
    return s >= 0 ? tau_all * (1 + p[model.param_column(s, t)]) : tau_all;
  }
};

// The parameters a simulation of `model` runs with: every rotor's lag at least 1 ms, the
// shared motor_lag.tau raised where motor_lag_spread's smallest factor (1 + value) would
// take a rotor below it. A lag below that (the equation error's "no lag") would make RK4 at
// 1 ms steps unstable; over a second, 1 ms of lag is invisible.
inline std::vector<double> simulation_params(const DynamicModel& model, std::vector<double> p) {
  constexpr double kShortestSimulatedLag = 1e-3;  // s
  double smallest_factor = 1;
  for (int i = 0; i < model.num_params(); ++i)
    if (shared_name(model.param_names()[i]).rfind("motor_lag_spread.", 0) == 0)
      smallest_factor = std::min(smallest_factor, 1 + p[i]);
  for (int i = 0; i < model.num_params(); ++i)
    if (shared_name(model.param_names()[i]) == "motor_lag.tau")
      p[i] = std::max(p[i], kShortestSimulatedLag / std::max(smallest_factor, 1e-3));
  return p;
}

// The median of the intervals between consecutive times (the upper median of an even count;
// 0 for fewer than two times): a log's sampling interval, which a dropped sample or a gap
// does not move.
inline double median_interval(const std::vector<double>& times) {
  std::vector<double> dts;
  for (size_t k = 1; k < times.size(); ++k) dts.push_back(times[k] - times[k - 1]);
  if (dts.empty()) return 0.0;
  std::nth_element(dts.begin(), dts.begin() + dts.size() / 2, dts.end());
  return dts[dts.size() / 2];
}

// The one gap rule of the pipeline: a sample interval longer than 1.5 times the log's median
// interval is a gap (a joined flight's boundary, trimmed ground contact, a dropped sample).
// No derivative, rotor-speed filter or delayed command lookup reaches across one. Relative
// to the median so that it holds at any logging rate; 1.5 lets sampling jitter through.
inline double gap_threshold(const std::vector<double>& times) { return 1.5 * median_interval(times); }

// Across a gap up to this long (a dropped sample; an in-flight motor dip trimmed as not
// airborne, up to 0.3 s in the ARPL log) the rotors kept spinning: a rotor-speed filter
// carries their speeds with the last command held. After a longer one (ground contact, a
// joined flight's start 1 s on) they restart in steady state with the commands.
constexpr double kRotorRestartGap = 0.5;  // s

// For each sample time, the index of the first sample of its contiguous stretch (gaps as
// gap_threshold says): a delayed command lookup is clamped there, so it never reaches across
// a gap into a previous joined flight or trimmed ground contact.
inline std::vector<size_t> stretch_starts(const std::vector<double>& times) {
  const double gap = gap_threshold(times);
  std::vector<size_t> out(times.size(), 0);
  for (size_t k = 1; k < times.size(); ++k) out[k] = times[k] - times[k - 1] > gap ? k : out[k - 1];
  return out;
}

}  // namespace quadgen::runtime
