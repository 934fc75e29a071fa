#include "diagnose/agreement.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include <boost/math/distributions/normal.hpp>

#include "diagnose/candidate_search.hpp"
#include "fit/equation_error.hpp"
#include "runtime/per_flight_model.hpp"

namespace quadgen::diagnose {

namespace {

using fit::kZ95;

// Flight k's (1-based) parameters under the single-flight model's names: its own copy of a
// per-flight parameter, the airframe's value of every other; free are the named effects'
// parameters and the flight's own parameters that the joint fit freed.
std::vector<fit::FitParameter> flight_start(const AgreementInputs& in, int k, const std::vector<std::string>& named) {
  std::map<std::string, double> start;
  for (const auto& e : in.effects)
    for (size_t j = 0; j < e.parameters.size(); ++j) start[e.parameters[j]] = e.start[j];
  std::map<std::string, const fit::FitParameter*> joint;
  for (const auto& p : in.joint_fit) joint[p.name] = &p;
  std::vector<fit::FitParameter> ps;
  for (const auto& n : in.model->param_names()) {
    const bool per_flight = std::find(in.per_flight.begin(), in.per_flight.end(), n) != in.per_flight.end();
    const auto it = joint.find(per_flight ? runtime::per_flight_name(n, k) : n);
    if (it == joint.end()) throw fit::FitError("agreement: no joint value for " + n);
    fit::FitParameter p = *it->second;
    p.name = n;
    const bool of_effect = std::find(named.begin(), named.end(), n) != named.end();
    p.free = of_effect || (per_flight && p.free);
    // An effect's parameter starts at its joint estimate; one not in `in.effects` (a base
    // parameter, or an effect freed beside them in base_parameter_agreement) where the joint
    // fit left it.
    if (of_effect && start.count(n)) p.value = std::clamp(start.at(n), p.lower, p.upper);
    ps.push_back(p);
  }
  return ps;
}

}  // namespace

bool on_a_bound_that_is_not_off(const fit::FitParameter& p, double off) {
  return fit::on_bound(p) && !(std::isfinite(off) && fit::sits_at(p, off));
}

namespace {

// One flight: its estimates of every named parameter and, per effect, the LR test against off
// (a parameter of no effect in `in`, a base parameter, has no such test: statistic and p NaN).
std::map<std::string, FlightEstimate> fit_one_flight(const AgreementInputs& in, int k, const std::vector<std::string>& named) {
  const fit::EquationErrorModel ee(*in.model, in.training_parts[static_cast<size_t>(k - 1)], in.use_accelerometer);
  const fit::FitOptions fo = refit_options();
  std::vector<fit::FitParameter> on = flight_start(in, k, named);
  const std::vector<double> weights = in.weights.empty() ? channel_weights(ee, on) : in.weights;
  const double cost_on = fit::solve_weighted(ee, on, weights, fo);
  const StandardErrors se = gauss_newton_standard_errors(ee, on, weights);
  std::map<std::string, FlightEstimate> out;
  // `off`: the effect's neutral value (NaN for a base parameter).
  const auto estimate = [&](const std::string& name, double statistic, double p_value, double off) {
    const int i = in.model->param_index(name);
    FlightEstimate f;
    f.value = on[i].value;
    const bool known = !se.confounded[i] && std::isfinite(se.value[i]) && se.value[i] > 0;
    f.standard_error = known ? se.value[i] : std::numeric_limits<double>::quiet_NaN();
    f.lower = f.value - kZ95 * f.standard_error;
    f.upper = f.value + kZ95 * f.standard_error;
    f.statistic = statistic;
    f.p_value = p_value;
    f.at_bound = on[i].free && on_a_bound_that_is_not_off(on[i], off);
    f.bound_lower = on[i].lower, f.bound_upper = on[i].upper;
    if (f.at_bound) f.lower = f.upper = std::numeric_limits<double>::quiet_NaN();  // no interval to draw or print
    return f;
  };
  for (const auto& e : in.effects) {
    std::vector<fit::FitParameter> off = on;
    for (size_t j = 0; j < e.parameters.size(); ++j) {
      const int i = in.model->param_index(e.parameters[j]);
      off[i].value = e.off[j];
      off[i].free = false;
    }
    const double cost_off = fit::solve_weighted(ee, off, weights, fo);
    const double statistic = std::max(0.0, cost_off - cost_on);
    // Judged as the search judges (the plain chi2 doubled the p-values of "off" on a bound
    // until the fifty-ninth session; a statistics review, helper-128).
    const fit::FitParameter& first = on[static_cast<size_t>(in.model->param_index(e.parameters.front()))];
    const double p_value =
        lr_p_value(statistic, static_cast<int>(e.parameters.size()), e.off.front(), first.lower, first.upper);
    for (size_t j = 0; j < e.parameters.size(); ++j) out[e.parameters[j]] = estimate(e.parameters[j], statistic, p_value, e.off[j]);
  }
  const double none = std::numeric_limits<double>::quiet_NaN();
  for (const auto& name : named)
    if (!out.count(name)) out[name] = estimate(name, none, none, none);
  return out;
}

// The median of the range, and P(range >= observed), by bisection on range_cdf.
void spread_under_agreement(ParameterAgreement& a) {
  std::vector<double> sd;
  for (const auto& f : a.flights) sd.push_back(flight_can_say(f) ? f.standard_error : std::numeric_limits<double>::quiet_NaN());
  const double scale = std::abs(a.joint_value);
  if (sd.size() < 2 || !(scale > 0) ||
      std::any_of(sd.begin(), sd.end(), [](double s) { return !(s > 0) || !std::isfinite(s); })) {
    a.spread_if_agree = a.spread_p_value = std::numeric_limits<double>::quiet_NaN();
    return;
  }
  double lo = 0, hi = 20 * *std::max_element(sd.begin(), sd.end());
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (range_cdf(sd, mid) < 0.5 ? lo : hi) = mid;
  }
  a.spread_if_agree = 0.5 * (lo + hi) / scale;
  a.spread_p_value = std::clamp(1 - range_cdf(sd, a.spread * scale), 0.0, 1.0);
}


}  // namespace

