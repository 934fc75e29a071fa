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
  Sums& operator+=(const Sums& o) {
    pos += o.pos, vel += o.vel, att += o.att, rate += o.rate;
    count += o.count, windows += o.windows, cut_short += o.cut_short;
    return *this;
  }
  double rms(double squares) const { return std::sqrt(squares / static_cast<double>(std::max<size_t>(count, 1))); }
};

// The fold a window starting at `t` counts toward: the last fold begun by then (the first
// before any).
size_t fold_of(double t, const std::vector<double>& fold_starts) {
  const auto after = std::upper_bound(fold_starts.begin(), fold_starts.end(), t + 1e-9);
  return after == fold_starts.begin() ? 0 : static_cast<size_t>(after - fold_starts.begin()) - 1;
}

}  // namespace

WindowedSimulation simulate_windows(runtime::DynamicModel& model, const std::vector<double>& params,
                                    const fit::Flight& f, const WindowOptions& o) {
  if (f.samples.size() < 2) return {};  // no window to simulate
  const double window = o.seconds;
  const predict::Replay replay = o.replay;
  const std::vector<double> sim_params = runtime::simulation_params(model, params);
  model.set_params(sim_params);
  predict::Rollout roll(model, f, sim_params);  // the prediction's rollout
  WindowedSimulation out;
  const auto& S = f.samples;
  const size_t n_folds = std::max<size_t>(o.fold_starts.size(), 1);
  // One window from sample k0: integrates until `window` seconds or a gap, scores each
  // sample into its fold's sums and, with `trace`, appends it to the plotted trace.
  struct WindowEnd {
    size_t last;    // the window's last sample scored (k0 if none)
    bool diverged;  // the simulation left the finite numbers after `last`
  };
  auto run_window = [&](size_t k0, std::vector<Sums>& folds, bool trace) -> WindowEnd {
    Sums& sums = folds[fold_of(S[k0].t, o.fold_starts)];
    auto [e, x] = roll.start_at(k0, replay);
    size_t k = k0;
    for (; k + 1 < S.size() && S[k + 1].t - S[k0].t <= window + 1e-9; ++k) {
      if (S[k + 1].t - S[k].t > predict::Rollout::kMaxGap) break;  // a gap: a new window
      if (!roll.advance(x, k, replay)) return {k, true};
      const predict::StateError err = predict::state_error(x, S[k + 1], e, false);
      const double e2 = err.position_squared, v2 = err.velocity_squared, w2 = err.body_rates_squared, angle = err.angle;
      sums.pos += e2, sums.vel += v2, sums.att += angle * angle, sums.rate += w2;
      ++sums.count;
      if (!trace) continue;
      out.t.push_back(S[k + 1].t);
      out.x.push_back(x[0]);
      out.y.push_back(x[1]);
      out.z.push_back(x[2]);
      out.e_pos.push_back(std::sqrt(e2));
      out.e_vel.push_back(std::sqrt(v2));
      out.e_att.push_back(angle);
      out.e_rate.push_back(std::sqrt(w2));
    }
    if (k == k0) return {k, false};  // scored nothing (a start just before a gap or the end)
    ++sums.windows;
    const bool ended_early = k + 1 >= S.size() || S[k + 1].t - S[k].t > predict::Rollout::kMaxGap;
    if (ended_early && S[k].t - S[k0].t < window - 1e-9) ++sums.cut_short;
    return {k, false};
  };
  const double inf = std::numeric_limits<double>::infinity();
  auto diverged = [&] {  // no error measure is meaningful (diagnosis.json shows null)
    out.position_rmse = out.velocity_rmse = out.attitude_rmse = out.rate_rmse = inf;
    out.folds.assign(n_folds, WindowedSimulation::Fold{inf, 0, 0});
    return out;
  };
  // The plotted trace: consecutive windows, NaN between them. A window starts only where the
  // rotor speeds are known (StartStates::settled: not in the first 0.3 s of the part).
  // Divergence is decided by the windows that are scored: when the scores come from the
  // overlapping windows, a diverging trace window just ends there (so that the scores do not
  // depend on whether a trace is kept).
  const bool overlapping = overlapping_windows(window, o.start_stride);
  std::vector<Sums> consecutive(n_folds);
  for (size_t k0 = 0; k0 + 1 < S.size() && (o.keep_trace || !overlapping);) {
    if (!roll.may_start_at(k0)) {
      ++k0;
      continue;
    }
    const size_t trace_before = out.t.size();
    const auto [k, window_diverged] = run_window(k0, consecutive, o.keep_trace);
    if (window_diverged && !overlapping) return diverged();
    const double nan = std::numeric_limits<double>::quiet_NaN();
    if (o.keep_trace) {
      if (window_diverged)  // its points up to the bound would only stretch the plot's axes
        for (auto* v : {&out.t, &out.x, &out.y, &out.z, &out.e_pos, &out.e_vel, &out.e_att, &out.e_rate}) v->resize(trace_before);
      out.t.push_back(S[k].t);
      for (auto* v : {&out.x, &out.y, &out.z, &out.e_pos, &out.e_vel, &out.e_att, &out.e_rate}) v->push_back(nan);
    }
    k0 = std::max(k, k0 + 1);
  }
  // The scores: from the consecutive windows, or from windows started every `start_stride`
  // seconds (overlapping; each sample is scored at several horizons).
  std::vector<Sums> scored = consecutive;
  if (overlapping) {
    scored.assign(n_folds, Sums{});
    double next_start = S.front().t;
    for (size_t k0 = 0; k0 + 1 < S.size(); ++k0) {
      if (S[k0].t + 1e-9 < next_start || !roll.may_start_at(k0)) continue;
      next_start = S[k0].t + o.start_stride;
      if (run_window(k0, scored, false).diverged) return diverged();
    }
  }
  Sums all;
  for (const Sums& fold : scored) {
    all += fold;
    out.folds.push_back({fold.rms(fold.pos), fold.windows, fold.cut_short});
  }
  out.position_rmse = all.rms(all.pos);
  out.velocity_rmse = all.rms(all.vel);
  out.attitude_rmse = all.rms(all.att);
  out.rate_rmse = all.rms(all.rate);
  out.windows = all.windows, out.cut_short = all.cut_short;
  return out;
}

}  // namespace quadgen::diagnose
