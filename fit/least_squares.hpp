// Weighted nonlinear least squares with Ceres: parameters with bounds and a free/fixed
// flag, residuals from a model that supplies its own analytic Jacobian, per-channel noise
// levels estimated from the fit, autocorrelation accounted for by effective sample sizes,
// and the covariance of the free parameters. The problem (ResidualModel) is kept apart
// from the solver (fit_least_squares) and its options (FitOptions).
#pragma once
#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "runtime/parameter.hpp"

namespace quadgen::fit {

// The model's parameter record (runtime/parameter.hpp): `free` marks the ones this solve fits.
using FitParameter = runtime::Parameter;

// r(p) and dr/dp over all parameters (row-major, num_residuals x num_params).
class ResidualModel {
 public:
  virtual ~ResidualModel() = default;
  virtual int num_residuals() const = 0;
  virtual void evaluate(const double* p, double* r, double* J) const = 0;
  // Channel of each residual (e.g. "rpm", "ax"): noise and autocorrelation are per channel.
  virtual int channel_of(int residual) const = 0;
  virtual std::vector<std::string> channels() const = 0;
  // r(p) and the Jacobian columns of the free parameters only (free[j]; empty: all): a
  // model may skip the work for the others and leave their columns unwritten. The mask is
  // an argument of each call, never state of the model, so what one solve fixed cannot
  // leak into the next evaluation.
  virtual void evaluate_free(const double* p, double* r, double* J, const std::vector<bool>& /*free*/) const {
    evaluate(p, r, J);
  }
  // r(p) and the Jacobian columns listed, packed: dr_i/dp[columns[k]] at
  // J[i * columns.size() + k]. The columns are distinct parameter indices (checked: FitError
  // otherwise); an empty list gives r alone. A solve that frees few of many parameters then
  // neither writes nor reads a Jacobian as wide as all of them (for a 40 s flight and the 45
  // parameters of a Crazyflie's model, 8 MB per evaluation, written, read and copied again
  // for the free columns: about 8 % of a diagnosis' time). The default goes through
  // evaluate_free.
  virtual void evaluate_columns(const std::vector<double>& p, double* r, double* J,
                                const std::vector<int>& columns) const;
  // An independent copy for another thread (a model may keep scratch state between
  // evaluations, so one instance serves one thread). nullptr: work on it stays sequential.
  virtual std::unique_ptr<ResidualModel> clone() const { return nullptr; }
};

struct FitError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// evaluate_columns()'s list: distinct indices below num_params, else FitError.
void check_columns(const std::vector<int>& columns, size_t num_params);

// The 97.5 % quantile of the standard normal: a 95 % Wald interval is value ± kZ95 standard
// errors. One constant for every interval and z test of a fit or diagnosis.
constexpr double kZ95 = 1.959963984540054;

struct FitOptions {
  int max_iterations = 200;
  double function_tolerance = 1e-12;
  double parameter_tolerance = 1e-12;
  bool robust = false;           // Huber loss (scale 1 in units of sigma)
  bool account_autocorrelation = true;
  bool verbose = false;
};

struct ChannelStats {
  std::string name;
  int count = 0;
  double sigma = 0;          // residual standard deviation (noise estimate)
  double lag1 = 0;           // lag-1 autocorrelation of the residuals
  double effective_n = 0;    // n (1 - rho) / (1 + rho)
};

struct FitResult {
  std::vector<FitParameter> parameters;  // estimates
  std::vector<double> standard_errors;   // NaN for fixed parameters
  std::vector<std::vector<double>> covariance;  // free parameters, in order of `parameters`
  std::vector<ChannelStats> channels;
  double chi2 = 0;           // weighted residual sum of squares (autocorrelation-scaled)
  int num_residuals = 0;
  int num_free = 0;
  std::vector<std::string> at_bound;  // free parameters that ended on a bound
  std::vector<double> weights;        // per channel: multiplies residuals
  bool converged = false;
  std::string solver_report;
};

// The parameters' current values, in order (what ResidualModel::evaluate takes).
std::vector<double> parameter_values(const std::vector<FitParameter>& ps);

// RMS of each of `nc` channels of residuals r, residual i belonging to channel_of(i) (the
// one home of this sum: validation tables of fit and diagnose).
template <class ChannelOf>
std::vector<double> rms_by_channel(const std::vector<double>& r, size_t nc, ChannelOf channel_of) {
  std::vector<double> ss(nc, 0.0);
  std::vector<size_t> n(nc, 0);
  for (size_t i = 0; i < r.size(); ++i) {
    const size_t c = static_cast<size_t>(channel_of(i));
    ss[c] += r[i] * r[i];
    ++n[c];
  }
  for (size_t c = 0; c < nc; ++c) ss[c] = std::sqrt(ss[c] / static_cast<double>(std::max<size_t>(1, n[c])));
  return ss;
}

// RMS of each channel of a residual model at the given parameters.
std::vector<double> channel_rms(const ResidualModel& m, const std::vector<FitParameter>& ps);

// Whether p's value sits on its lower or upper bound (to 1e-9 of the bounds' span where the
// span exceeds 1; to 1e-9 absolute below that).
bool on_bound(const FitParameter& p);
// Whether p's value sits at x, to on_bound's tolerance (an effect's "off" on a bound).
bool sits_at(const FitParameter& p, double x);

// Two passes: fit, estimate sigma and autocorrelation per channel, refit with weights.
FitResult fit_least_squares(const ResidualModel& model, std::vector<FitParameter> params, const FitOptions& opt);

// One weighted solve from the given start with fixed channel weights (used by profiles).
// Returns chi2 and updates params in place.
double solve_weighted(const ResidualModel& model, std::vector<FitParameter>& params,
                      const std::vector<double>& channel_weights, const FitOptions& opt, bool* converged = nullptr,
                      std::string* report = nullptr);

}  // namespace quadgen::fit
