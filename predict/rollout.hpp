// One simulation from a logged sample onward, the one home for it: the prediction's rollouts
// (predict/prediction.hpp) and the diagnosis' validation windows (diagnose/validation.hpp)
// both integrate with it, so that the two measures of a model cannot drift apart.
//  - It starts from StartStates (the measured state, rotor speeds as the lag carried them).
//  - Commands are held at the log's samples, delayed by the model's input delay and not read
//    from before the rollout's stretch; the battery voltage is held likewise.
//  - RK4 with a fixed step (1 ms by default: well inside its stability limit for rotor lags
//    down to 0.4 ms), the quaternion normalised after every full step.
//  - Optionally part of the state is imposed from the log at every RK4 stage (Replay).
#pragma once
#include <cstddef>
#include <vector>

#include "fit/flight_data.hpp"
#include "predict/start_state.hpp"
#include "runtime/data_side_effects.hpp"
#include "runtime/dynamic_model.hpp"

namespace quadgen::predict {

// What a rollout takes from the log at every RK4 stage instead of integrating it: nothing
// (open loop), the attitude and body rates (the force model alone), or the position and
// velocity (the moment model alone: the attitude it drifts to through its own moments, with
// the airspeed terms read at the measured velocity).
enum class Replay { kNothing, kAttitude, kTranslation };

class Rollout {
 public:
  // `p`: the parameters as the simulation runs with them (runtime::simulation_params), already
  // set in `model`. `model` and `f` must outlive the rollout.
  Rollout(runtime::DynamicModel& model, const fit::Flight& f, const std::vector<double>& p, double step = 1e-3);

  // Whether a rollout may start at sample k (its rotor speeds known: StartStates::settled).
  bool may_start_at(size_t k) const { return start_.settled(k); }

  // Begins a rollout at sample k: the data-side effects in force from there on (a rollout
  // stays within one flight) and its state, with what `replay` takes from the log imposed.
  const runtime::DataSideEffects& start_at(size_t k);
  std::vector<double> initial_state(size_t k, Replay replay) const;

  // Integrates x from sample k to sample k + 1; false if it left the finite numbers (or
  // |x_i| > 1e6).
  bool advance(std::vector<double>& x, size_t k, Replay replay);

 private:
  void impose(Replay replay, double t, size_t k, std::vector<double>& x) const;
  void impose_translation(double t, size_t k, std::vector<double>& x) const;
  void impose_attitude(double t, size_t k, std::vector<double>& x) const;
  void inputs(double t, double* u) const;
  void deriv(double t, const std::vector<double>& x, size_t k, Replay replay, std::vector<double>& f);
  void stage(const std::vector<double>& x, const std::vector<double>& k, double h);

  runtime::DynamicModel& m_;
  const fit::Flight& f_;
  const StartStates start_;  // the state each rollout starts from
  runtime::DataSideEffects e_;
  size_t first_command_ = 0;  // the rollout's stretch: delayed commands are not read before it
  double step_;
  int n_, t_in_ = -1, v_in_ = -1;
  std::vector<double> u_, k1_, k2_, k3_, k4_, tmp_, forced_;
};

}  // namespace quadgen::predict
