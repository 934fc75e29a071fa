// What one named effect buys on data the fit did not see: the search's final model against
// the model fitted without the effect (under its own weights), on four consecutive folds of
// the validation part. Measured three ways (Finding in diagnosis.hpp holds them):
//  - the report's metric per fold: the position RMSE of the open-loop windows that start in
//    the fold (each runs its whole horizon, across the fold's end) with a pose, else the
//    held-out equation-error cost;
//  - one step at a time, per kind of channel: the weighted cost, and the sums of squares of
//    the translational (the accelerometer's where one is logged and the fit differentiates
//    the pose), horizontal, vertical, rotational, roll/pitch and yaw channels;
//  - for a flight's own quantity acting on the force (the marker frame, a wind; with a pose),
//    the windows again with the measured attitude replayed: the force model alone.
// The rules that judge these numbers are held_out_test's (diagnosis.cpp).
#pragma once
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "diagnose/candidate_search.hpp"
#include "diagnose/diagnosis.hpp"
#include "diagnose/validation.hpp"
#include "fit/equation_error.hpp"
#include "fit/flight_data.hpp"
#include "runtime/dynamic_model.hpp"

namespace quadgen::diagnose {

// The validation part cut into `k` consecutive blocks of equal held-out time: the sample
// intervals of its contiguous stretches count, a gap (longer than a rollout steps over,
// predict::Rollout::kMaxGap, and than 1.5 median spacings) does not. Joined flights hold
// their validation parts apart on the joined clock (each flight's training part lies
// between); cut by that clock, two flights gave two blocks of four (a statistics review,
// helper-128). A block of fewer than two samples is dropped.
std::vector<fit::Flight> validation_folds(const fit::Flight& valid, int k);

// The mean of per-fold gains and its standard error (0 for one fold).
void mean_and_standard_error(const std::vector<double>& x, double* mean, double* se);

// The estimates of effect `e`'s parameters in the search's current final model.
std::vector<EffectEstimate> effect_estimates(const SearchResult& s, const std::string& e);

class HeldOutGain {
 public:
  // `valid`, `valid_ee`: the held-out part and its equation-error problem (the fit's
  // formulation, `accelerometer` or the differentiated pose); `search` refits without an
  // effect. All must outlive this object.
  HeldOutGain(runtime::DynamicModel& model, const CandidateSearch& search, const fit::Flight& valid,
              const fit::EquationErrorModel& valid_ee, bool accelerometer, double window, double window_stride);

  // The report's held-out metric of a parameter set, and its name; without a pose the
  // weighted cost under `weights`. With `sim`, the windows' trace is kept there.
  double metric(const std::vector<fit::FitParameter>& ps, const std::vector<double>& weights,
                WindowedSimulation* sim) const;
  const std::string& metric_name() const { return metric_name_; }
  // How the held-out part's open-loop windows are cut and scored: the diagnosis's window and
  // stride, and the folds' start times (the windows count toward the fold they start in).
  WindowOptions window_options(predict::Replay replay = predict::Replay::kNothing, bool keep_trace = false) const;
  // How the windows for parameter set `ps` end, and why the per-fold gains and the whole
  // part's metric can disagree: "of the 18 windows the 4 folds score, 5 end early (at the
  // held-out part's end or a gap) before 1 s (2.96 s held out); the whole part pools the
  // folds' squared errors, ...". With a pose only.
  std::string fold_windows_text(const std::vector<fit::FitParameter>& ps) const;

  // Effect `e` of the search's final model, against the model fitted without it under its
  // own weights (CandidateSearch::fit_as_own_model). Where a score is weighted (the one-step
  // cost; without a pose the metric itself), both are scored under the geometric mean of
  // their own weights: each model is the optimum under its own, so scoring both under
  // either one's would lean towards that model. Not thread-safe: it caches the final
  // model's rollouts (and the dynamic model is shared).
  Finding finding_for(const std::string& e, const SearchResult& s) const;

