#include "predict/prediction.hpp"

#include <algorithm>
#include <optional>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <Eigen/Dense>

#include "runtime/attitude.hpp"
#include "runtime/data_side_effects.hpp"
#include "fit/equation_error.hpp"
#include "predict/rollout.hpp"
#include "output/joined.hpp"
#include "output/estimate.hpp"
#include "output/numbers.hpp"
#include "runtime/rigid_body_state.hpp"

namespace quadgen::predict {

using namespace runtime::rigid_body;

double ErrorStats::mean() const { return count ? sum / static_cast<double>(count) : std::nan(""); }
double ErrorStats::rms() const { return count ? std::sqrt(sum_sq / static_cast<double>(count)) : std::nan(""); }

void OneStepErrors::merge(const OneStepErrors& o) {
  for (int a = 0; a < 3; ++a) {
    specific_force[a].merge(o.specific_force[a]);
    angular_acceleration[a].merge(o.angular_acceleration[a]);
  }
  vertical_acceleration_world.merge(o.vertical_acceleration_world);
  if (source.empty()) source = o.source;
  else if (!o.source.empty() && o.source != source) source = "mixed";
}

void Prediction::merge(const Prediction& o) {
  auto merge_rows = [](std::vector<HorizonErrors>& a, const std::vector<HorizonErrors>& b) {
    if (a.empty()) a = b;
    else
      for (size_t i = 0; i < a.size() && i < b.size(); ++i) {
        for (auto m : {&HorizonErrors::position, &HorizonErrors::velocity, &HorizonErrors::tilt, &HorizonErrors::heading, &HorizonErrors::attitude,
                       &HorizonErrors::body_rates})
          (a[i].*m).merge(b[i].*m);
        a[i].diverged += b[i].diverged;
      }
  };
  merge_rows(open_loop, o.open_loop);
  merge_rows(attitude_replayed, o.attitude_replayed);
  merge_rows(translation_replayed, o.translation_replayed);
  merge_rows(open_loop_past_disturbance, o.open_loop_past_disturbance);
  merge_rows(set_points_flown, o.set_points_flown);
  merge_rows(body_rates_held, o.body_rates_held);
  merge_rows(attitude_held, o.attitude_held);
  merge_rows(constant_velocity, o.constant_velocity);
  one_step.merge(o.one_step);
  if (o.one_step_corrected) {
    if (!one_step_corrected) one_step_corrected = OneStepErrors{};
    one_step_corrected->merge(*o.one_step_corrected);
  }
  if (disturbance_window == 0) disturbance_window = o.disturbance_window;
  start_points += o.start_points;
  seconds_of_data += o.seconds_of_data;
}

namespace {

using runtime::DataSideEffects;

// Errors of a simulated state against the measured sample (attitude unbiased).
void add_errors(const std::vector<double>& x, const fit::FlightSample& s, const DataSideEffects& e, HorizonErrors& h) {
  const StateError err = state_error(x, s, e, true);
  h.position.add(std::sqrt(err.position_squared));
  h.velocity.add(std::sqrt(err.velocity_squared));
  h.tilt.add(err.tilt);
  h.heading.add(err.heading);
  h.attitude.add(err.angle);
  h.body_rates.add(std::sqrt(err.body_rates_squared));
}

double median_spacing(const fit::Flight& f) {
  std::vector<double> dt;
  for (size_t k = 1; k < f.samples.size(); ++k) dt.push_back(f.samples[k].t - f.samples[k - 1].t);
  if (dt.empty()) return 0.01;
  std::nth_element(dt.begin(), dt.begin() + dt.size() / 2, dt.end());
  return dt[dt.size() / 2];
}

// Trajectories from start points every `stride` seconds, scored against the log: `begin(k0)`
// gives a trajectory's data-side effects and start state (Rollout::Start), `advance(x, k)`
// carries x from sample k to k + 1 (false: it diverged). The error at each horizon is taken at
// the first sample at or after start + horizon (within a quarter of a sample spacing). Every
// view, with or without a model, goes through here: the same start points, gaps and samples.
template <class Begin, class Advance>
std::vector<HorizonErrors> score_from_starts(const Rollout& roll, const fit::Flight& f, const PredictionOptions& o,
                                             size_t* starts, Begin begin, Advance advance) {
  std::vector<HorizonErrors> rows;
  for (double h : o.horizons) {
    HorizonErrors row;
    row.horizon = h;
    rows.push_back(row);
  }
  const auto& S = f.samples;
  const double dt = median_spacing(f), longest = *std::max_element(o.horizons.begin(), o.horizons.end());
  double next_start = S.empty() ? 0 : S.front().t;
  for (size_t k0 = 0; k0 + 1 < S.size(); ++k0) {
    if (S[k0].t + 1e-9 < next_start || !roll.may_start_at(k0)) continue;
    next_start = S[k0].t + o.start_stride;
    if (S.back().t - S[k0].t < longest - 0.25 * dt) break;  // the longest horizon must fit
    if (starts) ++*starts;
    auto [e, x] = begin(k0);
    size_t next = 0;  // the next horizon to score
    for (size_t k = k0; k + 1 < S.size() && next < rows.size(); ++k) {
      if (S[k + 1].t - S[k].t > o.max_gap) break;
      if (!advance(x, k)) {
        for (; next < rows.size(); ++next) ++rows[next].diverged;
        break;
      }
      while (next < rows.size() && S[k + 1].t - S[k0].t >= rows[next].horizon - 0.25 * dt) {
        if (S[k + 1].t - S[k0].t <= rows[next].horizon + dt) add_errors(x, S[k + 1], e, rows[next]);
        ++next;
      }
    }
  }
  return rows;
}

// The model's rollouts, with what `replay` takes from the log (and the past disturbance held
// when a window is given).
std::vector<HorizonErrors> rollouts(Rollout& roll, const fit::Flight& f, const PredictionOptions& o, Replay replay,
                                    size_t* starts = nullptr, double disturbance_window = 0) {
  return score_from_starts(
      roll, f, o, starts,
      [&](size_t k0) {
        Rollout::Start s = roll.start_at(k0, replay);
        if (disturbance_window > 0) roll.hold_disturbance(roll.past_disturbance(k0, disturbance_window));
        return s;
      },
      [&](std::vector<double>& x, size_t k) { return roll.advance(x, k, replay); });
}

// No model: the start state's position moved on at its velocity, everything else held (the
// attitude, the body rates). The start state is the rollouts' own, so the baseline and the
// model differ only in what carries the state forward.
std::vector<HorizonErrors> constant_velocity(Rollout& roll, const fit::Flight& f, const PredictionOptions& o) {
  using runtime::rigid_body::kPosition;
  using runtime::rigid_body::kVelocity;
  std::vector<double> x0;
  double t0 = 0;
  return score_from_starts(
      roll, f, o, nullptr,
      [&](size_t k0) {
        Rollout::Start s = roll.start_at(k0, Replay::kNothing);
        x0 = s.state;
        t0 = f.samples[k0].t;
        return s;
      },
      [&](std::vector<double>& x, size_t k) {
        const double elapsed = f.samples[k + 1].t - t0;
        for (int a = 0; a < 3; ++a) x[kPosition + a] = x0[kPosition + a] + x0[kVelocity + a] * elapsed;
        return true;
      });
}

// One-step residuals (model - measured) of every usable sample of `f`: body specific force
// (x y z), body angular acceleration (x y z) and world vertical acceleration, from the
// equation error (the fit's own formulation: lag, delay and bias applied to the data),
// rotated into body and world axes; with the regressors of the linear correction beside them.
struct OneStepRows {
  std::vector<std::array<double, 7>> residual;
  std::vector<std::vector<double>> regressors;
  std::string source;
};

// 1, u_i and u_i^2 per rotor, body rates; with a pose, body velocity and body velocity times
// the mean u^2 (rotor drag and flapping grow with both); with a battery log, the voltage
// times the mean u^2 (thrust per command follows the voltage).
std::vector<double> correction_regressors(const fit::FlightSample& s, const runtime::Rotation& R, const fit::Flight& f) {
  std::vector<double> x = {1.0};
  double mean_u2 = 0;
  for (double u : s.u) x.push_back(u), x.push_back(u * u), mean_u2 += u * u / static_cast<double>(s.u.size());
  for (int a = 0; a < 3; ++a) x.push_back(s.x[kBodyRate + a]);
  if (f.has_pose)
    for (int a = 0; a < 3; ++a) {
      const double* v = &s.x[kVelocity];  // in body axes of the unbiased attitude R
      const double v_body = R.m[0][a] * v[0] + R.m[1][a] * v[1] + R.m[2][a] * v[2];
      x.push_back(v_body), x.push_back(v_body * mean_u2);
    }
  if (f.has_vbat) x.push_back(s.vbat * mean_u2);
  return x;
}

OneStepRows one_step_rows(runtime::DynamicModel& model, const std::vector<double>& p, const fit::Flight& f) {
  OneStepRows out;
  const bool accel = f.has_accelerometer;
  out.source = accel ? "accelerometer (specific force) and differentiated gyro"
                     : "differentiated velocity and differentiated gyro";
  std::vector<double> r6;
  try {
    const fit::EquationErrorModel ee(model, f, accel);
    ee.all_channels(p.data(), r6);
    const runtime::DataSideParams data_side(model);
    for (size_t row = 0; row < ee.rows().size(); ++row) {
      const auto& s = f.samples[ee.rows()[row]];
      const DataSideEffects e = data_side.at(model, p.data(), s.t);
      double q[4];
      runtime::unbias_attitude(&s.x[kAttitude], e.roll, e.pitch, q);
      const runtime::Rotation R = runtime::rotation_matrix(q);
      const double* r = &r6[row * 6];
      std::array<double, 7> res;
      for (int a = 0; a < 3; ++a) {
        res[a] = accel ? r[a] : R.m[0][a] * r[0] + R.m[1][a] * r[1] + R.m[2][a] * r[2];
        res[3 + a] = r[3 + a];
      }
      res[6] = accel ? R.m[2][0] * r[0] + R.m[2][1] * r[1] + R.m[2][2] * r[2] : r[2];
      out.residual.push_back(res);
      out.regressors.push_back(correction_regressors(s, R, f));
    }
  } catch (const fit::FitError&) {
    out.source = "not available: too few samples for the derivative filter";
  }
  return out;
}

// The statistics of these rows, each residual minus its correction (none: uncorrected).
OneStepErrors one_step_errors(const OneStepRows& rows, const std::vector<Eigen::VectorXd>* correction = nullptr) {
  OneStepErrors out;
  out.source = rows.source;
  for (size_t k = 0; k < rows.residual.size(); ++k) {
    std::array<double, 7> r = rows.residual[k];
    if (correction) {
      const Eigen::Map<const Eigen::VectorXd> x(rows.regressors[k].data(), static_cast<Eigen::Index>(rows.regressors[k].size()));
      for (int c = 0; c < 7; ++c) r[c] -= x.dot((*correction)[c]);
    }
    for (int a = 0; a < 3; ++a) out.specific_force[a].add(r[a]), out.angular_acceleration[a].add(r[3 + a]);
    out.vertical_acceleration_world.add(r[6]);
  }
  return out;
}

OneStepErrors one_step(runtime::DynamicModel& model, const std::vector<double>& p, const fit::Flight& f) {
  return one_step_errors(one_step_rows(model, p, f));
}

}  // namespace

fit::Flight fill_missing_signals(fit::Flight f, double vbat_ref) {
  for (auto& s : f.samples) {
    if (!f.has_vbat) s.vbat = vbat_ref;
    if (!f.has_pose) s.x[kPosition + 2] = 1e3;
  }
  return f;
}

Prediction evaluate_prediction(runtime::DynamicModel& model, const std::vector<double>& params, const fit::Flight& f,
                               const PredictionOptions& o) {
  Prediction out;
  if (f.samples.size() < 2) return out;
  out.seconds_of_data = f.samples.back().t - f.samples.front().t;
  const std::vector<double> p = runtime::simulation_params(model, params);
  out.one_step = one_step(model, params, f);
  model.set_params(p);
  if (!f.has_pose) return out;  // an IMU-only log: no state to start from or compare with
  Rollout roll(model, f, p, o.step);
  out.open_loop = rollouts(roll, f, o, Replay::kNothing, &out.start_points);
  out.body_rates_held = rollouts(roll, f, o, Replay::kBodyRatesHeld);
  out.attitude_held = rollouts(roll, f, o, Replay::kAttitudeHeld);
  out.constant_velocity = constant_velocity(roll, f, o);
  out.attitude_replayed = rollouts(roll, f, o, Replay::kAttitude);
  out.translation_replayed = rollouts(roll, f, o, Replay::kTranslation);
  if (o.disturbance_window > 0) {
    out.disturbance_window = o.disturbance_window;
    out.open_loop_past_disturbance = rollouts(roll, f, o, Replay::kNothing, nullptr, o.disturbance_window);
  }
  if (o.set_points && f.has_attitude_ref) {
    roll.fly_set_points(*o.set_points);
    out.set_points_flown = rollouts(roll, f, o, Replay::kSetPoints);
  }
  return out;
}

OneStepErrors linearly_corrected_one_step(runtime::DynamicModel& model, const std::vector<double>& params,
                                          const fit::Flight& train, const fit::Flight& evaluated) {
  const OneStepRows fit_rows = one_step_rows(model, params, train), rows = one_step_rows(model, params, evaluated);
  if (fit_rows.residual.empty() || rows.residual.empty()) return one_step_errors(rows);
  const Eigen::Index n = static_cast<Eigen::Index>(fit_rows.residual.size()),
                     m = static_cast<Eigen::Index>(fit_rows.regressors.front().size());
  if (n < 10 * m) throw std::invalid_argument("linear correction: fewer than 10 training samples per regressor");
  Eigen::MatrixXd X(n, m), Y(n, 7);
  for (Eigen::Index k = 0; k < n; ++k) {
    for (Eigen::Index j = 0; j < m; ++j) X(k, j) = fit_rows.regressors[k][j];
    for (int c = 0; c < 7; ++c) Y(k, c) = fit_rows.residual[k][c];
  }
  // Columns scaled to unit RMS so that rank decisions do not depend on units (u^2 ~ 0.3,
  // velocity ~ 1, voltage times u^2 ~ 1.5); a column the data leave constant drops out.
  const Eigen::VectorXd scale = (X.colwise().squaredNorm() / static_cast<double>(n)).cwiseSqrt().cwiseMax(1e-12);
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(X * scale.cwiseInverse().asDiagonal());
  std::vector<Eigen::VectorXd> correction;
  for (int c = 0; c < 7; ++c) correction.push_back(scale.cwiseInverse().asDiagonal() * qr.solve(Y.col(c)));
  return one_step_errors(rows, &correction);
}

namespace {

// The row of `rows` whose horizon is nearest to h (rows not empty).
const HorizonErrors& nearest(const std::vector<HorizonErrors>& rows, double h) {
  return *std::min_element(rows.begin(), rows.end(), [h](const HorizonErrors& a, const HorizonErrors& b) {
    return std::fabs(a.horizon - h) < std::fabs(b.horizon - h);
  });
}

// The open loop's and no model's (extrapolating at the measured start velocity) mean position
// errors at the longest horizon; nothing without the no-model view or where either is not finite.
struct AtLongestHorizon {
  double horizon = 0, model = 0, none = 0;
};
std::optional<AtLongestHorizon> open_loop_and_no_model_at_longest(const Prediction& p) {
  if (p.open_loop.empty() || p.constant_velocity.size() != p.open_loop.size()) return std::nullopt;
  const auto by_horizon = [](const HorizonErrors& a, const HorizonErrors& b) { return a.horizon < b.horizon; };
  const size_t i = static_cast<size_t>(std::max_element(p.open_loop.begin(), p.open_loop.end(), by_horizon) -
                                       p.open_loop.begin());
  const AtLongestHorizon at{p.open_loop[i].horizon, p.open_loop[i].position.mean(), p.constant_velocity[i].position.mean()};
  if (!std::isfinite(at.model) || !std::isfinite(at.none)) return std::nullopt;
  return at;
}

// The open loop against extrapolating at the measured start velocity (no model), in words: at
// the longest horizon, and at which horizons the model is the closer ("" without that view).
std::string against_constant_velocity(const Prediction& p) {
  const auto at = open_loop_and_no_model_at_longest(p);
  if (!at) return "";
  std::string s = " Extrapolating at the measured start velocity, with no model, is " + output::short_number(at->none) + " m off";
  if (at->model <= at->none) return s + ": the model predicts better at this horizon.";
  std::vector<size_t> order(p.open_loop.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return p.open_loop[a].horizon < p.open_loop[b].horizon; });
  std::vector<std::string> closer;  // the horizons at which the model is at least as close
  for (size_t i : order)
    if (p.open_loop[i].position.mean() <= p.constant_velocity[i].position.mean())
      closer.push_back(output::short_number(p.open_loop[i].horizon) + " s");
  s += ": at this horizon the model is worse than that";
  return s + (closer.empty() ? " (and at every horizon)." : " (the model is the closer at " + output::joined(closer) + ").");
}

}  // namespace

