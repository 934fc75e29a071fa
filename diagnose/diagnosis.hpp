// The diagnosis pipeline (issue: fit the base model, show what is wrong, name the cause,
// extend the model, measure the gain): flight in, Diagnosis out. Writing files and the
// report is diagnosis_report's job; the command line is cli/diagnose_command.cpp.
#pragma once
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "diagnose/agreement.hpp"
#include "diagnose/candidate_search.hpp"
#include "diagnose/command_gain.hpp"
#include "diagnose/draft_signature.hpp"
#include "diagnose/flight_screening.hpp"
#include "derive/effects/effect_catalogue.hpp"
#include "fit/flight_data.hpp"
#include "predict/prediction.hpp"
#include "diagnose/residual_analysis.hpp"
#include "diagnose/term_discovery.hpp"
#include "diagnose/validation.hpp"
#include "model/vehicle.hpp"
#include "output/accepted_range.hpp"

namespace quadgen::diagnose {

// A change smaller than this, in per cent, is no change worth a word: a refit moves a channel
// its effect does not act on by hundredths of a per cent. Used where a gain is said to be paid
// for by a kind of channel, and where the report says which held-out channels got worse.
inline constexpr double kNegligibleChangePercent = 1.0;

// The values DiagnoseOptions accepts (its IsValid and the command line's checks).
inline constexpr output::AcceptedRange kDiagnoseValidationRange{0.1, 0.6};  // fraction held out
inline constexpr output::AcceptedRange kDiagnoseWindowRange{0.1, 10};       // s
// Below 10 ms the windows' starts would outnumber the samples of a 100 Hz log; from the
// window's length on, the windows would not overlap (consecutive windows are stride 0).
inline constexpr double kSmallestWindowStride = 0.01;  // s
inline constexpr output::AcceptedRange kAlphaRange{1e-9, 0.2};
// "auto": the pose where the log has one, else the accelerometer; or one of the sources.
inline const std::vector<std::string> kTranslationalChoices = [] {
  std::vector<std::string> c{"auto"};
  c.insert(c.end(), fit::kTranslationalSources.begin(), fit::kTranslationalSources.end());
  return c;
}();

struct DiagnoseOptions {
  double validation_fraction = 0.3;  // end of the flight, held out
  double window = 1.0;               // s, validation simulation windows
  // s between the starts of the windows the held-out position RMSE is taken over
  // (overlapping; 0: consecutive windows). Consecutive 1 s windows gave each fold of a
  // joint real-flight diagnosis a dozen windows whose last samples, where the attitude drift
  // has grown, dominate the RMSE: a small change at the windows' starts moved a fold's gain
  // by up to 0.04 m. Ten times as many starts steady it (the motor lag's standard error
  // over the folds 0.0043 -> 0.0021 m) at no cost that shows beside the refits (the joint
  // diagnosis of five flights took no longer).
  double window_stride = 0.1;
  // Translational channels: "pose" (differentiated mocap velocity, world frame),
  // "accelerometer" (specific force, body frame) or "auto" (pose when logged).
  std::string translational = "auto";
  // The search's options; its `environment` is where the flights were flown, on which what
  // is plausible depends (a steady wind indoors). Its `scales` are the vehicle's, set here.
  SearchOptions search;
  // Unexplained discrepancy: slow residual structure beyond this many times what the noise
  // gives, at this significance, after the selected effects.
  double unexplained_ratio = 3.0, unexplained_p = 1e-6;
  // One flight checked against an airframe diagnosed before (its named effects refitted on
  // this flight, compared with the airframe's values); none: no check.
  std::optional<AirframeReference> airframe;
  // Where the diagnosis says how far it has got (the search's steps and profiles too);
  // nowhere by default, the terminal from the command line.
  output::Progress progress;

