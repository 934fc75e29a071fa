#include "predict/rollout.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "runtime/attitude.hpp"
#include "runtime/rigid_body_state.hpp"

namespace quadgen::predict {

using namespace runtime::rigid_body;

namespace {

// The weight of sample k + 1 at time t in [t_k, t_k+1] for linear interpolation.
double weight(const fit::FlightSample& a, const fit::FlightSample& b, double t) {
  return b.t > a.t ? std::clamp((t - a.t) / (b.t - a.t), 0.0, 1.0) : 0.0;
}

}  // namespace

Rollout::Rollout(runtime::DynamicModel& model, const fit::Flight& f, const std::vector<double>& p, double step)
    : m_(model), f_(f), start_(model, p, f), step_(step), n_(model.num_states()), extra_(model),
      u_(model.num_inputs()), k1_(n_), k2_(n_), k3_(n_), k4_(n_), tmp_(n_), forced_(n_) {}

Rollout::Start Rollout::start_at(size_t k, Replay replay) {
  first_command_ = start_.stretch_starts()[k];
  e_ = start_.effects_at(k);
  held_ = {};
  std::vector<double> x = start_.at(k);
  // The measured state already, but imposed the way every later step imposes it (attitude:
  // unbiased with this rollout's bias, renormalised), so that a replayed view starts exactly
  // on what it replays.
  impose(replay, f_.samples[k].t, k, x);
  if (replay == Replay::kSetPoints) start_controller(k, x);
  return {e_, x};
}

namespace {

std::array<double, 2> roll_and_pitch(const std::vector<double>& x) {
  const auto e = runtime::euler_zyx(x[kAttitude], x[kAttitude + 1], x[kAttitude + 2], x[kAttitude + 3]);
  return {e[0], e[1]};
}

}  // namespace

void Rollout::fly_set_points(const SetPointFlying& s) {
  if (step_ > runtime::AttitudePid(s.pid).period() + 1e-12)
    throw std::invalid_argument("Rollout: an integration step longer than the attitude loop's period");
  flying_ = s;
}

// The loop's integrals from the log's window before sample k (AttitudePid::start): the means
// of the measured rate, of the angle error against the set points (the logged attitude
// unbiased as the rollout's is) and of the output the logged commands hold, over the samples
// of k's stretch at most start_window before it.
void Rollout::start_controller(size_t k, const std::vector<double>& x) {
  if (!flying_ || !f_.has_attitude_ref)
    throw std::logic_error("Rollout: flying set points needs fly_set_points and a flight with phi_ref, theta_ref");
  const auto& S = f_.samples;
  const runtime::AttitudePidOptions& o = flying_->pid;
  const size_t j0 = window_start(k, flying_->start_window, false);
  std::array<double, 2> output{}, rate{}, error{};
  for (size_t j = j0; j <= k; ++j) {
    double q[4];
    runtime::unbias_attitude(&S[j].x[kAttitude], e_.roll, e_.pitch, q);
    const auto angle = runtime::euler_zyx(q[0], q[1], q[2], q[3]);
    const auto out = flying_->mixer.outputs_in(S[j].u.data(), o.counts_per_command);
    for (int a = 0; a < 2; ++a) {
      output[a] += out[a] / o.output_scale;
      rate[a] += S[j].x[kBodyRate + a];
      error[a] += S[j].attitude_ref[a] - angle[a];
    }
  }
  const double n = static_cast<double>(k - j0 + 1);
  for (int a = 0; a < 2; ++a) output[a] /= n, rate[a] /= n, error[a] /= n;
  pid_ = runtime::AttitudePid(o);
  pid_.start(roll_and_pitch(x), {x[kBodyRate], x[kBodyRate + 1]}, output, rate, error);
  flight_start_ = S[k].t;
  updates_ = 0;
  flown_.clear();
}

// The controller's steps due by time t (on its 500 Hz grid from the rollout's first sample),
// on the state at t and the set points logged at or before t. Each output is stamped with t,
// the time of the state it used: the integration steps (at most one period) need not fall on
// the grid.
void Rollout::update_controller(double t, const std::vector<double>& x) {
  if (flight_start_ + static_cast<double>(updates_) * pid_.period() > t + 1e-9) return;
  while (flight_start_ + static_cast<double>(updates_) * pid_.period() <= t + 1e-9) ++updates_;
  const auto& s = f_.samples[held_sample(f_, t)];
  const auto out = pid_.update(roll_and_pitch(x), {x[kBodyRate], x[kBodyRate + 1]}, {s.attitude_ref[0], s.attitude_ref[1]});
  flown_.push_back({t, out[0], out[1]});
}

bool Rollout::advance(std::vector<double>& x, size_t k, Replay replay) {
  const double t0 = f_.samples[k].t, t1 = f_.samples[k + 1].t;
  const int steps = std::max(1, static_cast<int>(std::ceil((t1 - t0) / step_ - 1e-9)));
  const double h = (t1 - t0) / steps;
  for (int i = 0; i < steps; ++i) {
    const double t = t0 + i * h;
    if (replay == Replay::kSetPoints) update_controller(t, x);
    deriv(t, x, k, replay, k1_);
    stage(x, k1_, h / 2);
    deriv(t + h / 2, tmp_, k, replay, k2_);
    stage(x, k2_, h / 2);
    deriv(t + h / 2, tmp_, k, replay, k3_);
    stage(x, k3_, h);
    deriv(t + h, tmp_, k, replay, k4_);
    for (int j = 0; j < n_; ++j) x[j] += h / 6 * (k1_[j] + 2 * k2_[j] + 2 * k3_[j] + k4_[j]);
    runtime::normalize_quaternion(&x[kAttitude]);  // after full steps only, in every view alike
    impose(replay, t + h, k, x);
  }
  for (double v : x)
    if (!std::isfinite(v) || std::fabs(v) > kDivergenceBound) return false;
  return true;
}

// An imposed attitude is a unit quaternion; an integrated one is left as the RK4 stage made
// it, as in the open loop.
void Rollout::impose(Replay replay, double t, size_t k, std::vector<double>& x) const {
  switch (replay) {  // no default: a new view must say here what it imposes (-Wswitch)
    case Replay::kAttitude: impose_attitude(t, k, x); break;
    case Replay::kTranslation: impose_translation(t, k, x); break;
    case Replay::kNothing: case Replay::kSetPoints: case Replay::kBodyRatesHeld: case Replay::kAttitudeHeld: break;
  }
}

// The logged position and velocity at time t in [t_k, t_k+1], interpolated.
void Rollout::impose_translation(double t, size_t k, std::vector<double>& x) const {
  const auto& a = f_.samples[k];
  const auto& b = f_.samples[std::min(k + 1, f_.samples.size() - 1)];
  const double w = weight(a, b, t);
  for (int first : {kPosition, kVelocity})
    for (int i = first; i < first + 3; ++i) x[i] = (1 - w) * a.x[i] + w * b.x[i];
}

// The logged attitude (unbiased) and body rates at time t in [t_k, t_k+1], interpolated.
void Rollout::impose_attitude(double t, size_t k, std::vector<double>& x) const {
  const auto& a = f_.samples[k];
  const auto& b = f_.samples[std::min(k + 1, f_.samples.size() - 1)];
  const double w = weight(a, b, t);
  double qa[4], qb[4];
  runtime::unbias_attitude(&a.x[kAttitude], e_.roll, e_.pitch, qa);
  runtime::unbias_attitude(&b.x[kAttitude], e_.roll, e_.pitch, qb);
  const double sign = qa[0] * qb[0] + qa[1] * qb[1] + qa[2] * qb[2] + qa[3] * qb[3] < 0 ? -1.0 : 1.0;
  for (int i = 0; i < 4; ++i) x[kAttitude + i] = (1 - w) * qa[i] + w * sign * qb[i];
  runtime::normalize_quaternion(&x[kAttitude]);
  for (int i = kBodyRate; i < kBodyRate + 3; ++i) x[i] = (1 - w) * a.x[i] + w * b.x[i];
}

void Rollout::inputs(double t, Replay replay, double* u) const {
  const auto& s = f_.samples[command_sample(f_, t, e_.delay, first_command_)];
  std::copy(s.u.begin(), s.u.end(), u);
  if (replay == Replay::kSetPoints) replace_roll_and_pitch(t, u);
  extra_.fill(t, f_.samples[held_sample(f_, t)].vbat, u);
}

// The logged commands' roll and pitch parts replaced by the controller's output of the
// latest step at or before t - delay (a step's own time counts, as command_sample's does);
// before the first, the logged commands act unchanged.
void Rollout::replace_roll_and_pitch(double t, double* u) const {
  const double acting = t - e_.delay + 1e-9;
  const auto after = std::upper_bound(flown_.begin(), flown_.end(), acting,
                                      [](double v, const std::array<double, 3>& f) { return v < f[0]; });
  if (after == flown_.begin()) return;
  const std::array<double, 3>& out = *(after - 1);
  const auto& mix = flying_->mixer;
  const double counts = flying_->pid.counts_per_command;
  const double scale = flying_->pid.output_scale;
  const auto logged = mix.outputs_in(u, counts);
  for (size_t i = 0; i < mix.roll.size(); ++i)
    u[i] = std::clamp(u[i] + (mix.roll[i] * (scale * out[1] - logged[0]) + mix.pitch[i] * (scale * out[2] - logged[1])) / counts,
                      0.0, 1.0);
}

void Rollout::deriv(double t, const std::vector<double>& x, size_t k, Replay replay, std::vector<double>& f) {
  const std::vector<double>* state = &x;
  if (imposes_from_log(replay)) {
    forced_ = x;
    impose(replay, t, k, forced_);
    state = &forced_;
  }
  inputs(t, replay, u_.data());
  m_.rhs(state->data(), u_.data(), f.data(), nullptr, nullptr, nullptr);
  for (int a = 0; a < 3; ++a) f[kVelocity + a] += held_[a], f[kBodyRate + a] += held_[3 + a];
  // The reduced predictors: no angular acceleration (the body rates stay the start's), and
  // for kAttitudeHeld no turning either.
  if (holds_body_rates(replay))
    for (int a = 0; a < 3; ++a) f[kBodyRate + a] = 0;
  if (holds_attitude(replay))
    for (int a = 0; a < 4; ++a) f[kAttitude + a] = 0;
}

std::array<double, 6> Rollout::past_disturbance(size_t k, double window) {
  const auto& S = f_.samples;
  if (model_acc_.empty()) {  // once per flight: the model at every logged state
    const runtime::DataSideEffects saved = e_;
    const size_t saved_first = first_command_;
    std::vector<double> f(n_);
    model_acc_.resize(S.size());
    for (size_t j = 0; j < S.size(); ++j) {
      const std::vector<double> x = start_at(j, Replay::kNothing).state;
      inputs(S[j].t, Replay::kNothing, u_.data());
      m_.rhs(x.data(), u_.data(), f.data(), nullptr, nullptr, nullptr);
      for (int a = 0; a < 3; ++a) model_acc_[j][a] = f[kVelocity + a], model_acc_[j][3 + a] = f[kBodyRate + a];
    }
    e_ = saved, first_command_ = saved_first;
  }
  // The window stays within the sample's stretch and after the rotor speeds are known: just
  // after a restart the states carry the steady-state guess, and the model's accelerations
  // there would be part of the residual.
  const size_t j0 = window_start(k, window, true);
  std::array<double, 6> d{};
  const double span = S[k].t - S[j0].t;
  if (j0 == k || !(span >= 0.5 * window)) return d;
  std::array<double, 6> model_integral{};
  for (size_t j = j0; j < k; ++j)
    for (int c = 0; c < 6; ++c) model_integral[c] += 0.5 * (S[j + 1].t - S[j].t) * (model_acc_[j][c] + model_acc_[j + 1][c]);
  for (int a = 0; a < 3; ++a) {
    d[a] = (S[k].x[kVelocity + a] - S[j0].x[kVelocity + a] - model_integral[a]) / span;
    d[3 + a] = (S[k].x[kBodyRate + a] - S[j0].x[kBodyRate + a] - model_integral[3 + a]) / span;
  }
  return d;
}

size_t Rollout::window_start(size_t k, double window, bool settled_only) const {
  const auto& S = f_.samples;
  const size_t first = start_.stretch_starts()[k];
  size_t j0 = k;
  while (j0 > first && (!settled_only || start_.settled(j0 - 1)) && S[k].t - S[j0 - 1].t <= window + 1e-9) --j0;
  return j0;
}

void Rollout::stage(const std::vector<double>& x, const std::vector<double>& k, double h) {
  for (int j = 0; j < n_; ++j) tmp_[j] = x[j] + h * k[j];
}

StateError state_error(const std::vector<double>& x, const fit::FlightSample& s, const runtime::DataSideEffects& e,
                       bool tilt_and_heading) {
  constexpr double kPi = 3.14159265358979323846;
  StateError out;
  for (int a = 0; a < 3; ++a) {
    out.position_squared += std::pow(x[kPosition + a] - s.x[kPosition + a], 2);
    out.velocity_squared += std::pow(x[kVelocity + a] - s.x[kVelocity + a], 2);
    out.body_rates_squared += std::pow(x[kBodyRate + a] - s.x[kBodyRate + a], 2);
  }
  double q[4];
  runtime::unbias_attitude(&s.x[kAttitude], e.roll, e.pitch, q);
  const double* xq = &x[kAttitude];
  const double dot = std::abs(xq[0] * q[0] + xq[1] * q[1] + xq[2] * q[2] + xq[3] * q[3]);
  out.angle = 2 * std::acos(std::min(1.0, dot));
  if (!tilt_and_heading) return out;
  const runtime::Rotation rs = runtime::rotation_matrix(xq), rm = runtime::rotation_matrix(q);
  double zz = 0;
  for (int a = 0; a < 3; ++a) zz += rs.m[a][2] * rm.m[a][2];
  out.tilt = std::acos(std::clamp(zz, -1.0, 1.0));
  const auto heading_of = [](const runtime::Rotation& r) { return std::atan2(r.m[1][0], r.m[0][0]); };
  out.heading = std::fabs(std::fmod(heading_of(rs) - heading_of(rm) + 3 * kPi, 2 * kPi) - kPi);
  return out;
}

}  // namespace quadgen::predict
