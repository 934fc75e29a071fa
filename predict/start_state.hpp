// The state a simulation started at a logged sample begins from, the one home for it (the
// prediction's rollouts and the diagnosis' validation windows both start there):
//  - the 13 measured states, the attitude unbiased by the attitude_bias in effect;
//  - for a model with rotor-speed states (motor_lag), the speeds the logged commands have
//    produced through the lag up to that sample: delayed by input_delay and held between
//    samples (command_sample, the lookup the rollouts use), carried across gaps up to
//    runtime::kRotorRestartGap and restarted in steady state after longer ones and at the
//    first sample of the flight given (a held-out part starts there too).
// Why not the commanded speeds in steady state everywhere: a flight controller's commands
// move faster than a 50 ms lag follows, so starting the rotors at the command gives each
// rollout a differential thrust error at t = 0 of tau times the commands' rate of change,
// which the open-loop attitude then carries to every horizon: the very effect the lag models
// would make the rollouts worse at their start. After a restart the speeds are not known
// until the lag has forgotten it; a rollout does not start before then (settled()).
#pragma once
#include <cstddef>
#include <vector>

#include "runtime/data_side_effects.hpp"
#include "runtime/dynamic_model.hpp"
#include "fit/flight_data.hpp"

namespace quadgen::predict {

// The last sample at or before t (commands and battery voltage are held between samples).
size_t held_sample(const fit::Flight& f, double t);
// The sample whose command acts at time t: the last logged at or before t - delay, not one
// before sample `first` (the start of the rollout's stretch). A command's own switching time
// (a sample's time plus the delay, computed in floating point) counts as the new command's.
size_t command_sample(const fit::Flight& f, double t, double delay, size_t first);

class StartStates {
 public:
  // `params` as the simulation runs with them (runtime::simulation_params), already set in
  // `model` (the commanded speeds come from its right-hand side).
  StartStates(runtime::DynamicModel& model, std::vector<double> params, const fit::Flight& flight);
  // The full model state at sample k.
  std::vector<double> at(size_t k) const;
  // The data-side values in effect at sample k.
  runtime::DataSideEffects effects_at(size_t k) const;
  // Whether the rotor speeds at sample k are known: kSettle or more after the last restart.
  // The same for every model (with a lag or without), so that two models are scored on the
  // same rollouts.
  bool settled(size_t k) const { return settled_[k]; }
  // Five times a 60 ms lag: what is left of a restart's error is below 1 %.
  static constexpr double kSettle = 0.3;  // s
  // The first sample of each sample's contiguous stretch (runtime::stretch_starts).
  const std::vector<size_t>& stretch_starts() const { return stretch_; }

 private:
  runtime::DynamicModel& model_;
  const std::vector<double> params_;
  const fit::Flight& flight_;
  runtime::DataSideParams data_side_;
  std::vector<size_t> stretch_;
  std::vector<bool> settled_;
  size_t rotors_ = 0;           // rotor-speed states (DynamicModel::rotor_speed_states())
  std::vector<double> speeds_;  // samples x rotors_, at each sample's time
  // The commanded rotor speeds at time t (the model's dw/dt at w = 0, times tau), of the
  // command command_sample gives, with the battery voltage held at t.
  void commanded_speeds(double t, double delay, size_t first, double tau, std::vector<double>& c) const;
  // Rotor i's time constant at time t (runtime::DataSideParams::rotor_tau).
  double rotor_tau(double t, size_t i, double tau_all) const;
};

}  // namespace quadgen::predict
