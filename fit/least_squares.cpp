#include "fit/least_squares.hpp"
#include "fit/normal_matrix.hpp"
#include "runtime/dynamic_model.hpp"  // free_columns

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>

#include <ceres/ceres.h>
#include <Eigen/Dense>
#if __has_include(<glog/logging.h>)  // Ceres 2.1 and 2.2 (Debian 12) log through glog
#include <glog/logging.h>
#define QUADGEN_CERES_LOGS_THROUGH_GLOG 1
#endif

namespace quadgen::fit {

void check_columns(const std::vector<int>& columns, size_t num_params) {
  std::vector<bool> seen(num_params, false);
  for (int c : columns) {
    if (c < 0 || static_cast<size_t>(c) >= num_params || seen[static_cast<size_t>(c)])
      throw FitError("Jacobian columns: " + std::to_string(c) + (c >= 0 && static_cast<size_t>(c) < num_params
                                                                     ? " asked for twice"
                                                                     : " is no parameter index"));
    seen[static_cast<size_t>(c)] = true;
  }
}

void ResidualModel::evaluate_columns(const std::vector<double>& p, double* r, double* J,
                                     const std::vector<int>& columns) const {
  check_columns(columns, p.size());
  if (!J || columns.empty()) return evaluate(p.data(), r, nullptr);
  const size_t n = p.size(), nc = columns.size(), nr = static_cast<size_t>(num_residuals());
  std::vector<bool> free(n, false);
  for (int c : columns) free[static_cast<size_t>(c)] = true;
  // Reused: a fit evaluates thousands of times, and an array of nr x n allocated afresh
  // each time costs page faults and zero-filling (one per thread: fits run on several).
  thread_local std::vector<double> full;
  full.resize(nr * n);
  evaluate_free(p.data(), r, full.data(), free);
  for (size_t i = 0; i < nr; ++i)
    for (size_t k = 0; k < nc; ++k) J[i * nc + k] = full[i * n + static_cast<size_t>(columns[k])];
}

namespace {

// All parameters in one block; the residual model's Jacobian is passed through, each row
// scaled by its channel's weight.
// A point whose residuals or (free) Jacobian columns are not finite is reported as not
// evaluable: Ceres then rejects the step, or fails at the start (solve_weighted throws).
// Fixed columns are set to zero: a model may leave them unwritten (evaluate_free), and Ceres
// reads every entry of the block (the SubsetManifold product, its finiteness check). Used
// where all parameters must be one block: the covariance, and a cost with nothing free.
class WeightedCost : public ceres::CostFunction {
 public:
  WeightedCost(const ResidualModel& m, int n_params, const std::vector<double>& w, std::vector<bool> free)
      : m_(m), n_(n_params), w_(w), free_(std::move(free)) {
    set_num_residuals(m.num_residuals());
    mutable_parameter_block_sizes()->push_back(n_params);
  }
  bool Evaluate(double const* const* p, double* r, double** J) const override {
    const int nr = m_.num_residuals();
    if (J && J[0]) {
      m_.evaluate_free(p[0], r, J[0], free_);
    } else {
      m_.evaluate(p[0], r, nullptr);
    }
    for (int i = 0; i < nr; ++i) {
      const double w = w_[m_.channel_of(i)];
      r[i] *= w;
      if (!std::isfinite(r[i])) return false;
      if (!(J && J[0])) continue;
      double* row = J[0] + static_cast<size_t>(i) * n_;
      for (int j = 0; j < n_; ++j) {  // a held parameter's column may be left unwritten by the model
        row[j] = free_[j] ? row[j] * w : 0.0;
        if (!std::isfinite(row[j])) return false;
      }
    }
    return true;
  }