  // Ceres-style: false with a reason for a value no diagnosis can use.
  bool IsValid(std::string* error) const;
};

struct Finding {
  std::string effect;
  std::vector<EffectEstimate> parameters;
  CandidateEvidence evidence;
  std::string metric;  // of the gain: the final model without this effect -> with it
  double before = 0, after = 0;
  // Held-out gain per validation fold (before - after), its mean and standard error.
  std::vector<double> fold_gains;
  double gain_mean = 0, gain_standard_error = 0;
  // The same folds judged one step at a time: the held-out equation-error cost (weighted,
  // the fit's own measure), its reduction per fold in per cent. Open-loop rollouts of an
  // unstable vehicle are dominated by the attitude drift no catalogue effect removes, so an
  // effect that sharpens every one-step prediction (a motor lag) can leave them unchanged;
  // empty without a pose (then `fold_gains` already are equation-error costs).
  // A gain bought by making one kind of channel worse is no gain: the translational and the
  // rotational channels are also judged apart, each by its sum of squares per fold; the
  // translational ones by the accelerometer where one is logged (a sensor the fit did not
  // use when it differentiates the pose), else as the fit measures them. The horizontal
  // force (x, y) is judged once more apart: the vertical residual (z) is the larger, and a
  // better one would hide a worse horizontal force in their sum; the vertical is reported
  // but counts in the sum only (worse_channel_group in diagnosis.cpp says why). Likewise the
  // yaw channel is judged apart from the rotational sum, where roll and pitch, the larger,
  // could hide it; roll and pitch are reported and count in the sum. (x, y, z are
  // world axes when the pose is differentiated, body axes with the accelerometer; a flying
  // multirotor tilts by tens of degrees at most, so body z stays near the vertical.)
  // Each a reduction per fold in per cent of the fold's value without the effect.
  struct FoldGains {
    std::vector<double> per_fold;
    double mean = 0, standard_error = 0;
  };
  struct OneStep {
    FoldGains cost;                  // the weighted equation-error cost
    FoldGains translation, rotation;  // unweighted sums of squares of each channel group
    FoldGains horizontal, vertical;    // the translational ones split: x and y, and z
    FoldGains roll_pitch, yaw;         // the rotational ones split: p and q, and r
  } one_step;
  // A flight's own quantity acting on the force (Effect::judged_by_force_model: the marker
  // frame, a wind; with a pose) also judged by the force model alone: the same held-out
  // windows with the measured attitude replayed at every step (predict::Replay::kAttitude),
  // their position RMSE per fold, before - after [m]. Empty for other effects.
  FoldGains force_alone;
  // Which held-out test stood behind it: kByOpenLoopPosition, kByOneStep (the rollouts
  // neither better nor worse beyond their spread), or kByForceModelAlone (a flight's own
  // quantity); empty when none did.
  static constexpr const char* kByOpenLoopPosition = "open-loop position";
  static constexpr const char* kByOneStep = "one-step equation error";
  static constexpr const char* kByForceModelAlone = "force model alone (attitude replayed)";
  std::string accepted_by;
  // False where no pose was logged: no rollouts, the held-out metric is the one-step cost.
  bool rollouts = true;
  // How the model without the effect was fitted: under its own weights, settled or not, or
  // the base fit (a lone effect's). Unsettled weights make the comparison less certain than
  // its spread says; the report shows it. Empty for a suspect no held-out comparison judged
  // (one the search found wanting on its own).
  std::optional<Settling> comparison;
};

// A candidate significant on the training data that a later test does not stand behind:
// reported with the test it failed, never as a finding, and not in the extended model.
struct Suspected {
  Finding candidate;
  std::string failed;
  // Carried in the final model because a named look-alike's values need it (empty: not
  // carried); its values are then those of that fit, not `candidate`'s.
  std::optional<CarriedSuspect> carried;
};

// A finding whose value lies outside what its effect's physics can produce (a steady wind
// indoors, a 5 degree IMU misalignment): it stands in for something the model lacks. It
// stays in the extended model, since what it absorbs is real, but is never named.
struct StandIn {
  Finding candidate;
  std::string parameter, why;  // the parameter out of its range, and the physical argument
  double value = 0, plausible_lower = 0, plausible_upper = 0;
  std::string unit;
  // Training equation-error RMS per channel: the final model without it -> with it.
  std::vector<std::string> channels;
  std::vector<double> rms_without, rms_with;
};

struct Unexplained {
  std::string channel, unit;
  double slow_rms = 0, ratio = 0, p_value = 1;
  double t0 = 0, t1 = 0, worst_mean = 0;  // t0, t1 on the clock of the flight they lie in [s]
  std::string signal;  // most correlated physical signal
  double r = 0;
  // Of several flights diagnosed together, which one (1 = the first; 0 for one flight), and
  // where the window starts on the joined clock of the residual plots [s].
  int flight = 0;
  double t0_joined = 0;
};

// Of several flights diagnosed together, each window told on the clock of the flight its
// middle lies in, in seconds from that log's first row, cut to that flight's samples (the
// joined clock's "t = 54.1..55.1 s" of two 30 s flights named neither: a researcher's trial,
// helper-148), and its start on the joined clock kept for the plots. One flight: unchanged.
void place_on_their_flights(std::vector<Unexplained>& windows, const std::vector<fit::Flight>& flights);

struct ChannelGain {
  std::string channel;
  double before = 0, after = 0;  // validation equation-error RMS
};

struct Diagnosis {
  std::string vehicle, formulation;
  // The vehicle file's value of each base-model parameter (its nominal), beside the fitted one.
  std::map<std::string, double> file_values;
  std::vector<std::string> flights;  // the source of each flight diagnosed
  // Every flight given, screened (flight_screening.hpp); in a joint diagnosis the unusable
  // ones are not in `flights`.
  std::vector<FlightScreening> screening;
  // Jointly diagnosed flights: effects with one value per flight ("motor_gain.M2" is the
  // first flight's, "motor_gain.M2@2" the second's; runtime::PerFlightModel).
  std::vector<std::string> per_flight_effects;
  std::vector<std::string> channel_names, channel_units;
  size_t train_samples = 0, valid_samples = 0;
  double t_split = 0;
  // Where each held-out stretch begins on the (joined) clock: one per flight, for the plots.
  std::vector<double> validation_starts;
  std::vector<std::string> candidates;
  SearchResult search;
  ResidualAnalysis before, after;  // whole flight, base fit and final model
  std::vector<double> t, residual_before, residual_after;  // ns x 6, for plots
  std::vector<Finding> findings;
  std::vector<Suspected> suspected;
  std::string environment;  // as declared: indoor, outdoor, unknown
  std::vector<StandIn> stand_ins;
  // Jointly diagnosed flights: each named airframe parameter refitted on each flight alone,
  // and whether the flights agree (agreement.hpp).
  std::vector<ParameterAgreement> agreement;
  // And the base model's shared parameters (c_w, kappa where fitted), each flight refitted
  // with the named effects free beside them (base_parameter_agreement).
  std::vector<ParameterAgreement> base_agreement;
  // One flight diagnosed with an airframe: its named effects on this flight against it.
  std::string airframe_source;
  size_t airframe_flights = 0;  // the flights the airframe's diagnosis fitted (1: one flight's values; 0: not said)
  std::vector<ParameterAgreement> airframe_check;
  std::vector<Unexplained> unexplained;
  // Whether the slow roll/pitch residual the final model leaves follows the horizontal force
  // as a draft through the rotors would (draft_signature.hpp): a lead, never a named cause.
  DraftSignature draft;
  // Jointly diagnosed flights: the same check on each flight alone (its samples on the joined
  // clock, the joint model's residuals), in the order of `flights`.
  std::vector<DraftSignature> draft_per_flight;
  // How strongly the airframe answers a change of command against the base model's motor
  // map, band by band (command_gain.hpp): a lead on the map's slope, never a named cause.
  // Jointly diagnosed flights: each flight alone too, in the order of `flights`.
  CommandGain command_gain;
  std::vector<CommandGain> command_gain_per_flight;
  // Beyond the catalogue: per channel, the term sparse regression proposes for what the
  // final model still gets wrong on the training part, with its held-out gain (or why none).
  std::vector<DiscoveredTerm> discovered;
  // The proposed terms regenerated into the final model and simulated like an effect: the
  // held-out metric without -> with them, per validation fold (measured only with a pose).
  struct TermsGain {
    bool measured = false;
    std::string metric, note;
    double before = 0, after = 0;
    std::vector<double> fold_gains;
    double gain_mean = 0, gain_standard_error = 0;
  } terms_gain;
  std::vector<ChannelGain> channel_gain;
  // Free parameters of the final model that ended on a bound: the model is strained there,
  // and a finding may stand in for physics the catalogue lacks.
  std::vector<fit::FitParameter> at_bounds;
  // What a reader should know before trusting the held-out numbers (what reading each used
  // log noticed, fit::Flight::notes; a finding whose per-fold gain and whole-part numbers
  // disagree): diagnosis.json "notes", the report, the summary.
  std::vector<std::string> notes;
  // The final fit as the airframe's parameters: per-flight values averaged over the flights
  // (what the extended header and fitted_parameters.yaml carry). One flight: the final fit.
  std::vector<fit::FitParameter> airframe_fit;
  // Standard errors of the final fit's free parameters (Gauss-Newton, under the final
  // weights), by name; infinite where the data cannot determine the parameter (a direction
  // of the normal matrix the fit cannot see). diagnosis.json gives each a Wald interval.
  std::map<std::string, double> final_standard_errors;
  std::string metric;
  double metric_before = 0, metric_after = 0;
  WindowedSimulation sim_before, sim_after;  // validation part
  // Prediction error on the validation part as published models report it (one step only
  // without a pose).
  bool has_prediction = false;
  predict::Prediction prediction_before, prediction_after;
  double seconds = 0;
};

// Whether a parameter describes the flight rather than the airframe: those of per-flight
// effects (motor trims, wind, the marker frame) and the thrust constant c_t, which takes up
// the battery's state of charge (thrust per command differs from flight to flight; the
// within-flight decay is thrust_decay's or battery_sag's). In a joint diagnosis each flight
// gets its own value; quadgen predict --calibrate refits them on an unseen flight.
// The held-out test a finding passes (Finding::kByOpenLoopPosition or kByOneStep), "" for
// none: its open-loop position gain above its spread over the validation folds; or else its
// one-step equation-error gain above its spread with the rollouts, the translational and the
// rotational channels each no worse beyond their spread (a gain the rollouts cannot see, not
// one they refute or one channel pays for). The one-step route is for the airframe's
// effects only: a flight's own quantities (per-flight effects) need the open-loop rollouts,
// or, for those acting on the force (the marker frame, a wind), since the open loop over a
// window is dominated by the moment model's own attitude drift (docs/validation.md), the
// force model alone: its position gain with the measured attitude replayed above its
// spread, with the one-step cost lower beyond its spread and neither the translational nor
// the rotational channels worse beyond theirs.
std::string held_out_test(const Finding& f);

// The caution where a finding accepted by its open-loop gain per fold has its before -> after
// over the whole held-out part rising ("" where none has): the folds and the whole part
// score the same windows, but the mean of the folds' gains weighs each fold alike while the
// whole part pools their squared errors, so a fold with larger errors can turn it. Said
// above the findings so that neither number is read alone, with `how_windows_end` (called
// only then: it simulates). (An accepted gain is positive: held_out_test asks it beyond its
// spread.)
std::string gains_that_disagree_note(const std::vector<Finding>& findings,
                                     const std::function<std::string()>& how_windows_end);

// Of the effects that failed a round of acceptance (each with why), the one to take out
// first: the one whose held-out gain speaks most clearly against it (the lowest gain over
// its standard error). The acceptance takes one out at a time and tests the rest again.
size_t clearest_failure(const std::vector<std::pair<Finding, std::string>>& failed);

// The held-out routes' verdicts in words, as a suspect's reason carries them after its
// open-loop gain: "; one step: 43 % +- 9 %, bought with worse horizontal force and
// rotational channels; force model alone: ..." ("" without one-step folds). A refusal
// names every kind of channel that got worse beyond its spread.
std::string one_step_summary(const Finding& f);

bool belongs_to_flight(const std::string& parameter);

// An effect that refines another (motor_lag_spread scales motor_lag's time constant) changes
// nothing without it. remove_effects and the backward pass take refinements out with what
// they refine, and the look-alike checks only add to the model; this is the net behind them
// (run after the look-alike checks), for any later step that does not: a refinement left
// without its effect goes, listed as suspected where it was named, its look-alike pairs
// with it, and the intervals are profiled again.
void drop_refinements_without_their_effect(Diagnosis& d, CandidateSearch& search);

// What the agreement check of a joint diagnosis refits on each flight: each flight's training
// part, the joint fit, and each named airframe effect (and each suspected one that still holds
// its estimates: a value that differs between the flights is often why the joint fit gains
// nothing) with its start and "off" values. Not a per-flight effect, not a reference parameter
// (held at off, the others relative to it), not a refinement whose effect is not named.
// Declared here for its test.
AgreementInputs agreement_inputs(const Diagnosis& d, const SymbolicModel& all, runtime::DynamicModel& model,
                                 const std::vector<fit::Flight>& flights, double validation_fraction, bool accelerometer,
                                 const std::vector<std::string>& per_flight_names);

// What the draft check reads from a diagnosis: the final model's residuals over the whole
// flight (`used`: the samples they belong to, in order), each sample's heading and velocity,
// whether it lies in the held-out part (`valid`), and the coefficients and sizes the ratio
// needs, by name from the final fit (in a joint diagnosis the first flight's c_t, which only
// sets the implied draft speed's hover rotor speeds). `force_in_world`: the translational
// residuals are the differentiated pose's (world axes), not the accelerometer's.
DraftSignatureInput draft_signature_input(const Diagnosis& d, const fit::Flight& used, const fit::Flight& valid,
                                          const Vehicle& v, const std::vector<fit::FitParameter>& final_fit,
                                          bool force_in_world);

// Runs the whole diagnosis. `all` is the full-catalogue symbolic model of the vehicle and
// `model` its runtime form. Several flights of one vehicle are diagnosed jointly: one set
// of parameters for all, the end of each flight held out, the flights joined on one clock
// (fit::join_flights). thrust_decay, which runs on the time since each log's start, is
// then no candidate (a per-flight battery state, not a property of the airframe).
Diagnosis diagnose_flights(const Vehicle& v, const SymbolicModel& all, runtime::DynamicModel& model,
                           const std::vector<fit::Flight>& flights, const DiagnoseOptions& opt,
                           fit::Flight* validation_out);

}  // namespace quadgen::diagnose
