// Prediction error measured the way published quadrotor models report it, so that ours can be
// set beside theirs:
//  - open loop: from many start points (every sample, or a dense stride), the model is
//    integrated from the measured state (rotor speeds as the lag carried them; no start in
//    the first 0.3 s of the data: predict/start_state.hpp) with the logged commands; the
//    error AT a horizon (0.1, 0.25, 0.5, 1 s) is averaged over the start points (IDSIA nano-drone benchmark,
//    NanoBench rollouts). Tilt (angle between body z axes) and heading are reported apart.
//  - attitude replayed: the same with attitude and body rates taken from the log at every
//    step, integrating only translation (and rotor speeds): the force model alone.
//  - translation replayed: position and velocity taken from the log, integrating attitude,
//    body rates (and rotor speeds): the moment model alone. Its tilt against the open loop's
//    says how much of the open-loop drift the moments make by themselves.
//  - open loop, past disturbance held: the open loop with the acceleration residual of the
//    log's last disturbance_window seconds before each start added over the rollout
//    (Rollout::past_disturbance): how much of the error is slow enough to persist.
//  - set points flown (where the log holds attitude set points and a controller is given):
//    the open loop with the roll and pitch part of the commands from a replica of the
//    vehicle's attitude controller flying the logged set points (Rollout::fly_set_points),
//    the collective and yaw logged. Not a published measure and not the open loop: its
//    inputs are the controller's set points, one loop further out than the motor commands.
//    It says how far the model carries the translation when the attitude is held the way the
//    vehicle's controller held it.
//  - body rates held, attitude held: reduced predictors from the same start states and logged
//    commands, which leave out the moment model. Body rates held takes the model's angular
//    acceleration as zero (the rates stay those measured at the start, the attitude turns at
//    them; the structure of the IDSIA benchmark code's physics baseline); attitude held keeps
//    the attitude measured at the start as well, so the force model acts along it. They are
//    open-loop predictions (nothing measured after the start is read but the logged commands) of
//    a model without moments: against the open loop they say whether the moment model helps
//    the prediction or harms it at a horizon.
//  - constant velocity: no model. From the same start states, the position moves on at the
//    measured start velocity and the attitude and body rates stay as they were. The baseline
//    any model has to beat (on the NanoBench flights the open loop does not, at 1 s). It never
//    diverges, so where open-loop rollouts diverge it counts samples the open loop does not.
//  - one step: body-frame specific force and angular-acceleration residuals per axis, RMS
//    (NeuroBEM), and the world-vertical acceleration RMSE (NanoBench Task 1).
// Evaluated on the data given: callers pass held-out data. A log without a pose (IMU only)
// gets the one-step view alone.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "runtime/dynamic_model.hpp"
#include "fit/flight_data.hpp"
#include "runtime/plot.hpp"
#include "predict/rollout.hpp"

namespace quadgen::predict {

struct PredictionOptions {
  std::vector<double> horizons = {0.1, 0.25, 0.5, 1.0};  // s, every rollout view
  double start_stride = 0.05;  // s between start points (5 samples at 100 Hz)
  double step = 1e-3;          // s, RK4 step
  // A start whose horizon crosses a gap in the log (trimmed ground contact) is not counted.
  double max_gap = Rollout::kMaxGap;  // s
  // Seconds of log before each start from which the open loop with the past disturbance
  // takes the disturbance it holds (Rollout::past_disturbance); 0: that view is not run.
  double disturbance_window = 0.5;
  // The controller that flies the logged attitude set points (the set-points-flown view);
  // none: that view is not run, nor on a log without set points.
  std::optional<SetPointFlying> set_points;
};

// Mean and RMS of an error over start points; kept as sums so that flights can be pooled.
struct ErrorStats {
  double sum = 0, sum_sq = 0;
  size_t count = 0;
  void add(double e) {
    sum += e;
    sum_sq += e * e;
    ++count;
  }
  void merge(const ErrorStats& o) {
    sum += o.sum;
    sum_sq += o.sum_sq;
    count += o.count;
  }
  double mean() const;  // NaN without samples
  double rms() const;
};

struct HorizonErrors {
  double horizon = 0;  // s
  ErrorStats position, velocity, tilt, heading, body_rates;  // m, m/s, rad, rad, rad/s
  // The angle of the whole rotation between simulated and measured attitude (geodesic, rad):
  // the attitude error as the IDSIA benchmark reports it, beside tilt and heading apart.
  ErrorStats attitude;
  size_t diverged = 0;  // rollouts that left any bound (counted in no statistic)
};

struct OneStepErrors {
  ErrorStats specific_force[3];        // m/s^2, body x y z (model - measured)
  ErrorStats angular_acceleration[3];  // rad/s^2, body x y z
  ErrorStats vertical_acceleration_world;
  std::string source;  // where the measured accelerations come from