 private:
  const ResidualModel& m_;
  int n_;
  std::vector<double> w_;
  std::vector<bool> free_;
};

// The same weighted residuals with only the free parameters as Ceres' parameter block: the
// fixed ones are held inside. Ceres' SubsetManifold over all parameters would multiply every
// Jacobian row by the n x n_free plus-Jacobian, and check and clear all n columns, which was
// the largest single cost of a diagnosis (a per-flight model has 28 and more parameters, of
// which a search step frees few). Selecting columns is exact.
//
// Each free parameter is solved for in units of its own scale (block value = value / scale).
// Ceres stops when a step is below parameter_tolerance * (|x| + parameter_tolerance): over
// raw values, |x| was dominated by the motor map (~1e3 rad/s), so a step of 1e-7 counted as
// converged, while a rotor drag or blade flapping coefficient (~1e-6, ~3e-8) could still
// be moving by several times its size. In scaled units every parameter has to settle to the
// same relative precision. (The trust region is scaled per column already: Jacobi scaling.)
class FreeSubsetCost : public ceres::CostFunction {
 public:
  FreeSubsetCost(const ResidualModel& m, std::vector<double> all, const std::vector<double>& w, const std::vector<bool>& free,
                 std::vector<double> scale)
      : m_(m), all_(std::move(all)), w_(w), columns_(runtime::free_columns(free)),
        scale_(std::move(scale)) {
    set_num_residuals(m.num_residuals());
    mutable_parameter_block_sizes()->push_back(static_cast<int>(columns_.size()));
  }
  // All parameter values with the free ones taken from the (scaled) block.
  std::vector<double> expand(const double* free_values) const {
    std::vector<double> p = all_;
    for (size_t k = 0; k < columns_.size(); ++k) p[columns_[k]] = free_values[k] * scale_[k];
    return p;
  }
  bool Evaluate(double const* const* x, double* r, double** J) const override {
    const std::vector<double> p = expand(x[0]);
    const int nr = m_.num_residuals(), nf = static_cast<int>(columns_.size());
    const bool jacobian = J && J[0];
    if (jacobian) {
      packed_.resize(static_cast<size_t>(nr) * nf);
      m_.evaluate_columns(p, r, packed_.data(), columns_);
    } else {
      m_.evaluate(p.data(), r, nullptr);
    }
    for (int i = 0; i < nr; ++i) {
      const double w = w_[m_.channel_of(i)];
      r[i] *= w;
      if (!std::isfinite(r[i])) return false;
      if (!jacobian) continue;
      const double* in = packed_.data() + static_cast<size_t>(i) * nf;
      double* out = J[0] + static_cast<size_t>(i) * nf;
      for (int k = 0; k < nf; ++k) {
        out[k] = in[k] * w * scale_[k];
        if (!std::isfinite(out[k])) return false;
      }
    }
    return true;
  }

