#include "diagnose/term_discovery.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <Eigen/Dense>
#include <boost/math/distributions/normal.hpp>

#include "runtime/attitude.hpp"
#include "fit/least_squares.hpp"
#include "diagnose/residual_analysis.hpp"
#include "diagnose/validation.hpp"
#include "output/numbers.hpp"
#include "runtime/rigid_body_state.hpp"

namespace quadgen::diagnose {

RegressorLibrary physical_regressors(const fit::Flight& f, const std::vector<std::pair<std::string, double>>& given) {
  const size_t ns = f.samples.size();
  std::vector<std::string> names, units;
  std::vector<std::vector<double>> base;
  std::vector<std::pair<std::string, double>> centres;
  auto add = [&](const std::string& name, const std::string& unit, auto fn) {
    std::vector<double> v(ns);
    for (size_t k = 0; k < ns; ++k) v[k] = fn(f.samples[k]);
    names.push_back(name), units.push_back(unit), base.push_back(std::move(v));
  };
  // Body velocity exists only where a pose was logged (differentiated): without one the
  // velocity states are not measured.
  if (f.has_pose)
    for (int a = 0; a < 3; ++a)
      add(std::string("v_b") + "xyz"[a], "m/s",
          [a](const fit::FlightSample& s) { return runtime::rigid_body::body_velocity(s.x.data())[a]; });
  for (int a = 0; a < 3; ++a)
    add(std::string(1, "pqr"[a]), "rad/s",
        [a](const fit::FlightSample& s) { return s.x[runtime::rigid_body::kBodyRate + a]; });
  // The mean command and the battery voltage are taken about their means over the flight
  // given: their zero lies far outside what a flight visits, and products and powers of
  // uncentred signals give large coefficients that cancel each other.
  auto centred = [&](const std::string& name, const std::string& unit, auto fn) {
    double mean = 0;
    for (const auto& s : f.samples) mean += fn(s) / static_cast<double>(std::max<size_t>(1, ns));
    for (const auto& [n, m] : given)
      if (n == name) mean = m;
    add(name, unit, [&](const fit::FlightSample& s) { return fn(s) - mean; });
    centres.emplace_back(name, mean);
  };
  centred("dU", "1", [](const fit::FlightSample& s) {
    double sum = 0;
    for (double u : s.u) sum += u;
    return s.u.empty() ? 0.0 : sum / static_cast<double>(s.u.size());
  });
  if (f.has_vbat) centred("dvbat", "V", [](const fit::FlightSample& s) { return s.vbat; });

  RegressorLibrary lib;
  lib.centres = centres;
  lib.names.push_back("1"), lib.units.push_back(""), lib.columns.emplace_back(ns, 1.0);
  for (size_t i = 0; i < base.size(); ++i)
    lib.names.push_back(names[i]), lib.units.push_back(units[i]), lib.columns.push_back(base[i]);
  for (size_t i = 0; i < base.size(); ++i)
    for (size_t j = i; j < base.size(); ++j) {
      std::vector<double> v(ns);
      for (size_t k = 0; k < ns; ++k) v[k] = base[i][k] * base[j][k];
      lib.names.push_back(names[i] + "*" + names[j]);
      lib.units.push_back(units[i] == units[j] ? "(" + units[i] + ")^2" : units[i] + "*" + units[j]);
      lib.columns.push_back(std::move(v));
    }
  return lib;
}

namespace {

using Matrix = Eigen::MatrixXd;
using Vector = Eigen::VectorXd;

// Sufficient statistics of a least-squares problem over some rows, in scaled columns:
// everything the thresholded fits and their cross-validation errors need.
struct Normal {
  Matrix G;  // X^T X
  Vector b;  // X^T y
  double yy = 0;
  double n = 0;
  Normal& operator+=(const Normal& o) {
    G += o.G, b += o.b, yy += o.yy, n += o.n;
    return *this;
  }
  double sse(const Vector& xi) const { return yy - 2 * xi.dot(b) + xi.dot(G * xi); }
};

Normal normal_of(const Matrix& X, const Vector& y, const std::vector<size_t>& rows) {
  Normal s{Matrix::Zero(X.cols(), X.cols()), Vector::Zero(X.cols()), 0, 0};
  for (size_t r : rows) {
    const auto x = X.row(static_cast<Eigen::Index>(r));
    s.G.noalias() += x.transpose() * x;
    s.b += x.transpose() * y(static_cast<Eigen::Index>(r));
    s.yy += y(static_cast<Eigen::Index>(r)) * y(static_cast<Eigen::Index>(r));
    s.n += 1;
  }
  return s;
}

// Least squares on the active columns only (a small ridge keeps collinear products solvable).
Vector solve_active(const Normal& s, const std::vector<bool>& active) {
  std::vector<Eigen::Index> idx;
  for (size_t j = 0; j < active.size(); ++j)
    if (active[j]) idx.push_back(static_cast<Eigen::Index>(j));
  Vector xi = Vector::Zero(s.b.size());
  if (idx.empty()) return xi;
  const auto k = static_cast<Eigen::Index>(idx.size());
  Matrix A(k, k);
  Vector c(k);
  for (Eigen::Index i = 0; i < k; ++i) {
    c(i) = s.b(idx[i]);
    for (Eigen::Index j = 0; j < k; ++j) A(i, j) = s.G(idx[i], idx[j]);
  }
  A.diagonal().array() += 1e-9 * std::max(1.0, A.diagonal().mean());
  const Vector sol = A.ldlt().solve(c);
  for (Eigen::Index i = 0; i < k; ++i) xi(idx[i]) = sol(i);
  return xi;
}

// Sequentially thresholded least squares: fit, drop every term whose RMS contribution (the
// coefficient in scaled columns) is below `threshold` of the residual's RMS, refit, until
// the active set stops changing.
Vector stlsq(const Normal& s, double threshold) {
  const double cut = threshold * std::sqrt(s.yy / std::max(1.0, s.n));
  std::vector<bool> active(static_cast<size_t>(s.b.size()), true);
  Vector xi = solve_active(s, active);
  for (int it = 0; it < 25; ++it) {
    std::vector<bool> next(active.size());
    for (size_t j = 0; j < active.size(); ++j) next[j] = active[j] && std::abs(xi(static_cast<Eigen::Index>(j))) >= cut;
    if (next == active) break;
    active = next;
    xi = solve_active(s, active);
  }
  return xi;
}

// Folds for cross-validation: each flight's rows (several flights), else contiguous blocks.
std::vector<std::vector<size_t>> cv_folds(const fit::Flight& train, const std::vector<double>& flight_starts,
                                          int time_folds, std::string* how) {
  const size_t ns = train.samples.size();
  std::vector<std::vector<size_t>> by_flight(std::max<size_t>(1, flight_starts.size()));
  for (size_t k = 0; k < ns; ++k) {
    size_t i = 0;
    while (i + 1 < flight_starts.size() && train.samples[k].t >= flight_starts[i + 1]) ++i;
    by_flight[i].push_back(k);
  }
  by_flight.erase(std::remove_if(by_flight.begin(), by_flight.end(), [](const auto& f) { return f.size() < 20; }),
                  by_flight.end());
  if (by_flight.size() >= 2) {
    *how = "leave one flight out, " + std::to_string(by_flight.size()) + " flights";
    return by_flight;
  }
  std::vector<std::vector<size_t>> blocks(static_cast<size_t>(time_folds));
  for (size_t k = 0; k < ns; ++k) blocks[k * blocks.size() / ns].push_back(k);
  *how = std::to_string(time_folds) + " time blocks";
  return blocks;
}

// Covariance of least-squares coefficients when the residuals are autocorrelated (a smoothed
// derivative's noise is): Newey & West's estimator (Econometrica 55(3), 1987) with Bartlett
// weights out to five times the residual's integrated autocorrelation time.
Matrix hac_covariance(const Matrix& A, const Vector& e) {
  const Eigen::Index n = A.rows(), k = A.cols();
  const std::vector<double> ev(e.data(), e.data() + n);
  const auto L = static_cast<Eigen::Index>(
      std::min<double>(static_cast<double>(n) / 4, std::ceil(5 * integrated_autocorrelation_time(ev, 200))));
  const Matrix Z = A.array().colwise() * e.array();  // rows x_t e_t
  Matrix S = Z.transpose() * Z;
  for (Eigen::Index lag = 1; lag <= L; ++lag) {
    const Matrix C = Z.bottomRows(n - lag).transpose() * Z.topRows(n - lag);
    S += (1.0 - static_cast<double>(lag) / static_cast<double>(L + 1)) * (C + C.transpose());
  }
  const Matrix inv = (A.transpose() * A).inverse();
  (void)k;
  return inv * S * inv * (static_cast<double>(n) / static_cast<double>(std::max<Eigen::Index>(1, n - k)));
}

struct Chosen {
  double threshold = 0;  // 0: no term
  std::vector<double> cv_error;
};

// Cross-validated choice of the sparsity level, with the one-standard-error rule towards the
// sparser model ("no term" is the sparsest): a term must predict left-out data clearly better.
Chosen choose_threshold(const std::vector<Normal>& folds, const std::vector<double>& thresholds, int max_terms) {
  Normal total = folds.front();
  for (size_t f = 1; f < folds.size(); ++f) total += folds[f];
  const size_t L = thresholds.size();
  // Levels whose fit on the whole training part has more terms than a person can read are
  // not candidates.
  std::vector<bool> readable(L);
  for (size_t l = 0; l < L; ++l) {
    const Vector xi = stlsq(total, thresholds[l]);
    readable[l] = (xi.array() != 0).count() <= max_terms;
  }
  std::vector<std::vector<double>> fold_mse(L + 1);  // level L: no term
  for (const auto& held : folds) {
    Normal rest = total;
    rest.G -= held.G, rest.b -= held.b, rest.yy -= held.yy, rest.n -= held.n;
    for (size_t l = 0; l < L; ++l) fold_mse[l].push_back(held.sse(stlsq(rest, thresholds[l])) / held.n);
    fold_mse[L].push_back(held.yy / held.n);
  }
  Chosen c;
  std::vector<double> se(L + 1);
  for (size_t l = 0; l <= L; ++l) {
    double m = 0, ss = 0;
    for (double e : fold_mse[l]) m += e / static_cast<double>(folds.size());
    for (double e : fold_mse[l]) ss += (e - m) * (e - m);
    c.cv_error.push_back(m);
    se[l] = std::sqrt(ss / static_cast<double>(std::max<size_t>(1, folds.size() - 1)) / static_cast<double>(folds.size()));
  }
  size_t best = L;
  for (size_t l = 0; l < L; ++l)
    if (readable[l] && c.cv_error[l] < c.cv_error[best]) best = l;
  const double limit = c.cv_error[best] + se[best];
  if (c.cv_error[L] <= limit) return c;  // no term is within one standard error of the best
  for (size_t l = L; l-- > 0;)  // the sparsest level within it
    if (readable[l] && c.cv_error[l] <= limit) {
      c.threshold = thresholds[l];
      break;
    }
  return c;
}

}  // namespace

std::string DiscoveredTerm::expression() const {
  std::ostringstream os;
  os << channel << " +=";
  if (coefficients.empty()) os << " 0";
  for (size_t i = 0; i < coefficients.size(); ++i) {
    const double v = coefficients[i].value;
    os << (i == 0 ? (v < 0 ? " -" : " ") : (v < 0 ? " - " : " + ")) << output::short_number(std::abs(v));
    if (coefficients[i].regressor != "1") os << " " << coefficients[i].regressor;
  }
  return os.str();
}

namespace {

// The library's columns that carry information on the training part, each scaled to unit RMS
// there (the thresholds compare coefficients in these units), evaluated on both parts.
struct ScaledDesign {
  std::vector<size_t> used;  // library column of each design column
  std::vector<double> scale;
  Matrix train, valid;
};

ScaledDesign scaled_design(const RegressorLibrary& lt, const RegressorLibrary& lv) {
  const size_t nt = lt.columns.front().size(), nv = lv.columns.front().size();
  ScaledDesign d;
  for (size_t j = 0; j < lt.columns.size(); ++j) {
    double ss = 0, s = 0;
    for (double x : lt.columns[j]) ss += x * x, s += x;
    const double rms = std::sqrt(ss / static_cast<double>(nt)), mean = s / static_cast<double>(nt);
    const double spread = std::sqrt(std::max(0.0, rms * rms - mean * mean));
    if (j == 0 || spread > 1e-9 * std::max(1.0, rms)) d.used.push_back(j), d.scale.push_back(rms > 0 ? rms : 1.0);
  }
  const auto k = static_cast<Eigen::Index>(d.used.size());
  d.train.resize(static_cast<Eigen::Index>(nt), k), d.valid.resize(static_cast<Eigen::Index>(nv), k);
  for (Eigen::Index c = 0; c < k; ++c) {
    for (size_t r = 0; r < nt; ++r) d.train(static_cast<Eigen::Index>(r), c) = lt.columns[d.used[c]][r] / d.scale[c];
    for (size_t r = 0; r < nv; ++r) d.valid(static_cast<Eigen::Index>(r), c) = lv.columns[d.used[c]][r] / d.scale[c];
  }
  return d;
}

struct SignificantFit {
  Vector xi, se;  // coefficients and standard errors in scaled columns; zero where dropped
};

// Intervals on the chosen support by ordinary least squares with a covariance that holds for
// autocorrelated residuals (Newey-West). A term stays only if it is significant after
// Bonferroni's correction for the size of the library searched (|t| > 3.2 for 36
// regressors): the least significant is dropped and the rest refitted until all are.
SignificantFit keep_significant(const Matrix& X, const Vector& y, const Vector& support) {
  const Eigen::Index k = X.cols();
  const double z_keep = boost::math::quantile(boost::math::complement(boost::math::normal(), 0.025 / static_cast<double>(k)));
  std::vector<bool> active(static_cast<size_t>(k));
  for (Eigen::Index j = 0; j < k; ++j) active[static_cast<size_t>(j)] = support(j) != 0;
  SignificantFit f{Vector::Zero(k), Vector::Zero(k)};
  for (int pass = 0; pass < 10; ++pass) {
    std::vector<Eigen::Index> idx;
    for (Eigen::Index j = 0; j < k; ++j)
      if (active[static_cast<size_t>(j)]) idx.push_back(j);
    f.xi.setZero(), f.se.setZero();
    if (idx.empty()) break;
    Matrix A(X.rows(), static_cast<Eigen::Index>(idx.size()));
    for (size_t i = 0; i < idx.size(); ++i) A.col(static_cast<Eigen::Index>(i)) = X.col(idx[i]);
    const Eigen::ColPivHouseholderQR<Matrix> qr(A);
    const Vector sol = qr.solve(y);
    const Matrix cov = hac_covariance(A, y - A * sol);
    for (size_t i = 0; i < idx.size(); ++i) {
      f.xi(idx[i]) = sol(static_cast<Eigen::Index>(i));
      f.se(idx[i]) = std::sqrt(std::max(0.0, cov(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(i))));
    }
    // Drop the least significant term, one at a time.
    Eigen::Index worst = -1;
    double worst_t = z_keep;
    for (Eigen::Index j : idx) {
      const double t = std::abs(f.xi(j)) / std::max(f.se(j), 1e-300);
      if (t < worst_t) worst_t = t, worst = j;
    }
    if (worst < 0) break;
    active[static_cast<size_t>(worst)] = false;
  }
  return f;
}

// The held-out gain and its spread over consecutive blocks of the held-out part, and the
// verdict that follows from them.
void judge_held_out(DiscoveredTerm& d, const Vector& before_rows, const Vector& after_rows, int validation_folds) {
  const size_t nv = static_cast<size_t>(before_rows.size());
  const size_t nb = static_cast<size_t>(std::max(1, validation_folds));
  std::vector<double> before(nb, 0), after(nb, 0), count(nb, 0);
  for (size_t r = 0; r < nv; ++r) {
    const size_t b = r * nb / nv;
    before[b] += before_rows(static_cast<Eigen::Index>(r)) * before_rows(static_cast<Eigen::Index>(r));
    after[b] += after_rows(static_cast<Eigen::Index>(r)) * after_rows(static_cast<Eigen::Index>(r));
    count[b] += 1;
  }
  for (size_t b = 0; b < nb; ++b)
    if (count[b] > 0) d.fold_gains.push_back(std::sqrt(before[b] / count[b]) - std::sqrt(after[b] / count[b]));
  const double n = static_cast<double>(d.fold_gains.size());
  for (double g : d.fold_gains) d.gain_mean += g / n;
  double ss = 0;
  for (double g : d.fold_gains) ss += (g - d.gain_mean) * (g - d.gain_mean);
  d.gain_standard_error = n > 1 ? std::sqrt(ss / (n - 1) / n) : 0.0;
  // The gain with its unit, and its folds named as the held-out part's (a review, helper-111:
  // "gain 0.0439" had no unit beside gains in per cent, and "blocks" read as the
  // cross-validation's time blocks).
  const std::string unit = output::unit_after_number(d.unit);
  const std::string held = "held-out RMS " + output::short_number(d.valid_rms_before) + " -> " +
                           output::short_number(d.valid_rms_after) + unit + " (RMS lower by " +
                           output::short_number(d.gain_mean) + " +- " + output::short_number(d.gain_standard_error) + unit +
                           " per fold, over the held-out part's " + std::to_string(d.fold_gains.size()) + " folds)";
  d.proposed = d.gain_mean > 0 && d.gain_mean > d.gain_standard_error;
  d.verdict_label = d.proposed ? "proposed" : "not proposed";
  d.verdict_reason = (d.proposed ? "" : "no held-out gain beyond its spread: ") + held;
}

// One channel: the cross-validated sparsity level, the significant coefficients on it (in the
// library's units) and their held-out gain. `yt`, `yv`: what the model lacks on each part.
DiscoveredTerm discover_channel(DiscoveredTerm d, const ScaledDesign& x, const RegressorLibrary& lt, const Vector& yt,
                                const Vector& yv, const std::vector<std::vector<size_t>>& folds, const DiscoveryOptions& opt) {
  const auto nt = static_cast<double>(yt.size()), nv = static_cast<double>(yv.size());
  std::vector<Normal> fold_normals;
  for (const auto& f : folds) fold_normals.push_back(normal_of(x.train, yt, f));
  const Chosen chosen = choose_threshold(fold_normals, opt.thresholds, opt.max_terms);
  d.cv_error = chosen.cv_error;
  d.threshold = chosen.threshold;
  d.train_rms_before = d.train_rms_after = std::sqrt(yt.squaredNorm() / nt);
  d.valid_rms_before = d.valid_rms_after = std::sqrt(yv.squaredNorm() / nv);
  if (chosen.threshold == 0) {
    d.verdict_label = "no term";
    d.verdict_reason = "cross-validation (" + d.cross_validation + ") finds no combination of at most " +
                       std::to_string(opt.max_terms) + " regressors that predicts left-out residual better than none";
    return d;
  }
  std::vector<size_t> all_rows(static_cast<size_t>(yt.size()));
  for (size_t r = 0; r < all_rows.size(); ++r) all_rows[r] = r;
  const SignificantFit fit = keep_significant(x.train, yt, stlsq(normal_of(x.train, yt, all_rows), chosen.threshold));
  for (Eigen::Index j = 0; j < fit.xi.size(); ++j) {
    if (fit.xi(j) == 0) continue;
    const size_t col = x.used[static_cast<size_t>(j)];
    const double s = x.scale[static_cast<size_t>(j)];
    const std::string& ru = lt.units[col];
    d.coefficients.push_back({lt.names[col], ru.empty() || ru == "1" ? d.unit : d.unit + "/(" + ru + ")", fit.xi(j) / s,
                              (fit.xi(j) - fit::kZ95 * fit.se(j)) / s, (fit.xi(j) + fit::kZ95 * fit.se(j)) / s});
  }
  if (d.coefficients.empty()) {
    d.verdict_label = "no term";
    d.verdict_reason = "no selected coefficient is significant once corrected for the " + std::to_string(fit.xi.size()) +
                       " regressors searched";
    return d;
  }
  const Vector et = yt - x.train * fit.xi, ev = yv - x.valid * fit.xi;
  d.train_rms_after = std::sqrt(et.squaredNorm() / nt);
  d.valid_rms_after = std::sqrt(ev.squaredNorm() / nv);
  judge_held_out(d, yv, ev, opt.validation_folds);
  return d;
}

}  // namespace

std::vector<DiscoveredTerm> discover_terms(const fit::Flight& train, const std::vector<double>& residual_train,
                                           const fit::Flight& valid, const std::vector<double>& residual_valid,
                                           const std::vector<std::string>& channels,
                                           const std::vector<std::string>& units,
                                           const std::vector<double>& flight_starts, const DiscoveryOptions& opt) {
  const size_t nc = channels.size(), nt = train.samples.size(), nv = valid.samples.size();
  std::vector<DiscoveredTerm> out;
  if (nt < 50 || nv < 20 || residual_train.size() != nt * nc || residual_valid.size() != nv * nc) return out;
  const RegressorLibrary lt = physical_regressors(train), lv = physical_regressors(valid, lt.centres);
  const ScaledDesign x = scaled_design(lt, lv);
  std::string how;
  const auto folds = cv_folds(train, flight_starts, opt.time_folds, &how);
  for (size_t ch = 0; ch < nc; ++ch) {
    DiscoveredTerm d;
    d.channel = channels[ch], d.unit = units[ch], d.cross_validation = how, d.centres = lt.centres;
    // What the model lacks: measured - model = -residual.
    Vector yt(static_cast<Eigen::Index>(nt)), yv(static_cast<Eigen::Index>(nv));
    for (size_t r = 0; r < nt; ++r) yt(static_cast<Eigen::Index>(r)) = -residual_train[r * nc + ch];
    for (size_t r = 0; r < nv; ++r) yv(static_cast<Eigen::Index>(r)) = -residual_valid[r * nc + ch];
    out.push_back(discover_channel(std::move(d), x, lt, yt, yv, folds, opt));
  }
  return out;
}

std::vector<AddedTerm> proposed_terms(const std::vector<DiscoveredTerm>& terms) {
  std::vector<AddedTerm> out;
  for (const auto& t : terms) {
    if (!t.proposed) continue;
    AddedTerm a;
    a.channel = t.channel;
    a.centres = t.centres;
    for (const auto& c : t.coefficients) a.coefficients.emplace_back(c.regressor, c.value);
    out.push_back(a);
  }
  return out;
}

}  // namespace quadgen::diagnose