bool no_model_closer_at_longest_horizon(const Prediction& p) {
  const auto at = open_loop_and_no_model_at_longest(p);
  return at && at->model > at->none;
}

std::string open_loop_against_no_model(const Prediction& p) {
  const auto at = open_loop_and_no_model_at_longest(p);
  if (!at) return "";
  return "Open loop, " + output::short_number(at->horizon) + " s ahead of a measured state, the model is " +
         output::short_number(at->model) + " m off; extrapolating the measured velocity with no model is " +
         output::short_number(at->none) + " m off" +
         (at->model <= at->none ? ": the model is the closer." : ": at that horizon the velocity alone comes closer than the model.");
}

// m: below this at the longest horizon a model predicts the log exactly (its own flights).
constexpr double kNegligiblePositionError = 1e-3;

std::string one_step_text(const OneStepErrors& e) {
  const auto three = [](const ErrorStats (&axes)[3]) {
    return output::short_number(axes[0].rms()) + " / " + output::short_number(axes[1].rms()) + " / " +
           output::short_number(axes[2].rms());
  };
  return "body specific force " + three(e.specific_force) + " m/s², angular acceleration " +
         three(e.angular_acceleration) + " rad/s², world vertical acceleration " +
         output::short_number(e.vertical_acceleration_world.rms()) + " m/s²";
}

