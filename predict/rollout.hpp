// One simulation from a logged sample onward, the one home for it: the prediction's rollouts
// (predict/prediction.hpp) and the diagnosis' validation windows (diagnose/validation.hpp)
// both integrate with it, so that the two measures start, step and read commands alike.
//  - It starts from StartStates (the measured state, rotor speeds as the lag carried them).
//  - Commands are held at the log's samples, delayed by the model's input delay and not read
//    from before the rollout's stretch; the battery voltage is held likewise.
//  - RK4 with steps of at most `step` (1 ms by default; equal steps filling each sample
//    interval), the quaternion normalised after every full step. 1 ms keeps a rotor lag of
//    0.4 ms or more inside RK4's stability limit (h / tau < 2.79).
//  - A rollout diverges when a state leaves the finite numbers or exceeds kDivergenceBound.
//  - Optionally part of the state is imposed from the log at every RK4 stage (Replay).
#pragma once
#include <array>
#include <cstddef>
#include <optional>
#include <vector>

#include "fit/flight_data.hpp"
#include "predict/start_state.hpp"
#include "runtime/attitude_pid.hpp"
#include "runtime/data_side_effects.hpp"
#include "runtime/dynamic_model.hpp"

namespace quadgen::predict {

// What a rollout takes from the log at every RK4 stage instead of integrating it: nothing
// (open loop), the attitude and body rates (the force model alone), or the position and
// velocity (the moment model alone: the attitude it drifts to through its own moments, with
// the airspeed terms read at the measured velocity). kSetPoints imposes nothing either, but
// takes the roll and pitch part of the commands from a controller flying the logged attitude
// set points (Rollout::fly_set_points) instead of from the log. The last two impose nothing
// from the log after the start but hold part of the start state, as reduced predictors do:
// kBodyRatesHeld takes the model's angular acceleration as zero (the body rates stay those
// measured at the start and the attitude turns at them: the structure of the physics baseline
// in the IDSIA nano-drone benchmark's code, Busetto et al. 2025), kAttitudeHeld the attitude's
// rate of change as well (the force model acting along the attitude measured at the start).
// Neither uses the moment model; a held disturbance's angular part is dropped with it.
enum class Replay { kNothing, kAttitude, kTranslation, kSetPoints, kBodyRatesHeld, kAttitudeHeld };

// The one home for what each view does to the state: which impose part of the log at every
// RK4 stage, which drop the model's angular acceleration, which its turning as well.
constexpr bool imposes_from_log(Replay r) { return r == Replay::kAttitude || r == Replay::kTranslation; }  // as impose()
constexpr bool holds_body_rates(Replay r) { return r == Replay::kBodyRatesHeld || r == Replay::kAttitudeHeld; }
constexpr bool holds_attitude(Replay r) { return r == Replay::kAttitudeHeld; }

// The controller that flies the set points and how its outputs reach the rotors.
struct SetPointFlying {
  runtime::AttitudePidOptions pid;
  runtime::AttitudeMixer mixer;
  double start_window = 1.0;  // s of log before a start from which the loop's integrals are set
};

class Rollout {
 public:
  // `p`: the parameters as the simulation runs with them (runtime::simulation_params), already
  // set in `model`. `model` and `f` must outlive the rollout.
  Rollout(runtime::DynamicModel& model, const fit::Flight& f, const std::vector<double>& p, double step = 1e-3);
  Rollout(runtime::DynamicModel&, const fit::Flight&&, const std::vector<double>&, double = 1e-3) = delete;

  // Replay::kSetPoints flies with this controller (the flight must hold attitude set points).
  // The controller starts at each rollout's first sample where the vehicle's was on average
  // over the window before it (AttitudePid::start), runs at its own rate on the simulated
  // state, and its output acts after the model's input delay; until then, and for the
  // collective and yaw throughout, the logged commands act. Commands are held within [0, 1].
  // Throws std::invalid_argument when the rollout's step is longer than the loop's period.
  void fly_set_points(const SetPointFlying& s);

  // Whether a rollout may start at sample k (its rotor speeds known: StartStates::settled).
  bool may_start_at(size_t k) const { return start_.settled(k); }

  // Begins a rollout at sample k: the data-side effects in force from there on (a rollout
  // stays within one flight) and its state, with what `replay` takes from the log imposed.
  // It holds no disturbance until hold_disturbance is called.
  struct Start {
    runtime::DataSideEffects effects;
    std::vector<double> state;
  };
  Start start_at(size_t k, Replay replay);