 private:
  const ResidualModel& m_;
  std::vector<double> all_;
  std::vector<double> w_;
  std::vector<int> columns_;
  std::vector<double> scale_;  // per free column
  mutable std::vector<double> packed_;  // the model's Jacobian in the free columns, reused
};

std::vector<bool> free_mask(const std::vector<FitParameter>& ps) {
  std::vector<bool> m;
  for (const auto& p : ps) m.push_back(p.free);
  return m;
}

std::string values_text(const std::vector<FitParameter>& ps) {
  std::ostringstream os;
  for (const auto& p : ps) os << (os.tellp() ? ", " : "") << p.name << " = " << p.value;
  return os.str();
}

// The covariance of the free parameters needs a finite information matrix J^T J (Ceres
// forms it and hands it to Eigen's JacobiSVD, which crashes or never ends on inf/NaN).
void require_finite_information(const Eigen::MatrixXd& Jf, const std::vector<FitParameter>& ps,
                                const std::vector<int>& free_idx) {
  for (Eigen::Index k = 0; k < Jf.cols(); ++k)
    if (!Jf.col(k).allFinite())
      throw FitError("covariance: the Jacobian column of " + ps[free_idx[k]].name +
                     " is not finite at the estimate (" + values_text(ps) + ")");
  const Eigen::MatrixXd info = Jf.transpose() * Jf;
  if (!info.allFinite())
    throw FitError("covariance: J^T J overflows at the estimate (a residual or Jacobian entry beyond ~1e150 in units of "
                   "the noise: a corrupt or mis-scaled sample, or samples the model fits exactly, which leave no noise "
                   "to measure by: identical rows?)");
}


// A free parameter's unit for the solver: its starting magnitude, or for one that starts at
// zero (an effect at its neutral value) half its bound interval. A start far below that
// (a leftover 1e-12 of an earlier fit) is not its size: the scale is at least a thousandth
// of the half interval. Half intervals beyond 1 (in SI units) count as 1: bounds of
// +-1e300 say "unbounded", not "of size 1e300", and would scale the Jacobian to overflow.
// Positive scales keep the bounds' order.
double solve_scale(const FitParameter& p) {
  const double half_width = 0.5 * (p.upper - p.lower);
  const double size = std::isfinite(half_width) && half_width > 0 ? std::min(half_width, 1.0) : 1.0;
  if (p.value == 0 || !std::isfinite(p.value)) return size;
  return std::max(std::fabs(p.value), 1e-3 * size);
}

// The solver's settings: each says why it is what it is.
ceres::Solver::Options solver_options(const FitOptions& opt) {
  ceres::Solver::Options so;
  // Normal equations: the Jacobians are tall and thin (a joint diagnosis has 77 000 rows and
  // a few dozen free columns), where Householder QR of J costs twice the flops of forming
  // J^T J and does them unblocked; the five-flight joint diagnosis went from 385 to 268 s
  // with every printed finding and interval the same (docs/benchmarks.md). The columns are
  // in units of each parameter's scale and Levenberg-Marquardt damps the diagonal, so the
  // squared condition number costs nothing a converged fit shows.
  so.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  so.max_num_iterations = opt.max_iterations;
  so.function_tolerance = opt.function_tolerance;
  so.parameter_tolerance = opt.parameter_tolerance;
  so.gradient_tolerance = 1e-14;
  // With bounds, every trust-region step is followed by a projected line search. Cubic
  // interpolation asks for the gradient, i.e. a whole Jacobian, at each trial point: three
  // quarters of a diagnosis' Jacobians were line-search trials (docs/benchmarks.md).
  // Quadratic interpolation needs only the cost there, about a tenth of the work.
  so.line_search_interpolation_type = ceres::QUADRATIC;
  so.minimizer_progress_to_stdout = opt.verbose;
  so.num_threads = 1;
  return so;
}

// Twice the cost of a fit with no free parameter, evaluated where the parameters are.
double cost_without_free_parameters(const ResidualModel& model, const std::vector<FitParameter>& params,
                                    const std::vector<double>& w, const FitOptions& opt) {
  ceres::Problem::Options po;
  po.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem problem(po);
  std::vector<double> all = parameter_values(params);
  const int n = static_cast<int>(params.size());
  problem.AddResidualBlock(new WeightedCost(model, n, w, free_mask(params)), opt.robust ? new ceres::HuberLoss(1.0) : nullptr,
                           all.data());
  double cost = 0;
  if (!problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr, nullptr) || !std::isfinite(cost))
    throw FitError("least squares: a residual is not finite at " + values_text(params));
  return 2 * cost;
}

}  // namespace

double solve_weighted(const ResidualModel& model, std::vector<FitParameter>& params, const std::vector<double>& w,
                      const FitOptions& opt, bool* converged, std::string* report) {
  const int n = static_cast<int>(params.size());
  const std::vector<double> x = parameter_values(params);
  const std::vector<bool> free = free_mask(params);
  std::vector<double> xf, scale;  // the free values in units of their scale: Ceres' parameter block
  for (int i = 0; i < n; ++i)
    if (free[i]) {
      scale.push_back(solve_scale(params[i]));
      xf.push_back(x[i] / scale.back());
    }
  if (xf.empty()) {
    const double cost = cost_without_free_parameters(model, params, w, opt);
    if (converged) *converged = true;
    return cost;
  }
  ceres::Problem::Options po;
  po.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem problem(po);
  ceres::LossFunction* loss = opt.robust ? new ceres::HuberLoss(1.0) : nullptr;
  auto* cost_function = new FreeSubsetCost(model, x, w, free, scale);
  problem.AddResidualBlock(cost_function, loss, xf.data());
  for (int i = 0, k = 0; i < n; ++i) {
    if (!free[i]) continue;
    if (params[i].lower < params[i].upper) {
      problem.SetParameterLowerBound(xf.data(), k, params[i].lower / scale[k]);
      problem.SetParameterUpperBound(xf.data(), k, params[i].upper / scale[k]);
    }
    ++k;
  }
  const ceres::Solver::Options so = solver_options(opt);
  ceres::Solver::Summary summary;
  // Ceres' own warnings ("Linear solver failure ... Unable to perform dense Cholesky
  // factorization", through glog) reached the terminal between quadgen's lines: the fit's
  // outcome, said in quadgen's words, is what a user reads (a review, helper-135). Errors pass.
#ifdef QUADGEN_CERES_LOGS_THROUGH_GLOG  // process-wide, once: quadgen is the program that logs
  static const bool quiet = [] {
    FLAGS_minloglevel = std::max(FLAGS_minloglevel, static_cast<int>(google::GLOG_ERROR));
    return true;
  }();
  (void)quiet;
#endif
  ceres::Solve(so, &problem, &summary);
  // FAILURE is an evaluation or linear-solver error, most often a residual or Jacobian
  // entry that is not finite at the start; its cost (-1 when never evaluated) means nothing.
  if (summary.termination_type == ceres::FAILURE || !std::isfinite(summary.initial_cost) || !std::isfinite(summary.final_cost))
    throw FitError("least squares failed (" + summary.message + ") starting from " + values_text(params) +
                   ": a residual or Jacobian entry is not finite there");
  // Back in the parameters' units: a value Ceres left on a bound (bound / scale) times the
  // scale can miss the bound by an ulp, outside it, where the next fit could not start.
  const std::vector<double> solved = cost_function->expand(xf.data());
  for (int i = 0; i < n; ++i)
    params[i].value = free[i] && params[i].lower < params[i].upper
                          ? std::clamp(solved[i], params[i].lower, params[i].upper)
                          : solved[i];
  if (converged) *converged = summary.termination_type == ceres::CONVERGENCE;
  if (report) *report = summary.BriefReport();
  return 2 * summary.final_cost;
}