std::string what_limits_prediction(const Prediction& p) {
  if (p.open_loop.empty() || p.attitude_replayed.size() != p.open_loop.size()) return "";
  // The views' rows are in the order of PredictionOptions::horizons, which need not be sorted.
  const auto by_horizon = [](const HorizonErrors& a, const HorizonErrors& b) { return a.horizon < b.horizon; };
  const size_t longest = static_cast<size_t>(std::max_element(p.open_loop.begin(), p.open_loop.end(), by_horizon) - p.open_loop.begin());
  const HorizonErrors &open = p.open_loop[longest], &replayed = p.attitude_replayed[longest];
  const double both = open.position.mean(), forces = replayed.position.mean();
  if (!(both > 0) || !std::isfinite(forces)) return "";
  // Shares of an error below a millimetre are integration round-off, not a diagnosis.
  if (both < kNegligiblePositionError)
    return output::short_number(open.horizon) + " s ahead the open-loop position error is " + output::short_number(both) +
           " m: the model predicts this log to within its integration error.";
  std::string s = output::short_number(open.horizon) + " s ahead (at the end of each window) the open-loop position error is " + output::short_number(both) +
                  " m; with the measured attitude replayed (the force model alone) " + output::short_number(forces) + " m";
  if (forces < both)
    s += ", so " + std::to_string(static_cast<int>(std::lround(100 * (1 - forces / both)))) +
         " % of it comes from the attitude.";
  else
    s += ": the attitude does not add to it, the force model is what limits it.";
  if (p.body_rates_held.size() == p.open_loop.size() && std::isfinite(p.body_rates_held[longest].position.mean())) {
    const double held = p.body_rates_held[longest].position.mean();
    s += " Without the moment model (the body rates held at those measured at the start) it is " + output::short_number(held) +
         " m: " + (held < both ? "the moment model adds to the error at this horizon." : "the moment model helps at this horizon.");
  }
  s += against_constant_velocity(p);
  if (p.open_loop_past_disturbance.size() == p.open_loop.size()) {
    const double held = p.open_loop_past_disturbance[longest].position.mean();
    const long lower = std::lround(100 * (1 - held / both));  // per cent
    if (std::isfinite(held))
      s += " Holding the acceleration residual of the last " + output::short_number(p.disturbance_window) +
           " s before each start (model bias or disturbance) " +
           (lower >= 1    ? "lowers it to " + output::short_number(held) + " m: " + std::to_string(lower) +
                                " % of it is a residual slow enough to persist over the horizon."
            : lower <= -1 ? "raises it to " + output::short_number(held) + " m: the residual changes within the horizon."
                          : "leaves it at " + output::short_number(held) + " m: the residual is not slow.");
  }
  if (p.translation_replayed.size() != p.open_loop.size()) return s;
  // Near 0.5 s: long enough for the tilt to have grown well past the start's (at 0.1 s the
  // views agree by construction), short enough that the open loop has not yet left the
  // measured velocity so far that its airspeed terms (flapping) act on another flight. 0.8:
  // the moments alone drifting at least 80 % as far means the translation adds at most a
  // fifth (on the real flights they drift 1.2-1.8 times as far: docs/history.md).
  const HorizonErrors &tilt_open = nearest(p.open_loop, 0.5), &tilt_moments = nearest(p.translation_replayed, 0.5);
  const double a = tilt_open.tilt.mean(), m = tilt_moments.tilt.mean();
  if (!std::isfinite(a) || !std::isfinite(m)) return s;
  s += " At " + output::short_number(tilt_open.horizon) + " s the moment model alone (translation replayed) tilts by " +
       output::short_number(m) + " rad against " + output::short_number(a) + " rad open loop: ";
  s += m >= 0.8 * a ? "the attitude drift is the moment model's own error."
                    : "the attitude drift grows through the simulated translation (the force model's error turns the vehicle).";
  return s;
}