ParameterAgreement judge_against_airframe(const FlightEstimate& f, double airframe_value,
                                          double airframe_standard_error) {
  ParameterAgreement a;
  a.joint_value = a.pooled = airframe_value;
  a.flights = {f};
  // An airframe value without a standard error (a diagnosis that had none) cannot say either.
  // (The reader of --airframe gives 0 where a diagnosis has none.)
  a.reference_without_error = !(airframe_standard_error > 0 && std::isfinite(airframe_standard_error));
  // A flight without one cannot disagree, nor agree, and has no z.
  const bool measured = flight_can_say(f) && std::isfinite(f.standard_error);
  const bool says = measured && !a.reference_without_error;
  const double se = a.reference_without_error ? f.standard_error : std::hypot(f.standard_error, airframe_standard_error);
  a.q = measured ? std::pow((f.value - airframe_value) / se, 2) : std::numeric_limits<double>::quiet_NaN();
  a.q_p_value = measured ? chi2_upper(a.q, 1.0) : std::numeric_limits<double>::quiet_NaN();
  a.spread = airframe_value != 0 ? std::abs(f.value - airframe_value) / std::abs(airframe_value) : INFINITY;
  // The test of judge_heterogeneity with one flight: |z| < 1.96 at kAgreementLevel, or the
  // two within kNegligibleSpread.
  a.within_errors = !says || within_errors_or_negligible(a.q_p_value, a.spread);
  a.agree = says && a.within_errors && a.spread < kSpreadLimit;
  return a;
}

// Pooled value, Cochran's Q, spread and the verdict from the flights' estimates (again from
// nothing when called again: a second call doubled Q until the fifty-ninth session).
void judge_heterogeneity(ParameterAgreement& a) {
  a.q = 0;
  double swk = 0, lo = INFINITY, hi = -INFINITY;
  for (const auto& f : a.flights) {
    lo = std::min(lo, f.value), hi = std::max(hi, f.value);
    if (flight_can_say(f)) swk += 1 / (f.standard_error * f.standard_error) * f.value;
  }
  const double sw = inverse_variance_sum(a);
  a.pooled = sw > 0 ? swk / sw : a.joint_value;
  int counted = 0;
  bool every_flight_says = true;
  for (const auto& f : a.flights) {
    if (!flight_can_say(f)) {
      every_flight_says = false;  // a flight that cannot say: no agreement claimed, nor disagreement
      continue;
    }
    a.q += std::pow((f.value - a.pooled) / f.standard_error, 2);
    ++counted;
  }
  a.q_p_value = chi2_upper(a.q, counted - 1.0);
  a.spread = a.joint_value != 0 ? (hi - lo) / std::abs(a.joint_value) : INFINITY;
  // Within the errors: Cochran's Q does not reject one value at the 5 % level. One test per
  // parameter, not one per flight: "every flight's 95 % interval holds the pooled value",
  // the rule until the sixty-first session, called flights that measure one value "disagree"
  // 14 % of the time for five flights and 32 % for ten (MultiFlight.
  // AgreeingFlightsAreSaidToDisagreeAtTheTestsLevel). Fewer than two flights that can say
  // test nothing (p = 1). Values within kNegligibleSpread are within the errors whatever Q
  // says (its note there: agreement_reason).
  const bool within = within_errors_or_negligible(a.q_p_value, a.spread);
  a.agree = every_flight_says && within && a.spread < kSpreadLimit;
  a.within_errors = within;
}

bool unmeasured_base_parameter(const ParameterAgreement& a) {
  if (a.agree || !a.within_errors || !measured_by_no_flight(a)) return false;
  const double sw = inverse_variance_sum(a);  // a.pooled is their weighted mean (judge_heterogeneity)
  return !(sw > 0) || std::abs(a.pooled) <= kZ95 / std::sqrt(sw);
}

void summarise_agreement(ParameterAgreement& a) {
  judge_heterogeneity(a);
  spread_under_agreement(a);
}

