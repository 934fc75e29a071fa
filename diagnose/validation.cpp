#include "diagnose/validation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "output/numbers.hpp"
#include "runtime/data_side_effects.hpp"
#include "runtime/per_flight_model.hpp"
#include "predict/rollout.hpp"

namespace quadgen::diagnose {

std::string stride_clause(double window, double start_stride) {
  return overlapping_windows(window, start_stride) ? ", started every " + output::short_number(start_stride) + " s" : "";
}

namespace {

// Sums of squared errors over the scored samples of some windows.
struct Sums {
  double pos = 0, vel = 0, att = 0, rate = 0;
  size_t count = 0, windows = 0, cut_short = 0;
  bool diverged = false;  // a window left the finite numbers
  Sums& operator+=(const Sums& o) {
    pos += o.pos, vel += o.vel, att += o.att, rate += o.rate;
    count += o.count, windows += o.windows, cut_short += o.cut_short;
    diverged = diverged || o.diverged;
    return *this;
  }
  double rms(double squares) const {
    if (diverged) return std::numeric_limits<double>::infinity();
    return std::sqrt(squares / static_cast<double>(std::max<size_t>(count, 1)));
  }
};

// The fold a window starting at `t` counts toward: the last fold begun by then (the first
// before any).
size_t fold_of(double t, const std::vector<double>& fold_starts) {
  const auto after = std::upper_bound(fold_starts.begin(), fold_starts.end(), t + 1e-9);
  return after == fold_starts.begin() ? 0 : static_cast<size_t>(after - fold_starts.begin()) - 1;
}

// The windows of one part, one simulate_windows call: each window integrates from a measured
// state until the options' horizon or a gap and scores every sample it reaches into the sums
// of the fold its start lies in.
class WindowRunner {
 public:
  WindowRunner(runtime::DynamicModel& model, const std::vector<double>& sim_params, const fit::Flight& f,
               const WindowOptions& o, WindowedSimulation& out)
      : roll_(model, f, sim_params), S_(f.samples), o_(o), out_(out) {}

  // The plotted trace's consecutive windows, NaN between them; their sums (the scores where
  // the windows do not overlap). A diverged window is left out of the plot (its points up
  // to the bound would only stretch the axes) and marks its fold.
  std::vector<Sums> consecutive(bool trace) {
    std::vector<Sums> folds(fold_count());
    for (size_t k0 = 0; k0 + 1 < S_.size();) {
      if (!roll_.may_start_at(k0)) {
        ++k0;
        continue;
      }
      const size_t trace_before = out_.t.size();
      const auto [k, diverged] = run(k0, folds, trace);
      if (trace) {
        if (diverged)
          for (auto* v : trace_columns()) v->resize(trace_before);
        out_.t.push_back(S_[k].t);
        for (auto* v : trace_columns()) if (v != &out_.t) v->push_back(std::numeric_limits<double>::quiet_NaN());
      }
      k0 = std::max(k, k0 + 1);
    }
    return folds;
  }

  // Windows started every `start_stride` seconds (overlapping; each sample is scored at
  // several horizons), not traced.
  std::vector<Sums> overlapping() {
    std::vector<Sums> folds(fold_count());
    double next_start = S_.front().t;
    for (size_t k0 = 0; k0 + 1 < S_.size(); ++k0) {
      if (S_[k0].t + 1e-9 < next_start || !roll_.may_start_at(k0)) continue;
      next_start = S_[k0].t + o_.start_stride;
      run(k0, folds, false);
    }
    return folds;
  }

 private:
  struct WindowEnd {
    size_t last;    // the window's last sample scored (k0 if none)
    bool diverged;  // the simulation left the finite numbers after `last`
  };

  size_t fold_count() const { return std::max<size_t>(o_.fold_starts.size(), 1); }
  std::vector<std::vector<double>*> trace_columns() {
    return {&out_.t, &out_.x, &out_.y, &out_.z, &out_.e_pos, &out_.e_vel, &out_.e_att, &out_.e_rate};
  }