namespace {

nlohmann::ordered_json stats_json(const ErrorStats& s) {
  using output::number_or_null;
  return {{"mean", number_or_null(s.mean())}, {"rms", number_or_null(s.rms())}, {"count", s.count}};
}

double rms_of(const ErrorStats& s) { return s.rms(); }

nlohmann::ordered_json one_step_json(const OneStepErrors& o) {
  using output::number_or_null;
  return {{"specific_force_m_s2",
           {{"x", number_or_null(rms_of(o.specific_force[0]))},
            {"y", number_or_null(rms_of(o.specific_force[1]))},
            {"z", number_or_null(rms_of(o.specific_force[2]))}}},
          {"angular_acceleration_rad_s2",
           {{"x", number_or_null(rms_of(o.angular_acceleration[0]))},
            {"y", number_or_null(rms_of(o.angular_acceleration[1]))},
            {"z", number_or_null(rms_of(o.angular_acceleration[2]))}}},
          {"vertical_acceleration_world_m_s2", number_or_null(rms_of(o.vertical_acceleration_world))},
          {"samples", o.vertical_acceleration_world.count},
          {"measured_from", o.source},
          {"statistic", "RMS of model - measured over samples"}};
}

}  // namespace

nlohmann::ordered_json prediction_json(const Prediction& p) {
  using J = nlohmann::ordered_json;
  auto full_rows = [](const std::vector<HorizonErrors>& rows) {  // an open loop: every quantity
    J out = J::array();
    for (const auto& h : rows)
      out.push_back({{"horizon_s", h.horizon},
                     {"position_m", stats_json(h.position)},
                     {"velocity_m_s", stats_json(h.velocity)},
                     {"tilt_rad", stats_json(h.tilt)},
                     {"heading_rad", stats_json(h.heading)},
                     {"attitude_rad", stats_json(h.attitude)},
                     {"body_rates_rad_s", stats_json(h.body_rates)},
                     {"diverged", h.diverged}});
    return out;
  };
  J replayed = J::array();
  for (const auto& h : p.attitude_replayed)
    replayed.push_back({{"horizon_s", h.horizon},
                        {"position_m", stats_json(h.position)},
                        {"velocity_m_s", stats_json(h.velocity)},
                        {"diverged", h.diverged}});
  J moments = J::array();
  for (const auto& h : p.translation_replayed)
    moments.push_back({{"horizon_s", h.horizon},
                       {"tilt_rad", stats_json(h.tilt)},
                       {"heading_rad", stats_json(h.heading)},
                       {"attitude_rad", stats_json(h.attitude)},
                       {"body_rates_rad_s", stats_json(h.body_rates)},
                       {"diverged", h.diverged}});
  J out = {{"open_loop", full_rows(p.open_loop)},
          {"attitude_replayed", replayed},
          {"translation_replayed", moments},
          {"open_loop_past_disturbance", full_rows(p.open_loop_past_disturbance)},
          {"disturbance_window_s", p.disturbance_window},
          {"body_rates_held", full_rows(p.body_rates_held)},
          {"attitude_held", full_rows(p.attitude_held)},
          {"constant_velocity", full_rows(p.constant_velocity)},
          {"one_step", one_step_json(p.one_step)},
          {"start_points", p.start_points},
          {"seconds_of_data", p.seconds_of_data},
          {"definition",
           "error at each horizon after a start from the measured state, averaged over start points; "
           "tilt = angle between body z axes, heading = yaw difference, attitude = angle of the whole rotation between "
           "the simulated and the measured attitude (geodesic; the measured one corrected by a fitted marker-frame "
           "offset)"}};
  if (!p.set_points_flown.empty()) out["set_points_flown"] = full_rows(p.set_points_flown);
  if (p.one_step_corrected) {
    out["one_step_linear_correction"] = one_step_json(*p.one_step_corrected);
    out["one_step_linear_correction"]["statistic"] =
        "RMS of model - linear correction (fitted on the part before) - measured over samples";
  }
  return out;
}

