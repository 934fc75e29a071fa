#include "fit/equation_error.hpp"

#include "fit/evaluation_threads.hpp"
#include "runtime/attitude.hpp"
#include "runtime/rigid_body_state.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <sstream>
#include <utility>

#include <Eigen/Dense>

#include "output/joined.hpp"
#include "output/nearest_word.hpp"
#include "output/sinks.hpp"

namespace quadgen::fit {

using namespace runtime::rigid_body;

EquationErrorModel::EquationErrorModel(runtime::DynamicModel& model, Flight flight, bool use_accelerometer,
                                       std::vector<std::string> use, Derivatives d, double window)
    : model_(&model), flight_(std::move(flight)), accel_(use_accelerometer), g_index_(model.param_index("g")),
      data_side_(model), extra_(model), derivatives_(d) {
  const auto names = channel_names();
  if (use.empty()) use = names;
  for (const auto& u : use) {
    const int c = runtime::index_in(names, u);
    if (c < 0) {
      throw FitError("unknown residual channel '" + output::printable(u) + "' (channels: " + output::joined(names) + ")" +
                     output::did_you_mean(u, names));
    }
    used_.push_back(c);
  }
  speed_states_ = model.rotor_speed_states();
  for (int i = kNumStates; i < model.num_states(); ++i) {
    const bool filtered = std::find(speed_states_.begin(), speed_states_.end(), i) != speed_states_.end();
    if (data_side_.tau < 0 || !filtered)
      throw FitError("equation error needs every state measured or filtered from the commands; this model has state " +
                     model.state_names()[i]);
  }
  if (!flight_.samples.empty() && speed_states_.size() > flight_.samples.front().u.size())
    throw FitError("more rotor-speed states than logged commands");
  if (accel_ && !flight_.has_accelerometer) throw FitError(flight_.source + ": no accelerometer columns ax, ay, az");
  if (!accel_ && !flight_.has_pose) throw FitError(flight_.source + ": no pose to differentiate");
  mark_contiguous_intervals();
  find_data_side_columns();
  if (derivatives_ == Derivatives::kPointwise) {
    for (size_t k = 0; k < flight_.samples.size(); ++k) rows_.push_back(k);
  } else {
    build_filter(window);
    if (rows_.empty()) {
      std::ostringstream os;  // most often a time unit: samples 10 s apart read as ms
      const auto& S = flight_.samples;
      os << flight_.source << ": no stretch of the log is long enough for the derivative window of " << window
         << " s (its samples are " << (S.size() > 1 ? (S.back().t - S.front().t) / static_cast<double>(S.size() - 1) : 0.0)
         << " s apart on average, over " << (S.empty() ? 0.0 : S.back().t - S.front().t)
         << " s: is t in seconds, and a --resample rate, where one is given, high enough?)";
      throw FitError(os.str());
    }
  }
}

// An interval longer than 1.5 median sample spacings is a gap (trimmed ground contact, the
// second of several joined flights): nothing is integrated or differentiated across it.
void EquationErrorModel::mark_contiguous_intervals() {
  const auto& S = flight_.samples;
  const size_t ns = S.size();
  if (ns < 2) return;
  std::vector<double> times;
  for (const auto& s : S) times.push_back(s.t);
  gap_ = runtime::gap_threshold(times);
  interval_ok_.assign(ns, false);
  rotors_restart_.assign(ns, true);
  for (size_t k = 0; k + 1 < ns; ++k) {
    interval_ok_[k] = S[k + 1].t - S[k].t <= gap_;
    rotors_restart_[k] = S[k + 1].t - S[k].t > runtime::kRotorRestartGap;
  }
}

// Each column of a data-side parameter, and the stretches of the log it acts on: from its
// first to its last sample, widened to whole contiguous stretches (the rotor speeds are
// filtered along a stretch, and no derivative window crosses a gap).
void EquationErrorModel::find_data_side_columns() {
  const auto& S = flight_.samples;
  std::map<int, SampleSpan> spans;
  const auto reach = [&](int c, size_t k) {
    auto [it, fresh] = spans.try_emplace(c, SampleSpan{k, k + 1});
    if (!fresh) it->second.lo = std::min(it->second.lo, k), it->second.hi = std::max(it->second.hi, k + 1);
  };
  for (int index : data_side_.indices()) {
    if (index < 0) continue;
    for (size_t k = 0; k < S.size(); ++k) reach(model_->param_column(index, S[k].t), k);
  }
  for (const auto& [c, k] : commanded_speed_columns()) reach(c, k);
  for (auto [c, span] : spans) {
    while (span.lo > 0 && !rotors_restart_.empty() && !rotors_restart_[span.lo - 1]) --span.lo;
    while (span.hi < S.size() && !rotors_restart_.empty() && !rotors_restart_[span.hi - 1]) ++span.hi;
    data_side_columns_.push_back(c);
    data_side_spans_.push_back(span);
  }
}

// Under a motor lag the rotor speeds are filtered on the data side (prepare()), so the model's
// analytic df/dp cannot see a parameter that shapes the commanded speed (the motor map
// a0..a2): its column would be zero and a fit would leave it where it started. Such a
// parameter is found by where the speed states' derivative at zero speed (tau times the
// commanded speed) depends on it, and is differentiated through the filter like the
// data-side effects (only when it is free, as they are). Returns (column, sample) for
// every sample at which a column acts.
std::vector<std::pair<int, size_t>> EquationErrorModel::commanded_speed_columns() const {
  std::vector<std::pair<int, size_t>> out;
  if (speed_states_.empty()) return out;
  const int n = model_->num_states(), nu = model_->num_inputs(), np = model_->num_params();
  std::vector<bool> data_side(np, false);
  for (int c : data_side_.indices())
    if (c >= 0) data_side[c] = true;
  std::vector<double> x(n), u(nu, 0.0), f(n), B(static_cast<size_t>(n) * np);
  model_->restrict_param_jacobian({});
  for (size_t k = 0; k < flight_.samples.size(); ++k) {
    const FlightSample& s = flight_.samples[k];
    std::copy(s.x.begin(), s.x.end(), x.begin());
    for (int i : speed_states_) x[i] = 0;
    inputs_at(s, s.t, u.data());
    model_->rhs(x.data(), u.data(), f.data(), nullptr, B.data(), nullptr);
    for (int c = 0; c < np; ++c) {
      if (data_side[c]) continue;  // already differentiated on the data side
      for (int i : speed_states_)
        if (B[static_cast<size_t>(i) * np + c] != 0.0) {
          out.emplace_back(c, k);
          break;
        }
    }
  }
  return out;
}

// Savitzky-Golay derivative weights c_i (local quadratic over +-window), and the weights
// of the interval accelerations that give the same derivative of a signal whose rate is
// those accelerations: y_i - y_k is the sum of (t_{j+1} - t_j) a_{j+1/2} over the
// intervals in between, so interval j carries (t_{j+1} - t_j) * sum_{i > j} c_i.
void EquationErrorModel::build_filter(double window) {
  const auto& S = flight_.samples;
  const size_t ns = S.size();
  if (interval_ok_.empty()) return;
  const double gap = gap_;
  for (size_t k = 0; k < ns; ++k) {
    size_t lo = k, hi = k;
    while (lo > 0 && interval_ok_[lo - 1] && S[k].t - S[lo - 1].t <= window + 1e-9) --lo;
    while (hi + 1 < ns && interval_ok_[hi] && S[hi + 1].t - S[k].t <= window + 1e-9) ++hi;
    // A full window on both sides (one sample of slack for uneven sampling).
    if (lo == k || hi == k || S[k].t - S[lo].t < window - gap || S[hi].t - S[k].t < window - gap) continue;
    const size_t m = hi - lo + 1;
    if (m < 5) continue;
    Eigen::MatrixXd A(m, 3);
    for (size_t i = 0; i < m; ++i) {
      const double dt = S[lo + i].t - S[k].t;
      A.row(i) << 1, dt, dt * dt;
    }
    const Eigen::MatrixXd P = (A.transpose() * A).ldlt().solve(A.transpose());  // 3 x m
    std::vector<double> c(m), W(m - 1);
    for (size_t i = 0; i < m; ++i) c[i] = P(1, i);
    double tail = 0;
    for (size_t j = m - 1; j-- > 0;) {
      tail += c[j + 1];
      W[j] = (S[lo + j + 1].t - S[lo + j].t) * tail;
    }
    std::array<double, 6> meas{};
    for (int a = 0; a < 3; ++a)
      for (size_t i = 0; i < m; ++i) {
        meas[a] += c[i] * S[lo + i].x[3 + a];
        meas[3 + a] += c[i] * S[lo + i].x[10 + a];
      }
    rows_.push_back(k);
    window_start_.push_back(lo);
    interval_weights_.push_back(std::move(W));
    measured_.push_back(meas);
  }
}

// The same names whichever frame the acceleration is in (fit.json's channels).
std::vector<std::string> EquationErrorModel::channel_names() {
  return {std::begin(kResidualChannels), std::end(kResidualChannels)};
}

std::vector<std::string> EquationErrorModel::channels() const {
  const auto names = channel_names();
  std::vector<std::string> out;
  for (int c : used_) out.push_back(names[c]);
  return out;
}

void EquationErrorModel::evaluate_free(const double* p, double* r, double* J, const std::vector<bool>& free) const {
  if (J) model_->restrict_param_jacobian(runtime::free_columns(free));
  const int np = model_->num_params();
  const std::vector<int> columns = runtime::jacobian_columns(free, np);
  if (!J || columns.empty()) return evaluate_packed(p, r, nullptr, columns);
  const size_t nr = static_cast<size_t>(num_residuals()), nc = columns.size();
  std::vector<double>& packed = scratch_.packed;
  packed.resize(nr * nc);
  evaluate_packed(p, r, packed.data(), columns);
  for (size_t i = 0; i < nr; ++i)
    for (size_t k = 0; k < nc; ++k) J[i * np + columns[k]] = packed[i * nc + k];
}

void EquationErrorModel::evaluate_columns(const std::vector<double>& p, double* r, double* J,
                                          const std::vector<int>& columns) const {
  check_columns(columns, static_cast<size_t>(model_->num_params()));
  if (columns.empty()) J = nullptr;  // r alone
  if (J) model_->restrict_param_jacobian(columns);
  evaluate_packed(p.data(), r, J, columns);
}

void EquationErrorModel::evaluate_packed(const double* p, double* r, double* J, const std::vector<int>& columns) const {
  if (used_.size() == 6) return evaluate6(p, r, J, columns);
  const size_t ns = rows_.size(), nc = columns.size(), nu = used_.size();
  std::vector<double>& r6 = scratch_.r6;
  std::vector<double>& J6 = scratch_.J6;
  r6.resize(ns * 6);  // evaluate6 writes every entry
  J6.resize(J ? ns * 6 * nc : 0);
  evaluate6(p, r6.data(), J ? J6.data() : nullptr, columns);
  for (size_t k = 0; k < ns; ++k)
    for (size_t c = 0; c < nu; ++c) {
      r[k * nu + c] = r6[k * 6 + used_[c]];
      if (J)
        for (size_t q = 0; q < nc; ++q) J[(k * nu + c) * nc + q] = J6[(k * 6 + used_[c]) * nc + q];
    }
}

void EquationErrorModel::all_channels(const double* p, std::vector<double>& r6) const {
  r6.resize(rows_.size() * 6);
  evaluate6(p, r6.data(), nullptr, {});
}

std::vector<double> EquationErrorModel::all_channels(const std::vector<FitParameter>& ps) const {
  const auto p = parameter_values(ps);
  std::vector<double> r6;
  all_channels(p.data(), r6);
  return r6;
}

std::vector<double> EquationErrorModel::measured_channels() const {
  std::vector<double> m(rows_.size() * 6);
  const bool filtered = derivatives_ == Derivatives::kFiltered;
  for (size_t row = 0; row < rows_.size(); ++row) {
    const FlightSample& sample = flight_.samples[rows_[row]];
    for (int c = 0; c < 3; ++c) {
      m[row * 6 + c] = accel_ ? sample.specific_force[c] : filtered ? measured_[row][c] : sample.acc_world[c];
      m[row * 6 + 3 + c] = filtered ? measured_[row][3 + c] : sample.rate_dot[c];
    }
  }
  return m;
}

void EquationErrorModel::inputs_at(const FlightSample& s, double command_time, double* u, size_t* cursor) const {
  commands_at(command_time, u, cursor);
  extra_.fill(s.t, s.vbat, u);
}

std::vector<FlightSample>::const_iterator first_at_or_after(const std::vector<FlightSample>& S, double t,
                                                            size_t* cursor) {
  const auto before = [](const FlightSample& s, double v) { return s.t < v; };
  auto it = S.begin();
  bool found = false;
  if (cursor && *cursor <= S.size() && (*cursor == 0 || S[*cursor - 1].t < t)) {
    it += static_cast<std::ptrdiff_t>(*cursor);
    for (int step = 0; step < 4 && !found; ++step) {
      found = it == S.end() || !(it->t < t);
      if (!found) ++it;
    }
  }
  if (!found) it = std::lower_bound(it, S.end(), t, before);
  if (cursor) *cursor = static_cast<size_t>(it - S.begin());
  return it;
}

void EquationErrorModel::commands_at(double t, double* u, size_t* cursor) const {
  const auto& S = flight_.samples;
  const auto it = first_at_or_after(S, t, cursor);
  if (it == S.begin() || it == S.end()) {
    const FlightSample& s = it == S.end() ? S.back() : S.front();
    std::copy(s.u.begin(), s.u.end(), u);
    return;
  }
  // A delayed lookup that falls into a gap (before the start of the sample's stretch, the
  // previous joined flight's end) holds the stretch's first command instead of blending in
  // commands from across the gap.
  const size_t after = static_cast<size_t>(it - S.begin());
  if (!interval_ok_.empty() && !interval_ok_[after - 1]) {
    std::copy(it->u.begin(), it->u.end(), u);
    return;
  }
  const FlightSample &b = *it, &a = *(it - 1);
  const double w = (t - a.t) / (b.t - a.t);
  for (size_t i = 0; i < a.u.size(); ++i) u[i] = a.u[i] + w * (b.u[i] - a.u[i]);
}

void EquationErrorModel::prepare(const double* p, std::vector<double>& X, std::vector<double>& U,
                                 SampleSpan span) const {
  const int n = model_->num_states(), nu = model_->num_inputs();
  const size_t ns = flight_.samples.size();
  X.assign(ns * n, 0.0);
  U.assign(ns * nu, 0.0);
  // The data-side values in effect at each sample (one per flight in a per-flight model);
  // each rotor's lag is kept for the rotor-speed filter below.
  const size_t nr = speed_states_.size();
  std::vector<double>& tau = scratch_.tau;
  tau.assign(ns * nr, 0.0);
  // The attitude bias is one pair of angles per flight: its rotation is recomputed only when
  // their bits change (-0 and +0 kept apart, so results stay bit for bit).
  bool have_bias = false;
  double bias_roll = 0, bias_pitch = 0, conj_q_bias[4] = {1, 0, 0, 0};
  size_t command_cursor = 0;
  for (size_t k = span.lo; k < span.hi; ++k) {
    const FlightSample& s = flight_.samples[k];
    const runtime::DataSideEffects e = data_side_.at(*model_, p, s.t);
    for (size_t i = 0; i < nr; ++i) tau[k * nr + i] = data_side_.rotor_tau(*model_, p, s.t, i, e.tau);
    double* x = &X[k * n];
    double* u = &U[k * nu];
    std::copy(s.x.begin(), s.x.end(), x);
    if (!have_bias || std::memcmp(&e.roll, &bias_roll, sizeof(double)) != 0 ||
        std::memcmp(&e.pitch, &bias_pitch, sizeof(double)) != 0) {
      have_bias = true, bias_roll = e.roll, bias_pitch = e.pitch;
      runtime::attitude_bias_conjugate(bias_roll, bias_pitch, conj_q_bias);
    }
    runtime::quaternion_product(&s.x[kAttitude], conj_q_bias, x + kAttitude);
    // The commands logged at t_k - d act now (held until the next sample; between
    // samples the linear interpolation is their average over the interval).
    inputs_at(s, s.t - e.delay, u, &command_cursor);
  }
  if (!speed_states_.empty()) filter_rotor_speeds(X, U, span);
}

void EquationErrorModel::filter_rotor_speeds(std::vector<double>& X, const std::vector<double>& U, SampleSpan span) const {
  const int n = model_->num_states(), nu = model_->num_inputs();
  const size_t ns = flight_.samples.size(), nr = speed_states_.size();
  const std::vector<double>& tau = scratch_.tau;
  // Rotor speeds: the commanded speed (the model's dw/dt at w = 0, times tau) through the
  // first-order lag, started in steady state; the commands are held between samples, for
  // which the discretisation is exact. The mean over each interval (what its mid-interval
  // acceleration sees) goes to scratch_.mean_speed; as tau -> 0 it is the held command's speed.
  scratch_.mean_speed.assign(ns * nr, 0.0);
  std::vector<double> f(n), c(nr), w_now(nr);
  for (size_t k = span.lo; k < span.hi; ++k) {
    double* x = &X[k * n];
    // After a long gap the rotors restart in steady state with the commands, as at the start
    // (a span starts at such a gap or at the log's start); across a short one they are
    // carried with the last command held (see runtime::kRotorRestartGap).
    const bool restart = k == span.lo || !rotors_continue(k);
    if (!restart) {
      const double h = flight_.samples[k].t - flight_.samples[k - 1].t;
      for (size_t i = 0; i < nr; ++i) {
        // exp of less than -700 is 0 in a double; libm's underflow path for it (a lag of 1 us,
        // the "no lag" of the search, over a 10 ms interval) costs more than the rest of the filter.
        const double t_i = tau[k * nr + i], a = h > 700 * t_i ? 0.0 : std::exp(-h / t_i);
        const double w0 = X[(k - 1) * n + speed_states_[i]];
        x[speed_states_[i]] = a * w0 + (1 - a) * c[i];
        scratch_.mean_speed[(k - 1) * nr + i] = c[i] + (w0 - c[i]) * t_i / h * (1 - a);
      }
    }
    // dw/dt = (w_cmd - w) / tau, so at w = 0 it gives the commanded speed.
    for (size_t i = 0; i < nr; ++i) w_now[i] = x[speed_states_[i]], x[speed_states_[i]] = 0;
    model_->rhs_rows(x, &U[k * nu], speed_states_, f.data());
    for (size_t i = 0; i < nr; ++i) {
      c[i] = tau[k * nr + i] * f[speed_states_[i]];
      x[speed_states_[i]] = restart ? c[i] : w_now[i];
    }
  }
}

void EquationErrorModel::evaluate6(const double* p, double* r, double* J, const std::vector<int>& columns) const {
  const int np = model_->num_params();
  residuals(p, r, J, all_samples(), columns);
  if (!J) return;
  // Columns of the parameters applied to the data: central differences over the rows each
  // column can change (zero elsewhere).
  const size_t nc = columns.size();
  std::vector<double> pp(p, p + np), rp, rm;
  for (size_t d = 0; d < data_side_columns_.size(); ++d) {
    const int c = data_side_columns_[d];
    const auto at = std::find(columns.begin(), columns.end(), c);
    if (at == columns.end()) continue;
    const size_t q = static_cast<size_t>(at - columns.begin());
    const auto [row_lo, row_hi] = rows_in(data_side_spans_[d]);
    rp.resize((row_hi - row_lo) * 6);
    rm.resize(rp.size());
    const double h = 1e-6 * std::max(std::abs(p[c]), 1e-2);
    pp[c] = p[c] + h;
    residuals(pp.data(), rp.data(), nullptr, data_side_spans_[d], {});
    pp[c] = p[c] - h;
    residuals(pp.data(), rm.data(), nullptr, data_side_spans_[d], {});
    pp[c] = p[c];
    for (size_t i = 0; i < rows_.size() * 6; ++i) J[i * nc + q] = 0.0;
    for (size_t i = 0; i < rp.size(); ++i) J[(row_lo * 6 + i) * nc + q] = (rp[i] - rm[i]) / (2 * h);
  }
  model_->set_params(pp);
}

std::pair<size_t, size_t> EquationErrorModel::rows_in(SampleSpan span) const {
  const auto lo = std::lower_bound(rows_.begin(), rows_.end(), span.lo);
  const auto hi = std::lower_bound(lo, rows_.end(), span.hi);
  return {static_cast<size_t>(lo - rows_.begin()), static_cast<size_t>(hi - rows_.begin())};
}

template <class Part>
void EquationErrorModel::split_over_cores(size_t lo, size_t hi, const double* p, const std::vector<int>* columns,
                                          const Part& part) const {
  const size_t parts = hi > lo ? evaluation_parts(hi - lo) : 1;
  auto& helpers = helpers_.list;
  while (helpers.size() + 1 < parts) {
    Helper h;
    h.model = model_->clone();
    if (!h.model) break;  // a model that cannot be copied stays on one thread
    helpers.push_back(std::move(h));
  }
  const size_t n = std::min(parts, helpers.size() + 1);
  helpers_.last_parts = n;
  if (n <= 1) return part(*model_, lo, hi);
  const std::vector<double> params(p, p + model_->num_params());
  for (size_t i = 0; i + 1 < n; ++i) {  // before any thread starts: these may throw
    Helper& h = helpers[i];
    if (h.params != params) h.model->set_params(params), h.params = params;
    if (columns && h.columns != *columns) h.model->restrict_param_jacobian(*columns), h.columns = *columns;
  }
  const auto bound = [&](size_t i) { return lo + (hi - lo) * i / n; };
  run_workers(n, [&](size_t i, const std::atomic<bool>&) {
    part(i == 0 ? *model_ : *helpers[i - 1].model, bound(i), bound(i + 1));
  });
}

// Model accelerations (rows 3..5 and 10..12 of f, and of df/dp) at the middle of every
// interval k -> k+1: state averaged, the commands of t_k held over it.
void EquationErrorModel::interval_accelerations(const double* p, const std::vector<double>& X,
                                                const std::vector<double>& U, std::vector<double>& F,
                                                std::vector<double>* Bm, SampleSpan span,
                                                const std::vector<int>& columns) const {
  const int n = model_->num_states(), nu = model_->num_inputs();
  const int t_in = extra_.t, v_in = extra_.vbat;
  const size_t ns = flight_.samples.size(), nc = columns.size();
  F.assign(ns * 6, 0.0);
  // Only the columns asked for, packed: a search step frees a few of a per-flight model's
  // 45 and more parameters, and the window sums (window_sums()) then run over contiguous memory.
  if (Bm) Bm->assign(ns * 6 * nc, 0.0);
  // The residual rows: linear acceleration (world) and angular acceleration (body).
  static const int kRows[6] = {kVelocity, kVelocity + 1, kVelocity + 2, kBodyRate, kBodyRate + 1, kBodyRate + 2};
  // Their df/dp in the columns asked for, straight from the model (a helper thread's copy
  // of it reads the same block).
  const runtime::DynamicModel::ParamBlock block =
      Bm ? model_->param_block(std::vector<int>(kRows, kRows + 6), columns) : runtime::DynamicModel::ParamBlock{};
  // Intervals k_lo .. k_hi - 1; each writes its own rows of F and Bm only.
  const auto part = [&](const runtime::DynamicModel& model, size_t k_lo, size_t k_hi) {
    std::vector<double> xm(n), um(nu), f(n), B(Bm ? 6 * nc : 0);
    for (size_t k = k_lo; k < k_hi; ++k) {
      if (!interval_ok_[k]) continue;
      for (int i = 0; i < n; ++i) xm[i] = 0.5 * (X[k * n + i] + X[(k + 1) * n + i]);
      runtime::normalize_quaternion(&xm[kAttitude]);
      for (size_t i = 0; i < speed_states_.size(); ++i) xm[speed_states_[i]] = scratch_.mean_speed[k * speed_states_.size() + i];
      std::copy(&U[k * nu], &U[k * nu] + nu, um.begin());
      if (t_in >= 0) um[t_in] = 0.5 * (U[k * nu + t_in] + U[(k + 1) * nu + t_in]);
      if (v_in >= 0) um[v_in] = 0.5 * (U[k * nu + v_in] + U[(k + 1) * nu + v_in]);
      if (quadrature_ == Quadrature::kMidpoint) {
        if (Bm)
          model.rhs_block(xm.data(), um.data(), f.data(), block, &(*Bm)[k * 6 * nc]);
        else
          model.rhs(xm.data(), um.data(), f.data(), nullptr, nullptr, nullptr);
        for (int c = 0; c < 6; ++c) F[k * 6 + c] = f[kRows[c]];
        continue;
      }
      // Trapezoid: the rigid-body state at both ends, the held command and the interval's
      // mean rotor speeds (a rotor speed at the switching instant belongs to neither side).
      for (size_t end = k; end <= k + 1; ++end) {
        std::vector<double> xe(&X[end * n], &X[end * n] + n);
        for (size_t i = 0; i < speed_states_.size(); ++i) xe[speed_states_[i]] = xm[speed_states_[i]];
        if (Bm)
          model.rhs_block(xe.data(), um.data(), f.data(), block, B.data());
        else
          model.rhs(xe.data(), um.data(), f.data(), nullptr, nullptr, nullptr);
        for (int c = 0; c < 6; ++c) {
          F[k * 6 + c] += 0.5 * f[kRows[c]];
          if (Bm)
            for (size_t qi = 0; qi < nc; ++qi) (*Bm)[(k * 6 + c) * nc + qi] += 0.5 * B[c * nc + qi];
        }
      }
    }
  };
  if (span.hi > span.lo + 1) split_over_cores(span.lo, span.hi - 1, p, Bm ? &columns : nullptr, part);
}

void EquationErrorModel::residuals(const double* p, double* r, double* J, SampleSpan span,
                                   const std::vector<int>& columns) const {
  const int n = model_->num_states(), np = model_->num_params();
  model_->set_params(std::vector<double>(p, p + np));
  std::vector<double>& X = scratch_.X;
  std::vector<double>& U = scratch_.U;
  prepare(p, X, U, span);
  std::vector<double>& F = scratch_.F;
  std::vector<double>& Bm = scratch_.Bm;
  if (derivatives_ == Derivatives::kFiltered) interval_accelerations(p, X, U, F, J ? &Bm : nullptr, span, columns);
  const Evaluation e{p, X, U, F, Bm, columns, J != nullptr};
  const auto rows = rows_in(span);  // not a structured binding: C++17 lambdas cannot capture one
  const size_t row_lo = rows.first, row_hi = rows.second;
  // Rows from_row .. to_row - 1; each writes its own rows of r and J only.
  const auto part = [&](const runtime::DynamicModel& model, size_t from_row, size_t to_row) {
    RowScratch s;
    s.f.assign(n, 0.0);
    s.B.assign(J ? n * np : 0, 0.0);
    s.a6.assign(6, 0.0);
    s.Ba6.assign(J ? 6 * columns.size() : 0, 0.0);
    for (size_t row = from_row; row < to_row; ++row) {
      row_accelerations(model, e, row, s);
      row_residuals(e, row, s, r + 6 * (row - row_lo), J ? J + 6 * (row - row_lo) * columns.size() : nullptr);
    }
  };
  split_over_cores(row_lo, row_hi, p, J ? &columns : nullptr, part);
}

namespace {

// to[c * nc + q] = sum over j of W[j] * from[(j * 6 + c) * nc + q]: the window sums of the
// interval accelerations' df/dp columns. Four columns at a time are summed in registers;
// added to memory, each sum went out and back once per interval of the window. Every sum
// is still taken in the order of j from 0, so the result is the same to the bit.
void window_sums(const std::vector<double>& W, const double* from, size_t nc, double* to) {
  const size_t stride = 6 * nc;
  for (size_t c = 0; c < 6; ++c) {
    const double* b = from + c * nc;
    size_t q = 0;
    for (; q + 4 <= nc; q += 4) {
      double a0 = 0, a1 = 0, a2 = 0, a3 = 0;
      for (size_t j = 0; j < W.size(); ++j) {
        const double* x = b + j * stride + q;
        a0 += W[j] * x[0], a1 += W[j] * x[1], a2 += W[j] * x[2], a3 += W[j] * x[3];
      }
      to[c * nc + q] = a0, to[c * nc + q + 1] = a1, to[c * nc + q + 2] = a2, to[c * nc + q + 3] = a3;
    }
    for (; q < nc; ++q) {
      double a = 0;
      for (size_t j = 0; j < W.size(); ++j) a += W[j] * b[j * stride + q];
      to[c * nc + q] = a;
    }
  }
}

}  // namespace

// The model's six accelerations seen by the measurement at this row (and their df/dp
// columns): the filtered derivatives' window sums of the interval accelerations, or the rows
// of f at the sample itself; the measured ones beside them.
void EquationErrorModel::row_accelerations(const runtime::DynamicModel& model, const Evaluation& e, size_t row,
                                           RowScratch& s) const {
  const int n = model_->num_states(), np = model_->num_params(), nu = model_->num_inputs();
  const size_t k = rows_[row], nc = e.columns.size();
  const bool filtered = derivatives_ == Derivatives::kFiltered;
  if (!filtered || accel_)  // the specific force needs f at the sample itself
    model.rhs(&e.X[k * n], &e.U[k * nu], s.f.data(), nullptr, e.jacobian ? s.B.data() : nullptr, nullptr);
  if (filtered) {
    const auto& W = interval_weights_[row];
    const size_t lo = window_start_[row];
    // Summed in a local array: through s.a6 every addition went to memory and back, as the
    // compiler cannot rule out that it overlaps e.F (a seventh of a diagnosis' time).
    double a6[6] = {0, 0, 0, 0, 0, 0};
    for (size_t j = 0; j < W.size(); ++j)
      for (int c = 0; c < 6; ++c) a6[c] += W[j] * e.F[(lo + j) * 6 + c];
    std::copy(a6, a6 + 6, s.a6.begin());
    if (e.jacobian) window_sums(W, &e.Bm[lo * 6 * nc], nc, s.Ba6.data());
    for (int c = 0; c < 6; ++c) s.measured[c] = measured_[row][c];
    return;
  }
  const FlightSample& sample = flight_.samples[k];
  for (int c = 0; c < 3; ++c) {
    s.a6[c] = s.f[3 + c];
    s.a6[3 + c] = s.f[10 + c];
    s.measured[c] = sample.acc_world[c];
    s.measured[3 + c] = sample.rate_dot[c];
    if (!e.jacobian) continue;
    for (size_t qi = 0; qi < nc; ++qi) {
      s.Ba6[c * nc + qi] = s.B[(3 + c) * np + e.columns[qi]];
      s.Ba6[(3 + c) * nc + qi] = s.B[(10 + c) * np + e.columns[qi]];
    }
  }
}

// The row's six residuals at rk (model minus measurement) and, when Jk is given, their
// derivatives in the columns asked for (packed: residual i's column qi at Jk[i * nc + qi]).
// With an accelerometer the translation residual is the specific force in body axes at the
// sample, R^T (a + g e_z), against the measured one.
void EquationErrorModel::row_residuals(const Evaluation& e, size_t row, const RowScratch& s, double* rk,
                                       double* Jk) const {
  const int n = model_->num_states(), np = model_->num_params();
  const size_t k = rows_[row];
  const runtime::Rotation rotation = runtime::rotation_matrix(&e.X[k * n] + 6);  // body -> world, true attitude
  const auto& R = rotation.m;
  const double g = e.p[g_index_];
  for (int i = 0; i < 3; ++i) {
    if (accel_) {
      double sf = 0;
      for (int j = 0; j < 3; ++j) sf += R[j][i] * (s.f[3 + j] + (j == 2 ? g : 0.0));
      rk[i] = sf - flight_.samples[k].specific_force[i];
    } else {
      rk[i] = s.a6[i] - s.measured[i];
    }
    rk[3 + i] = s.a6[3 + i] - s.measured[3 + i];
  }
  if (!Jk) return;
  const size_t nc = e.columns.size();
  for (size_t qi = 0; qi < nc; ++qi) {
    const int c = e.columns[qi];
    for (int i = 0; i < 3; ++i) {
      double d = s.Ba6[i * nc + qi];
      if (accel_) {
        d = 0;
        for (int j = 0; j < 3; ++j) d += R[j][i] * (s.B[(3 + j) * np + c] + (j == 2 && c == g_index_ ? 1.0 : 0.0));
      }
      Jk[i * nc + qi] = d;
      Jk[(3 + i) * nc + qi] = s.Ba6[(3 + i) * nc + qi];
    }
  }
}

}  // namespace quadgen::fit

namespace quadgen::fit {

std::unique_ptr<ResidualModel> EquationErrorModel::clone() const {
  std::shared_ptr<runtime::DynamicModel> own = model_->clone();
  if (!own) return nullptr;
  auto copy = std::make_unique<EquationErrorModel>(*this);
  copy->owned_model_ = own;
  copy->model_ = own.get();
  return copy;
}

}  // namespace quadgen::fit
