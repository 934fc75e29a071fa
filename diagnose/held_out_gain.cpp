#include "diagnose/held_out_gain.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include "derive/effects/effect_catalogue.hpp"
#include "output/numbers.hpp"
#include "runtime/data_side_effects.hpp"

namespace quadgen::diagnose {

namespace {

void summarise(Finding::FoldGains& g) { mean_and_standard_error(g.per_fold, &g.mean, &g.standard_error); }

// The held-out time before each sample of `valid`: its positive sample intervals up to a gap
// count; a gap is longer than a rollout steps over (predict::Rollout::kMaxGap) and than 1.5
// of the log's median spacing (a log sampled at 10 Hz or slower is no gap throughout). The
// training parts between joined flights' held-out parts add nothing.
std::vector<double> held_out_clock(const fit::Flight& valid) {
  const auto& s = valid.samples;
  std::vector<double> times;
  for (const auto& x : s) times.push_back(x.t);
  const double gap = std::max(predict::Rollout::kMaxGap, s.size() > 1 ? runtime::gap_threshold(times) : 0.0);
  std::vector<double> clock(s.size(), 0.0);
  for (size_t i = 1; i < s.size(); ++i) {
    const double dt = s[i].t - s[i - 1].t;
    clock[i] = clock[i - 1] + (dt > 0 && dt <= gap ? dt : 0.0);
  }
  return clock;
}

}  // namespace

HeldOutGain::ChannelGroupSquares HeldOutGain::channel_group_squares(const fit::EquationErrorModel& m,
                                                                    const std::vector<fit::FitParameter>& ps) {
  const std::vector<double> r = m.all_channels(ps);
  ChannelGroupSquares ss;
  for (size_t i = 0; i < r.size(); ++i) {
    const size_t channel = i % 6;
    (channel < 2 ? ss.horizontal : channel == 2 ? ss.vertical : channel < 5 ? ss.roll_pitch : ss.yaw) += r[i] * r[i];
  }
  return ss;
}

void mean_and_standard_error(const std::vector<double>& x, double* mean, double* se) {
  const double n = static_cast<double>(x.size());
  *mean = 0;
  for (double v : x) *mean += v / n;
  double ss = 0;
  for (double v : x) ss += (v - *mean) * (v - *mean);
  *se = x.size() > 1 ? std::sqrt(ss / (n - 1) / n) : 0.0;
}

std::vector<fit::Flight> validation_folds(const fit::Flight& valid, int k) {
  std::vector<fit::Flight> folds(static_cast<size_t>(k), valid);
  for (auto& f : folds) f.samples.clear();
  const auto& s = valid.samples;
  const std::vector<double> held_out = held_out_clock(valid);
  const double span = (s.empty() ? 0.0 : held_out.back()) + 1e-9;
  for (size_t i = 0; i < s.size(); ++i)
    folds[std::min<size_t>(static_cast<size_t>(k) - 1, static_cast<size_t>(held_out[i] / span * k))].samples.push_back(s[i]);
  folds.erase(std::remove_if(folds.begin(), folds.end(), [](const fit::Flight& f) { return f.samples.size() < 2; }),
              folds.end());
  return folds;
}

std::vector<EffectEstimate> effect_estimates(const SearchResult& s, const std::string& e) {
  std::vector<EffectEstimate> out;
  for (const auto& est : s.estimates)
    if (est.name.rfind(e + ".", 0) == 0) out.push_back(est);
  return out;
}

HeldOutGain::HeldOutGain(runtime::DynamicModel& model, const CandidateSearch& search, const fit::Flight& valid,
                         const fit::EquationErrorModel& valid_ee, bool accelerometer, double window,
                         double window_stride)
    : model_(model),
      search_(search),
      valid_(valid),
      valid_ee_(valid_ee),
      pose_(valid.has_pose),
      window_(window),
      window_stride_(window_stride),
      folds_(validation_folds(valid, 4)) {
  for (const auto& f : folds_) fold_starts_.push_back(f.samples.front().t);
  // Every point of a window is scored (0 to `window` s ahead): less than the error at the
  // window's end, which predict reports; the wording keeps the two apart.
  metric_name_ = pose_ ? "validation position RMSE (" + output::short_number(window) +
                             " s open-loop windows from measured states" + stride_clause(window, window_stride) +
                             "; every point of a window scored) [m]"
                       : "validation equation-error cost (weighted, no pose logged)";
  // Without a pose the folds' one-step costs are the metric's folds too (until the
  // fifty-ninth session such a part was one fold: a gain was judged by its sign alone).
  for (const auto& f : folds_)
    try {  // a fold of short stretches between gaps has no row to differentiate: skipped
      FoldProblems p{std::make_unique<fit::EquationErrorModel>(model, f, accelerometer), nullptr};
      if (!accelerometer && f.has_accelerometer) p.accelerometer = std::make_unique<fit::EquationErrorModel>(model, f, true);
      fold_problems_.push_back(std::move(p));
    } catch (const fit::FitError&) {
    }
}

double HeldOutGain::metric(const std::vector<fit::FitParameter>& ps, const std::vector<double>& weights,
                           WindowedSimulation* sim) const {
  return pose_ ? open_loop_rmse(ps, sim) : CandidateSearch::cost(valid_ee_, ps, weights);
}

WindowOptions HeldOutGain::window_options(predict::Replay replay, bool keep_trace) const {
  WindowOptions o;
  o.seconds = window_, o.start_stride = window_stride_, o.keep_trace = keep_trace, o.replay = replay;
  o.fold_starts = fold_starts_;
  return o;
}

WindowedSimulation HeldOutGain::windows(const std::vector<fit::FitParameter>& ps, predict::Replay replay,
                                        bool keep_trace) const {
  return simulate_windows(model_, fit::parameter_values(ps), valid_, window_options(replay, keep_trace));
}

double HeldOutGain::open_loop_rmse(const std::vector<fit::FitParameter>& ps, WindowedSimulation* sim) const {
  WindowedSimulation w = windows(ps, predict::Replay::kNothing, sim != nullptr);
  if (sim) *sim = w;
  return w.position_rmse;
}

std::string HeldOutGain::fold_windows_text(const std::vector<fit::FitParameter>& ps) const {
  const WindowedSimulation w = windows(ps, predict::Replay::kNothing, false);
  // The held-out time itself, as the folds cut it: a joint diagnosis's parts lie apart on
  // the joined clock.
  const std::vector<double> clock = held_out_clock(valid_);
  const double held_out = clock.empty() ? 0.0 : clock.back();
  const bool diverged = !std::isfinite(w.position_rmse);
  return "of the " + std::to_string(w.windows) + " windows the " + std::to_string(fold_starts_.size()) +
         " folds score, " + std::to_string(w.cut_short) + " end early (at the held-out part's end or a gap) before " +
         output::short_number(window_) + " s (" + output::short_number(held_out) + " s held out" +
         (diverged ? "; the windows diverged" : "") +
         "); the whole part pools the folds' squared errors, so a fold with larger errors weighs more in it than in "
         "the mean of the folds' gains";
}

HeldOutGain::Scores HeldOutGain::unweighted_scores(const std::vector<fit::FitParameter>& ps, bool force_alone) const {
  Scores out;
  if (pose_) {
    // One simulation of the part scores the whole and each fold (its windows start in it).
    const WindowedSimulation w = windows(ps, predict::Replay::kNothing, false);
    out.metric = w.position_rmse;
    out.fold_metrics = fold_position_rmses(w);
    if (force_alone) out.force_alone = fold_position_rmses(windows(ps, predict::Replay::kAttitude, false));
  }
  for (const auto& fold : fold_problems_) {
    out.fit_groups.push_back(channel_group_squares(*fold.fit, ps));
    // The translational channels as the fit measures them, or by the accelerometer.
    out.translational_groups.push_back(fold.accelerometer ? channel_group_squares(*fold.accelerometer, ps)
                                                          : out.fit_groups.back());
  }
  return out;
}

void HeldOutGain::weigh(Scores& s, const std::vector<fit::FitParameter>& ps, const std::vector<double>& weights) const {
  s.fold_costs.clear();
  for (const auto& fold : fold_problems_) s.fold_costs.push_back(CandidateSearch::cost(*fold.fit, ps, weights));
  if (pose_) return;
  s.metric = CandidateSearch::cost(valid_ee_, ps, weights);
  s.fold_metrics = {s.metric};  // read only where no fold problem could be built (finding_for)
}

const HeldOutGain::Scores& HeldOutGain::final_scores(const SearchResult& s, bool force_alone) const {
  const auto values = fit::parameter_values(s.final_fit);
  if (values != cached_values_) {
    cached_ = unweighted_scores(s.final_fit, force_alone);
    cached_values_ = values;
    cached_force_alone_ = force_alone;
  } else if (force_alone && !cached_force_alone_ && pose_) {
    cached_.force_alone = fold_position_rmses(windows(s.final_fit, predict::Replay::kAttitude, false));
    cached_force_alone_ = true;
  }
  return cached_;
}

Finding::OneStep HeldOutGain::one_step(const Scores& without, const Scores& with) {
  Finding::OneStep o;
  for (size_t k = 0; k < with.fold_costs.size(); ++k) {
    o.cost.per_fold.push_back(percent_lower(without.fold_costs[k], with.fold_costs[k]));
    const auto &gb = without.fit_groups[k], &ga = with.fit_groups[k];
    o.rotation.per_fold.push_back(percent_lower(gb.rotational(), ga.rotational()));
    o.roll_pitch.per_fold.push_back(percent_lower(gb.roll_pitch, ga.roll_pitch));
    o.yaw.per_fold.push_back(percent_lower(gb.yaw, ga.yaw));
    const auto &tb = without.translational_groups[k], &ta = with.translational_groups[k];
    o.translation.per_fold.push_back(percent_lower(tb.translational(), ta.translational()));
    o.horizontal.per_fold.push_back(percent_lower(tb.horizontal, ta.horizontal));
    o.vertical.per_fold.push_back(percent_lower(tb.vertical, ta.vertical));
  }
  for (auto* g : {&o.cost, &o.translation, &o.rotation, &o.horizontal, &o.vertical, &o.roll_pitch, &o.yaw}) summarise(*g);
  return o;
}

std::vector<fit::FitParameter> HeldOutGain::model_without(const std::string& e, const SearchResult& s,
                                                          std::vector<double>* own_weights, Settling* settling) const {
  const auto values = fit::parameter_values(s.final_fit);
  auto cached = without_.find(e);
  if (cached == without_.end() || cached->second.final_values != values ||
      cached->second.final_effects != s.selected) {
    std::set<std::string> others(s.selected.begin(), s.selected.end());
    others.erase(e);
    // A lone effect's comparison model is the base fit, which a final model left without
    // effects is (CandidateSearch::run says why it is not settled further).
    Without w{s.selected, values, s.base_fit, s.base_weights, Settling::of_base_fit()};
    if (!others.empty())
      w.fit = search_.fit_as_own_model(others, s.final_fit, s.final_weights, &w.weights, &w.settling);
    cached = without_.insert_or_assign(e, std::move(w)).first;
  }
  *own_weights = cached->second.weights;
  if (settling) *settling = cached->second.settling;
  return cached->second.fit;
}

Finding HeldOutGain::finding_for(const std::string& e, const SearchResult& s) const {
  Finding f;
  f.effect = e;
  for (const auto& step : s.steps)
    if (step.selected == e) f.evidence = step.candidates.front();
  f.parameters = effect_estimates(s, e);
  std::vector<double> own_weights;
  Settling settling;
  const auto without = model_without(e, s, &own_weights, &settling);
  f.comparison = settling;
  std::vector<double> between(own_weights.size());
  for (size_t k = 0; k < between.size(); ++k) between[k] = std::sqrt(own_weights[k] * s.final_weights[k]);
  const bool force_alone = pose_ && find_effect(e).judged_by_force_model;
  Scores a = final_scores(s, force_alone), b = unweighted_scores(without, force_alone);
  weigh(a, s.final_fit, between);
  weigh(b, without, between);
  f.metric = metric_name_;
  f.rollouts = pose_;
  f.before = b.metric;
  f.after = a.metric;
  f.one_step = one_step(b, a);
  // Without a pose the metric is the one-step cost: its gain per fold is the one-step route's
  // own, in per cent, so the two routes cannot disagree in sign (summed costs did: a
  // fold with a larger cost weighs more in a difference than in a per cent).
  f.fold_gains = pose_ || f.one_step.cost.per_fold.empty() ? fold_gains(b.fold_metrics, a.fold_metrics)
                                                           : f.one_step.cost.per_fold;
  mean_and_standard_error(f.fold_gains, &f.gain_mean, &f.gain_standard_error);
  if (force_alone) {
    f.force_alone.per_fold = fold_gains(b.force_alone, a.force_alone);
    summarise(f.force_alone);
  }
  f.accepted_by = held_out_test(f);
  // Without a pose the report's metric itself is the held-out equation-error cost.
  if (!pose_ && f.accepted_by == Finding::kByOpenLoopPosition) f.accepted_by = Finding::kByOneStep;
  return f;
}

}  // namespace quadgen::diagnose