std::string prediction_csv(const Prediction& p) {
  std::ostringstream os;
  os.precision(6);
  os << "view,horizon_s,quantity,unit,mean,rms,count\n";
  auto row = [&](const char* view, double h, const char* q, const char* unit, const ErrorStats& s) {
    os << view << ',' << h << ',' << q << ',' << unit << ',' << s.mean() << ',' << s.rms() << ',' << s.count << '\n';
  };
  auto open_loop_rows = [&](const char* view, const std::vector<HorizonErrors>& rows) {  // every quantity
    for (const auto& h : rows) {
      row(view, h.horizon, "position", "m", h.position);
      row(view, h.horizon, "velocity", "m/s", h.velocity);
      row(view, h.horizon, "tilt", "rad", h.tilt);
      row(view, h.horizon, "heading", "rad", h.heading);
      row(view, h.horizon, "attitude", "rad", h.attitude);
      row(view, h.horizon, "body_rates", "rad/s", h.body_rates);
    }
  };
  open_loop_rows("open_loop", p.open_loop);
  for (const auto& h : p.attitude_replayed) {
    row("attitude_replayed", h.horizon, "position", "m", h.position);
    row("attitude_replayed", h.horizon, "velocity", "m/s", h.velocity);
  }
  open_loop_rows("open_loop_past_disturbance", p.open_loop_past_disturbance);
  open_loop_rows("set_points_flown", p.set_points_flown);
  open_loop_rows("body_rates_held", p.body_rates_held);
  open_loop_rows("attitude_held", p.attitude_held);
  open_loop_rows("constant_velocity", p.constant_velocity);
  for (const auto& h : p.translation_replayed) {
    row("translation_replayed", h.horizon, "tilt", "rad", h.tilt);
    row("translation_replayed", h.horizon, "heading", "rad", h.heading);
    row("translation_replayed", h.horizon, "attitude", "rad", h.attitude);
    row("translation_replayed", h.horizon, "body_rates", "rad/s", h.body_rates);
  }
  const char* axes[] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    row("one_step", 0, (std::string("specific_force_") + axes[a]).c_str(), "m/s^2", p.one_step.specific_force[a]);
    row("one_step", 0, (std::string("angular_acceleration_") + axes[a]).c_str(), "rad/s^2", p.one_step.angular_acceleration[a]);
  }
  row("one_step", 0, "vertical_acceleration_world", "m/s^2", p.one_step.vertical_acceleration_world);
  return os.str();
}