double range_cdf(const std::vector<double>& sd, double r) {
  if (!(r > 0)) return 0.0;
  const double s_max = *std::max_element(sd.begin(), sd.end());
  // The smallest value x (mean 0) over +-9 of the widest deviation; the integrand is smooth,
  // and 4000 trapezoids resolve the narrowest normal when it is 1/100 of the widest or more.
  constexpr int kSteps = 4000;
  std::vector<boost::math::normal> normal;
  for (double s : sd) normal.emplace_back(0.0, s);
  const double x0 = -9 * s_max, dx = 18 * s_max / kSteps;
  double total = 0;
  for (size_t i = 0; i < sd.size(); ++i)
    for (int k = 0; k <= kSteps; ++k) {
      const double x = x0 + k * dx;
      double v = boost::math::pdf(normal[i], x);
      for (size_t j = 0; j < sd.size() && v > 0; ++j)
        if (j != i) v *= boost::math::cdf(normal[j], x + r) - boost::math::cdf(normal[j], x);
      total += (k == 0 || k == kSteps ? 0.5 : 1.0) * v * dx;
    }
  return std::clamp(total, 0.0, 1.0);
}

std::vector<ParameterAgreement> per_flight_agreement(const AgreementInputs& in) {
  std::vector<std::string> named;
  for (const auto& e : in.effects) named.insert(named.end(), e.parameters.begin(), e.parameters.end());
  std::vector<ParameterAgreement> out;
  if (named.empty() || in.training_parts.size() < 2) return out;
  std::vector<std::map<std::string, FlightEstimate>> per_flight;
  for (size_t k = 1; k <= in.training_parts.size(); ++k) per_flight.push_back(fit_one_flight(in, static_cast<int>(k), named));
  for (const auto& e : in.effects)
    for (size_t j = 0; j < e.parameters.size(); ++j) {
      ParameterAgreement a;
      a.parameter = e.parameters[j];
      a.effect = e.name;
      a.named = e.named;
      for (const auto& p : in.joint_fit)
        if (p.name == a.parameter) a.unit = p.unit;
      a.joint_value = e.start[j];
      for (const auto& f : per_flight) a.flights.push_back(f.at(a.parameter));
      summarise_agreement(a);
      out.push_back(a);
    }
  return out;
}

std::vector<ParameterAgreement> base_parameter_agreement(const AgreementInputs& in, const std::vector<std::string>& base) {
  std::vector<ParameterAgreement> out;
  if (base.empty() || in.training_parts.size() < 2) return out;
  // The named effects free beside the base parameters, from the joint fit's values (no test
  // alone: `effects` empty); a suspect, which the joint fit does not hold, stays off.
  AgreementInputs marginal = in;
  marginal.effects.clear();
  std::vector<std::string> free = base;
  for (const auto& e : in.effects)
    if (e.named) free.insert(free.end(), e.parameters.begin(), e.parameters.end());
  std::vector<std::map<std::string, FlightEstimate>> per_flight;
  for (size_t k = 1; k <= in.training_parts.size(); ++k) per_flight.push_back(fit_one_flight(marginal, static_cast<int>(k), free));
  for (const auto& name : base) {
    ParameterAgreement a;
    a.parameter = name;
    a.base = true;
    a.named = true;  // part of every model: no suspect
    for (const auto& p : in.joint_fit)
      if (p.name == name) a.unit = p.unit, a.joint_value = p.value;
    for (const auto& f : per_flight) a.flights.push_back(f.at(name));
    summarise_agreement(a);
    out.push_back(a);
  }
  return out;
}

std::vector<ParameterAgreement> check_against_airframe(runtime::DynamicModel& model, const fit::Flight& training_part,
                                                       bool use_accelerometer, const std::vector<double>& weights,
                                                       const AirframeReference& airframe) {
  AgreementInputs in;
  in.model = &model;
  in.training_parts = {training_part};
  in.use_accelerometer = use_accelerometer;
  in.joint_fit = airframe.values;
  for (auto& p : in.joint_fit) p.free = false;
  for (const auto& n : airframe.flight_parameters)
    for (auto& p : in.joint_fit)
      if (p.name == n) p.free = true;
  in.per_flight = airframe.flight_parameters;
  in.weights = weights;
  std::vector<std::string> named;
  for (const auto& e : airframe.effects) {
    in.effects.push_back({e.name, true, e.parameters, e.off, e.value});
    named.insert(named.end(), e.parameters.begin(), e.parameters.end());
  }
  std::vector<ParameterAgreement> out;
  if (named.empty()) return out;
  const auto here = fit_one_flight(in, 1, named);
  for (const auto& e : airframe.effects)
    for (size_t j = 0; j < e.parameters.size(); ++j) {
      ParameterAgreement a = judge_against_airframe(here.at(e.parameters[j]), e.value[j], e.standard_error[j]);
      a.parameter = e.parameters[j];
      a.effect = e.name;
      a.named = true;
      for (const auto& p : airframe.values)
        if (p.name == a.parameter) a.unit = p.unit;
      out.push_back(a);
    }
  return out;
}

}  // namespace quadgen::diagnose
