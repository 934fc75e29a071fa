// Beyond the catalogue: when the residual of the final model still has structure, propose a
// term for it by sparse regression over physical regressors (sequentially thresholded least
// squares, as in SINDy: Brunton, Proctor & Kutz, PNAS 113(15), 2016), with the sparsity
// chosen by cross-validation across flights (or across time blocks of one flight) on the
// training part, and the gain measured on the held-out part, which no fit saw but which also
// decides whether the term is proposed (as it decides which catalogue effects are named): a
// gate, so the gain it reports is not an untouched test score. The result is a proposal with
// its regressors, coefficients and intervals; what it means physically is the user's call.
#pragma once
#include <string>
#include <vector>

#include "derive/added_terms.hpp"
#include "fit/flight_data.hpp"

namespace quadgen::diagnose {

// Candidate regressors, sampled like the flight: the constant, body velocity (with a pose),
// body rates, the mean rotor command about its mean (dU = U - mean U), battery voltage about
// its mean (dvbat, when logged), and every pairwise product of the non-constant ones
// (v_bx*dU is rotor drag's form about hover, v_bx*v_bx parasitic drag's, p*q a gyroscopic
// coupling).
struct RegressorLibrary {
  std::vector<std::string> names, units;
  std::vector<std::vector<double>> columns;  // columns[regressor][sample]
  std::vector<std::pair<std::string, double>> centres;  // ("dU", mean U), ("dvbat", mean vbat)
};
// centres: given (the training part's), or empty to take the means of this flight.
RegressorLibrary physical_regressors(const fit::Flight& flight,
                                     const std::vector<std::pair<std::string, double>>& centres = {});

struct DiscoveryOptions {
  // Sparsity levels tried: a term stays only if its RMS contribution is at least this
  // fraction of the channel's residual RMS. "No term" is always a candidate too.
  std::vector<double> thresholds = {0.01, 0.02, 0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 1.0};
  int time_folds = 5;        // cross-validation blocks when only one flight is trained on
  int validation_folds = 4;  // blocks of the held-out part for the gain's spread
  // At most this many terms per channel: a proposal a person can read (sparser levels are
  // tried until the fit on the whole training part has no more).
  int max_terms = 4;
};

struct TermCoefficient {
  std::string regressor, unit;  // unit of the coefficient
  double value = 0, lower = 0, upper = 0;  // 95 % interval, widened for autocorrelated residuals
};

// The term proposed for one channel (added to the model's side: measured - model), or why
// none is.
struct DiscoveredTerm {
  std::string channel, unit;
  std::vector<TermCoefficient> coefficients;
  std::vector<std::pair<std::string, double>> centres;  // what dU and dvbat are taken about
  double threshold = 0;           // chosen sparsity level (0 when no term)
  std::string cross_validation;   // "leave one flight out, 5 flights" or "5 time blocks"
  std::vector<double> cv_error;   // per level tried, "no term" last: mean squared error
  double train_rms_before = 0, train_rms_after = 0;
  double valid_rms_before = 0, valid_rms_after = 0;
  std::vector<double> fold_gains;  // held-out RMS before - after, per validation block
  double gain_mean = 0, gain_standard_error = 0;
  bool proposed = false;
  // The verdict in two parts, so that each report says the label once, in its own way:
  // "proposed", "not proposed" or "no term", and why (the held-out gain, or what the search found).
  std::string verdict_label, verdict_reason;
  std::string verdict() const { return verdict_label + ": " + verdict_reason; }  // diagnosis.json's words
  std::string expression() const;  // "pdot += 0.12 v_bx*U - 3.1 (1)" style, for reports
};

// residual_*: rows x channels (model - measurement) at the flight's samples (one row per
// sample of `train` / `valid`). flight_starts: where each flight begins on the clock (one
// entry for a single flight).
std::vector<DiscoveredTerm> discover_terms(const fit::Flight& train, const std::vector<double>& residual_train,
                                           const fit::Flight& valid, const std::vector<double>& residual_valid,
                                           const std::vector<std::string>& channels,
                                           const std::vector<std::string>& units,
                                           const std::vector<double>& flight_starts, const DiscoveryOptions& opt = {});

}  // namespace quadgen::diagnose

namespace quadgen::diagnose {

// The proposed terms in the form the symbolic model takes them (derive's AddedTerm).
std::vector<AddedTerm> proposed_terms(const std::vector<DiscoveredTerm>& terms);

}  // namespace quadgen::diagnose