namespace {

// Refuses a fit that cannot be made: fewer residuals than free parameters, or a free
// parameter without bounds. Returns the number of free parameters.
int check_fit_inputs(int num_residuals, const std::vector<FitParameter>& params) {
  int n_free = 0;
  for (const auto& p : params) n_free += p.free;
  if (num_residuals <= n_free)
    throw FitError("too few samples: " + std::to_string(num_residuals) + " residuals for " + std::to_string(n_free) +
                   " free parameters");
  for (const auto& p : params)
    if (p.free && !(p.lower < p.upper))
      throw FitError("parameter " + p.name + " is to be fitted but has no bounds (add bounds: [lower, upper])");
  return n_free;
}

// Each channel's noise from the residuals at `params`: its sigma (the degrees of freedom
// shared out over the channels in proportion to their size), lag-1 autocorrelation and
// effective sample size, into `channels`; the weights that make every channel count in
// units of its own noise, into `w`.
void estimate_channel_noise(const ResidualModel& model, const std::vector<FitParameter>& params, int n_free,
                            const FitOptions& opt, std::vector<ChannelStats>& channels, std::vector<double>& w) {
  const int nr = model.num_residuals(), nc = static_cast<int>(channels.size());
  std::vector<double> r(nr);
  model.evaluate(parameter_values(params).data(), r.data(), nullptr);
  std::vector<std::vector<double>> per(nc);
  for (int i = 0; i < nr; ++i) {
    if (!std::isfinite(r[i]))
      throw FitError("residual " + std::to_string(i) + " (channel " + channels[model.channel_of(i)].name +
                     ") is not finite at " + values_text(params));
    per[model.channel_of(i)].push_back(r[i]);
  }
  for (int c = 0; c < nc; ++c) {
    auto& s = channels[c];
    const auto& v = per[c];
    s.count = static_cast<int>(v.size());
    if (v.size() < 2) throw FitError("channel " + s.name + " has fewer than 2 samples");
    const double mean = std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
    double ss = 0, lag = 0, rss = 0;
    for (size_t i = 0; i < v.size(); ++i) {
      ss += (v[i] - mean) * (v[i] - mean);
      rss += v[i] * v[i];
      if (i) lag += (v[i] - mean) * (v[i - 1] - mean);
    }
    const double dof = static_cast<double>(v.size()) * (1.0 - static_cast<double>(n_free) / nr);
    s.sigma = std::sqrt(rss / std::max(dof, 1.0));
    if (!std::isfinite(s.sigma))
      throw FitError("channel " + s.name + ": the residuals' sum of squares overflows (residuals beyond ~1e150: a "
                     "corrupt or mis-scaled sample?)");
    if (!(s.sigma > 0)) s.sigma = 1e-300;
    s.lag1 = ss > 0 ? std::clamp(lag / ss, -0.99, 0.99) : 0.0;
    const double rho = opt.account_autocorrelation ? std::max(0.0, s.lag1) : 0.0;
    s.effective_n = static_cast<double>(v.size()) * (1 - rho) / (1 + rho);
    w[c] = std::sqrt(s.effective_n / static_cast<double>(v.size())) / s.sigma;
  }
}

// Covariance of the free parameters: the pseudo-inverse of the weighted Gauss-Newton
// normal matrix, scaled to unit diagonal first (normal_matrix.hpp). Ceres' covariance
// with a relative cut-off on the raw matrix dropped the weakest direction when the
// parameters' units differ by many orders (c_w beside rotor_drag.k, a motor map term in
// rad/s) and reported a standard error near zero along it.
void free_parameter_covariance(const ResidualModel& model, const std::vector<FitParameter>& params,
                               const std::vector<double>& w, FitResult& res) {
  std::vector<int> free_idx;
  for (int i = 0; i < static_cast<int>(params.size()); ++i)
    if (params[i].free) free_idx.push_back(i);
  const Eigen::MatrixXd Jf = weighted_free_jacobian(model, params, w);
  require_finite_information(Jf, params, free_idx);
  const Eigen::MatrixXd C = analyse_normal_matrix(Jf.transpose() * Jf).covariance;
  if (!C.allFinite()) throw FitError("covariance of the free parameters is not finite at " + values_text(params));
  const bool singular = columns_dependent(Jf);
  res.standard_errors.assign(params.size(), std::numeric_limits<double>::quiet_NaN());
  const size_t nf = free_idx.size();
  res.covariance.assign(nf, std::vector<double>(nf));
  for (size_t a = 0; a < nf; ++a) {
    for (size_t b = 0; b < nf; ++b) res.covariance[a][b] = C(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b));
    const double variance = C(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(a));
    res.standard_errors[free_idx[a]] = singular ? std::numeric_limits<double>::infinity() : std::sqrt(std::max(0.0, variance));
  }
  for (int i : free_idx)
    if (on_bound(params[i])) res.at_bound.push_back(params[i].name);
}

}  // namespace

