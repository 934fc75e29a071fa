// Profile likelihood (Raue et al., Bioinformatics 25(15):1923-1929, 2009): for each fitted
// parameter, fix it along a grid, re-optimise the others, and read confidence intervals
// off the crossings of chi2 quantile thresholds. The profile's shape gives the verdict:
// identifiable (crosses on both sides), practically non-identifiable (open on a side),
// structurally non-identifiable (flat: other parameters compensate exactly).
#pragma once
#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "fit/least_squares.hpp"

namespace quadgen::fit {

// The profile's shape in a word (Raue et al.): both sides cross the threshold; a side stays
// open; the profile is flat (another parameter compensates exactly).
enum class Identifiability { kIdentifiable, kPracticallyNonIdentifiable, kStructurallyNonIdentifiable };
// "identifiable", "practically non-identifiable", "structurally non-identifiable": the words
// of fit.json's and diagnosis.json's "identifiability" (docs/formats.md).
const char* identifiability_text(Identifiability verdict);
// The same, or "" for a verdict not assessed (a suspect's values, which are not profiled).
inline const char* identifiability_text(const std::optional<Identifiability>& verdict) {
  return verdict ? identifiability_text(*verdict) : "";
}

struct ProfilePoint {
  double value;
  double delta_chi2;            // chi2(value) - chi2(best)
  std::vector<double> others;   // re-optimised parameter vector at this point
};

struct Profile {
  std::string parameter;
  int index = -1;
  std::vector<ProfilePoint> points;  // sorted by value
  double threshold_pointwise = 0;    // chi2_{1, 0.95}
  double threshold_simultaneous = 0; // chi2_{#free, 0.95}
  double lower = 0, upper = 0;       // 95 % pointwise interval (NaN side = open)
  bool lower_open = false, upper_open = false;
  Identifiability verdict = Identifiability::kIdentifiable;
  std::string compensated_by;  // for a flat profile: which parameters move with it, and how
};

// Whether the profile's 95 % interval holds zero, an open side (NaN) reaching `p`'s bound.
// "Identifiable" says the profile closes, not that the value is told from zero (a newcomer
// read a2 = -656 [-1630, 318] "identifiable" as significant: helper-143).
inline bool interval_holds_zero(const Profile& pr, const FitParameter& p) {
  const double lower = std::isnan(pr.lower) ? p.lower : pr.lower, upper = std::isnan(pr.upper) ? p.upper : pr.upper;
  return lower <= 0 && upper >= 0;
}

struct ProfileOptions {
  int max_steps_each_side = 30;
  double confidence = 0.95;
  // How far each side is walked: past the pointwise threshold (what the intervals and the
  // verdict need), or on past the simultaneous one (for a plot of the joint region).
  bool walk_past_simultaneous = false;
  // profile_all: sides of profiles run on this many threads (0: one per core), each with
  // its own copy of the model (ResidualModel::clone); a model without copies runs on one.
  int threads = 1;
  // Called as each parameter's profile is finished (profiles of many parameters take
  // minutes): its name, how many are done, of how many, and its wall-clock seconds.
  std::function<void(const std::string& parameter, int done, int count, double seconds)> progress;
};

Profile profile_parameter(const ResidualModel& model, const FitResult& best, int index, const FitOptions& fo,
                          const ProfileOptions& po);
// Profiles of the free parameters in `which` (indices into best.parameters; empty: all
// free ones), in that order.
std::vector<Profile> profile_all(const ResidualModel& model, const FitResult& best, const FitOptions& fo,
                                 const ProfileOptions& po, const std::vector<int>& which = {});

double chi2_quantile(double p, double dof);

}  // namespace quadgen::fit
