// fit.json (estimates, standard errors, profile-likelihood intervals, verdicts, noise per
// channel) and the profile plots.
#pragma once
#include "runtime/plot.hpp"
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "output/estimate.hpp"
#include "fit/least_squares.hpp"
#include "fit/profile_likelihood.hpp"

namespace quadgen::fit {

// A fitted parameter as output::Estimate: its profile's interval and verdict when it was
// profiled (nullptr: not profiled, the interval stays null).
output::Estimate estimate_of(const FitParameter& p, const Profile* profile, bool at_bound);

nlohmann::ordered_json fit_json(const FitResult& r, const std::vector<Profile>& profiles);

// One panel per profile: delta chi2 against the parameter, with both thresholds (for
// runtime::render_svg, and runtime::panels_csv for the data beside the plot).
std::vector<runtime::Panel> profile_panels(const std::vector<Profile>& profiles);

}  // namespace quadgen::fit
