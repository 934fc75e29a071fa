#include "fit/fit_report.hpp"

#include <algorithm>
#include <cmath>

#include "runtime/plot.hpp"

namespace quadgen::fit {

using output::number_or_null;

output::Estimate estimate_of(const FitParameter& p, const Profile* profile, bool at_bound) {
  output::Estimate e{p.value, p.unit, NAN, NAN, "", at_bound};
  if (profile) e.lower = profile->lower, e.upper = profile->upper, e.identifiability = identifiability_text(profile->verdict);
  return e;
}

nlohmann::ordered_json fit_json(const FitResult& r, const std::vector<Profile>& profiles) {
  using J = nlohmann::ordered_json;
  J j;
  J est = J::object();
  for (size_t i = 0; i < r.parameters.size(); ++i) {
    const auto& p = r.parameters[i];
    const Profile* profile = nullptr;
    for (const auto& pr : profiles)
      if (pr.index == static_cast<int>(i)) profile = &pr;
    const bool at_bound = std::find(r.at_bound.begin(), r.at_bound.end(), p.name) != r.at_bound.end();
    J e = output::estimate_json(estimate_of(p, profile, at_bound));
    e["fitted"] = p.free;
    e["standard_error"] = number_or_null(r.standard_errors[i]);
    e["bounds"] = {p.lower, p.upper};
    if (profile) {
      e["interval_method"] = "profile likelihood";
      if (!profile->compensated_by.empty()) e["compensated_by"] = profile->compensated_by;
    }
    est[p.name] = e;
  }
  j["estimates"] = est;
  J ch = J::array();
  for (const auto& c : r.channels)
    ch.push_back({{"channel", c.name}, {"samples", c.count}, {"sigma", c.sigma}, {"lag1_autocorrelation", c.lag1},
                  {"effective_samples", c.effective_n}});
  j["noise"] = ch;
  j["chi2"] = r.chi2;
  j["residuals"] = r.num_residuals;
  j["free_parameters"] = r.num_free;
  j["converged"] = r.converged;
  j["solver"] = r.solver_report;
  j["parameters_at_bounds"] = r.at_bound;
  if (!profiles.empty())
    j["thresholds"] = {{"pointwise_chi2_1_95", profiles.front().threshold_pointwise},
                       {"simultaneous_chi2_k_95", profiles.front().threshold_simultaneous}};
  J prof = J::object();
  for (const auto& pr : profiles) {
    J pts = J::array();
    for (const auto& q : pr.points) pts.push_back({q.value, q.delta_chi2});
    prof[pr.parameter] = pts;
  }
  j["profiles"] = prof;
  return j;
}

std::vector<runtime::Panel> profile_panels(const std::vector<Profile>& profiles) {
  std::vector<runtime::Panel> panels;
  for (const auto& pr : profiles) {
    runtime::Panel p{pr.parameter + " (" + identifiability_text(pr.verdict) + ")", pr.parameter, "delta chi2", {}};
    runtime::Series s{"profile", {}, {}};
    for (const auto& q : pr.points) {
      s.x.push_back(q.value);
      s.y.push_back(q.delta_chi2);
    }
    const double a = s.x.front(), b = s.x.back();
    p.series.push_back(s);
    p.series.push_back({"pointwise 95 %", {a, b}, {pr.threshold_pointwise, pr.threshold_pointwise}});
    p.series.push_back({"simultaneous 95 %", {a, b}, {pr.threshold_simultaneous, pr.threshold_simultaneous}});
    panels.push_back(p);
  }
  return panels;
}

}  // namespace quadgen::fit
