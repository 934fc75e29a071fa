// The gain on data the fit did not see, in the quantity a user cares about: the position
// error of the simulation. The validation part is cut into windows; each is simulated from
// the measured state at its start with the logged commands (open loop: a whole flight would
// drift off, as the thesis' did) and compared with the measured positions.
#pragma once
#include <algorithm>
#include <string>
#include <vector>

#include "runtime/dynamic_model.hpp"
#include "fit/flight_data.hpp"
#include "predict/rollout.hpp"

namespace quadgen::diagnose {

// How much lower `after` is than `before`, in percent of `before`: the one formula of every
// gain the diagnosis reports (held-out cost, position error, a channel group's sum of squares).
inline double percent_lower(double before, double after) {
  return 100 * (before - after) / std::max(1e-300, before);
}

struct WindowedSimulation {
  double position_rmse = 0;  // m, over every sample of every window
  double velocity_rmse = 0;  // m/s
  double attitude_rmse = 0;  // rad, angle of the rotation between simulated and logged attitude
  double rate_rmse = 0;      // rad/s, body rates against the gyro
  std::vector<double> t, x, y, z;  // simulated positions (NaN between windows) for plots
  // Error norms at the same times: position, velocity, attitude angle, body rates.
  std::vector<double> e_pos, e_vel, e_att, e_rate;
  // The scored windows (those that scored a sample), and of them those cut short by the
  // part's end or a gap before they ran `window` seconds (a part not much longer than a
  // window scores mostly short ones). Zero where the windows diverged.
  size_t windows = 0, cut_short = 0;
  // Per held-out fold (WindowOptions::fold_starts): the position RMSE of the windows that
  // start in that fold, NaN where none does (fold_gains leaves it out) and infinite where
  // one of them diverged (the whole part's RMSEs are then infinite too). The whole part's
  // numbers pool the folds' squares.
  struct Fold {
    double position_rmse = 0;  // m
    size_t windows = 0, cut_short = 0;
  };
  std::vector<Fold> folds;
};

// How simulate_windows cuts a part into windows and what it keeps.
struct WindowOptions {
  double seconds = 1.0;     // each window's horizon
  double start_stride = 0;  // windows started this often (overlapping_windows), else consecutive
  bool keep_trace = true;   // keep the plotted trace (consecutive windows, NaN between them)
  predict::Replay replay = predict::Replay::kNothing;  // what the windows take from the log
  // The times at which the held-out folds begin. A window counts toward the fold its start
  // lies in and runs its whole horizon across the fold's end, so the folds judge the same
  // windows as the whole part. Empty: one fold, the whole part.
  std::vector<double> fold_starts;
};

// Whether simulate_windows scores overlapping windows for this stride.
inline bool overlapping_windows(double window, double start_stride) { return start_stride > 0 && start_stride < window; }
// What a held-out position metric's name says about its windows: ", started every 0.1 s"
// when they overlap, nothing when they are consecutive.
std::string stride_clause(double window, double start_stride);

// `model` must be the full-catalogue model with `params` (effects off at their neutral values).
// The RMSEs come from windows started every `start_stride` seconds (overlapping: see
// overlapping_windows), or else from the consecutive windows of the plotted trace; each
// fold's from the windows that start in it. Without `keep_trace` the trace is left empty,
// and with overlapping windows not simulated at all. A scored window that diverges makes
// every RMSE of the whole part, and its fold's, infinite; a diverging window of the trace is
// left out of the plot. With `replay` the windows take that part of the state from the log
// (predict::Replay::kAttitude: the force model alone).
WindowedSimulation simulate_windows(runtime::DynamicModel& model, const std::vector<double>& params,
                                    const fit::Flight& flight, const WindowOptions& options);

// The folds' position RMSEs of a simulation, in fold order.
std::vector<double> fold_position_rmses(const WindowedSimulation& w);
// Per fold, `before` - `after` (m): the gain a finding or a proposed term buys, over the
// folds both score (a fold no window starts in, NaN, is left out, and so is one where both
// diverged; where one alone diverged the gain is infinite, for or against it).
std::vector<double> fold_gains(const std::vector<double>& before, const std::vector<double>& after);

}  // namespace quadgen::diagnose
