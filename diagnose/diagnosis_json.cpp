#include "diagnose/diagnosis_report.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <optional>
#include <sstream>

#include "derive/effects/effect_catalogue.hpp"
#include "diagnose/report_words.hpp"
#include "fit/fit_report.hpp"
#include "output/estimate.hpp"
#include "output/sinks.hpp"
#include "runtime/per_flight_model.hpp"
#include "runtime/plot.hpp"

namespace quadgen::diagnose {

using json = nlohmann::ordered_json;
using namespace words;

namespace {

using output::number_or_null;

json evidence_json(const CandidateEvidence& e) {
  return {{"statistic", e.statistic},
          {"dof", e.dof},
          {"null_distribution", e.boundary ? "chi-bar-square 0.5 chi2_0 + 0.5 chi2_1 (neutral value on the bound)"
                                           : "chi2_" + std::to_string(e.dof)},
          {"p_value", e.p_value},
          {"level", e.level},
          {"delta_bic", e.delta_bic},
          {"delta_aic", e.delta_aic},
          {"training_cost", e.cost},
          {"validation_cost_before", e.validation_cost_before},
          {"validation_cost_after", e.validation_cost_after},
          {"validation_gain_percent", e.validation_gain_percent},
          {"validation_rejudged_as_own_model", e.rejudged},
          {"size_fraction_of_g", e.size_translation},
          {"size_fraction_of_rotation_scale", e.size_rotation},
          {"significant", e.significant},
          {"why_not", e.why_not},
          {"implausible", e.implausible}};
}

// The free parameters of a fit, each in the one estimate shape, no interval (the base fit).
json parameters_json(const std::vector<fit::FitParameter>& ps) {
  json j = json::object();
  for (const auto& p : ps)
    if (p.free) j[p.name] = output::estimate_json({p.value, p.unit, NAN, NAN, "", fit::on_bound(p)});
  return j;
}

// A fitted parameter with its standard error and one interval: a selected effect's own (its
// profile, widened by the numerical allowance, as under findings: one parameter, one
// interval in a file), else the Wald interval of wald_interval. `errors` by name; a name
// missing from it (a mean over the flights' own copies) has its error and interval null.
json fitted_parameters_json(const Diagnosis& d, const std::vector<fit::FitParameter>& ps,
                            const std::map<std::string, double>& errors) {
  json j = json::object();
  for (const auto& p : ps) {
    if (!p.free) continue;
    const auto se = errors.find(p.name);
    const auto e = std::find_if(d.search.estimates.begin(), d.search.estimates.end(),
                                [&](const EffectEstimate& x) { return x.name == p.name; });
    const bool own = se != errors.end() && e != d.search.estimates.end();
    const auto [lower, upper] = own ? std::pair{e->lower, e->upper} : wald_interval(p, errors);
    j[p.name] = output::estimate_json({p.value, p.unit, lower, upper, "", fit::on_bound(p)});
    j[p.name]["standard_error"] = output::number_or_null(se == errors.end() ? NAN : se->second);
    // A flight's copy the data cannot separate has no Wald interval (add_wald_estimates): no method.
    j[p.name]["interval_method"] = std::isnan(lower) && std::isnan(upper) ? json(nullptr) : own ? json(e->interval) : json("wald");
  }
  return j;
}

// The airframe's values carry the final fit's errors where they are the final fit's own
// (a shared parameter); a mean over the flights' copies is left out (its error null).
std::map<std::string, double> airframe_standard_errors(const Diagnosis& d) {
  std::map<std::string, double> out;
  for (const auto& p : d.airframe_fit) {
    const bool copied = std::any_of(d.search.final_fit.begin(), d.search.final_fit.end(), [&](const fit::FitParameter& q) {
      return runtime::flight_of_name(q.name) != 1 && runtime::shared_name(q.name) == p.name;
    });
    const auto se = d.final_standard_errors.find(p.name);
    if (!copied && se != d.final_standard_errors.end()) out[p.name] = se->second;
  }
  return out;
}

// Effects the extended model carries without naming them: the stronger of a look-alike pair
// (or a named effect's absorbed look-alike, or a suspect a named look-alike's values need),
// and stand-ins for missing physics (kept apart in the outputs).
std::vector<std::string> stand_in_effects(const Diagnosis& d) {
  std::vector<std::string> out;
  for (const auto& st : d.stand_ins) out.push_back(st.candidate.effect);
  return out;
}

std::vector<std::string> carried_look_alikes(const Diagnosis& d) {
  const auto stand_ins = stand_in_effects(d);
  std::vector<std::string> out;
  for (const auto& e : d.search.carried)
    if (std::find(stand_ins.begin(), stand_ins.end(), e) == stand_ins.end()) out.push_back(e);
  return out;
}

json point_of_action_json(const Diagnosis& d) {
  const auto p = point_of_action(d);
  if (!p) return nullptr;
  return {{"height_above_cog", output::estimate_json({p->height, "m", p->lower, p->upper, "", false})},
          {"from", "blade_flapping.k / rotor_drag.k"},
          {"interval_method", "delta method on the two standard errors, their covariance neglected"},
          {"headline", point_of_action_headline(*p)}};
}

json fold_gains_json(const Finding::FoldGains& g) {
  return {{"fold_gains", g.per_fold},
          {"gain_mean", number_or_null(g.mean)},
          {"gain_standard_error", number_or_null(g.standard_error)}};
}

json draft_pair_json(const DraftSignature::Pair& p) {
  return {{"force", p.force},
          {"moment", p.moment},
          {"draft_slope", p.draft_slope},
          {"r_before_velocity_partialled_out", number_or_null(p.raw_r)},
          {"r", number_or_null(p.r)},
          {"effective_n", number_or_null(p.effective_n)},
          {"p", number_or_null(p.p)},
          {"slope", number_or_null(p.slope)},
          {"reverse_slope", number_or_null(p.reverse_slope)},
          {"shows_draft", p.shows_draft()}};
}

json command_gain_json(const CommandGain& g) {
  if (!g.measured) return {{"measured", false}, {"why_not", g.why_not}};
  json axes = json::array();
  for (const auto& a : g.axes) {
    json bands = json::array();
    for (const auto& b : a.bands)
      bands.push_back({{"low_hz", b.low_hz},
                       {"high_hz", b.high_hz},
                       {"gain", number_or_null(b.gain)},
                       {"r", number_or_null(b.r)},
                       {"delay_s", b.delay_s}});
    axes.push_back({{"axis", a.name}, {"bands", bands}});
  }
  const auto& lead = g.axes.front().bands[CommandGain::kLeadBand];
  return {{"measured", true},
          {"samples", g.rows},
          {"mean_command", g.hover_command},
          {"thrust_scale", number_or_null(g.thrust_scale)},
          {"model_slope", g.model_slope},
          {"lead_band_hz", {lead.low_hz, lead.high_hz}},
          {"axes", axes},
          {"roll_pitch_gain", number_or_null(g.roll_pitch_gain())},
          {"slope_looks_off", g.slope_looks_off()},
          {"suggested_slope", g.slope_looks_off() ? json(g.suggested_slope()) : json(nullptr)},
          {"note", "the airframe's answer to a change of rotor command over the base model's (1: the motor map's "
                   "slope at the operating point is right); a lead, never a named cause"}};
}

// A check's JSON for the diagnosis as a whole, with `per_flight`: the same check on each flight
// of a joint diagnosis, named by its log (none for a single flight).
template <class Check, class ToJson>
json with_per_flight(json whole, const std::vector<Check>& per_flight, const Diagnosis& d, ToJson to_json) {
  if (per_flight.empty()) return whole;
  json per = json::array();
  for (size_t i = 0; i < per_flight.size(); ++i) {
    json one = to_json(per_flight[i]);
    one["flight"] = i < d.flights.size() ? d.flights[i] : "";
    per.push_back(one);
  }
  whole["per_flight"] = per;
  return whole;
}

json draft_signature_json(const DraftSignature& d) {
  if (!d.measured) return {{"measured", false}, {"why_not", d.why_not}};
  json parts = json::array();
  for (const auto& p : d.parts)
    parts.push_back({{"part", p.name},
                     {"running_means", p.means},
                     {"a_y_on_pdot", draft_pair_json(p.y_roll)},
                     {"a_x_on_qdot", draft_pair_json(p.x_pitch)},
                     {"implied_draft_at_most_m_s", number_or_null(p.implied_speed)}});
  return {{"measured", true},
          {"window_s", DraftSignature::kWindow},
          {"grid_s", DraftSignature::kGrid},
          {"level", DraftSignature::kLevel},
          {"parts", parts},
          {"axes_showing_it", d.axes_showing_it()},
          {"note", "a hypothesis of air moving through the rotors (unmeasured), never a named cause"}};
}

json one_step_json(const Finding::OneStep& o) {
  json j = {{"metric", "held-out equation-error cost (weighted), reduction per validation fold [%]"}};
  j.update(fold_gains_json(o.cost));
  j["translation"] = fold_gains_json(o.translation);
  j["rotation"] = fold_gains_json(o.rotation);
  j["horizontal"] = fold_gains_json(o.horizontal);
  j["vertical"] = fold_gains_json(o.vertical);
  j["roll_pitch"] = fold_gains_json(o.roll_pitch);
  j["yaw"] = fold_gains_json(o.yaw);
  return j;
}

// How a model's channel weights were settled (Settling): the model a finding is compared
// with, and the extended model.
json settling_json(const Settling& s) {
  if (s.base_fit) return {{"model", "the base fit (weights of its own residuals, reweighted once)"}};
  return {{"model", "refitted under the weights of its own residuals"},
          {"refits", s.refits},
          {"weights_settled", s.settled},
          {"last_weight_change_percent", s.last_change_percent}};
}

// A finding (or a suspected one): its parameters, the one gain figure (the final model
// without it -> with it, on held-out data, with its spread over validation folds), evidence.
json finding_json(const Finding& f) {
  json ps = json::object();
  const std::string& anchor = find_effect(f.effect).ratios_only_beside;
  const std::string reference = held_reference(f);
  const bool has_reference = !reference.empty();
  for (const auto& p : f.evidence.parameters)
    if (p.name == reference) {
      ps[p.name] = output::estimate_json({0.0, p.unit, 0.0, 0.0, "reference (held at 0)", false});
      ps[p.name]["reference"] = true;
    }
  for (const auto& e : f.parameters) {
    json pj = output::estimate_json({e.value, e.unit, e.lower, e.upper, fit::identifiability_text(e.verdict), e.at_bound});
    pj["standard_error"] = number_or_null(e.standard_error);
    pj["numerical_allowance"] = e.numerical_allowance;
    pj["interval_method"] = e.interval;
    ps[e.name] = pj;
  }
  json fj = {{"effect", f.effect},
             {"scope", scope(f.effect)},
             {"headline", headline(f)},
             {"parameters", ps},
             {"gain", {{"metric", f.metric},
                       {"before", number_or_null(f.before)},
                       {"after", number_or_null(f.after)},
                       {"reduction_percent", reduction(f.before, f.after)},
                       {"fold_gains", f.fold_gains},
                       {"gain_mean", number_or_null(f.gain_mean)},
                       {"gain_standard_error", number_or_null(f.gain_standard_error)}}},
             {"one_step_gain", one_step_json(f.one_step)},
             {"accepted_by", f.accepted_by},
             {"compared_with", f.comparison ? settling_json(*f.comparison) : json(nullptr)},
             {"evidence", evidence_json(f.evidence)}};
  if (!f.force_alone.per_fold.empty()) {
    fj["force_alone_gain"] = {{"metric", "held-out position RMSE of the same windows with the measured attitude replayed, "
                                         "before - after per validation fold [m]"}};
    fj["force_alone_gain"].update(fold_gains_json(f.force_alone));
  }
  if (has_reference)
    fj["note"] = anchor + " is fitted with these parameters, so only their ratios are identifiable: the first is the reference, held at 0";
  return fj;
}

// Each airframe parameter per flight (flight names: `flights`), and whether they agree.
json agreement_json(const std::vector<ParameterAgreement>& list, const std::vector<std::string>& flights) {
  json out = json::array();
  for (const auto& a : list) {
    json per_flight = json::array();
    for (size_t k = 0; k < a.flights.size(); ++k) {
      const FlightEstimate& f = a.flights[k];
      // The one estimate shape (output/estimate.hpp), then what belongs to agreement.
      json entry = output::estimate_json({f.value, a.unit, f.lower, f.upper, "", f.at_bound});
      entry["flight"] = k < flights.size() ? flights[k] : std::string();
      entry["standard_error"] = number_or_null(f.standard_error);
      // A base parameter has no test alone (no "off"): null.
      entry["alone"] = std::isnan(f.statistic) ? json(nullptr) : json{{"statistic", f.statistic}, {"p_value", f.p_value}};
      per_flight.push_back(std::move(entry));
    }
    out.push_back({{"parameter", a.parameter},
                   {"effect", a.effect},
                   {"named", a.named},
                   {"base", a.base},
                   {"unit", a.unit},
                   {"joint_value", a.joint_value},
                   {"pooled", a.pooled},
                   {"spread", number_or_null(a.spread)},
                   {"spread_if_agree", number_or_null(a.spread_if_agree)},
                   {"spread_p_value", number_or_null(a.spread_p_value)},
                   {"cochran_q", number_or_null(a.q)},
                   {"q_p_value", number_or_null(a.q_p_value)},
                   {"agree", a.agree},
                   {"verdict", agreement_verdict(a)},
                   // How many flights tell the value from none (flight_measures): 0 for a value
                   // only the fit chose.
                   {"flights_measuring", flights_measuring(a)},
                   {"flights", per_flight}});
  }
  return out;
}

json channels_json(const ResidualAnalysis& a) {
  json arr = json::array();
  for (const auto& c : a.channels) {
    json cor = json::array();
    for (size_t i = 0; i < c.correlations.size() && i < 3; ++i)
      cor.push_back({{"signal", c.correlations[i].signal}, {"r", c.correlations[i].r}, {"p_value", c.correlations[i].p_value}});
    arr.push_back({{"channel", c.name},
                   {"unit", c.unit},
                   {"rms", c.rms},
                   {"bias", c.bias},
                   {"sigma", c.sigma},
                   {"integrated_autocorrelation_time", c.tau_int},
                   {"acf_fraction_outside_band", c.acf_outside},
                   {"slow_rms", c.slow_rms},
                   {"slow_ratio", c.slow_ratio},
                   {"slow_p_value", c.slow_p_value},
                   {"worst_window", {c.worst_window_t0, c.worst_window_t1}},
                   {"strongest_correlations", cor}});
  }
  return arr;
}

// Each flight given: the share of its samples with a command at its limit, whether it could
// inform the diagnosis, and whether it was left out of this one.
json screening_json(const Diagnosis& d) {
  json out = json::array();
  for (const auto& s : d.screening)
    out.push_back({{"flight", s.source}, {"commands_at_limit_share", s.saturated_share}, {"usable", s.usable},
                   {"left_out", s.left_out}, {"reason", s.reason}});
  return out;
}

// The same logs as absolute paths, so that quadgen predict matches them from any directory.
json flight_paths_json(const Diagnosis& d) {
  json paths = json::array();
  for (const auto& f : d.flights) {
    std::error_code ec;
    const auto c = std::filesystem::weakly_canonical(std::filesystem::absolute(f, ec), ec);
    paths.push_back(ec ? f : c.string());
  }
  return paths;
}

json suspected_json(const Diagnosis& d) {
  json suspected = json::array();
  for (const auto& x : d.suspected) {
    json sj = finding_json(x.candidate);
    sj["failed"] = x.failed;
    sj["carried_beside"] = nullptr;
    if (x.carried)
      sj["carried_beside"] = {{"effect", x.carried->beside},
                              {"named_values_p", x.carried->named_values_p},
                              {"values_without", x.carried->without},
                              {"values_with", x.carried->with}};
    suspected.push_back(sj);
  }
  return suspected;
}

// Accepted by every statistical test but outside what the effect's physics can produce: in
// the extended model (carried), never named; with the residual each absorbs.
json stand_ins_json(const Diagnosis& d) {
  json stand_ins = json::array();
  for (const auto& st : d.stand_ins) {
    json absorbs = json::array();
    for (size_t c = 0; c < st.channels.size(); ++c)
      absorbs.push_back({{"channel", st.channels[c]},
                         {"training_rms_without", st.rms_without[c]},
                         {"training_rms_with", st.rms_with[c]}});
    json sj = finding_json(st.candidate);
    sj["parameter"] = st.parameter;
    sj["value"] = st.value;
    sj["unit"] = st.unit;
    sj["plausible"] = {st.plausible_lower, st.plausible_upper};
    sj["why"] = st.why;
    sj["absorbs"] = absorbs;
    stand_ins.push_back(sj);
  }
  return stand_ins;
}

json removed_json(const SearchResult& s) {
  json removed = json::array();
  for (const auto& r : s.removed)
    removed.push_back({{"effect", r.effect}, {"reason", r.reason}, {"p_value", r.p_value}, {"tested_beside", r.beside},
                       {"validation_gain_percent", r.validation_gain_percent}});
  return removed;
}

json left_at_limit_json(const SearchResult& s) {
  json left = json::array();
  for (const auto& ev : s.left_at_limit)
    left.push_back({{"effect", ev.effect}, {"p_value", ev.p_value}, {"statistic", ev.statistic},
                    {"implausible", ev.implausible}});
  return left;
}

json ambiguous_json(const SearchResult& s) {
  json amb = json::array();
  for (const auto& a : s.unresolved) {
    json one = {{"effects", {a.a, a.b}},
                {"statistics", {a.statistic_a, a.statistic_b}},
                {"p_value_adding_second_to_first", a.b_given_a_p},
                {"p_value_adding_first_to_second", a.a_given_b_p},
                {"verdict", "both explain the discrepancy and neither adds anything to the other: not named"},
                {"separating_manoeuvre", a.manoeuvre}};
    if (a.absorbed) {  // the first reproduces the second (CandidateSearch::check_absorbed_look_alikes)
      one["verdict"] = a.b + " explains the discrepancy on its own (" + a.b_own_estimate + ") and adds nothing beside " +
                       a.a + ", and the final model fits as well with it held there, where " + a.a +
                       "'s values as fitted without it are rejected: how much of the discrepancy is " + a.b +
                       " the data cannot say, so " + a.a + "'s values are not named";
      one["second_own_estimate"] = a.b_own_estimate;
      one["p_value_second_held_at_its_own_estimate"] = a.b_at_own_estimate_p;
      one["first_with_second_held"] = a.a_with_b_held;
    }
    amb.push_back(one);
  }
  return amb;
}

// One flight against an airframe diagnosed before: joint_value is the airframe's, cochran_q
// the squared z of the difference.
json airframe_check_json(const Diagnosis& d) {
  if (d.airframe_source.empty()) return json(nullptr);
  return {{"airframe", d.airframe_source},
          {"airframe_flights", d.airframe_flights > 0 ? json(d.airframe_flights) : json(nullptr)},
          {"parameters", agreement_json(d.airframe_check, d.flights)}};
}

json unexplained_json(const Diagnosis& d) {
  json un = json::array();
  for (const auto& u : d.unexplained)
    un.push_back({{"channel", u.channel},
                  {"unit", u.unit},
                  {"slow_rms", u.slow_rms},
                  {"ratio_to_noise", u.ratio},
                  {"p_value", u.p_value},
                  {"largest_in", {u.t0, u.t1}},
                  {"flight", u.flight ? json(u.flight) : json(nullptr)},
                  {"starts_on_joined_clock", u.flight ? json(u.t0_joined) : json(nullptr)},
                  {"mean_there", u.worst_mean},
                  {"most_correlated_signal", u.signal},
                  {"r", u.r}});
  return un;
}

// Beyond the catalogue: one entry per channel, proposed or not (and why).
json discovered_terms_json(const Diagnosis& d) {
  json disc = json::array();
  for (const auto& t : d.discovered) {
    json cs = json::array();
    for (const auto& c : t.coefficients) {
      json cj = {{"regressor", c.regressor}};
      cj.update(output::estimate_json({c.value, c.unit, c.lower, c.upper, "", false}));
      cs.push_back(cj);
    }
    disc.push_back({{"channel", t.channel},
                    {"unit", t.unit},
                    {"proposed", t.proposed},
                    {"expression", t.expression()},
                    {"coefficients", cs},
                    {"sparsity_threshold", t.threshold},
                    {"cv_mean_squared_error", t.cv_error},  // per sparsity level tried, "no term" last
                    {"cross_validation", t.cross_validation},
                    {"training_rms", {number_or_null(t.train_rms_before), number_or_null(t.train_rms_after)}},
                    {"held_out_rms", {number_or_null(t.valid_rms_before), number_or_null(t.valid_rms_after)}},
                    {"held_out_gain", {{"mean", number_or_null(t.gain_mean)},
                                       {"standard_error", number_or_null(t.gain_standard_error)},
                                       {"per_block", t.fold_gains}}},
                    {"verdict", t.verdict()}});
  }
  return disc;
}

json discovered_terms_gain_json(const Diagnosis& d) {
  const auto& tg = d.terms_gain;
  return {{"measured", tg.measured},
          {"metric", tg.metric},
          {"before", number_or_null(tg.before)},
          {"after", number_or_null(tg.after)},
          {"per_fold", tg.fold_gains},
          {"mean", number_or_null(tg.gain_mean)},
          {"standard_error", number_or_null(tg.gain_standard_error)},
          {"note", tg.note}};
}

json simulation_rmse_json(const WindowedSimulation& w) {
  return json{{"position_m", number_or_null(w.position_rmse)}, {"velocity_m_s", number_or_null(w.velocity_rmse)},
              {"attitude_rad", number_or_null(w.attitude_rmse)}, {"body_rates_rad_s", number_or_null(w.rate_rmse)}};
}

json validation_channels_json(const Diagnosis& d) {
  json cg = json::array();
  for (const auto& c : d.channel_gain)
    cg.push_back({{"channel", c.channel}, {"rms_before", c.before}, {"rms_after", c.after},
                  {"reduction_percent", reduction(c.before, c.after)}});
  return cg;
}

// Every selection step with its ranked candidates, each with its evidence and estimates.
json selection_json(const SearchResult& search) {
  json steps = json::array();
  for (const auto& s : search.steps) {
    json cands = json::array();
    for (const auto& c : s.candidates) {
      json cj = {{"effect", c.effect}};
      cj.update(evidence_json(c));
      json ps = json::object();
      for (const auto& p : c.parameters)
        if (p.name.rfind(c.effect + ".", 0) == 0 && p.free) ps[p.name] = p.value;
      cj["estimates"] = ps;
      cands.push_back(cj);
    }
    steps.push_back({{"base_effects", s.base_effects}, {"selected", s.selected}, {"outcome", s.outcome}, {"candidates", cands}});
  }
  return steps;
}

// Which fitted parameters belong to a flight rather than to the airframe (battery state in
// c_t, trims, marker frame, wind): quadgen predict takes them from a flight's own fit.
json flight_parameters_json(const SearchResult& s) {
  json own = json::array();
  for (const auto& p : s.final_fit)
    if (p.free && runtime::flight_of_name(p.name) == 1 && belongs_to_flight(p.name)) own.push_back(p.name);
  return own;
}

json extended_model_json(const Diagnosis& d) {
  return {{"effects", d.search.selected},
          {"carried_look_alikes", carried_look_alikes(d)},
          {"carried_stand_ins", stand_in_effects(d)},
          {"weights", settling_json(d.search.final_settling)},
          {"header", "extended_model.hpp"},
          {"model_json", "extended_model.json"},
          {"fitted_parameters", "fitted_parameters.yaml"}};
}

}  // namespace

json diagnosis_json(const Diagnosis& d, const std::string& log_path) {
  json j;
  j["vehicle"] = d.vehicle;
  j["log"] = log_path;
  j["flights"] = d.flights;  // each flight's log; several: diagnosed jointly
  j["flight_screening"] = screening_json(d);
  j["flight_paths"] = flight_paths_json(d);
  // Effects with one value per flight: "name" is the first flight's, "name@k" the k-th's.
  j["per_flight_effects"] = d.per_flight_effects;
  j["formulation"] = d.formulation;
  j["samples"] = {{"training", d.train_samples}, {"validation", d.valid_samples}, {"validation_from_s", d.t_split}};
  json findings = json::array();
  for (const auto& f : d.findings) {
    findings.push_back(finding_json(f));
    findings.back()["flights_own_look_alikes"] = flights_own_look_alikes_named_alone(d, f.effect);
  }
  j["findings"] = findings;
  j["suspected"] = suspected_json(d);
  j["environment"] = d.environment;
  j["stand_ins"] = stand_ins_json(d);
  j["removed_by_backward_pass"] = removed_json(d.search);
  j["left_at_max_effects"] = left_at_limit_json(d.search);
  j["max_effects"] = d.search.max_effects;
  j["ambiguous"] = ambiguous_json(d.search);
  j["agreement"] = agreement_json(d.agreement, d.flights);
  j["base_agreement"] = agreement_json(d.base_agreement, d.flights);
  j["airframe_check"] = airframe_check_json(d);
  j["point_of_action"] = point_of_action_json(d);  // null unless rotor_drag and blade_flapping are both named
  j["unexplained"] = unexplained_json(d);
  j["draft_signature"] = with_per_flight(draft_signature_json(d.draft), d.draft_per_flight, d, draft_signature_json);
  j["command_gain"] = with_per_flight(command_gain_json(d.command_gain), d.command_gain_per_flight, d, command_gain_json);
  j["discovered_terms"] = discovered_terms_json(d);
  j["discovered_terms_gain"] = discovered_terms_gain_json(d);
  json at_bounds = json::array();
  for (const auto& p : d.at_bounds) at_bounds.push_back(p.name);
  j["parameters_at_bounds"] = at_bounds;
  j["notes"] = d.notes;
  j["gain"] = {{"metric", d.metric},
               {"before", number_or_null(d.metric_before)},
               {"after", number_or_null(d.metric_after)},
               {"reduction_percent", reduction(d.metric_before, d.metric_after)}};
  if (!d.sim_before.t.empty())
    j["validation_simulation_rmse"] = {{"before", simulation_rmse_json(d.sim_before)},
                                       {"after", simulation_rmse_json(d.sim_after)}};
  j["validation_channels"] = validation_channels_json(d);
  if (d.has_prediction)
    j["prediction"] = {{"before", predict::prediction_json(d.prediction_before)},
                       {"after", predict::prediction_json(d.prediction_after)}};
  j["selection"] = selection_json(d.search);
  j["candidates_considered"] = d.candidates;
  j["base_fit"] = parameters_json(d.search.base_fit);
  j["final_fit"] = fitted_parameters_json(d, d.search.final_fit, d.final_standard_errors);
  // For predicting other flights (quadgen predict): the airframe's values.
  j["airframe_fit"] = d.airframe_fit.empty() ? j["final_fit"] : fitted_parameters_json(d, d.airframe_fit, airframe_standard_errors(d));
  json scopes = json::object();
  for (const auto& e : d.candidates) scopes[e] = scope(e);
  j["effect_scopes"] = scopes;
  j["flight_parameters"] = flight_parameters_json(d.search);
  j["residuals"] = {{"before", channels_json(d.before)}, {"after", channels_json(d.after)}};
  j["extended_model"] = extended_model_json(d);
  j["timing_s"] = d.seconds;
  return j;
}

}  // namespace quadgen::diagnose