const std::vector<PublishedPoint>& published_position_errors() {
  // The IDSIA benchmark's table (idsia-robotics/nanodrone-sysid-benchmark, results/
  // model_comparison.ipynb): the mean over windows of the position-error norm at the horizon,
  // on a trajectory type left out of training, driven by measured rotor speeds. NanoBench's
  // (syediu/nanobench-iros2026, benchmarks/task2_control/debug/sanity_check_dynamics.py): the
  // output its debug script prints for one rollout from take-off, with the logged position set
  // points and battery voltage fed in at every step (a review, helper-108: earlier called
  // "published" like the others).
  static const std::vector<PublishedPoint> points = {
      {"IDSIA nano-drone benchmark, physics model with angular acceleration zero (Busetto et al. 2026)", 0.1, 0.0126,
       "Crazyflie 2.1 Brushless, measured rotor speeds, 10 steps at 100 Hz, an unseen trajectory type", true},
      {"IDSIA nano-drone benchmark, hybrid model (Busetto et al. 2026)", 0.5, 0.112,
       "Crazyflie 2.1 Brushless, measured rotor speeds, 50 steps at 100 Hz, an unseen trajectory type", true},
      {"NanoBench dynamics MLP, one rollout", 0.5, 0.193,
       "this airframe's figure-8, from take-off, logged set points fed in, 50 steps", false},
      {"NanoBench dynamics MLP, one rollout", 1.0, 0.533, "the same rollout, 100 steps", false},
  };
  return points;
}