  // Adds another flight's errors; a source that differs between them becomes "mixed".
  void merge(const OneStepErrors& o);
};

struct Prediction {
  std::vector<HorizonErrors> open_loop, attitude_replayed, translation_replayed;
  // The open loop holding the disturbance the log showed just before each start (the mean
  // acceleration residual over PredictionOptions::disturbance_window, Rollout::
  // past_disturbance): a predictor that reads the recent past, as an observer would. Against
  // the open loop it says how much of the error is a disturbance slow enough to persist
  // over the horizon, which the model does not carry.
  std::vector<HorizonErrors> open_loop_past_disturbance;
  double disturbance_window = 0;  // s
  // The open loop with the attitude controller flying the logged set points (see above).
  std::vector<HorizonErrors> set_points_flown;
  // No model: the measured start state moved on at its velocity (see above); empty without a
  // pose, like the open loop.
  std::vector<HorizonErrors> constant_velocity;
  // The reduced predictors (see above; Replay::kBodyRatesHeld, Replay::kAttitudeHeld).
  std::vector<HorizonErrors> body_rates_held, attitude_held;
  OneStepErrors one_step;
  // With a linear correction fitted on the part before (linearly_corrected_one_step).
  std::optional<OneStepErrors> one_step_corrected;
  size_t start_points = 0;
  double seconds_of_data = 0;
  void merge(const Prediction& o);  // pools another flight's errors (same horizons)
};

// Samples lacking what the full-catalogue model reads get neutral values: without a battery
// log the voltage is the reference one, without a pose the height is far from the ground.
fit::Flight fill_missing_signals(fit::Flight f, double vbat_ref);

// `model` with `params` (a full parameter vector of it) on `flight`.
Prediction evaluate_prediction(runtime::DynamicModel& model, const std::vector<double>& params,
                               const fit::Flight& flight, const PredictionOptions& options);

// The one-step errors on `evaluated` left after a linear correction, fitted on `train` by
// least squares per channel, is subtracted from the model's accelerations. Regressors: 1,
// u_i and u_i^2 per rotor, body rates; with a pose body velocity and body velocity times the
// mean u^2; with a battery log the voltage times the mean u^2. On the nominal model this is a
// linear-regression baseline on the same split and the same measured accelerations
// (NanoBench's Task 1 reports linear regression as its best baseline); on a fitted model it
// shows how much of what the model still gets wrong a linear model of these signals explains.
OneStepErrors linearly_corrected_one_step(runtime::DynamicModel& model, const std::vector<double>& params,
                                          const fit::Flight& train, const fit::Flight& evaluated);

// In words, what limits the open-loop prediction ("" without rollouts): the share of the
// position error at the longest horizon that the attitude causes (open loop against attitude
// replayed), against the attitude held (no moment model) and constant velocity (no model),
// and near 0.5 s whether the attitude drift is the moment model's own (translation
// replayed drifts at least 80 % as far as the open loop) or grows through the simulated
// translation; and how much of the error at the longest horizon holding the past
// disturbance removes.
std::string what_limits_prediction(const Prediction& p);
// The one-step RMS errors in words: "body specific force 0.1 / 0.2 / 0.3 m/s^2, angular
// acceleration 4 / 5 / 6 rad/s^2, world vertical acceleration 0.2 m/s^2" (the report's
// prediction section and predict's summary).
std::string one_step_text(const OneStepErrors& e);
// One sentence for a report's summary: the open loop at the longest horizon against
// extrapolating the measured velocity with no model, and which is the closer ("" without
// those views). A gain over the base model alone can hide that no model does better.
std::string open_loop_against_no_model(const Prediction& p);
// Whether, at the longest horizon, extrapolating the measured velocity comes closer than the
// open loop (false without those views).
bool no_model_closer_at_longest_horizon(const Prediction& p);

// The layout of prediction.json (docs/formats.md): open_loop, attitude_replayed,
// translation_replayed, open_loop_past_disturbance, disturbance_window_s, body_rates_held,
// attitude_held, constant_velocity, one_step (set_points_flown and one_step_linear_correction
// where they ran).
nlohmann::ordered_json prediction_json(const Prediction& p);

// One row per view, horizon and quantity: view,horizon_s,quantity,unit,mean,rms,count.
std::string prediction_csv(const Prediction& p);

// Position errors at a horizon reported by others for a Crazyflie, drawn beside ours as the
// scale of what learned and physical models reach; none is measured on our split, and the
// caveat says how each differs (docs/validation.md, "Published anchors").
struct PublishedPoint {
  std::string source;
  double horizon_s, position_m;
  std::string caveat;
  bool benchmark_statistic;  // a mean over a test set; false: a single rollout a repository printed
};
const std::vector<PublishedPoint>& published_position_errors();

// Position error against horizon for each labelled prediction, with the published points.
std::vector<runtime::Panel> horizon_panels(const std::vector<std::pair<std::string, const Prediction*>>& predictions);

}  // namespace quadgen::predict
