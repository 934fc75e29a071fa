// The effects that act on the logged data rather than in the ODE, and the one place their
// parameters are looked up by name:
//  - input_delay: the commands logged at t - delay act at t;
//  - attitude_bias: the logged attitude is the true one rotated by roll and pitch;
//  - motor_lag: the commanded rotor speeds reach the rotors through a first-order lag.
// A fit or a simulation against a log applies them to the log (the equation error, the
// validation windows, the prediction rollouts); their values may differ by flight, so they
// are read through DynamicModel::param_column at the sample's time.
#pragma once
#include <array>

#include "dynamic_model.hpp"

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

  explicit DataSideParams(const DynamicModel& model)
      : delay(model.param_index("input_delay.seconds")),
        roll(model.param_index("attitude_bias.roll")),
        pitch(model.param_index("attitude_bias.pitch")),
        tau(model.param_index("motor_lag.tau")) {}

  std::array<int, 4> indices() const { return {delay, roll, pitch, tau}; }

  // The values in effect at time t, read from parameter vector p.
  DataSideEffects at(const DynamicModel& model, const double* p, double t) const {
    const auto value = [&](int index) { return index >= 0 ? p[model.param_column(index, t)] : 0.0; };
    return {value(delay), value(roll), value(pitch), value(tau)};
  }
};

}  // namespace quadgen::runtime
