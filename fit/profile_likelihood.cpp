#include "fit/profile_likelihood.hpp"
#include "fit/evaluation_threads.hpp"
#include "output/numbers.hpp"
#include "output/progress.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <sstream>
#include <thread>

#include <boost/math/distributions/chi_squared.hpp>

namespace quadgen::fit {

const char* identifiability_text(Identifiability verdict) {
  switch (verdict) {
    case Identifiability::kIdentifiable: return "identifiable";
    case Identifiability::kPracticallyNonIdentifiable: return "practically non-identifiable";
    case Identifiability::kStructurallyNonIdentifiable: return "structurally non-identifiable";
  }
  return "identifiable";  // not reached: every value is named above
}

double chi2_quantile(double p, double dof) { return boost::math::quantile(boost::math::chi_squared(dof), p); }

namespace {

struct Side {
  std::vector<ProfilePoint> points;  // outward from the optimum
  bool reached_bound = false;
};

// The first step: a fraction of the standard error (a profile is quadratic near the
// optimum), kept within the bounds' span.
double first_step(const FitResult& best, int k) {
  const auto& p = best.parameters[k];
  const double range = p.upper - p.lower;
  double step = best.standard_errors[k];
  if (!std::isfinite(step) || step <= 0) step = range / 100;
  return std::clamp(step * 0.5, range * 1e-6, range / 10);
}

double stop_level(const FitResult& best, const ProfileOptions& po) {
  const double pointwise = chi2_quantile(po.confidence, 1);
  const double simultaneous = chi2_quantile(po.confidence, std::max(1, best.num_free));
  return 1.5 * (po.walk_past_simultaneous ? std::max(pointwise, simultaneous) : pointwise);
}

// Walks from the optimum in one direction until `stop` is exceeded, a bound is reached, or
// the step budget is spent. Each point starts from the previous point's re-optimised
// parameters. For a quadratic profile sqrt(delta chi2) grows linearly with the distance, so
// the last point predicts where sqrt(delta chi2) will have grown by a quarter of
// sqrt(stop): about four points a side; flat stretches grow the step fourfold at most.
Side walk(const ResidualModel& model, const FitResult& best, int k, double dir, const FitOptions& fo,
          const ProfileOptions& po, double stop) {
  Side side;
  std::vector<FitParameter> ps = best.parameters;
  ps[k].free = false;
  const double lo = best.parameters[k].lower, hi = best.parameters[k].upper, v0 = best.parameters[k].value;
  const double root_step = std::sqrt(stop) / 4;
  double offset = first_step(best, k);
  for (int s = 0; s < po.max_steps_each_side; ++s) {
    double next = v0 + dir * offset;
    if (next <= lo || next >= hi) {
      next = dir < 0 ? lo : hi;
      side.reached_bound = true;
    }
    ps[k].value = next;
    double c = 0;
    try {
      c = solve_weighted(model, ps, best.weights, fo);
    } catch (const FitError& e) {  // say which profile point could not be fitted
      throw FitError("profile of " + ps[k].name + " at " + output::six_digits(next) + ": " + e.what());
    }
    std::vector<double> vals;
    for (const auto& p : ps) vals.push_back(p.value);
    const double d = c - best.chi2;
    side.points.push_back({next, d, vals});
    if (d > stop || side.reached_bound) break;
    const double grow = d > 1e-9 * stop ? (std::sqrt(d) + root_step) / std::sqrt(d) : 4.0;
    offset *= std::clamp(grow, 1.2, 4.0);
  }
  return side;
}

// Where the profile crosses `level` on one side, NaN if never. Interpolated linearly in
// sqrt(delta chi2), which is linear in the parameter where the profile is quadratic, so
// the few points of a walk place the crossing accurately.
double crossing(const std::vector<ProfilePoint>& side, double best_value, double level) {
  const auto root = [](double d) { return std::sqrt(std::max(0.0, d)); };
  double prev_v = best_value, prev_r = 0;
  for (const auto& p : side) {
    const double r = root(p.delta_chi2);
    if (p.delta_chi2 >= level) {
      const double f = (root(level) - prev_r) / (r - prev_r);
      return prev_v + f * (p.value - prev_v);
    }
    prev_v = p.value;
    prev_r = r;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

// A profile from its two walks: interval, verdict, and for a flat one what compensates it.
Profile assemble(const FitResult& best, int k, const ProfileOptions& po, const Side& left_side, const Side& right_side) {
  Profile pr;
  pr.parameter = best.parameters[k].name;
  pr.index = k;
  pr.threshold_pointwise = chi2_quantile(po.confidence, 1);
  pr.threshold_simultaneous = chi2_quantile(po.confidence, std::max(1, best.num_free));
  const auto& p = best.parameters[k];
  const auto& left = left_side.points;
  const auto& right = right_side.points;
  pr.lower = crossing(left, p.value, pr.threshold_pointwise);
  pr.upper = crossing(right, p.value, pr.threshold_pointwise);
  pr.lower_open = std::isnan(pr.lower);
  pr.upper_open = std::isnan(pr.upper);
  // Flatness is judged where the other parameters were free to compensate: points at which
  // another parameter sits on its bound are blocked, not informative.
  double max_delta = 0;
  int interior = 0;
  for (const auto* side : {&left, &right})
    for (const auto& q : *side) {
      bool blocked = false;
      for (size_t j = 0; j < best.parameters.size(); ++j) {
        const auto& o = best.parameters[j];
        if (static_cast<int>(j) == k || !o.free) continue;
        const double tol = 1e-6 * (o.upper - o.lower);
        blocked = blocked || q.others[j] <= o.lower + tol || q.others[j] >= o.upper - tol;
      }
      if (blocked) continue;
      ++interior;
      max_delta = std::max(max_delta, q.delta_chi2);
    }
  std::vector<double> best_vals;
  for (const auto& q : best.parameters) best_vals.push_back(q.value);
  pr.points.push_back({p.value, 0.0, best_vals});
  for (const auto& q : left) pr.points.push_back(q);
  for (const auto& q : right) pr.points.push_back(q);
  // Stable: two steps that land on one value keep the order they were taken in (std::sort
  // leaves ties in the library's order).
  std::stable_sort(pr.points.begin(), pr.points.end(), [](const auto& a, const auto& b) { return a.value < b.value; });
  if (!pr.lower_open && !pr.upper_open) {
    pr.verdict = Identifiability::kIdentifiable;
  } else if (interior >= 3 && max_delta < 1e-3 * pr.threshold_pointwise) {
    pr.verdict = Identifiability::kStructurallyNonIdentifiable;
    // Which parameters moved along the flat profile, and their log-log slope against it.
    const auto& a = pr.points.front();
    const auto& b = pr.points.back();
    std::ostringstream os;
    for (size_t j = 0; j < best.parameters.size(); ++j) {
      if (static_cast<int>(j) == k || !best.parameters[j].free) continue;
      const double ra = a.others[j], rb = b.others[j];
      if (std::fabs(rb - ra) <= 1e-3 * std::max(std::fabs(ra), std::fabs(rb))) continue;
      if (ra > 0 && rb > 0 && a.value > 0 && b.value > 0) {
        const double slope = std::log(rb / ra) / std::log(b.value / a.value);
        os << (os.tellp() ? "; " : "") << best.parameters[j].name << " ∝ " << pr.parameter << "^" << std::round(slope * 100) / 100
           << " (identifiable: " << best.parameters[j].name << " / " << pr.parameter << "^" << std::round(slope * 100) / 100 << ")";
      } else {
        os << (os.tellp() ? "; " : "") << best.parameters[j].name;
      }
    }
    pr.compensated_by = os.str();
  } else {
    pr.verdict = Identifiability::kPracticallyNonIdentifiable;
  }
  return pr;
}

}  // namespace

Profile profile_parameter(const ResidualModel& model, const FitResult& best, int k, const FitOptions& fo,
                          const ProfileOptions& po) {
  const double stop = stop_level(best, po);
  const Side left = walk(model, best, k, -1, fo, po, stop);
  const Side right = walk(model, best, k, +1, fo, po, stop);
  return assemble(best, k, po, left, right);
}

// The sides of all profiles are independent jobs (two per parameter, for balance on few
// cores); each worker thread owns a copy of the model.
std::vector<Profile> profile_all(const ResidualModel& model, const FitResult& best, const FitOptions& fo,
                                 const ProfileOptions& po, const std::vector<int>& which) {
  std::vector<int> params = which;
  if (params.empty())
    for (size_t k = 0; k < best.parameters.size(); ++k)
      if (best.parameters[k].free) params.push_back(static_cast<int>(k));
  for (int k : params)
    if (k < 0 || k >= static_cast<int>(best.parameters.size()) || !best.parameters[k].free)
      throw FitError("profile: parameter index " + std::to_string(k) + " is not a free parameter");
  const size_t jobs = 2 * params.size();
  unsigned threads = po.threads > 0 ? po.threads : std::max(1u, std::thread::hardware_concurrency());
  threads = static_cast<unsigned>(std::min<size_t>(threads, jobs));
  std::vector<std::unique_ptr<ResidualModel>> copies;
  for (unsigned t = 1; t < threads; ++t) {
    copies.push_back(model.clone());
    if (!copies.back()) {
      threads = 1;
      break;
    }
  }
  const double stop = stop_level(best, po);
  std::vector<Side> sides(jobs);
  std::vector<int> sides_done(params.size(), 0);
  std::vector<std::chrono::steady_clock::time_point> started(params.size());
  std::atomic<size_t> next_job{0};
  std::mutex mutex;  // guards sides_done, started and the progress callback
  int profiles_done = 0;
  run_workers(threads, [&](size_t w, const std::atomic<bool>& stopped) {
    const ResidualModel& m = w == 0 ? model : *copies[w - 1];
    // One profile side per core: its evaluations stay on its thread (a lone one splits).
    const OneCorePerFit one_core(threads > 1);
    for (size_t j; !stopped && (j = next_job++) < jobs;) {
      const size_t i = j / 2;
      if (j % 2 == 0) {
        std::lock_guard<std::mutex> lock(mutex);
        started[i] = std::chrono::steady_clock::now();
      }
      sides[j] = walk(m, best, params[i], j % 2 == 0 ? -1.0 : 1.0, fo, po, stop);
      std::lock_guard<std::mutex> lock(mutex);
      if (++sides_done[i] == 2 && po.progress) {
        const double s = output::seconds_since(started[i]);
        po.progress(best.parameters[params[i]].name, ++profiles_done, static_cast<int>(params.size()), s);
      }
    }
  });
  std::vector<Profile> out;
  for (size_t i = 0; i < params.size(); ++i) out.push_back(assemble(best, params[i], po, sides[2 * i], sides[2 * i + 1]));
  return out;
}

}  // namespace quadgen::fit