  // The search's final model without effect `e`, fitted under its own weights (returned in
  // `own_weights`); a lone effect's is the base fit. Cached per effect and final model, for
  // finding_for and the stand-in report ask for the same model.
  std::vector<fit::FitParameter> model_without(const std::string& e, const SearchResult& s,
                                               std::vector<double>* own_weights, Settling* settling = nullptr) const;

 private:
  // Sums of squares of one fold's channel groups (six channels per sample).
  struct ChannelGroupSquares {
    double horizontal = 0, vertical = 0, roll_pitch = 0, yaw = 0;  // channels 0-1, 2, 3-4 and 5
    double translational() const { return horizontal + vertical; }
    double rotational() const { return roll_pitch + yaw; }
  };
  // Everything a finding compares, for one parameter set.
  struct Scores {
    // Unweighted: the open-loop rollouts (with a pose) and the channel groups.
    double metric = 0;
    std::vector<double> fold_metrics;  // the open-loop windows per fold (one cost without a pose)
    std::vector<double> force_alone;   // the same with the measured attitude replayed (when asked)
    // Per one-step fold (a fold without a row to differentiate has none, so these can be
    // fewer than the open-loop folds; the two families are never indexed together).
    std::vector<ChannelGroupSquares> fit_groups, translational_groups;  // the latter as the guard reads it
    // Weighted (weigh): the one-step cost per fold; without a pose also the metric and
    // fold_metrics (the whole part's cost; the folds' gains are then the one-step route's).
    std::vector<double> fold_costs;
  };
  Scores unweighted_scores(const std::vector<fit::FitParameter>& ps, bool force_alone) const;
  void weigh(Scores& s, const std::vector<fit::FitParameter>& ps, const std::vector<double>& weights) const;
  // The final model's unweighted scores: every finding of one acceptance round compares with
  // the same final model, which is simulated once per round, not once per finding.
  const Scores& final_scores(const SearchResult& s, bool force_alone) const;
  // The open-loop windows of the whole held-out part, scored per fold too (with a pose).
  WindowedSimulation windows(const std::vector<fit::FitParameter>& ps, predict::Replay replay, bool keep_trace) const;
  // Their position RMSE over the whole part; with `sim`, the windows' trace is kept there.
  double open_loop_rmse(const std::vector<fit::FitParameter>& ps, WindowedSimulation* sim) const;
  static ChannelGroupSquares channel_group_squares(const fit::EquationErrorModel& m,
                                                   const std::vector<fit::FitParameter>& ps);
  static Finding::OneStep one_step(const Scores& without, const Scores& with);

  // A fold's one-step problems: the fit's own, and the accelerometer's where one is logged
  // and the fit differentiates the pose instead (null otherwise) — the translational guard
  // then judges the force by a sensor the fit did not use (a per-flight wind once improved
  // the differentiated pose and made the accelerometer's horizontal force 5x worse).
  struct FoldProblems {
    std::unique_ptr<fit::EquationErrorModel> fit, accelerometer;
  };

  runtime::DynamicModel& model_;
  const CandidateSearch& search_;
  const fit::Flight& valid_;
  const fit::EquationErrorModel& valid_ee_;
  const bool pose_;
  const double window_, window_stride_;
  std::string metric_name_;
  std::vector<fit::Flight> folds_;  // the one-step problems' folds
  std::vector<double> fold_starts_;
  std::vector<FoldProblems> fold_problems_;  // with a pose; a fold without rows is skipped
  // final_scores' cache, keyed on the final model's values.
  mutable std::vector<double> cached_values_;
  mutable Scores cached_;
  mutable bool cached_force_alone_ = false;
  // model_without's cache: per effect, the final model it was fitted from (its effects and
  // values), the model and its weights.
  struct Without {
    std::vector<std::string> final_effects;
    std::vector<double> final_values;
    std::vector<fit::FitParameter> fit;
    std::vector<double> weights;
    Settling settling;
  };
  mutable std::map<std::string, Without> without_;
};

}  // namespace quadgen::diagnose
