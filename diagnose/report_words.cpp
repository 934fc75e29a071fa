#include "diagnose/report_words.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <set>
#include <sstream>

#include "derive/effects/effect_catalogue.hpp"
#include "fit/fit_report.hpp"
#include "output/estimate.hpp"
#include "output/joined.hpp"
#include "output/numbers.hpp"
#include "output/sinks.hpp"

namespace quadgen::diagnose::words {

using output::number_or_null;

namespace {

// A lead's claim and its numbers, or an empty claim when there is nothing to say beyond the JSON.
struct OneLead {
  std::string claim, evidence;
};

// When an axis shows the draft's signature on both parts.
OneLead draft_lead(const DraftSignature& d) {
  const auto axes = d.axes_showing_it();
  if (axes.empty()) return {};
  std::string claim = "hypothesis (not a named cause): the slow roll/pitch residual follows the horizontal force as air "
                      "moving through the rotors would, on axis ";
  for (size_t i = 0; i < axes.size(); ++i) claim += (i ? " and " : "") + axes[i];
  claim += " (1 s means, the velocity along the axis partialled out, p <= " + significant(DraftSignature::kLevel, 2) +
           " on both parts); no logged signal measures the air";
  std::string numbers;
  for (const auto& p : d.parts) {
    numbers += (numbers.empty() ? "" : "; ") + p.name;
    for (const auto& axis : axes) {
      const auto& pair = axis == "y (roll)" ? p.y_roll : p.x_pitch;
      numbers += (axes.size() > 1 ? " " + axis.substr(0, 1) + ":" : "") + " r = " + significant(pair.r, 2) + ", " +
                 output::p_is(pair.p) + ", slope " + significant(pair.slope, 3) + " against " + significant(pair.draft_slope, 3);
    }
    if (p.implied_speed > 0) numbers += ", draft at most " + significant(p.implied_speed, 2) + " m/s";
  }
  return {claim, numbers};
}

// When the airframe's answer to the commands puts the motor map's slope in doubt.
OneLead command_gain_lead(const CommandGain& g) {
  if (!g.slope_looks_off()) return {};
  const auto& roll = g.axes[0].bands[CommandGain::kLeadBand];
  const auto& pitch = g.axes[1].bands[CommandGain::kLeadBand];
  const auto& vertical = g.axes[2].bands[CommandGain::kLeadBand];
  const std::string claim =
      "lead (not a named cause): the airframe answers a change of rotor command " +
      std::string(g.roll_pitch_gain() < 1 ? "more weakly" : "more strongly") +
      " than the base model's motor map gives. Either the map's slope at the operating point is off (a map measured on "
      "a stand) or the controller answers a disturbance at these frequencies, which reads the same in closed loop; a "
      "flight with a known excitation added to the rate set points separates them";
  const std::string numbers =
      "at " + significant(roll.low_hz, 2) + "-" + significant(roll.high_hz, 2) + " Hz roll " + significant(roll.gain, 2) + " (r = " +
      significant(roll.r, 2) + ", " + significant(1000 * roll.delay_s, 2) + " ms later), pitch " + significant(pitch.gain, 2) + " (r = " +
      significant(pitch.r, 2) + ", " + significant(1000 * pitch.delay_s, 2) + " ms later), vertical " + significant(vertical.gain, 2) +
      " (r = " + significant(vertical.r, 2) + ") of the map's; if it is the map: motor_map slope " + significant(g.suggested_slope(), 2) +
      " with pivot " + significant(g.hover_command, 2) + " (the mean command)";
  return {claim, numbers};
}

// A check's leads: the diagnosis as a whole first ("this flight", or "the flights together"
// in a joint diagnosis), then each flight of a joint diagnosis that shows it; sources with the
// same claim share one lead.
template <class Check, class LeadOf>
std::vector<Lead> leads(const Check& whole, const std::vector<Check>& per_flight, const Diagnosis& d, LeadOf lead_of) {
  std::vector<Lead> out;
  const auto add = [&](const std::string& source, const OneLead& one) {
    if (one.claim.empty()) return;
    auto same = std::find_if(out.begin(), out.end(), [&](const Lead& l) { return l.claim == one.claim; });
    if (same == out.end()) same = out.insert(out.end(), Lead{one.claim, {}});
    same->evidence.emplace_back(source, one.evidence);
  };
  add(d.flights.size() > 1 ? "the flights together" : "this flight", lead_of(whole));
  for (size_t i = 0; i < per_flight.size() && i < d.flights.size(); ++i)
    add("flight " + std::to_string(i + 1) + " (" + d.flights[i] + ")", lead_of(per_flight[i]));
  return out;
}

}  // namespace

// A reduction to show: 0 where it is undefined (a diverged simulation, nothing before).
double reduction(double before, double after) {
  return before > 0 && std::isfinite(before) && std::isfinite(after) ? percent_lower(before, after) : 0.0;
}

std::string lower_or_higher(double before, double after, int digits) {
  const double r = reduction(before, after);
  return significant(std::fabs(r), digits) + (r < 0 ? " % higher" : " % lower");
}

namespace {

// An estimate whose interval (widened by its numerical allowance) holds no 0.
bool told_apart_from_zero(const EffectEstimate* p) {
  return p->lower - p->numerical_allowance > 0 || p->upper + p->numerical_allowance < 0;
}
bool has_interval(const EffectEstimate* p) { return std::isfinite(p->lower) && std::isfinite(p->upper); }

// One flight's sentence (or the one flight's): `ps` are that flight's parameters, `reference`
// the plain name of the reference parameter where the effect has one. Where the first
// parameter is the reference (motor gains), one whose interval holds 0 is not told apart from
// the reference: the sentence names the others and says so, instead of "motor M2 gives 1.2 %
// more thrust" for a gain that may be none. Where every interval holds 0 (the gains
// significant only together) all are named, and that is said.
std::string flight_headline(const Effect& e, const std::vector<const EffectEstimate*>& ps, const std::string& reference) {
  std::set<std::string> apart;  // shared names with an interval away from 0
  for (const auto* p : ps)
    if (told_apart_from_zero(p)) apart.insert(runtime::shared_name(p->name));
  const bool ratios = !e.ratios_only_beside.empty();
  const bool drop_unresolved = ratios && !apart.empty();
  std::map<std::string, double> values;
  size_t dropped = 0;
  for (const auto* p : ps) {
    if (drop_unresolved && !apart.count(runtime::shared_name(p->name))) {
      ++dropped;
      continue;
    }
    values[runtime::shared_name(p->name)] = p->value;
  }
  std::string s = e.headline(values, reference);
  if (dropped > 0) s += reference.empty() ? " The others' intervals hold 0 (no change)." : " The others are within their intervals of the reference.";
  else if (ratios && apart.empty() && !values.empty() && std::all_of(ps.begin(), ps.end(), has_interval))
    s += " Each interval holds 0: the values are significant only together.";
  return s;
}

}  // namespace

// The finding in one sentence (the effect's own words), from its values. A per-flight effect
// of several flights gets one sentence per flight: their mean described none of them (a
// newcomer's trial, helper-136: "Motor FL gives 2.5 % more thrust" for 5 % on one flight and
// none on the other).
std::string held_reference(const Finding& f) {
  // By the one rule that holds it in the fit, and held there: not any held parameter of
  // the effect.
  std::vector<std::string> names;
  std::set<std::string> fitted;
  for (const auto& p : f.evidence.parameters) {
    names.push_back(p.name);
    if (p.free) fitted.insert(p.name);
  }
  for (const auto& name : quadgen::reference_parameters(names, fitted))
    if (effect_of_parameter(name) == f.effect && !fitted.count(name)) return name;
  return "";
}

std::string headline(const Finding& f) {
  const Effect& e = find_effect(f.effect);
  const std::string reference = held_reference(f);
  std::map<int, std::vector<const EffectEstimate*>> by_flight;
  for (const auto& p : f.parameters) by_flight[runtime::flight_of_name(p.name)].push_back(&p);
  if (by_flight.size() <= 1) {
    std::vector<const EffectEstimate*> all;
    for (const auto& p : f.parameters) all.push_back(&p);
    return flight_headline(e, all, reference);
  }
  std::string s;
  for (const auto& [flight, ps] : by_flight) {
    // A flight where nothing is told apart: the effect was named on the flights together, so
    // "significant only together" would not be this flight's to claim. An open interval holds
    // nothing that can be said (a review, helper-137).
    s += (s.empty() ? "" : " ") + std::string("Flight ") + std::to_string(flight) + ": " +
         (std::any_of(ps.begin(), ps.end(), told_apart_from_zero) ? flight_headline(e, ps, reference)
          : std::all_of(ps.begin(), ps.end(), has_interval)       ? std::string("none told apart from 0 (each interval holds it).")
                       : std::string("none told apart from 0 (not every value has an interval)."));
  }
  return s;
}

std::string airframe_from_one_flight(const Diagnosis& d) {
  if (d.airframe_source.empty() || d.airframe_flights != 1) return "";
  return "the airframe comes from the diagnosis of one flight: its values are that flight's (several flights "
         "diagnosed together give the airframe's)";
}

std::string carried_suspect(const CarriedSuspect& c) {
  return "carried in the model, not named: " + c.beside + "'s values fitted without it (" + c.without +
         ") are rejected once it is held at its estimate (" + output::p_is(c.named_values_p) +
         "); beside it they are " + c.with;
}

// "" for a name that is no catalogue effect (a test's made-up finding): the sinks then say nothing.
std::string scope(const std::string& effect) {
  const Effect* e = effect_named(effect);
  return !e ? "" : e->per_flight ? "flight" : "airframe";
}

std::string flights_own(const Diagnosis& d) {
  return d.flights.size() > 1 ? "a property of each flight, not of the airframe" : "a property of the flight, not of the airframe";
}

std::string flights_own_note(const Diagnosis& d, const std::string& effect) {
  return scope(effect) == "flight" ? " (" + flights_own(d) + ")" : "";
}

// The command a reader types to diagnose several flights of one vehicle together.
const std::string kJointDiagnosis = "quadgen diagnose VEHICLE LOG1 LOG2 ...";

std::vector<std::string> flights_own_look_alikes_named_alone(const Diagnosis& d, const std::string& effect) {
  if (d.flights.size() > 1 || !effect_named(effect)) return {};
  return flights_own_look_alikes(effect);
}

// B3 rep 1 named a CoG offset alone; the three flights of its day, diagnosed together, carried
// each flight's own trims instead (docs/validation.md): the finding needed this sentence. Not
// "cannot tell": a flight with the look-alike's separating manoeuvre may (the catalogue's).
std::string one_flight_caveat(const Diagnosis& d, const std::string& effect) {
  const auto others = flights_own_look_alikes_named_alone(d, effect);
  if (others.empty()) return "";
  return "named on one flight: " + output::joined(others, " or ") + ", " +
         (others.size() > 1 ? "properties" : "a property") + " of the flight, can give the same residual; " +
         "several flights of the vehicle diagnosed together (" + kJointDiagnosis + ") show whether " +
         "it is the airframe's, whose value is the same on each flight";
}

// Where the rotor drag force acts, when the diagnosis names both halves of it: the force
// (rotor_drag, at the CoG) and its forward-flight moment (blade_flapping) have coefficients of
// their own, and a force at height h above the CoG gives exactly blade_flapping.k =
// h rotor_drag.k (r x F with r = (0, 0, h)). Their ratio is that height, estimated rather than
// assumed from the blocks. The interval is the delta method on the two standard errors with
// their covariance neglected: a rough one, said so in diagnosis.json.

std::optional<PointOfAction> point_of_action(const Diagnosis& d) {
  const EffectEstimate *drag = nullptr, *flap = nullptr;
  for (const auto& f : d.findings)
    for (const auto& p : f.parameters) {
      if (p.name == "rotor_drag.k") drag = &p;
      if (p.name == "blade_flapping.k") flap = &p;
    }
  if (!drag || !flap || !(std::fabs(drag->value) > 0)) return std::nullopt;
  PointOfAction out;
  out.height = flap->value / drag->value;
  const double rel_f = flap->standard_error / flap->value, rel_d = drag->standard_error / drag->value;
  const double se = std::fabs(out.height) * std::sqrt(rel_f * rel_f + rel_d * rel_d);
  if (std::isfinite(se) && se > 0) out.lower = out.height - fit::kZ95 * se, out.upper = out.height + fit::kZ95 * se;
  return out;
}

std::string point_of_action_headline(const PointOfAction& p) {
  std::ostringstream os;
  os << "The rotor drag force acts " << std::fixed << std::setprecision(0) << std::fabs(1000 * p.height) << " mm "
     << (p.height >= 0 ? "above" : "below") << " the centre of gravity (blade_flapping.k / rotor_drag.k).";
  return os.str();
}

// The command-gain check per flight of a joint diagnosis (the flight's log), or the one
// flight's (named "").
std::vector<std::pair<std::string, const CommandGain*>> command_gains_by_flight(const Diagnosis& d) {
  std::vector<std::pair<std::string, const CommandGain*>> out;
  if (d.command_gain_per_flight.empty()) out.emplace_back("", &d.command_gain);
  for (size_t i = 0; i < d.command_gain_per_flight.size() && i < d.flights.size(); ++i)
    out.emplace_back(d.flights[i], &d.command_gain_per_flight[i]);
  return out;
}

std::vector<std::string> short_flight_labels(const std::vector<std::string>& paths, const std::vector<std::string>& taken) {
  std::vector<std::string> stems, seen;
  for (const auto& p : paths) {
    stems.push_back(std::filesystem::path(p).stem().string());
    // As the sinks show them: "x y" and "x<tab>y" both read "x y" in a CSV and a legend (a
    // red-team review: two flights were one series there), "flight" and "flight<U+200B>" alike;
    // and as a reader sees them: "café" with its accent precomposed or combining, "flight a"
    // with a Latin or a Cyrillic a (Unicode's confusables).
    seen.push_back(output::lookalike_skeleton(stems.back()));
  }
  const auto numbered = [&](size_t i) { return "flight " + std::to_string(i + 1) + " (" + stems[i] + ")"; };
  std::vector<std::string> taken_seen;
  for (const auto& t : taken) taken_seen.push_back(output::lookalike_skeleton(t));
  const auto takes_a_name = [&](const std::string& s) {
    for (const auto& name : taken_seen)
      if (s == name || s.rfind(name + ",", 0) == 0) return true;
    return false;
  };
  std::vector<std::string> out;
  for (size_t i = 0; i < stems.size(); ++i)
    out.push_back(std::count(seen.begin(), seen.end(), seen[i]) > 1 || takes_a_name(seen[i]) ? numbered(i) : stems[i]);
  // A log may itself be named as a numbered label is ("flight 1 (x).csv" beside two x.csv, a
  // review): then every flight is numbered, and the numbers differ.
  std::set<std::string> labels;
  for (const auto& l : out)
    if (!labels.insert(output::lookalike_skeleton(l)).second) {
      for (size_t i = 0; i < stems.size(); ++i) out[i] = numbered(i);
      break;
    }
  return out;
}

// What the screening says in words: flights left out, or a caution on an unusable flight
// diagnosed anyway (alone, or when no flight given was usable).
std::vector<std::string> screening_notes(const Diagnosis& d) {
  std::vector<std::string> out;
  for (const auto& s : d.screening) {
    if (s.usable) continue;
    const std::string source = output::printable(s.source);  // printed to a terminal too
    out.push_back(s.left_out ? "left out: " + source + ": " + s.reason +
                                   "; it would bend the airframe to explain motors that cannot give what was asked"
                             : "caution: " + source + ": " + s.reason +
                                   "; the commands there do not tell the thrust, and what is found may stand in for that");
  }
  return out;
}

std::string environment_note(const Diagnosis& d) {
  if (d.environment != "unknown") return "";
  for (const auto& c : d.candidates) {
    const Effect* e = effect_named(c);
    if (!e) continue;
    for (const auto& indoor : e->plausible) {
      if (indoor.only_in != Environment::kIndoor || indoor.scale != PlausibleRange::Scale::kSI) continue;
      // The ranges with their unit (a review, helper-111: "within [-15, 15]" said no m/s).
      std::string unit;
      for (const auto& p : d.search.final_fit)
        if (p.name == indoor.parameter || (indoor.parameter.empty() && p.name.rfind(c + ".", 0) == 0)) {
          unit = p.unit;
          break;
        }
      const auto range = [&](const PlausibleRange& r) {
        return "[" + output::short_number(r.lower) + ", " + output::short_number(r.upper) + "]" +
               output::unit_after_number(unit);
      };
      std::string anywhere = "its bounds";
      for (const auto& r : e->plausible)
        if (r.only_in == Environment::kUnknown && r.parameter == indoor.parameter && r.scale == indoor.scale)
          anywhere = range(r);
      return "note: where " + std::string(d.flights.size() > 1 ? "the flights were" : "the flight was") +
             " flown is unknown (not declared, or declared so: --environment, or "
             "`environment:` in the mapping), so " +
             (indoor.parameter.empty() ? c : indoor.parameter) + " counts as plausible within " + anywhere +
             "; indoors only " + range(indoor) + " would, and a value beyond it would be a stand-in for missing physics, "
             "not a cause (--environment indoor)";
    }
  }
  return "";
}

namespace {

// The flights that lie apart from the pooled value by more than 1.96 of their standard
// errors (or, where none does, the farthest), by number as the agreement lines print them:
// "flights 1 (high) and 4 (low)". A next step that said "the flights that lie apart" left the
// reader to find them (a review, helper-133).
std::string flights_apart(const ParameterAgreement& a) {
  // Each residual against its own error, sqrt(se^2 - 1/sum w) (the pooled value moves with
  // the flight): divided by se alone, a flight with a tiny error, which sets the pooled value,
  // looked close and was never named (a review, helper-134); for two flights both residuals
  // are then sqrt(Q), so both are named exactly when Q rejects.
  const double sw = inverse_variance_sum(a);
  std::vector<std::pair<size_t, double>> z;
  for (size_t k = 0; k < a.flights.size(); ++k) {
    const FlightEstimate& f = a.flights[k];
    const double var = f.standard_error * f.standard_error - 1 / sw;
    if (flight_can_say(f) && var > 0) z.emplace_back(k, (f.value - a.pooled) / std::sqrt(var));
  }
  if (z.empty()) return "";
  std::vector<std::pair<size_t, double>> apart;
  for (const auto& e : z)
    if (std::abs(e.second) > fit::kZ95) apart.push_back(e);
  if (apart.empty())
    apart.push_back(*std::max_element(z.begin(), z.end(),
                                      [](const auto& x, const auto& y) { return std::abs(x.second) < std::abs(y.second); }));
  std::string out = apart.size() > 1 ? "flights " : "flight ";
  for (size_t i = 0; i < apart.size(); ++i)
    out += (i == 0 ? "" : i + 1 == apart.size() ? " and " : ", ") + std::to_string(apart[i].first + 1) +
           (apart[i].second > 0 ? " (high)" : " (low)");
  return out;
}

// A base parameter no flight measures (c_w beside rotor drag on the NanoBench flights): the
// report said "too uncertain" and the fitted-parameters table showed the joint value, with
// nothing to do about a value the flights cannot give.
std::string hold_unmeasured_step(const ParameterAgreement& a) {
  // Where the flights that can say allow it, within the parameter's bounds: the intersection
  // (every such interval holds zero, so it alone straddled zero and offered a negative drag
  // coefficient; a review, helper-134).
  double lo = -INFINITY, hi = INFINITY;
  bool any = false;
  for (const auto& f : a.flights) {
    if (flight_can_say(f)) lo = std::max(lo, f.lower), hi = std::min(hi, f.upper), any = true;
    if (std::isfinite(f.bound_lower)) lo = std::max(lo, f.bound_lower);
    if (std::isfinite(f.bound_upper)) hi = std::min(hi, f.bound_upper);
  }
  const std::string allowed = any && std::isfinite(lo) && std::isfinite(hi) && lo <= hi
                                  ? " inside every flight's interval and its bounds ([" + significant(lo, kEstimateDigits) +
                                        ", " + significant(hi, kEstimateDigits) + "])"
                                  : "";
  return "no flight tells the base model's " + a.parameter + " from zero, nor do the flights together " +
         "(each value on its bound or its interval holding zero): the joint value is the fit's choice, not a " +
         "measurement; hold it in the vehicle file (fit: false) at a value" + allowed + " that you can " +
         "defend, or fly what would measure it" + (a.parameter == "c_w" ? " (for the frame's drag: faster)" : "");
}

}  // namespace

std::vector<std::string> next_steps(const Diagnosis& d) {
  std::vector<std::string> out;
  for (const auto& a : d.search.unresolved)
    out.push_back("fly this to tell " + a.a + " from " + a.b + ", and diagnose that flight with " +
                  (d.flights.size() > 1 ? "these" : "this one") + ": " + a.manoeuvre);
  bool airframe_named = false;
  for (const auto& f : d.findings) airframe_named = airframe_named || scope(f.effect) == "airframe";
  // Not after --airframe with a joint diagnosis' airframe: this flight was checked against it.
  if (airframe_named && d.flights.size() <= 1 && !(d.airframe_flights > 1))
    out.push_back("diagnose this flight with other flights of the vehicle (" + kJointDiagnosis +
                  "): an airframe's cause holds on each of them, with the same value");
  // A named cause the flights disagree on (a user trial, helper-106: the report named it and
  // said the disagreement, but gave nothing to do about it).
  for (const auto& a : d.agreement)
    if (a.named && flights_disagree(a)) {
      const std::string apart = flights_apart(a);
      out.push_back("the flights disagree on " + a.parameter + ": its joint value is no one airframe's; compare what " +
                    "differs between the flights that lie apart from the pooled value" +
                    (apart.empty() ? "" : ", " + apart + ", and the others") +
                    " (speed, battery, payload, the day) and diagnose them apart, or together without the odd one");
    }
  // A suspected one too: flights of a vehicle changed between them (a camera added, the CoG
  // moved) showed it only here, beside "do not put it in the vehicle file" (a researcher's
  // trial, helper-148).
  for (const auto& a : d.agreement)
    if (!a.named && flights_disagree(a)) {
      const std::string apart = flights_apart(a);
      out.push_back("the flights disagree on the suspected " + a.parameter + (apart.empty() ? "" : ", " + apart + " lying apart") +
                    ": one airframe gives it one value; if the vehicle changed between the flights (a block moved or "
                    "added, other propellers), diagnose each flight alone, or one against another's airframe (--airframe)");
    }
  for (const auto& a : d.base_agreement)
    if (unmeasured_base_parameter(a)) out.push_back(hold_unmeasured_step(a));
  for (const auto& a : d.base_agreement)
    if (flights_disagree(a))
      out.push_back("the flights disagree on the base model's " + a.parameter + ": it carries something that differs " +
                    "between them (" + (a.parameter == "c_w" ? "a drag the model lacks, or one the flights' speeds cannot "
                                                               "tell from rotor drag"
                                                             : "a property the vehicle file gives one value, or something "
                                                               "the model lacks") +
                    "); read its values per flight before taking the joint value as the airframe's");
  for (const auto& x : d.suspected)
    if (!x.carried)
      out.push_back("do not put " + x.candidate.effect + " in the vehicle file (suspected: " + x.failed + ")" +
                    (x.candidate.evidence.implausible.empty()
                         ? ""
                         : "; its value is implausible here too: " + x.candidate.evidence.implausible));
  for (const auto& st : d.stand_ins)
    out.push_back("do not believe " + st.parameter + ": the model lacks something " + st.candidate.effect +
                  " absorbs; the channels it changes say where");
  for (const auto& p : d.at_bounds)
    out.push_back("check the units and the number of " + p.name + " before widening its bounds (the vehicle file's, or "
                  "the effect's own)");
  if (!d.search.left_at_limit.empty()) {
    const size_t limit = d.search.max_effects, wider = std::min(limit + d.search.left_at_limit.size(), kMaxEffectsAllowed);
    out.push_back(wider > limit ? "rerun with --max-effects " + std::to_string(wider) + " to see what is left tested (this "
                                  "run's limit, " + std::to_string(limit) + ", binds)"
                                : "what is left untested stays so: --max-effects is at its largest, " + std::to_string(limit));
  }
  if (d.findings.empty() && !d.unexplained.empty())
    out.push_back("the cause may lie outside the catalogue: read the proposed terms and the hypotheses; a flight of "
                  "another kind (speed, height, payload) separates causes");
  if (!d.findings.empty())
    out.push_back("the fitted model: quadgen derive VEHICLE --params fitted_parameters.yaml (this folder) --out "
                  "FOLDER, or extended_model.hpp as it is");
  return out;
}

std::string significant(double v, int prec) {
  if (!std::isfinite(v)) return "–";
  std::ostringstream os;
  os.precision(prec);
  os << v;
  return os.str();
}

std::vector<Lead> draft_leads(const Diagnosis& d) { return leads(d.draft, d.draft_per_flight, d, draft_lead); }

std::vector<Lead> command_gain_leads(const Diagnosis& d) {
  return leads(d.command_gain, d.command_gain_per_flight, d, command_gain_lead);
}

// Where the one-step test or the force model alone, not the open-loop rollouts, stood behind a
// finding: say so beside the rollouts' numbers, which then show no gain (or a loss).
std::string judged_by_text(const Finding& f) {
  if (f.accepted_by == Finding::kByForceModelAlone)
    return "; accepted by the force model alone: with the measured attitude replayed the held-out position RMSE is " +
           significant(f.force_alone.mean, 3) + " m +- " + significant(f.force_alone.standard_error, 3) +
           " m lower per fold, and the equation-error cost " + significant(f.one_step.cost.mean, 3) + " % +- " +
           significant(f.one_step.cost.standard_error, 3) +
           " % lower, neither kind of channel worse (the open loop is dominated by the moment model's attitude drift)";
  if (f.accepted_by != Finding::kByOneStep || f.one_step.cost.per_fold.empty()) return "";
  return "; accepted by its one-step gain: held-out equation-error cost " + significant(f.one_step.cost.mean, 3) +
         " % +- " + significant(f.one_step.cost.standard_error, 3) + " % lower per fold" +
         (f.rollouts ? ", the rollouts unchanged within their spread" : " (no pose logged: no rollouts)");
}

std::string beside_gain_text(const Finding& f) {
  // A comparison whose weights had not settled is less certain than its spread says.
  const std::string unsettled =
      !f.comparison || f.comparison->settled
          ? ""
          : "; the model without it had not settled its weights after " + std::to_string(f.comparison->refits) +
                " refits (last change " + significant(f.comparison->last_change_percent, 2) + " %)";
  return judged_by_text(f) + unsettled;
}

std::string own_weights_note(const Diagnosis& d) {
  // Compared with the first finding judged by the diagnosis' own measure (one judged by another
  // says its own, beside it).
  const auto judged_here = [&](const Finding& f) { return f.metric == d.metric; };
  const auto first = std::find_if(d.findings.begin(), d.findings.end(), judged_here);
  if (first == d.findings.end()) return "";
  const auto differs = [&](const Finding& f) {
    return judged_here(f) && std::fabs(f.after - first->after) > 1e-9 * std::fabs(f.after);
  };
  if (std::none_of(d.findings.begin(), d.findings.end(), differs)) return "";
  return "each line's costs are weighted by its own comparison's refit, so they compare within a line, not across lines";
}

std::string terms_gain_verdict(double gain_mean, double gain_standard_error) {
  return gain_mean > 0 && gain_mean > gain_standard_error
             ? ": a gain beyond its spread"
             : ": no gain beyond its spread, so the term fits the residual without helping the prediction: not worth "
               "adding";
}

std::string name_value(const std::string& name, double value, const std::string& unit, int prec) {
  return name + " = " + significant(value, prec) + output::unit_after_number(unit);
}

// What spread agreeing flights would show, beside the one seen: " (if they agree: median
// 41 %, p = 0.62)"; nothing where it cannot be computed (one flight, no standard error).
std::string spread_context(const ParameterAgreement& a) {
  if (!std::isfinite(a.spread_if_agree) || a.flights.size() < 2) return "";
  return " (if they agree: median " + significant(100 * a.spread_if_agree, 2) + " %, " + output::p_is(a.spread_p_value) + ")";
}

std::string channel_unit(const Diagnosis& d, const std::string& channel) {
  for (size_t c = 0; c < d.channel_names.size() && c < d.channel_units.size(); ++c)
    if (d.channel_names[c] == channel) return d.channel_units[c];
  return "";
}

bool got_worse(const ChannelGain& c) { return reduction(c.before, c.after) < -kNegligibleChangePercent; }

std::string worse_channels(const Diagnosis& d) {
  std::string out;
  for (const auto& c : d.channel_gain)
    if (got_worse(c))
      out += (out.empty() ? "" : "; ") + c.channel + " " + significant(c.before) + " -> " + significant(c.after) +
             output::unit_after_number(channel_unit(d, c.channel)) + " (" + lower_or_higher(c.before, c.after, 3) + ")";
  return out;
}

// A 95 % interval; a side the profile never closed (NaN) reads "open", not as a number.
int estimate_digits(double value, double lower, double upper) {
  const auto apart = [](double a, double b, int prec) {
    return !std::isfinite(a) || !std::isfinite(b) || a == b || significant(a, prec) != significant(b, prec);
  };
  int prec = kEstimateDigits;
  while (prec < 12 && !(apart(value, lower, prec) && apart(value, upper, prec) && apart(lower, upper, prec))) ++prec;
  return prec;
}

std::vector<const fit::FitParameter*> base_parameters(const Diagnosis& d) {
  std::vector<const fit::FitParameter*> base;
  for (const auto& p : d.search.final_fit)
    if (p.free && !is_effect_parameter(runtime::shared_name(p.name))) base.push_back(&p);
  return base;
}

std::pair<double, double> wald_interval(const fit::FitParameter& p, const std::map<std::string, double>& errors) {
  const auto se = errors.find(p.name);
  // On a bound the curvature is not the likelihood's (the interval would cross the bound).
  // A zero error is no interval either (as add_wald_estimates has it for the findings).
  if (se == errors.end() || !(std::isfinite(se->second) && se->second > 0) || fit::on_bound(p)) return {NAN, NAN};
  return {p.value - fit::kZ95 * se->second, p.value + fit::kZ95 * se->second};
}

std::pair<double, double> wald_interval(const Diagnosis& d, const fit::FitParameter& p) {
  return wald_interval(p, d.final_standard_errors);
}

std::string estimate(double value, double lower, double upper) {
  const int prec = estimate_digits(value, lower, upper);
  return significant(value, prec) + " " + interval(lower, upper, prec);
}

std::string estimate_against(double value, double lower, double upper, double other, const std::string& other_is) {
  const int prec = std::max(estimate_digits(value, lower, upper), estimate_digits(other, lower, upper));
  return significant(value, prec) + " " + interval(lower, upper, prec) + " against " + other_is + significant(other, prec);
}

std::string interval(double lower, double upper, int prec) {
  const auto side = [&](double v) { return std::isfinite(v) ? significant(v, prec) : std::string("open"); };
  return "[" + side(lower) + ", " + side(upper) + "]";
}

}  // namespace quadgen::diagnose::words