FitResult fit_least_squares(const ResidualModel& model, std::vector<FitParameter> params, const FitOptions& opt) {
  const int nr = model.num_residuals();
  const int n_free = check_fit_inputs(nr, params);
  const auto channels = model.channels();
  FitResult res;
  res.channels.resize(channels.size());
  for (size_t c = 0; c < channels.size(); ++c) res.channels[c].name = channels[c];
  std::vector<double> w(channels.size(), 1.0);
  // Noise per channel from the residuals: first at the starting point (so that no channel's
  // units dominate the first solve), then at the estimate, re-solving in between.
  estimate_channel_noise(model, params, n_free, opt, res.channels, w);
  for (int pass = 0; pass < 2; ++pass) {
    solve_weighted(model, params, w, opt);
    estimate_channel_noise(model, params, n_free, opt, res.channels, w);
  }
  // Pass 2: weighted, so chi2 is in units of the noise with autocorrelation accounted for.
  bool conv = false;
  res.chi2 = solve_weighted(model, params, w, opt, &conv, &res.solver_report);
  res.converged = conv;
  res.weights = w;
  res.num_residuals = nr;
  res.num_free = n_free;
  free_parameter_covariance(model, params, w, res);
  res.parameters = params;
  return res;
}

std::vector<double> channel_rms(const ResidualModel& m, const std::vector<FitParameter>& ps) {
  const std::vector<double> p = parameter_values(ps);
  std::vector<double> r(m.num_residuals());
  m.evaluate(p.data(), r.data(), nullptr);
  return rms_by_channel(r, m.channels().size(), [&](size_t i) { return m.channel_of(static_cast<int>(i)); });
}

bool sits_at(const FitParameter& p, double x) {
  return std::fabs(p.value - x) < 1e-9 * std::max(1.0, std::fabs(p.upper - p.lower));
}

bool on_bound(const FitParameter& p) { return sits_at(p, p.lower) || sits_at(p, p.upper); }

std::vector<double> parameter_values(const std::vector<FitParameter>& ps) {
  std::vector<double> v;
  for (const auto& p : ps) v.push_back(p.value);
  return v;
}

}  // namespace quadgen::fit
