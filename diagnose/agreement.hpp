// Do the flights agree? A joint diagnosis names an airframe effect once, from all flights
// together; that says nothing yet about whether every flight shows the same value. Here each
// named airframe parameter is refitted on each flight's training part alone: the other
// airframe values held at the joint fit, the flight's own parameters (its thrust constant,
// trims, marker frame) free with it. Beside each flight's estimate and its interval stand
//  - whether the effect is significant on that flight alone (a likelihood-ratio test against
//    the same fit with the effect off), and
//  - the heterogeneity of the estimates: Cochran's Q = sum (k_i - k_pooled)^2 / se_i^2
//    against chi2 with (flights - 1) degrees of freedom (inverse-variance pooling, as in a
//    meta-analysis), and the spread (largest - smallest) / |joint value|.
// A property of the airframe should give agreeing estimates; a value that changes from
// flight to flight is the model's error absorbed, not a cause.
#pragma once
#include <limits>
#include <string>
#include <vector>

#include "runtime/dynamic_model.hpp"
#include "fit/flight_data.hpp"
#include "fit/least_squares.hpp"

namespace quadgen::diagnose {

// The level of the test that says flights disagree (Cochran's Q, one test per parameter).
inline constexpr double kAgreementLevel = 0.05;
// Flights agree only within this spread, (largest - smallest) / |joint value| (issue #14's 30 %).
inline constexpr double kSpreadLimit = 0.3;
// Values this close are one value whatever Cochran's Q says: a chosen margin, not a derived
// one. Q weighs the differences by the standard errors alone, which reflect noise, not the
// bias each flight's model error gives its estimate; where the noise is nearly nil the
// bias alone decides. Noise-free generated flights "disagreed" on kappa at a spread of
// 0.0002 % (sixty-second session). Real flights' differences sit far above it (rotor drag's
// 20.6 % on the five NanoBench flights, Q's p = 0.013: still "disagree").
inline constexpr double kNegligibleSpread = 0.01;

// The one rule for "within the errors": the test (Cochran's Q, or against an airframe the
// z test) does not reject one value at kAgreementLevel, or the values are within
// kNegligibleSpread of each other. A NaN p-value (nothing tested) rejects nothing.
inline bool within_errors_or_negligible(double p_value, double spread) {
  return !(p_value < kAgreementLevel) || spread < kNegligibleSpread;
}

struct FlightEstimate {
  double value = 0, standard_error = 0, lower = 0, upper = 0;  // Wald 95 % interval; NaN sides: none
  double statistic = 0, p_value = 1;  // the effect on this flight alone: LR test against "off"
  // Ended on a bound of its fit (fit::on_bound) that is not the effect's "off": its Wald
  // interval is no interval (c_w at 0.05 read [-4.3, 4.4]; lower and upper are NaN then), so
  // the flight cannot say, as one without a standard error cannot.
  bool at_bound = false;
  // The bounds of the parameter in the flight's fit (NaN: not known): which side a value on a
  // bound sits on, and where a held value may lie.
  double bound_lower = std::numeric_limits<double>::quiet_NaN(), bound_upper = std::numeric_limits<double>::quiet_NaN();
};

struct ParameterAgreement {
  std::string parameter, effect, unit;
  bool named = false;  // the effect is a finding (else a suspected candidate, checked the same way)
  double joint_value = 0;
  std::vector<FlightEstimate> flights;  // in the order the flights were given
  double q = 0, q_p_value = 1;          // Cochran's heterogeneity statistic and its p-value
  double pooled = 0;                    // inverse-variance weighted mean of the flights' values
  double spread = 0;                    // (largest - smallest) / |joint value|
  // The spread the flights would show if each measured the pooled value with its own
  // standard error (the range of independent normals, integrated exactly): its median, and
  // the chance of a spread at least as large as the one seen. A 30 % limit is out of reach
  // of flights whose intervals are each ±20 % wide, however well they agree. NaN when a
  // flight has no standard error.
  double spread_if_agree = std::numeric_limits<double>::quiet_NaN();
  double spread_p_value = std::numeric_limits<double>::quiet_NaN();
  // Every flight can say (a standard error, not on a bound), the flights are within the
  // errors (within_errors_or_negligible), and the spread is below 30 %.
  bool agree = false;
  // Within the errors though perhaps not agreeing: Cochran's Q over the flights that can say
  // does not reject one value at kAgreementLevel (against an airframe: the difference within
  // 1.96 standard errors of both), or the values are within 1 % of each other. Without
  // `agree` only the 30 % is missed, or a flight cannot say: the values may well be one,
  // measured too loosely to show it.
  bool within_errors = false;
  // Against an airframe: its value came without a standard error, so the flight can neither
  // agree nor disagree with it.
  bool reference_without_error = false;
  // A base model's parameter (base_parameter_agreement), not an effect's.
  bool base = false;
};

// Whether a flight's refitted `p` ended on a bound that is not `off`, the effect's neutral
// value (NaN for a base parameter, which has none): then its Wald interval is no interval and
// the flight cannot say. A value on the bound that is its "off" (rotor drag 0, no delay, a
// lag at its 1e-6 s floor) is the effect absent from that flight: a value like any other,
// which may disagree with the flights that have it (a review, helper-132: an effect present on
// four flights and absent on the fifth read "too uncertain").
bool on_a_bound_that_is_not_off(const fit::FitParameter& p, double off);

// A flight that can say where the value lies: a standard error, and not on a bound.
inline bool flight_can_say(const FlightEstimate& f) { return f.standard_error > 0 && !f.at_bound; }

// Sum of 1 / se^2 over the flights that can say: the weight of the pooled value, whose
// standard error is 1 / sqrt of it.
inline double inverse_variance_sum(const ParameterAgreement& a) {
  double sw = 0;
  for (const auto& f : a.flights)
    if (flight_can_say(f)) sw += 1 / (f.standard_error * f.standard_error);
  return sw;
}

// A flight that tells the value from zero: it can say, and its 95 % interval holds neither
// zero nor the other sign (diagnosis.json's `flights_measuring` counts them).
inline bool flight_measures(const FlightEstimate& f) { return flight_can_say(f) && (f.lower > 0 || f.upper < 0); }

inline size_t flights_measuring(const ParameterAgreement& a) {
  size_t n = 0;
  for (const auto& f : a.flights) n += flight_measures(f);
  return n;
}

// A flight whose value ended on the bound nearer zero (c_w on its 0.05 of [0.05, 3]): the fit
// wanted it smaller, so the flight does not tell it from zero. On the other bound (c_w at 3)
// it wanted it larger, which is no sign of zero. Bounds not known: the value's side is not
// known either, and it counts as the nearer.
inline bool on_the_bound_nearer_zero(const FlightEstimate& f) {
  if (!f.at_bound) return false;
  if (!std::isfinite(f.bound_lower) || !std::isfinite(f.bound_upper)) return true;
  const bool on_lower = std::abs(f.value - f.bound_lower) <= std::abs(f.value - f.bound_upper);
  return std::abs(on_lower ? f.bound_lower : f.bound_upper) <= std::abs(on_lower ? f.bound_upper : f.bound_lower);
}

// A base parameter that no flight tells from zero: each flight's value on the bound nearer
// zero, or its interval holding zero (the frame's drag beside rotor drag on the NanoBench
// flights: three on the 0.05 bound, two at +-2000 % and +-200 %). A flight without a
// standard error says nothing either way (its own reason stands then), and an effect's
// parameter is judged against its "off" by the test alone, not here (a CoG offset of 0.1 +-
// 0.3 mm is measured well).
inline bool measured_by_no_flight(const ParameterAgreement& a) {
  if (!a.base || a.flights.empty()) return false;
  for (const auto& f : a.flights)
    if (!on_the_bound_nearer_zero(f) && !(flight_can_say(f) && f.lower <= 0 && f.upper >= 0)) return false;
  return true;
}

// Nor do the flights together (the inverse-variance pooled value within 1.96 of its standard
// error of zero, or no flight that can say): then the joint value is the fit's choice, and a
// next step says to hold it. A "too uncertain" verdict only: flights that agree on it measure
// it together, and flights that disagree carry something else (their own next step).
bool unmeasured_base_parameter(const ParameterAgreement& a);

// The verdict in a word: "agree", "too uncertain" (within the errors, but apart by 30 % or
// more, or a flight without a standard error) or "disagree" (beyond the errors and 1 % or
// more apart: within_errors_or_negligible).
inline const char* agreement_verdict(const ParameterAgreement& a) {
  return a.agree ? "agree" : a.within_errors ? "too uncertain" : "disagree";
}

// The flights' values differ beyond their errors (not merely "too uncertain"): said beside a
// named cause wherever it is named, and given a next step.
inline bool flights_disagree(const ParameterAgreement& a) { return !a.agree && !a.within_errors; }

// The flights agree, though the test rejects one value, because the values are within
// kNegligibleSpread of each other: said beside the verdict so that an "agree" beside p = 0
// reads right. Only on "agree": a "too uncertain" verdict keeps its own reason (a flight on
// its bound, an airframe value without a standard error; a review, helper-144).
inline bool agree_within_negligible_spread(const ParameterAgreement& a) {
  return a.agree && a.q_p_value < kAgreementLevel && a.spread < kNegligibleSpread;
}

// Why a verdict is "too uncertain" ("" for the other two): an airframe value or a flight that
// has no standard error cannot say, else the values are within the errors but 30 % or more apart.
inline const char* why_too_uncertain(const ParameterAgreement& a) {
  if (a.agree || !a.within_errors) return "";
  if (a.reference_without_error) return "the airframe's value has no standard error";
  if (measured_by_no_flight(a)) return "no flight tells it from zero: each value is on its bound or its interval holds zero";
  for (const auto& f : a.flights)
    if (f.at_bound) return "a flight's value on its bound cannot say";
  for (const auto& f : a.flights)
    if (!(f.standard_error > 0)) return "a flight without a standard error cannot say";
  // Flights measuring one value this loosely would spread by 30 % or more anyway (a review,
  // helper-131: c_w's flights would spread by a median of 570 %): they cannot measure it.
  if (a.spread_if_agree >= kSpreadLimit) return "the flights cannot measure it to 30 %: agreeing flights would spread as far";
  return "within the errors, but 30 % or more apart";
}

// The words beside any verdict: why it is "too uncertain", or that the values agree to within
// 1 % though the test rejects one value; "" otherwise.
inline const char* agreement_reason(const ParameterAgreement& a) {
  static_assert(kNegligibleSpread == 0.01, "the words below say 1 %");
  if (agree_within_negligible_spread(a))
    return "the test rejects one value, but the values are within 1 % of each other, which counts as one value here";
  return why_too_uncertain(a);
}

struct AgreementInputs {
  runtime::DynamicModel* model = nullptr;   // the single-flight model (shared parameter names)
  std::vector<fit::Flight> training_parts;  // each flight's training part, in order
  bool use_accelerometer = false;
  // The joint final fit, with per-flight copies named as runtime::PerFlightModel names them.
  std::vector<fit::FitParameter> joint_fit;
  // The parameters each flight has its own value of (shared names: c_t, the trims); freed on
  // each flight where the joint fit freed them.
  std::vector<std::string> per_flight;
  // Per channel; empty: each flight's own, from its residuals where its fit starts (the
  // joint fit's values). Under the joint search's weights a flight noisier than the others
  // got standard errors too small and Cochran's Q too large (a statistics review,
  // helper-128, fifty-ninth session). Against an airframe: the flight's own diagnosis's.
  std::vector<double> weights;
  // Per airframe effect to check: its parameters (shared names), their values at "off" and
  // where each flight's fit starts (the joint estimate; for a suspected candidate, which the
  // joint fit no longer holds, its own).
  struct Effect {
    std::string name;
    bool named = false;
    std::vector<std::string> parameters;
    std::vector<double> off, start;
  };
  std::vector<Effect> effects;
};

std::vector<ParameterAgreement> per_flight_agreement(const AgreementInputs& in);

// The base model's parameters the flights share (`base`: the frame's drag coefficient, the
// torque ratio; each free in the joint fit and no flight's own), refitted together on each
// flight's training part with the named effects free beside them (the flight's own thrust
// constant and trims free too), judged as an effect's are. Free beside them, not held: the
// frame's drag and rotor drag have nearly one shape at walking speeds, and a drag coefficient
// refitted with rotor drag held carried each flight's rotor-drag difference under intervals
// far too narrow (a review, helper-131: r = 0.78 between the two over the five NanoBench
// flights). The brief's "vehicle properties must agree across flights" covers these as much
// as the named causes: a drag coefficient that each flight alone sends to another bound is
// not the airframe's. `effect` is empty and no
// "alone" test is made (statistic and p NaN): the base model has no "off".
std::vector<ParameterAgreement> base_parameter_agreement(const AgreementInputs& in, const std::vector<std::string>& base);

// Pooled value, Cochran's Q, spread and the verdict of `a`, from its flights' estimates and
// joint value; summarise_agreement adds the spread under agreement (a numerical integral).
void judge_heterogeneity(ParameterAgreement& a);
void summarise_agreement(ParameterAgreement& a);

// P(max - min <= r) for independent normals with standard deviations `sd` (their means
// equal): sum over which one is the smallest, integrated over its value.
double range_cdf(const std::vector<double>& sd, double r);

// The airframe a joint diagnosis found, as a flight it was not fitted to is checked against
// it (quadgen diagnose LOG --airframe DIAGNOSIS.json).
struct AirframeReference {
  std::string source;                       // the diagnosis.json it came from
  size_t flights = 0;                       // how many flights that diagnosis fitted jointly
  std::vector<fit::FitParameter> values;    // its airframe_fit: the model's parameters
  std::vector<std::string> flight_parameters;  // its own on every flight (c_t, the trims): freed here
  struct Effect {
    std::string name;
    std::vector<std::string> parameters;
    std::vector<double> value, standard_error, off;
  };
  std::vector<Effect> effects;  // the airframe's named effects (not the per-flight ones)
};

// The airframe's named effects refitted on this flight's training part (the airframe's other
// values held, this flight's own parameters free), each against the airframe's value: the
// flight agrees when |z| = |k - k_airframe| / sqrt(se^2 + se_airframe^2) < 1.96 or the two
// differ by less than 1 %, and by less than 30 %. One entry per parameter, its `flights` this one flight.
std::vector<ParameterAgreement> check_against_airframe(runtime::DynamicModel& model, const fit::Flight& training_part,
                                                       bool use_accelerometer, const std::vector<double>& weights,
                                                       const AirframeReference& airframe);

// One flight's estimate `f` against an airframe's value and its standard error (0 or NaN: none), as
// check_against_airframe judges each parameter. Where either side has no standard error the
// verdict is "too uncertain"; where the flight has none, q and its p-value are NaN too (until
// the fifty-ninth session it made q infinite, and the p-value's Boost call aborted the run).
ParameterAgreement judge_against_airframe(const FlightEstimate& f, double airframe_value,
                                          double airframe_standard_error);

}  // namespace quadgen::diagnose
