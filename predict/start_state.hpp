// The state a simulation started at a logged sample begins from, the one home for it (the
// prediction's rollouts and the diagnosis' validation windows both start there):
//  - the 13 measured states, the attitude unbiased by the attitude_bias in effect;
//  - for a model with rotor-speed states (motor_lag), the speeds the logged commands have
//    produced through the lag up to that sample: delayed by input_delay and held between
//    samples, exactly what the simulation itself does after its start.
// Why not the commanded speeds in steady state: a flight controller's commands move
// faster than a 50 ms lag follows, so starting the rotors at the command gives each rollout
// a differential thrust error at t = 0 of tau times the commands' rate of change. Over the
// lag it turns into a body-rate error that a rollout then carries to every horizon: the
// very effect the lag models would make the rollouts worse at their start.
#pragma once
#include <cstddef>
#include <vector>

#include "runtime/data_side_effects.hpp"
#include "runtime/dynamic_model.hpp"
#include "fit/flight_data.hpp"

namespace quadgen::predict {

class StartStates {
 public:
  // `params` as the simulation runs with them (runtime::simulation_params), already set in
  // `model` (the commanded speeds come from its right-hand side).
  StartStates(runtime::DynamicModel& model, const std::vector<double>& params, const fit::Flight& flight);
  // The full model state at sample k.
  std::vector<double> at(size_t k) const;
  // The data-side values in effect at sample k.
  runtime::DataSideEffects effects_at(size_t k) const;

  // Across a gap up to this long (a dropped sample) the rotors keep turning with the last
  // command; after a longer one (trimmed ground contact, a joined flight) they restart in
  // steady state with the commands. The equation error's rule (fit/equation_error.hpp).
  static constexpr double kRotorRestartGap = 0.5;  // s

 private:
  runtime::DynamicModel& model_;
  const std::vector<double>& params_;
  const fit::Flight& flight_;
  runtime::DataSideParams data_side_;
  std::vector<size_t> stretch_;   // first sample of each sample's contiguous stretch
  size_t rotors_ = 0;             // rotor-speed states (13 .. 13 + rotors_)
  std::vector<double> speeds_;    // samples x rotors_, at each sample's time
  // The commanded rotor speeds at time t (the model's dw/dt at w = 0, times tau): of the
  // command logged at or before t - delay, not read from before sample `first` (the
  // stretch's first), with the battery voltage held at t.
  void commanded_speeds(double t, double delay, size_t first, double tau, std::vector<double>& c) const;
};

}  // namespace quadgen::predict
