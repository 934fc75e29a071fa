// fit.json (estimates, standard errors, profile-likelihood intervals, verdicts, noise per
// channel) and the profile plots.
#pragma once
#include "plot.hpp"
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "least_squares.hpp"
#include "profile_likelihood.hpp"

namespace quadgen::fit {

// A number in JSON, or null for NaN and infinities (an open interval side, a missing value).
nlohmann::ordered_json number_or_null(double v);

nlohmann::ordered_json fit_json(const FitResult& r, const std::vector<Profile>& profiles);

// One panel per profile: delta chi2 against the parameter, with both thresholds (for
// runtime::render_svg, and runtime::panels_csv for the data beside the plot).
std::vector<runtime::Panel> profile_panels(const std::vector<Profile>& profiles);

}  // namespace quadgen::fit
