#include "profile_likelihood.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <boost/math/distributions/chi_squared.hpp>

namespace quadgen::fit {

double chi2_quantile(double p, double dof) { return boost::math::quantile(boost::math::chi_squared(dof), p); }

namespace {

// Walks from the optimum in one direction until the simultaneous threshold is exceeded,
// a bound is reached, or the step budget is spent. Steps grow when the profile is flat.
void walk(const ResidualModel& model, const FitResult& best, int k, double dir, double step, const FitOptions& fo,
          const ProfileOptions& po, double stop, std::vector<ProfilePoint>& out, bool* reached_bound) {
  std::vector<FitParameter> ps = best.parameters;
  ps[k].free = false;
  const double lo = best.parameters[k].lower, hi = best.parameters[k].upper;
  double v = best.parameters[k].value;
  *reached_bound = false;
  for (int s = 0; s < po.max_steps_each_side; ++s) {
    double next = v + dir * step;
    if (next <= lo || next >= hi) {
      next = dir < 0 ? lo : hi;
      *reached_bound = true;
    }
    ps[k].value = next;
    double c = 0;
    try {
      c = solve_weighted(model, ps, best.weights, fo);
    } catch (const FitError& e) {  // say which profile point could not be fitted
      throw FitError("profile of " + ps[k].name + " at " + std::to_string(next) + ": " + e.what());
    }
    std::vector<double> vals;
    for (const auto& p : ps) vals.push_back(p.value);
    const double d = c - best.chi2;
    out.push_back({next, d, vals});
    if (d > stop || *reached_bound) return;
    // Aim for about a tenth of the threshold per step.
    if (d < 0.02 * stop) step *= 2.0;
    else if (d > 0.3 * stop && s > 0) step *= 0.7;
    v = next;
  }
}

// Where the profile crosses `level` on one side, by linear interpolation; NaN if never.
double crossing(const std::vector<ProfilePoint>& side, double best_value, double level) {
  double prev_v = best_value, prev_d = 0;
  for (const auto& p : side) {
    if (p.delta_chi2 >= level) {
      const double f = (level - prev_d) / (p.delta_chi2 - prev_d);
      return prev_v + f * (p.value - prev_v);
    }
    prev_v = p.value;
    prev_d = p.delta_chi2;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

Profile profile_parameter(const ResidualModel& model, const FitResult& best, int k, const FitOptions& fo,
                          const ProfileOptions& po) {
  Profile pr;
  pr.parameter = best.parameters[k].name;
  pr.index = k;
  pr.threshold_pointwise = chi2_quantile(po.confidence, 1);
  pr.threshold_simultaneous = chi2_quantile(po.confidence, std::max(1, best.num_free));
  const auto& p = best.parameters[k];
  double step = best.standard_errors[k];
  const double range = p.upper - p.lower;
  if (!std::isfinite(step) || step <= 0) step = range / 100;
  step = std::clamp(step * 0.3, range * 1e-6, range / 10);
  const double stop = 1.2 * std::max(pr.threshold_simultaneous, pr.threshold_pointwise);
  std::vector<ProfilePoint> left, right;
  bool lb = false, ub = false;
  walk(model, best, k, -1, step, fo, po, stop, left, &lb);
  walk(model, best, k, +1, step, fo, po, stop, right, &ub);
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
  std::sort(pr.points.begin(), pr.points.end(), [](const auto& a, const auto& b) { return a.value < b.value; });
  if (!pr.lower_open && !pr.upper_open) {
    pr.verdict = "identifiable";
  } else if (interior >= 3 && max_delta < 1e-3 * pr.threshold_pointwise) {
    pr.verdict = "structurally non-identifiable";
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
    pr.verdict = "practically non-identifiable";
  }
  return pr;
}

std::vector<Profile> profile_all(const ResidualModel& model, const FitResult& best, const FitOptions& fo,
                                 const ProfileOptions& po) {
  std::vector<Profile> out;
  const int count = best.num_free;
  for (size_t k = 0; k < best.parameters.size(); ++k)
    if (best.parameters[k].free) {
      if (po.progress) po.progress(best.parameters[k].name, static_cast<int>(out.size()) + 1, count);
      out.push_back(profile_parameter(model, best, static_cast<int>(k), fo, po));
    }
  return out;
}

}  // namespace quadgen::fit
