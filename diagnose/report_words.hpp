// The words and numbers a diagnosis is told in, shared by its four outputs (diagnosis.json,
// the terminal summary, report.html and the plots: diagnosis_report.hpp), so that each says a
// finding, an interval or a lead the same way. Text comes back unescaped; each sink escapes it.
#pragma once
#include <cmath>
#include <optional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "diagnose/diagnosis.hpp"

namespace quadgen::diagnose::words {

// A reduction to show [%]: 0 where it is undefined (a diverged simulation, nothing before).
double reduction(double before, double after);
// The change from before to after in words, with `digits` significant digits: "75.5 % lower",
// or "3.8 % higher" (a rise said as one, not as a negative reduction).
std::string lower_or_higher(double before, double after, int digits);
// A finding in one sentence ("Motor M4 gives 6.9 % less thrust than motor M1").
std::string headline(const Finding& f);
// The parameter of a finding's effect its fit held as the reference (reference_parameters:
// the first of an effect identifiable only as ratios beside a fitted anchor, and held), or "".
std::string held_reference(const Finding& f);
// Said where the airframe a flight is checked against came from one flight's diagnosis ("" else).
std::string airframe_from_one_flight(const Diagnosis& d);
// A suspect carried for a named look-alike's sake, in one sentence.
std::string carried_suspect(const CarriedSuspect& c);
// What a catalogue effect describes, as its descriptor declares (`per_flight`): "airframe", a
// property of the vehicle that every flight of it shares (compare it across flights), or
// "flight", a condition of the one flight (motor trims, the marker frame, a wind) that may
// differ on the next. Said beside every finding, so that diagnoses of several flights of one
// vehicle can be read for what must agree.
std::string scope(const std::string& effect);
// Said beside a finding whose scope is "flight" ("... of each flight ..." in a joint diagnosis).
std::string flights_own(const Diagnosis& d);
// " (a property of the flight, not of the airframe)" after a flight's own effect, else "":
// the terminal summary says it beside each finding, stand-in and suspect.
std::string flights_own_note(const Diagnosis& d, const std::string& effect);
// The flight's own look-alikes of an airframe's effect named on one flight (catalogue's
// flights_own_look_alikes): they may give the same residual on one flight; several flights
// diagnosed together tell them apart.
// Empty in a joint diagnosis, where the airframe's value is shared and the flight's own are not.
std::vector<std::string> flights_own_look_alikes_named_alone(const Diagnosis& d, const std::string& effect);
// The sentence said beside such a finding, or "".
std::string one_flight_caveat(const Diagnosis& d, const std::string& effect);

// Where the rotor drag force acts: blade_flapping.k / rotor_drag.k, with a delta-method interval.
struct PointOfAction {
  double height = 0, lower = NAN, upper = NAN;  // m above the CoG
};
std::optional<PointOfAction> point_of_action(const Diagnosis& d);  // none without both effects
std::string point_of_action_headline(const PointOfAction& p);

// The command-gain check per flight of a joint diagnosis (the flight's log), or the one
// flight's (named "").
std::vector<std::pair<std::string, const CommandGain*>> command_gains_by_flight(const Diagnosis& d);

// Short names of flights for a plot's legend: each log's file name without its folder and
// extension, and where two share one (day1/log.csv, day2/log.csv) "flight k (log)" for each
// of those, so that no two series carry one name. A flight named as one of `taken` is (the
// plot's other series: "the model"; a name that starts "base model," takes its colour), or
// that name and a comma, is numbered too.
std::vector<std::string> short_flight_labels(const std::vector<std::string>& paths,
                                             const std::vector<std::string>& taken = {});

// What the screening says in words: flights left out, or a caution on an unusable flight
// diagnosed anyway (the flight's path made printable: these go to a terminal too).
std::vector<std::string> screening_notes(const Diagnosis& d);
// Where no environment was declared and some candidate's plausible range depends on it (a
// steady wind): what counted as plausible, and how to say "indoor". "" otherwise. A user's
// own mapping may lack the key, and a wind indoors would then be named, not a stand-in.
std::string environment_note(const Diagnosis& d);
// "wind.x = -0.296 m/s", "motor_gain.M2 = 0.027" (no unit for a dimensionless value), with
// `prec` significant digits: a value in a sentence or a cell.
std::string name_value(const std::string& name, double value, const std::string& unit, int prec = 4);
// The base model's parameters the fit freed (the thrust constant, kappa, c_w, ...; a joint
// diagnosis' per-flight copies "c_t@2" each), in the final fit's order.
std::vector<const fit::FitParameter*> base_parameters(const Diagnosis& d);
// A final-fit parameter's 95 % Wald interval (value +- 1.96 standard errors); NaN sides on a
// bound or where the data cannot determine it (diagnosis.json's `ci95` the same).
// `errors` by name as Diagnosis::final_standard_errors has them.
std::pair<double, double> wald_interval(const fit::FitParameter& p, const std::map<std::string, double>& errors);
std::pair<double, double> wald_interval(const Diagnosis& d, const fit::FitParameter& p);
// The unit of a residual channel, as the diagnosis names its channels ("" for none).
std::string channel_unit(const Diagnosis& d, const std::string& channel);
// The held-out channels the extended model gets more than 1 % worse than the base model
// ("az_world 0.2575 -> 0.371 m/s^2 (44.1 % higher)", joined by "; "), "" where none is: said
// beside the overall gain, which averages over them.
std::string worse_channels(const Diagnosis& d);
// Whether the extended model is worse on this held-out channel by more than a negligible change.
bool got_worse(const ChannelGain& c);

// What to do next, one line per outcome the diagnosis has (docs/diagnosis.md, "What to do
// next", keyed to this diagnosis): fly the manoeuvre that separates a pair, confirm an
// airframe's finding on a second flight, distrust a stand-in's value, ... Said at the end of
// the summary and as the report's last section, so a reader is not left at the numbers.
std::vector<std::string> next_steps(const Diagnosis& d);

// A number with `prec` significant digits ("–" where it is not finite); a 95 % interval,
// "open" on a side its profile never closed.
std::string significant(double v, int prec = 4);
std::string interval(double lower, double upper, int prec = 4);
// The significant digits of an estimate and its interval wherever one is printed (the
// terminal, the report's tables), so that a value reads the same in each: one page printed a
// delay as 0.0409 [0.0377, 0.0439] in one table and 0.0409 [0.0377, 0.04395] in the next. A
// sentence rounds further (headline::words); diagnosis.json keeps every digit.
inline constexpr int kEstimateDigits = 3;
// The digits for an estimate and its interval: kEstimateDigits, or as many more (up to 12) as
// print a side apart from the value or the other side where they differ. A weak motor fitted
// to a generated flight read "-0.08 [-0.08, -0.08]", an interval of no width (a newcomer's
// trial, helper-118); it reads "-0.08 [-0.08004, -0.07996]", on a noiseless flight
// "-0.08 [-0.080000004, -0.079999996]".
int estimate_digits(double value, double lower, double upper);
// An estimate and its interval at those digits: "0.0409 [0.0377, 0.0439]".
std::string estimate(double value, double lower, double upper);
// The same against a value it is compared with, printed apart from the interval's sides too:
// "-0.08 [-0.08004, -0.07996] against -0.0802" (it read "against -0.08").
std::string estimate_against(double value, double lower, double upper, double other, const std::string& other_is = "");

// A check's lead: what it suggests, said once, and the numbers of each source that shows it
// ("this flight" or "the flights together" for the diagnosis as a whole, "flight k (path)"
// for a flight of a joint one). A joint diagnosis whose flights show the same said it once
// per flight, 400-500 characters each.
struct Lead {
  std::string claim;
  std::vector<std::pair<std::string, std::string>> evidence;  // source, numbers
};

// The draft check's and the command-gain check's leads (unescaped: each sink escapes).
std::vector<Lead> draft_leads(const Diagnosis& d);
std::vector<Lead> command_gain_leads(const Diagnosis& d);


// What stood behind a finding when the rollouts did not (the one-step test, the force model
// alone), and that text with a note on unsettled weights: said beside the gain.
std::string judged_by_text(const Finding& f);
std::string beside_gain_text(const Finding& f);
// Where the findings' "with it" figures differ (a weighted cost, without a pose: each
// comparison refits under its own residual weights), the sentence that says they compare only
// within a line; else nothing (a review, helper-111: the ARPL report gave one final model three
// scores).
std::string own_weights_note(const Diagnosis& d);
// Whether the proposed terms, regenerated into the model, gain on held-out data beyond the
// spread of their per-fold gains, as an effect must: ": a gain beyond its spread" or why not.
std::string terms_gain_verdict(double gain_mean, double gain_standard_error);
// A parameter's spread across flights beside what agreeing flights with these intervals show.
std::string spread_context(const ParameterAgreement& a);

}  // namespace quadgen::diagnose::words