  WindowEnd run(size_t k0, std::vector<Sums>& folds, bool trace) {
    Sums& sums = folds[fold_of(S_[k0].t, o_.fold_starts)];
    auto [e, x] = roll_.start_at(k0, o_.replay);
    size_t k = k0;
    for (; k + 1 < S_.size() && S_[k + 1].t - S_[k0].t <= o_.seconds + 1e-9; ++k) {
      if (S_[k + 1].t - S_[k].t > predict::Rollout::kMaxGap) break;  // a gap: a new window
      if (!roll_.advance(x, k, o_.replay)) {
        sums.diverged = true;
        return {k, true};
      }
      const predict::StateError err = predict::state_error(x, S_[k + 1], e, false);
      sums.pos += err.position_squared, sums.vel += err.velocity_squared;
      sums.att += err.angle * err.angle, sums.rate += err.body_rates_squared;
      ++sums.count;
      if (trace) {
        for (auto [v, value] : {std::pair{&out_.t, S_[k + 1].t}, {&out_.x, x[0]}, {&out_.y, x[1]}, {&out_.z, x[2]},
                                {&out_.e_pos, std::sqrt(err.position_squared)},
                                {&out_.e_vel, std::sqrt(err.velocity_squared)}, {&out_.e_att, err.angle},
                                {&out_.e_rate, std::sqrt(err.body_rates_squared)}})
          v->push_back(value);
      }
    }
    if (k == k0) return {k, false};  // scored nothing (a start just before a gap or the end)
    ++sums.windows;
    const bool ended_early = k + 1 >= S_.size() || S_[k + 1].t - S_[k].t > predict::Rollout::kMaxGap;
    if (ended_early && S_[k].t - S_[k0].t < o_.seconds - 1e-9) ++sums.cut_short;
    return {k, false};
  }

  predict::Rollout roll_;  // the prediction's rollout
  const std::vector<fit::FlightSample>& S_;
  const WindowOptions& o_;
  WindowedSimulation& out_;
};

}  // namespace

WindowedSimulation simulate_windows(runtime::DynamicModel& model, const std::vector<double>& params,
                                    const fit::Flight& f, const WindowOptions& o) {
  if (f.samples.size() < 2) return {};  // no window to simulate
  const std::vector<double> sim_params = runtime::simulation_params(model, params);
  model.set_params(sim_params);
  WindowedSimulation out;
  WindowRunner runner(model, sim_params, f, o, out);
  // Without a trace the overlapping windows alone are simulated (about a tenth of the work
  // at the default 0.1 s stride of 1 s windows); the scores never depend on the trace.
  const bool overlapping = overlapping_windows(o.seconds, o.start_stride);
  std::vector<Sums> scored;
  if (o.keep_trace || !overlapping) scored = runner.consecutive(o.keep_trace);
  if (overlapping) scored = runner.overlapping();
  Sums all;
  for (const Sums& fold : scored) {
    all += fold;
    // A fold no window starts in has no score: NaN (fold_gains leaves it out).
    out.folds.push_back({fold.windows || fold.diverged ? fold.rms(fold.pos) : std::numeric_limits<double>::quiet_NaN(),
                         fold.windows, fold.cut_short});
  }
  out.position_rmse = all.rms(all.pos);
  out.velocity_rmse = all.rms(all.vel);
  out.attitude_rmse = all.rms(all.att);
  out.rate_rmse = all.rms(all.rate);
  out.windows = all.diverged ? 0 : all.windows, out.cut_short = all.diverged ? 0 : all.cut_short;
  return out;
}

std::vector<double> fold_gains(const std::vector<double>& before, const std::vector<double>& after) {
  std::vector<double> gains;
  // A fold where both diverged (inf - inf) says nothing of either: left out, as a NaN is
  // (a statistics review, helper-128: its NaN gain made the mean NaN).
  for (size_t k = 0; k < std::min(before.size(), after.size()); ++k)
    if (!std::isnan(before[k]) && !std::isnan(after[k]) && (std::isfinite(before[k]) || std::isfinite(after[k])))
      gains.push_back(before[k] - after[k]);
  return gains;
}

std::vector<double> fold_position_rmses(const WindowedSimulation& w) {
  std::vector<double> m;
  for (const auto& fold : w.folds) m.push_back(fold.position_rmse);
  return m;
}

}  // namespace quadgen::diagnose