std::vector<runtime::Panel> horizon_panels(const std::vector<std::pair<std::string, const Prediction*>>& predictions) {
  runtime::Panel open{"open loop: mean position error at a horizon", "horizon [s]", "m", {}};
  runtime::Panel reduced{"without the moment model, and with no model: mean position error", "horizon [s]", "m", {}};
  runtime::Panel replay{"attitude replayed (force model alone): mean position error", "horizon [s]", "m", {}};
  runtime::Panel tilt{"open loop: mean tilt and heading error (angles: at most pi)", "horizon [s]", "rad", {}};
  runtime::Panel moments{"translation replayed (moment model alone): mean tilt error", "horizon [s]", "rad", {}};
  // One series of a view's mean errors (of `quantity`); markers of type `marker` where
  // `points`, so that one model's views keep its colour and still differ. Empty views (not
  // run) add nothing.
  enum Marker { kCircle = 7, kSquare = 5, kTriangle = 9, kDiamond = 13, kStar = 3, kPentagon = 15 };
  const auto add = [](runtime::Panel& panel, const std::string& label, const std::vector<HorizonErrors>& rows,
                      ErrorStats HorizonErrors::*quantity, bool points, int marker = kCircle, const std::string& colour = "") {
    runtime::Series s{label, {}, {}, points, colour, marker};
    for (const auto& h : rows) s.x.push_back(h.horizon), s.y.push_back((h.*quantity).mean());
    if (!s.x.empty()) panel.series.push_back(s);
  };
  for (const auto& [label, p] : predictions) {
    add(open, label, p->open_loop, &HorizonErrors::position, false);
    add(open, label + ", past disturbance held", p->open_loop_past_disturbance, &HorizonErrors::position, true);
    add(open, label + ", set points flown", p->set_points_flown, &HorizonErrors::position, true, kSquare);
    add(reduced, label + ", open loop", p->open_loop, &HorizonErrors::position, false);
    add(reduced, label + ", body rates held", p->body_rates_held, &HorizonErrors::position, true, kTriangle);
    add(reduced, label + ", attitude held", p->attitude_held, &HorizonErrors::position, true, kSquare);
    add(replay, label, p->attitude_replayed, &HorizonErrors::position, false);
    // Heading as markers, so that it keeps its model's colour beside the tilt's line.
    add(tilt, label + ", tilt", p->open_loop, &HorizonErrors::tilt, false);
    add(tilt, label + ", heading", p->open_loop, &HorizonErrors::heading, true);
    add(moments, label, p->translation_replayed, &HorizonErrors::tilt, false);
  }
  // No model: the same for every model of the same log, drawn once.
  if (!predictions.empty())
    add(reduced, "constant velocity (no model)", predictions.front().second->constant_velocity, &HorizonErrors::position, true,
        kDiamond, "#555555");
  // Published for the Crazyflie only; drawn for every vehicle as the scale of the state of the
  // art, and labelled with the vehicle they are of.
  // One colour and marker in every panel and plot (gnuplot's next colour differed by panel);
  // a benchmark's means apart from a single rollout a repository printed.
  // (a marker and colour no model's view uses: helper-109)
  // Short labels: the legend shares the figure's width with the plot (the vehicles and how each
  // is made: docs/validation.md, "Published anchors").
  runtime::Series benchmark{"IDSIA benchmark, best (mean)", {}, {}, true, "#ff7f0e", kStar},
      single{"NanoBench MLP, one rollout", {}, {}, true, "#8c564b", kPentagon};
  for (const auto& pt : published_position_errors()) {
    runtime::Series& s = pt.benchmark_statistic ? benchmark : single;
    s.x.push_back(pt.horizon_s), s.y.push_back(pt.position_m);
  }
  for (runtime::Panel* panel : {&open, &reduced}) panel->series.insert(panel->series.end(), {benchmark, single});
  return {open, reduced, replay, tilt, moments};
}

}  // namespace quadgen::predict