  // Integrates x from sample k to sample k + 1 (of the rollout begun last); false if it
  // diverged.
  bool advance(std::vector<double>& x, size_t k, Replay replay);
  static constexpr double kDivergenceBound = 1e6;  // |x_i| beyond this counts as divergence
  // A rollout ends at a gap between samples longer than this (trimmed ground contact).
  static constexpr double kMaxGap = 0.1;  // s

  // The acceleration residual the log showed just before sample k (model bias or external
  // disturbance alike): over the `window` seconds before it (fewer where the sample's stretch
  // began later), the measured mean acceleration minus the model's, [0..2] world linear
  // (m/s^2), [3..5] body angular (rad/s^2). The measured means are the changes of the logged
  // velocity and body rates over the window divided by its length (no derivative of noisy
  // data is taken here); the model's the trapezoid mean of its right-hand side at the logged
  // states and commands. Only samples at or before k are read (a velocity the log did not
  // hold is itself a centred derivative of the positions: flight_data.cpp). Zero where less
  // than half the window lies in the stretch: a difference over a few samples is noise.
  std::array<double, 6> past_disturbance(size_t k, double window);
  // Added to the model's accelerations in every advance of the rollout begun last.
  void hold_disturbance(const std::array<double, 6>& d) { held_ = d; }

 private:
  void impose(Replay replay, double t, size_t k, std::vector<double>& x) const;
  void impose_translation(double t, size_t k, std::vector<double>& x) const;
  void impose_attitude(double t, size_t k, std::vector<double>& x) const;
  // The commands acting at time t (Replay::kSetPoints: their roll and pitch from the
  // controller) and the extra inputs.
  void inputs(double t, Replay replay, double* u) const;
  // The first sample of the `window` seconds up to sample k within k's stretch; with
  // `settled_only`, also where the rotor speeds were known (StartStates::settled).
  size_t window_start(size_t k, double window, bool settled_only) const;
  void start_controller(size_t k, const std::vector<double>& x);
  void update_controller(double t, const std::vector<double>& x);
  void replace_roll_and_pitch(double t, double* u) const;
  void deriv(double t, const std::vector<double>& x, size_t k, Replay replay, std::vector<double>& f);
  void stage(const std::vector<double>& x, const std::vector<double>& k, double h);

  runtime::DynamicModel& m_;
  const fit::Flight& f_;
  const StartStates start_;  // the state each rollout starts from
  runtime::DataSideEffects e_;
  size_t first_command_ = 0;  // the rollout's stretch: delayed commands are not read before it
  double step_;
  int n_;
  runtime::ExtraInputs extra_;
  std::vector<double> u_, k1_, k2_, k3_, k4_, tmp_, forced_;
  std::array<double, 6> held_{};  // hold_disturbance
  // Flying the set points (fly_set_points): the controller, the rollout's start time, its
  // updates so far and each update's output [counts] (time, roll, pitch).
  std::optional<SetPointFlying> flying_;
  runtime::AttitudePid pid_;
  double flight_start_ = 0;
  long updates_ = 0;
  std::vector<std::array<double, 3>> flown_;
  // The model's accelerations (world linear, body angular) at each logged sample, computed on
  // the first past_disturbance call.
  std::vector<std::array<double, 6>> model_acc_;
};

// How far a rolled-out state `x` is from the logged sample `s` (its attitude unbiased by the
// rollout's data-side effects `e`), the one measure both the prediction and the diagnosis'
// validation windows score: squared norms of the position, velocity and body-rate errors, and
// the attitude error as one angle (of q_sim^-1 ⊗ q_logged), as the tilt between the body z
// axes and as the heading difference (wrapped to [0, π]). The tilt and the heading need two
// rotation matrices per sample, which only the prediction reports: `tilt_and_heading` asks
// for them (else they stay 0), keeping them off the diagnosis' validation windows.
struct StateError {
  double position_squared = 0, velocity_squared = 0, body_rates_squared = 0;  // m^2, m^2/s^2, rad^2/s^2
  double angle = 0, tilt = 0, heading = 0;                                    // rad
};
StateError state_error(const std::vector<double>& x, const fit::FlightSample& s, const runtime::DataSideEffects& e,
                       bool tilt_and_heading);

}  // namespace quadgen::predict
