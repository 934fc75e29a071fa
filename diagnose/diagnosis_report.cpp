#include "diagnose/diagnosis_report.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <map>
#include <optional>
#include <sstream>

#include "derive/effects/effect_catalogue.hpp"
#include "runtime/per_flight_model.hpp"
#include "output/estimate.hpp"
#include "fit/fit_report.hpp"
#include "runtime/plot.hpp"
#include "output/sinks.hpp"

namespace quadgen::diagnose {

using json = nlohmann::ordered_json;

namespace {

using output::number_or_null;

// A reduction to show: 0 where it is undefined (a diverged simulation, nothing before).
double reduction(double before, double after) {
  return before > 0 && std::isfinite(before) && std::isfinite(after) ? percent_lower(before, after) : 0.0;
}

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

// A discovered term's verdict for the report: "proposed" in bold, said once (the verdict
// text may already begin with it).
std::string verdict_cell(const DiscoveredTerm& t) {
  const std::string said = t.proposed ? "proposed" : "not proposed";
  const bool begins = t.verdict.rfind(said, 0) == 0;
  const std::string rest = begins ? t.verdict.substr(said.size()) : ": " + t.verdict;
  return (t.proposed ? "<b>proposed</b>" : said) + output::html_text(rest);
}

// The free parameters of a fit, each in the one estimate shape: intervals are only computed
// for the named effects' parameters (findings), so here they stay null.
json parameters_json(const std::vector<fit::FitParameter>& ps) {
  json j = json::object();
  for (const auto& p : ps)
    if (p.free) j[p.name] = output::estimate_json({p.value, p.unit, NAN, NAN, "", fit::on_bound(p)});
  return j;
}

// Effects the extended model carries without naming them: the stronger of a look-alike pair,
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

// The unit of a residual channel, as the diagnosis names its channels.
std::string channel_unit(const Diagnosis& d, const std::string& channel) {
  for (size_t c = 0; c < d.channel_names.size() && c < d.channel_units.size(); ++c)
    if (d.channel_names[c] == channel) return d.channel_units[c];
  return "";
}

// A finding (or a suspected one): its parameters, the one gain figure (the final model
// without it -> with it, on held-out data, with its spread over validation folds), evidence.
// The finding in one sentence (the effect's own words), from its values: a per-flight
// parameter at its mean over the flights.
std::string headline(const Finding& f) {
  const Effect& e = find_effect(f.effect);
  std::vector<std::pair<std::string, double>> named;
  for (const auto& p : f.parameters) named.emplace_back(p.name, p.value);
  const std::map<std::string, double> values = runtime::mean_over_flights(named);
  std::string reference;
  if (e.first_parameter_is_reference)
    for (const auto& p : f.evidence.parameters)
      if (effect_of_parameter(p.name) == f.effect && !p.free && runtime::flight_of_name(p.name) == 1) {
        reference = p.name;
        break;
      }
  std::string s = e.headline(values, reference);
  if (values.size() < f.parameters.size()) s += " (mean over the flights; each flight's values below)";
  return s;
}

// Where the rotor drag force acts, when the diagnosis names both halves of it: the force
// (rotor_drag, at the CoG) and its forward-flight moment (blade_flapping) have coefficients of
// their own, and a force at height h above the CoG gives exactly blade_flapping.k =
// h rotor_drag.k (r x F with r = (0, 0, h)). Their ratio is that height, estimated rather than
// assumed from the blocks. The interval is the delta method on the two standard errors with
// their covariance neglected: a rough one, said so in diagnosis.json.
struct PointOfAction {
  double height = 0, lower = NAN, upper = NAN;
};

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
     << (p.height >= 0 ? "above" : "below") << " the centre of gravity (blade_flapping.k / rotor_drag.k)";
  return os.str();
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

// The command-gain check per flight of a joint diagnosis (the flight's log), or the one
// flight's (named "").
std::vector<std::pair<std::string, const CommandGain*>> command_gains_by_flight(const Diagnosis& d) {
  std::vector<std::pair<std::string, const CommandGain*>> out;
  if (d.command_gain_per_flight.empty()) out.emplace_back("", &d.command_gain);
  for (size_t i = 0; i < d.command_gain_per_flight.size() && i < d.flights.size(); ++i)
    out.emplace_back(d.flights[i], &d.command_gain_per_flight[i]);
  return out;
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

json finding_json(const Finding& f) {
  json ps = json::object();
  const bool has_reference = find_effect(f.effect).first_parameter_is_reference;
  if (has_reference)
    for (const auto& p : f.evidence.parameters)
      if (effect_of_parameter(p.name) == f.effect && !p.free) {
        ps[p.name] = output::estimate_json({0.0, p.unit, 0.0, 0.0, "reference (held at 0)", false});
        ps[p.name]["reference"] = true;
      }
  for (const auto& e : f.parameters) {
    json pj = output::estimate_json({e.value, e.unit, e.lower, e.upper, e.verdict, e.at_bound});
    pj["standard_error"] = number_or_null(e.standard_error);
    pj["numerical_allowance"] = e.numerical_allowance;
    pj["interval_method"] = e.interval;
    ps[e.name] = pj;
  }
  json fj = {{"effect", f.effect},
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
    fj["note"] = "c_t is fitted with these parameters, so only their ratios are identifiable: the first is the reference, held at 0";
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
      json entry = output::estimate_json({f.value, a.unit, f.lower, f.upper, "", false});
      entry["flight"] = k < flights.size() ? flights[k] : std::string();
      entry["standard_error"] = number_or_null(f.standard_error);
      entry["alone"] = {{"statistic", f.statistic}, {"p_value", f.p_value}};
      per_flight.push_back(std::move(entry));
    }
    out.push_back({{"parameter", a.parameter},
                   {"effect", a.effect},
                   {"named", a.named},
                   {"unit", a.unit},
                   {"joint_value", a.joint_value},
                   {"pooled", a.pooled},
                   {"spread", number_or_null(a.spread)},
                   {"spread_if_agree", number_or_null(a.spread_if_agree)},
                   {"spread_p_value", number_or_null(a.spread_p_value)},
                   {"cochran_q", number_or_null(a.q)},
                   {"q_p_value", a.q_p_value},
                   {"agree", a.agree},
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

}  // namespace

namespace {

// Each flight given: the share of its samples with a command at its limit, whether it could
// inform the diagnosis, and whether it was left out of this one.
json screening_json(const Diagnosis& d) {
  json out = json::array();
  for (const auto& s : d.screening)
    out.push_back({{"flight", s.source}, {"commands_at_limit_share", s.saturated_share}, {"usable", s.usable},
                   {"left_out", s.left_out}, {"reason", s.reason}});
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
    removed.push_back({{"effect", r.effect}, {"reason", r.reason}, {"p_value", r.p_value},
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
  for (const auto& a : s.unresolved)
    amb.push_back({{"effects", {a.a, a.b}},
                   {"statistics", {a.statistic_a, a.statistic_b}},
                   {"p_value_adding_second_to_first", a.b_given_a_p},
                   {"p_value_adding_first_to_second", a.a_given_b_p},
                   {"verdict", "both explain the discrepancy and neither adds anything to the other: not named"},
                   {"separating_manoeuvre", a.manoeuvre}});
  return amb;
}

// One flight against an airframe diagnosed before: joint_value is the airframe's, cochran_q
// the squared z of the difference.
json airframe_check_json(const Diagnosis& d) {
  if (d.airframe_source.empty()) return json(nullptr);
  return {{"airframe", d.airframe_source}, {"parameters", agreement_json(d.airframe_check, d.flights)}};
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
                    {"verdict", t.verdict}});
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
  for (const auto& f : d.findings) findings.push_back(finding_json(f));
  j["findings"] = findings;
  j["suspected"] = suspected_json(d);
  j["environment"] = d.environment;
  j["stand_ins"] = stand_ins_json(d);
  j["removed_by_backward_pass"] = removed_json(d.search);
  j["left_at_max_effects"] = left_at_limit_json(d.search);
  j["ambiguous"] = ambiguous_json(d.search);
  j["agreement"] = agreement_json(d.agreement, d.flights);
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
  j["final_fit"] = parameters_json(d.search.final_fit);
  // For predicting other flights (quadgen predict): the airframe's values.
  j["airframe_fit"] = parameters_json(d.airframe_fit.empty() ? d.search.final_fit : d.airframe_fit);
  j["flight_parameters"] = flight_parameters_json(d.search);
  j["residuals"] = {{"before", channels_json(d.before)}, {"after", channels_json(d.after)}};
  j["extended_model"] = extended_model_json(d);
  j["timing_s"] = d.seconds;
  return j;
}

namespace {

runtime::Series series(const std::string& label, const std::vector<double>& x, const std::vector<double>& y,
                       size_t stride = 1, bool points = false) {
  runtime::Series s{label, {}, {}, points};
  for (size_t i = 0; i < x.size() && i < y.size(); i += stride) {
    s.x.push_back(x[i]);
    s.y.push_back(y[i]);
  }
  return s;
}


}  // namespace

std::vector<std::pair<std::string, std::string>> diagnosis_plots(
    const Diagnosis& d, const fit::Flight& valid, std::string* error,
    std::vector<std::pair<std::string, std::string>>* data) {
  std::vector<std::pair<std::string, std::string>> out;
  // One colour per model in every plot: measured black, base model red, extended model blue.
  const std::map<std::string, std::string> colours = {{"measured", "#000000"},
                                                       {"base model", "#d62728"},
                                                       {"extended model", "#1f77b4"},
                                                       {"95 % white-noise band", "#7f7f7f"},
                                                       {"", "#7f7f7f"}};
  auto render = [&](const std::string& name, const std::string& title, std::vector<runtime::Panel> panels) {
    for (auto& p : panels)
      for (auto& s : p.series)
        for (const auto& [model, colour] : colours)  // "base model, tilt" is the base model's too
          if (!model.empty() && (s.label == model || s.label.rfind(model + ",", 0) == 0)) s.color = colour;
    if (data) data->emplace_back(name.substr(0, name.rfind('.')) + ".csv", runtime::panels_csv(title, panels));
    std::string svg;
    if (runtime::render_svg(title, panels, &svg, error)) out.emplace_back(name, svg);
  };
  const size_t stride = std::max<size_t>(1, d.t.size() / 3000);
  // Measured vs simulated positions on the validation part.
  if (!d.sim_before.t.empty()) {
    std::vector<runtime::Panel> panels;
    const char* axes[3] = {"x", "y", "z"};
    for (int a = 0; a < 3; ++a) {
      std::vector<double> tm, ym;
      for (const auto& s : valid.samples) tm.push_back(s.t), ym.push_back(s.x[a]);
      const auto& yb = a == 0 ? d.sim_before.x : a == 1 ? d.sim_before.y : d.sim_before.z;
      const auto& ya = a == 0 ? d.sim_after.x : a == 1 ? d.sim_after.y : d.sim_after.z;
      panels.push_back({std::string("position ") + axes[a] + " (validation, open-loop windows)", "t [s]", "m",
                        {series("measured", tm, ym, 1, true), series("base model", d.sim_before.t, yb),
                         series("extended model", d.sim_after.t, ya)}});
    }
    render("validation.svg", d.vehicle + ": measured vs simulated, before and after", panels);
    // The simulation's error over time, per quantity.
    const struct {
      const char* title;
      const char* unit;
      std::vector<double> WindowedSimulation::*err;
    } quantities[] = {{"position error", "m", &WindowedSimulation::e_pos},
                      {"velocity error", "m/s", &WindowedSimulation::e_vel},
                      {"attitude error (rotation angle)", "rad", &WindowedSimulation::e_att},
                      {"body-rate error", "rad/s", &WindowedSimulation::e_rate}};
    std::vector<runtime::Panel> errs;
    for (const auto& q : quantities)
      errs.push_back({std::string(q.title) + " in the open-loop windows", "t [s]", q.unit,
                      {series("base model", d.sim_before.t, d.sim_before.*q.err),
                       series("extended model", d.sim_after.t, d.sim_after.*q.err)}});
    render("simulation_errors.svg", d.vehicle + ": simulation error over time (validation part)", errs);
  }
  // Residuals over time.
  std::vector<runtime::Panel> res;
  for (int c = 0; c < 6; ++c) {
    std::vector<double> rb, ra;
    for (size_t k = 0; k < d.t.size(); ++k) rb.push_back(d.residual_before[k * 6 + c]), ra.push_back(d.residual_after[k * 6 + c]);
    res.push_back({d.channel_names[c] + " residual (model - measured; dashed: held-out part starts)", "t [s]",
                   d.channel_units[c], {series("base model", d.t, rb, stride), series("extended model", d.t, ra, stride)},
                   d.validation_starts});
  }
  render("residuals.svg",
         d.vehicle + ": equation-error residuals (" +
             (d.flights.size() > 1 ? std::to_string(d.flights.size()) + " flights joined, 1 s apart; the end of each held out"
                                   : "validation from t = " + std::to_string(d.t_split).substr(0, 5) + " s") + ")",
         res);
  // Autocorrelation with the white-noise band.
  std::vector<runtime::Panel> acf;
  for (size_t c = 0; c < d.before.channels.size(); ++c) {
    const auto& b = d.before.channels[c];
    const auto& a = d.after.channels[c];
    std::vector<double> lag, band, nband;
    const double dt = d.t.size() > 1 ? (d.t.back() - d.t.front()) / static_cast<double>(d.t.size() - 1) : 0.01;
    for (size_t k = 0; k < b.acf.size(); ++k) lag.push_back(static_cast<double>(k) * dt), band.push_back(b.acf_band), nband.push_back(-b.acf_band);
    acf.push_back({b.name + " autocorrelation", "lag [s]", "1",
                   {series("base model", lag, b.acf), series("extended model", lag, a.acf), series("95 % white-noise band", lag, band),
                    series("", lag, nband)}});
  }
  render("autocorrelation.svg", d.vehicle + ": residual autocorrelation", acf);
  // The answer to the commands, band by band: one series per flight, 1 where the model is right.
  std::vector<std::pair<std::string, const CommandGain*>> gains;
  for (const auto& [flight, g] : command_gains_by_flight(d))
    gains.emplace_back(flight.empty() ? "this flight" : std::filesystem::path(flight).stem().string(), g);
  std::vector<runtime::Panel> gain_panels;
  for (size_t a = 0; a < 3; ++a) {
    runtime::Panel panel{"", "band centre [Hz]", "gain (1: as the model)", {}};
    std::vector<double> hz;
    for (const auto& [flight, g] : gains) {
      if (!g->measured || g->axes.size() <= a) continue;
      panel.title = g->axes[a].name + ": measured over the base model's answer to the commands";
      std::vector<double> x, y;
      for (const auto& b : g->axes[a].bands) x.push_back(std::sqrt(b.low_hz * b.high_hz)), y.push_back(b.gain);
      hz = x;
      panel.series.push_back(series(flight, x, y, 1, true));
    }
    if (hz.empty()) continue;
    panel.series.push_back(series("the model", hz, std::vector<double>(hz.size(), 1.0)));
    gain_panels.push_back(panel);
  }
  if (!gain_panels.empty()) render("command_gain.svg", d.vehicle + ": the answer to the commands, band by band", gain_panels);
  if (d.has_prediction)
    render("prediction.svg", d.vehicle + ": prediction error against horizon (validation part)",
           predict::horizon_panels({{"base model", &d.prediction_before}, {"extended model", &d.prediction_after}}));
  if (!d.search.profiles.empty())
    render("profiles.svg", d.vehicle + ": profile likelihood of the found parameters", fit::profile_panels(d.search.profiles));
  return out;
}

namespace {

std::string esc(const std::string& s) { return output::html_text(s); }

std::string num(double v, int prec = 4) {
  if (!std::isfinite(v)) return "–";
  std::ostringstream os;
  os.precision(prec);
  os << v;
  return os.str();
}

// One sentence for the printout and the report when an axis shows the draft's signature on
// both parts ("" otherwise: then there is nothing to say beyond the JSON).
std::string draft_lead(const DraftSignature& d) {
  const auto axes = d.axes_showing_it();
  if (axes.empty()) return "";
  std::string s = "hypothesis (not a named cause): the slow roll/pitch residual follows the horizontal force as air "
                  "moving through the rotors would, on axis ";
  for (size_t i = 0; i < axes.size(); ++i) s += (i ? " and " : "") + axes[i];
  s += " (1 s means, the velocity along the axis partialled out, p <= " + num(DraftSignature::kLevel, 2) +
       " on both parts";
  for (const auto& p : d.parts) {
    s += "; " + p.name;
    for (const auto& axis : axes) {
      const auto& pair = axis == "y (roll)" ? p.y_roll : p.x_pitch;
      s += (axes.size() > 1 ? " " + axis.substr(0, 1) + ":" : "") + " r = " + num(pair.r, 2) + ", p = " + num(pair.p, 2) +
           ", slope " + num(pair.slope, 3) + " against " + num(pair.draft_slope, 3);
    }
    if (p.implied_speed > 0) s += ", draft at most " + num(p.implied_speed, 2) + " m/s";
  }
  return s + "); no logged signal measures the air";
}

// A check's sentences, each with the flight it is about (empty for the diagnosis as a whole;
// a joint diagnosis adds one per flight that shows it), unescaped for each sink.
template <class Check, class Lead>
std::vector<std::pair<std::string, std::string>> leads(const Check& whole, const std::vector<Check>& per_flight,
                                                       const Diagnosis& d, Lead lead_of) {
  std::vector<std::pair<std::string, std::string>> out;
  if (std::string lead = lead_of(whole); !lead.empty()) out.emplace_back("", std::move(lead));
  for (size_t i = 0; i < per_flight.size() && i < d.flights.size(); ++i)
    if (std::string lead = lead_of(per_flight[i]); !lead.empty())
      out.emplace_back("flight " + std::to_string(i + 1) + " (" + d.flights[i] + ")", std::move(lead));
  return out;
}

std::vector<std::pair<std::string, std::string>> draft_leads(const Diagnosis& d) {
  return leads(d.draft, d.draft_per_flight, d, draft_lead);
}

// One sentence for the printout and the report when the airframe's answer to the commands
// puts the motor map's slope in doubt ("" otherwise: the JSON holds the bands).
std::string command_gain_lead(const CommandGain& g) {
  if (!g.slope_looks_off()) return "";
  const auto& roll = g.axes[0].bands[CommandGain::kLeadBand];
  const auto& pitch = g.axes[1].bands[CommandGain::kLeadBand];
  const auto& vertical = g.axes[2].bands[CommandGain::kLeadBand];
  return "lead (not a named cause): at " + num(roll.low_hz, 2) + "-" + num(roll.high_hz, 2) +
         " Hz the airframe answers a change of rotor command at " + num(roll.gain, 2) + " (roll, r = " + num(roll.r, 2) +
         ", " + num(1000 * roll.delay_s, 2) + " ms later) and " + num(pitch.gain, 2) + " (pitch, r = " + num(pitch.r, 2) +
         ", " + num(1000 * pitch.delay_s, 2) + " ms later) of what the base model's motor map gives, the vertical at " +
         num(vertical.gain, 2) + " (r = " + num(vertical.r, 2) + "). Either the motor map's slope at the operating " +
         "point (mean command " + num(g.hover_command, 2) + ") is off (a map measured on a stand: motor_map slope " +
         num(g.suggested_slope(), 2) + " with pivot " + num(g.hover_command, 2) + ") or the controller answers a " +
         "disturbance in this band, which reads the same in closed loop; a flight with a known excitation added to " +
         "the rate set points separates them";
}

std::vector<std::pair<std::string, std::string>> command_gain_leads(const Diagnosis& d) {
  return leads(d.command_gain, d.command_gain_per_flight, d, command_gain_lead);
}

// Where the one-step test or the force model alone, not the open-loop rollouts, stood behind a
// finding: say so beside the rollouts' numbers, which then show no gain (or a loss).
std::string judged_by_text(const Finding& f) {
  if (f.accepted_by == Finding::kByForceModelAlone)
    return "; accepted by the force model alone: with the measured attitude replayed the held-out position RMSE is " +
           num(f.force_alone.mean, 3) + " m +- " + num(f.force_alone.standard_error, 3) +
           " m lower per fold, and the equation-error cost " + num(f.one_step.cost.mean, 3) + " % +- " +
           num(f.one_step.cost.standard_error, 3) +
           " % lower, neither kind of channel worse (the open loop is dominated by the moment model's attitude drift)";
  if (f.accepted_by != Finding::kByOneStep || f.one_step.cost.per_fold.empty()) return "";
  return "; accepted by its one-step gain: held-out equation-error cost " + num(f.one_step.cost.mean, 3) +
         " % +- " + num(f.one_step.cost.standard_error, 3) + " % lower per fold, the rollouts unchanged within their spread";
}

std::string beside_gain_text(const Finding& f) {
  // A comparison whose weights had not settled is less certain than its spread says.
  const std::string unsettled =
      !f.comparison || f.comparison->settled
          ? ""
          : "; the model without it had not settled its weights after " + std::to_string(f.comparison->refits) +
                " refits (last change " + num(f.comparison->last_change_percent, 2) + " %)";
  return judged_by_text(f) + unsettled;
}

// What spread agreeing flights would show, beside the one seen: " (if they agree: median
// 41 %, p = 0.62)"; nothing where it cannot be computed (one flight, no standard error).
std::string spread_context(const ParameterAgreement& a) {
  if (!std::isfinite(a.spread_if_agree) || a.flights.size() < 2) return "";
  return " (if they agree: median " + num(100 * a.spread_if_agree, 2) + " %, p = " + num(a.spread_p_value, 2) + ")";
}

// A 95 % interval; a side the profile never closed (NaN) reads "open", not as a number.
std::string interval(double lower, double upper, int prec = 4) {
  const auto side = [&](double v) { return std::isfinite(v) ? num(v, prec) : std::string("open"); };
  return "[" + side(lower) + ", " + side(upper) + "]";
}

}  // namespace

std::string diagnosis_summary(const Diagnosis& d) {
  std::ostringstream os;
  for (const auto& note : screening_notes(d)) os << note << "\n";
  if (d.findings.empty() && d.search.unresolved.empty() && d.unexplained.empty())
    os << "no significant discrepancy: the base model explains the flight\n";
  for (const auto& f : d.findings) {
    os << "found " << f.effect << ":";
    for (const auto& p : f.parameters)
      os << " " << p.name << " = " << num(p.value) << " " << interval(p.lower, p.upper);
    os << "; " << f.metric << ", the final model without it -> with it: " << num(f.before) << " -> " << num(f.after)
       << beside_gain_text(f) << "\n  "
       << headline(f) << "\n";
  }
  for (const auto& a : d.agreement) {
    os << "flights " << (a.agree ? "agree" : "disagree") << " on " << a.parameter << (a.named ? "" : " (suspected)") << " (spread " << num(100 * a.spread, 3)
       << " %" << spread_context(a) << ", Cochran's Q p = " << num(a.q_p_value, 2) << "):";
    for (size_t k = 0; k < a.flights.size(); ++k)
      os << " " << k + 1 << ": " << num(a.flights[k].value, 3) << " " << interval(a.flights[k].lower, a.flights[k].upper, 3);
    os << "\n";
  }
  for (const auto& a : d.airframe_check)
    os << "this flight " << (a.agree ? "agrees" : "disagrees") << " with the airframe on " << a.parameter << ": "
       << num(a.flights.front().value, 3) << " " << interval(a.flights.front().lower, a.flights.front().upper, 3)
       << " against " << num(a.joint_value, 3) << " (" << num(100 * a.spread, 3) << " % apart, p = " << num(a.q_p_value, 2)
       << ")\n";
  for (const auto& a : d.search.unresolved)
    os << "ambiguous: " << a.a << " or " << a.b << " (the data cannot tell them apart; the model carries " << a.a
       << "); to separate them: " << a.manoeuvre << "\n";
  for (const auto& st : d.stand_ins)
    os << "stands in for missing physics, not named: " << st.candidate.effect << " (" << st.parameter << " = "
       << num(st.value) << " " << st.unit << " lies outside [" << num(st.plausible_lower) << ", "
       << num(st.plausible_upper) << "], the plausible range" << (d.environment == "unknown" ? "" : " " + d.environment + "s")
       << ": " << st.why << ")\n";
  for (const auto& x : d.suspected)
    os << "suspected, not named: " << x.candidate.effect << " (" << x.failed << ")\n";
  for (const auto& r : d.search.removed) os << "dropped by the backward pass: " << r.effect << " (" << r.reason << ")\n";
  if (!d.search.left_at_limit.empty()) {
    os << "the search stopped at its limit of " << d.search.steps.size()
       << (d.search.steps.size() == 1 ? " effect" : " effects") << " (--max-effects); still significant in its last step:";
    for (size_t k = 0; k < d.search.left_at_limit.size(); ++k) {
      const auto& ev = d.search.left_at_limit[k];
      os << (k ? ", " : " ") << ev.effect << " (p = " << num(ev.p_value, 2) << (ev.implausible.empty() ? "" : ", implausible")
         << ")";
    }
    os << "\n";
  }
  for (const auto& p : d.at_bounds)
    os << "caution: " << p.name << " = " << num(p.value) << (p.unit == "1" ? "" : " " + p.unit)
       << (std::fabs(p.value - p.lower) <= std::fabs(p.value - p.upper) ? " (lower bound)" : " (upper bound)") << " — the model is strained there; a finding may stand in for missing physics\n";
  for (const auto& u : d.unexplained)
    os << "unexplained: " << u.channel << " residual has slow structure " << num(u.ratio, 3)
       << "x what noise gives, largest in t = " << num(u.t0, 3) << ".." << num(u.t1, 3) << " s, most correlated with "
       << u.signal << " (r = " << num(u.r, 2) << ")\n";
  for (const auto& [flight, lead] : draft_leads(d))
    os << (flight.empty() ? "" : output::printable(flight) + ": ") << lead << "\n";
  for (const auto& [flight, lead] : command_gain_leads(d))
    os << (flight.empty() ? "" : output::printable(flight) + ": ") << lead << "\n";
  for (const auto& t : d.discovered)
    if (t.proposed)
      os << "proposed term (beyond the catalogue, not a named cause): " << t.expression() << " [" << t.unit << "]; "
         << t.verdict << "\n";
  if (d.terms_gain.measured)
    os << "  with the proposed terms regenerated into the model (discovered_model.hpp): " << d.terms_gain.metric << " "
       << num(d.terms_gain.before) << " -> " << num(d.terms_gain.after) << " (per-fold gain " << num(d.terms_gain.gain_mean, 3)
       << " +- " << num(d.terms_gain.gain_standard_error, 3) << ")\n";
  if (d.has_prediction)
    if (const std::string limits = predict::what_limits_prediction(d.prediction_after); !limits.empty())
      os << "prediction of the extended model on the held-out part: " << limits << "\n";
  return os.str();
}

namespace {

// The command-gain check as a table: per flight (or the one flight) and axis, the gain,
// correlation and delay in each band; the leads below it.
void command_gain_html(std::ostream& h, const Diagnosis& d) {
  const auto rows = command_gains_by_flight(d);
  const CommandGain* first = nullptr;
  for (const auto& [flight, g] : rows)
    if (g->measured && !first) first = g;
  if (!first) return;
  h << "<h2>The answer to the commands</h2>\n<p>Gain of the measured on the base model's accelerations, band by band "
       "(1: the motor map's slope at the operating point is right), with the correlation and the delay of the model "
       "that correlates best. The lowest band carries the controller's answer to slow disturbances.</p>\n"
       "<table><tr>"
    << (d.command_gain_per_flight.empty() ? "" : "<th>flight</th>") << "<th>axis</th>";
  for (const auto& b : first->axes.front().bands) h << "<th>" << num(b.low_hz, 2) << "&ndash;" << num(b.high_hz, 2) << " Hz</th>";
  h << "</tr>\n";
  for (const auto& [flight, g] : rows) {
    if (!g->measured) continue;
    for (const auto& a : g->axes) {
      h << "<tr>" << (d.command_gain_per_flight.empty() ? "" : "<td>" + esc(flight) + "</td>") << "<td>" << esc(a.name) << "</td>";
      for (const auto& b : a.bands)
        h << "<td>" << num(b.gain, 2) << " (r " << num(b.r, 2) << ", " << num(1000 * b.delay_s, 2) << " ms)</td>";
      h << "</tr>\n";
    }
  }
  h << "</table>\n";
  for (const auto& [flight, lead] : command_gain_leads(d))
    h << "<p class=\"warn\">" << (flight.empty() ? "" : esc(flight) + ": ") << esc(lead) << "</p>\n";
}

// Beyond the catalogue: the proposed terms with their coefficients, and one line per channel
// for which none is proposed.
void discovered_terms_html(std::ostream& h, const Diagnosis& d) {
  if (d.discovered.empty()) return;
  h << "<h2>Beyond the catalogue: proposed terms</h2>\n<p>Sparse regression (sequentially thresholded least "
       "squares) of what the final model still gets wrong on the training part, over the constant, body velocity, "
       "body rates, mean command U, battery voltage and their pairwise products; sparsity chosen by "
       "cross-validation, a term kept only if significant after correction for the regressors searched, and "
       "proposed only if it predicts the held-out part better. What a term means physically is for you to "
       "decide; it is not a named cause.</p>\n<table><tr><th>channel</th><th>term added to the model</th>"
       "<th>coefficients (95 % interval)</th><th>held-out RMS</th><th>verdict</th></tr>\n";
  for (const auto& t : d.discovered) {
    h << "<tr><td>" << esc(t.channel) << "</td><td>" << (t.coefficients.empty() ? "&mdash;" : esc(t.expression()))
      << "</td><td>";
    for (size_t i = 0; i < t.coefficients.size(); ++i) {
      const auto& c = t.coefficients[i];
      h << (i ? "<br>" : "") << esc(c.regressor) << ": " << num(c.value, 3) << " " << interval(c.lower, c.upper, 3) << " " << esc(c.unit);
    }
    h << "</td><td>" << num(t.valid_rms_before, 3) << " &rarr; " << num(t.valid_rms_after, 3) << " " << esc(t.unit)
      << "</td><td>" << verdict_cell(t) << "</td></tr>\n";
  }
  h << "</table>\n";
  const auto& g = d.terms_gain;
  if (g.measured)
    h << "<p>With the proposed terms regenerated into the model (<code>discovered_model.hpp</code>) and simulated like an "
         "effect: "
      << esc(g.metric) << " " << num(g.before, 3) << " &rarr; " << num(g.after, 3) << " (gain per validation fold "
      << num(g.gain_mean, 3) << " &plusmn; " << num(g.gain_standard_error, 3) << ").</p>\n";
  else if (!g.note.empty())
    h << "<p>" << esc(g.note) << ".</p>\n";
}

// A per-flight finding at a glance: one row per parameter, one column per flight, each cell
// the value and its 95 % interval (and the verdict when it is not "identifiable").
void per_flight_table(std::ostringstream& h, const Finding& f, size_t flights) {
  std::map<std::string, std::vector<const EffectEstimate*>> rows;
  std::map<std::string, std::string> units;
  for (const auto& p : f.parameters) {
    auto& row = rows[runtime::shared_name(p.name)];
    row.resize(flights, nullptr);
    const size_t k = static_cast<size_t>(runtime::flight_of_name(p.name)) - 1;
    if (k < flights) row[k] = &p;
    units[runtime::shared_name(p.name)] = p.unit;
  }
  h << "<table><tr><th>parameter [unit]</th>";
  for (size_t k = 0; k < flights; ++k) h << "<th>flight " << k + 1 << "</th>";
  h << "</tr>\n";
  for (const auto& [name, row] : rows) {
    h << "<tr><td>" << esc(name) << " [" << esc(units[name]) << "]</td>";
    for (const auto* p : row)
      if (p)
        h << "<td>" << num(p->value, 3) << " " << interval(p->lower, p->upper, 3)
          << (p->verdict == "identifiable" ? "" : " <span class=\"warn\">(" + esc(p->verdict) + ")</span>") << "</td>";
      else h << "<td>–</td>";
    h << "</tr>\n";
  }
  h << "</table>\n";
}

// Each named airframe parameter per flight as a forest plot in the table: the flight's 95 %
// interval as a bar, its value as a dot, the joint value as a vertical line; agreeing
// flights' bars all cross the line.
void agreement_table_html(std::ostringstream& h, const std::vector<ParameterAgreement>& list,
                          const std::vector<std::string>& flights, const std::string& reference_name) {
  for (const auto& a : list) {
    double lo = a.joint_value, hi = a.joint_value;
    for (const auto& f : a.flights)
      for (double v : {f.value, f.lower, f.upper})
        if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
    const double pad = 0.05 * (hi - lo) + 1e-300;
    lo -= pad, hi += pad;
    const auto at = [&](double v) { return num(100 * (v - lo) / (hi - lo), 4) + "%"; };
    h << "<h3>" << esc(a.parameter) << " [" << esc(a.unit) << "]" << (a.named ? "" : " (suspected, not named)")
      << ": <span class=\"" << (a.agree ? "ok\">agree" : "warn\">disagree") << "</span></h3>\n<p>"
      << esc(reference_name) << " " << num(a.joint_value, 3) << ", pooled " << num(a.pooled, 3) << ", spread "
      << num(100 * a.spread, 3) << " %" << esc(spread_context(a)) << ", Cochran's Q = " << num(a.q, 3) << " (p = " << num(a.q_p_value, 2)
      << ").</p>\n<table><tr><th>flight</th><th>value</th><th>95 % interval</th><th>alone: p</th>"
         "<th style=\"width:40%\">at a glance</th></tr>\n";
    for (size_t k = 0; k < a.flights.size(); ++k) {
      const FlightEstimate& f = a.flights[k];
      h << "<tr><td>" << k + 1 << ". " << esc(k < flights.size() ? flights[k] : std::string()) << "</td><td>"
        << num(f.value, 3) << "</td><td>" << interval(f.lower, f.upper, 3) << "</td><td>"
        << num(f.p_value, 2) << "</td><td><div style=\"position:relative;height:14px\">"
        << "<div style=\"position:absolute;left:" << at(a.joint_value) << ";top:0;bottom:0;border-left:1px solid #c00\"></div>";
      if (std::isfinite(f.lower) && std::isfinite(f.upper))
        h << "<div style=\"position:absolute;left:" << at(f.lower) << ";width:calc(" << at(f.upper) << " - " << at(f.lower)
          << ");top:5px;height:4px;background:#357\"></div>";
      h << "<div style=\"position:absolute;left:calc(" << at(f.value) << " - 4px);top:3px;width:8px;height:8px;"
        << "border-radius:4px;background:#123\"></div></div></td></tr>\n";
    }
    h << "</table>\n";
  }
}

void agreement_html(std::ostringstream& h, const Diagnosis& d) {
  if (!d.airframe_check.empty()) {
    h << "<h2>Against the airframe</h2>\n<p>The named effects of the airframe in " << esc(d.airframe_source)
      << " refitted on this flight's training part (the airframe's other values held, this flight's own thrust "
         "constant and trims free). The flight agrees with the airframe when the difference is within 1.96 of its "
         "standard error (both estimates' errors) and below 30 %. Line: the airframe's value.</p>\n";
    agreement_table_html(h, d.airframe_check, d.flights, "airframe");
  }
  if (d.agreement.empty()) return;
  h << "<h2>Do the flights agree?</h2>\n<p>Each named airframe effect refitted on each flight's training part alone "
       "(the other airframe values held at the joint fit, the flight's own trims and thrust constant free). Bars: "
       "each flight's 95 % interval (Wald); dot: its value; line: the joint value (a suspected candidate's own "
       "joint estimate). \"Alone\": the effect's "
       "likelihood-ratio test on that flight by itself. The flights agree when every interval holds the pooled "
       "value and the spread (largest &minus; smallest over the joint value) is below 30 %. Beside the spread: the "
       "median spread the flights would show if each measured the pooled value with its own standard error, and the "
       "chance of one at least as large as seen: a limit of 30 % cannot be met by flights whose intervals are much "
       "wider, however well they agree.</p>\n";
  agreement_table_html(h, d.agreement, d.flights, "joint");
}


// The page's head, the title (the flights numbered: per-flight values refer to these
// numbers), what was fitted to what, and the screening's warnings.
void head_html(std::ostringstream& h, const Diagnosis& d, const std::string& log_path) {
  h << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>quadgen diagnosis: " << esc(d.vehicle)
    << "</title>\n<style>body{font-family:sans-serif;max-width:1100px;margin:2em auto;color:#222}"
       "table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #bbb;padding:3px 8px;text-align:right}"
       "th{background:#eee}td:first-child{text-align:left}.ok{color:#070}.no{color:#888}.warn{color:#a40}"
       "svg{max-width:100%;height:auto}pre{background:#f6f6f6;padding:.5em;white-space:pre-wrap}"
       ".headline{font-size:1.1em}</style></head><body>\n";
  // Several flights: their count in the title (their paths, a wall of text there, numbered
  // below it: the per-flight values refer to these numbers).
  const std::string subject = d.flights.size() > 1    ? std::to_string(d.flights.size()) + " flights"
                              : d.flights.size() == 1 ? d.flights[0]  // the others left out, said below
                                                      : log_path;
  h << "<h1>Diagnosis of " << esc(subject) << " (" << esc(d.vehicle) << ")</h1>\n";
  if (d.flights.size() > 1) {
    h << "<ol>\n";
    for (const auto& f : d.flights) h << "<li>" << esc(f) << "</li>\n";
    h << "</ol>\n";
  }
  h << "<p>" << esc(d.formulation) << "; " << d.train_samples << " training samples, " << d.valid_samples;
  if (d.flights.size() > 1)
    h << " validation samples (the end of each of " << d.flights.size() << " flights, diagnosed jointly: one set of "
      << "vehicle parameters)";
  else
    h << " validation samples from t = " << num(d.t_split, 4) << " s";
  h << "; " << num(d.seconds, 3) << " s.</p>\n";
  for (const auto& note : screening_notes(d)) h << "<p class=\"warn\">" << esc(note) << "</p>\n";
}

// One line per named cause and the held-out gain, then the command's own printout (for a
// reader who compares it with a terminal) and the overall gain.
void in_short_html(std::ostringstream& h, const Diagnosis& d) {
  h << "<h2>In short</h2>\n<ul class=\"headline\">\n";
  if (d.findings.empty()) h << "<li>No cause named.</li>\n";
  for (const auto& f : d.findings) h << "<li>" << esc(headline(f)) << "</li>\n";
  if (const auto p = point_of_action(d)) h << "<li>" << esc(point_of_action_headline(*p)) << "</li>\n";
  if (!d.findings.empty())
    h << "<li>With " << (d.findings.size() > 1 ? "them" : "it") << ", the model predicts the held-out part "
      << num(reduction(d.metric_before, d.metric_after), 2) << " % better (" << esc(d.metric) << " "
      << num(d.metric_before) << " &rarr; " << num(d.metric_after) << ").</li>\n";
  // The command's own printout, for a reader who compares it with a terminal; the sections
  // below say the same in tables.
  h << "</ul>\n<details><summary>Verdict as the command printed it</summary>\n<pre>" << output::html_preformatted(diagnosis_summary(d))
    << "</pre></details>\n";
  h << "<p>Overall gain: " << esc(d.metric) << " " << num(d.metric_before) << " &rarr; " << num(d.metric_after) << " ("
    << num(reduction(d.metric_before, d.metric_after), 3) << " % lower).</p>\n";
}

void findings_html(std::ostringstream& h, const Diagnosis& d) {
  h << "<h2>Findings</h2>\n";
  if (d.findings.empty()) h << "<p>None.</p>\n";
  if (!d.per_flight_effects.empty()) {
    h << "<p>One value per flight for ";
    for (size_t i = 0; i < d.per_flight_effects.size(); ++i) h << (i ? ", " : "") << esc(d.per_flight_effects[i]);
    h << " (a property of the flight, not of the airframe): a plain name is flight 1's, <i>name</i>@<i>k</i> flight "
         "<i>k</i>'s (flights numbered as under the title).</p>\n";
  }
  for (const auto& f : d.findings) {
    h << "<h3>" << esc(f.effect) << "</h3>\n<p class=\"headline\"><b>" << esc(headline(f)) << "</b> Held out: "
      << esc(f.metric) << " " << num(f.before) << " without it &rarr; " << num(f.after) << " with it ("
      << num(reduction(f.before, f.after), 3) << " % lower)" << esc(beside_gain_text(f)) << ".</p>\n";
    const bool per_flight = d.flights.size() > 1 && std::find(d.per_flight_effects.begin(), d.per_flight_effects.end(),
                                                              f.effect) != d.per_flight_effects.end();
    if (per_flight) {
      per_flight_table(h, f, d.flights.size());
      h << "<p>Intervals: each flight's value &plusmn; 1.96 standard errors of the joint fit (Wald), which includes "
           "the uncertainty of the airframe's parameters; the airframe's parameters have profile-likelihood "
           "intervals.</p>\n";
    }
    else {
      h << "<table><tr><th>parameter</th><th>value</th><th>95 % interval</th><th>unit</th><th>identifiability</th></tr>\n";
      for (const auto& p : f.parameters)
        h << "<tr><td>" << esc(p.name) << "</td><td>" << num(p.value) << "</td><td>" << interval(p.lower, p.upper)
          << "</td><td>" << esc(p.unit) << "</td><td>" << esc(p.verdict) << "</td></tr>\n";
      h << "</table>\n";
    }
    h << "<p>Evidence: LR statistic " << num(f.evidence.statistic) << " on " << f.evidence.dof << " dof, p = "
      << num(f.evidence.p_value, 3) << " (level " << num(f.evidence.level, 3) << "), &Delta;BIC " << num(f.evidence.delta_bic)
      << ".</p>\n";
  }
}

void stand_ins_html(std::ostringstream& h, const Diagnosis& d) {
  if (!d.stand_ins.empty()) {
    h << "<h2>Stand-ins for missing physics</h2>\n<p>Each passed every statistical test, but its value lies outside "
         "what its physics can produce here: it absorbs an error of something the model lacks. It stays in the "
         "extended model and is not named.</p>\n<table><tr><th>effect</th><th>value</th><th>plausible</th><th>why</th>"
         "<th>training residual RMS it absorbs (without &rarr; with)</th></tr>\n";
    for (const auto& st : d.stand_ins) {
      h << "<tr><td>" << esc(st.candidate.effect) << "</td><td>" << esc(st.parameter) << " = " << num(st.value) << " "
        << esc(st.unit) << "</td><td>[" << num(st.plausible_lower) << ", " << num(st.plausible_upper) << "]</td><td>"
        << esc(st.why) << "</td><td>";
      for (size_t c = 0; c < st.channels.size(); ++c)
        h << (c ? "; " : "") << esc(st.channels[c]) << " " << num(st.rms_without[c], 3) << " &rarr; "
          << num(st.rms_with[c], 3);
      h << "</td></tr>\n";
    }
    h << "</table>\n";
  }
}

void ambiguous_html(std::ostringstream& h, const Diagnosis& d) {
  if (!d.search.unresolved.empty()) {
    h << "<h2>Ambiguous</h2>\n";
    for (const auto& a : d.search.unresolved)
      h << "<p class=\"warn\"><b>" << esc(a.a) << "</b> or <b>" << esc(a.b)
        << "</b>: both explain the discrepancy and neither adds anything significant to the other (p = "
        << num(a.b_given_a_p, 3) << ", " << num(a.a_given_b_p, 3) << "). Not named. To separate them: " << esc(a.manoeuvre)
        << ".</p>\n";
  }
}

// Slow structure the catalogue leaves, and the draft check's leads.
void unexplained_html(std::ostringstream& h, const Diagnosis& d) {
  if (!d.unexplained.empty()) {
    h << "<h2>Unexplained discrepancies</h2>\n<table><tr><th>channel</th><th>slow RMS</th><th>x noise</th><th>largest in [s]</th><th>most correlated with</th><th>r</th></tr>\n";
    for (const auto& u : d.unexplained)
      h << "<tr><td>" << esc(u.channel) << "</td><td>" << num(u.slow_rms) << " " << esc(u.unit) << "</td><td>" << num(u.ratio, 3)
        << "</td><td>" << num(u.t0, 4) << "&ndash;" << num(u.t1, 4) << "</td><td>" << esc(u.signal) << "</td><td>" << num(u.r, 2)
        << "</td></tr>\n";
    h << "</table>\n";
  }
  for (const auto& [flight, lead] : draft_leads(d))
    h << "<p>" << (flight.empty() ? "" : esc(flight) + ": ") << esc(lead) << "</p>\n";
}

void prediction_html(std::ostringstream& h, const Diagnosis& d) {
  if (d.has_prediction) {
    // Comparable with published models: the error AT a horizon, averaged over start points.
    h << "<h2>Prediction on the validation part</h2>\n";
    if (d.prediction_after.open_loop.empty())
      h << "<p>No pose logged: no open-loop rollouts (each starts from a measured state); one-step errors only.</p>\n";
    h << "<table><tr><th>horizon [s]</th><th>position, base [m]</th>"
         "<th>position, extended [m]</th><th>tilt, extended [rad]</th><th>heading, extended [rad]</th>"
         "<th>position, attitude replayed [m]</th><th>tilt, translation replayed [rad]</th>"
         "<th>position, past disturbance held, extended [m]</th></tr>\n";
    const auto& b = d.prediction_before;
    const auto& a = d.prediction_after;
    for (size_t i = 0; i < a.open_loop.size() && i < b.open_loop.size(); ++i)
      h << "<tr><td>" << num(a.open_loop[i].horizon) << "</td><td>" << num(b.open_loop[i].position.mean()) << "</td><td>"
        << num(a.open_loop[i].position.mean()) << "</td><td>" << num(a.open_loop[i].tilt.mean()) << "</td><td>"
        << num(a.open_loop[i].heading.mean()) << "</td><td>"
        << (i < a.attitude_replayed.size() ? num(a.attitude_replayed[i].position.mean()) : "–") << "</td><td>"
        << (i < a.translation_replayed.size() ? num(a.translation_replayed[i].tilt.mean()) : "–") << "</td><td>"
        << (i < a.open_loop_past_disturbance.size() ? num(a.open_loop_past_disturbance[i].position.mean()) : "–")
        << "</td></tr>\n";
    h << "</table>\n<p>Means over " << a.start_points << " start points; one step (extended model), RMS: body specific force "
      << num(a.one_step.specific_force[0].rms(), 3) << " / " << num(a.one_step.specific_force[1].rms(), 3) << " / "
      << num(a.one_step.specific_force[2].rms(), 3) << " m/s², angular acceleration "
      << num(a.one_step.angular_acceleration[0].rms(), 3) << " / " << num(a.one_step.angular_acceleration[1].rms(), 3) << " / "
      << num(a.one_step.angular_acceleration[2].rms(), 3) << " rad/s², world vertical acceleration "
      << num(a.one_step.vertical_acceleration_world.rms(), 3) << " m/s².</p>\n";
    if (const std::string limits = predict::what_limits_prediction(a); !limits.empty())
      h << "<p>What limits it (extended model): " << esc(limits) << "</p>\n";
  }
}

void validation_channels_html(std::ostringstream& h, const Diagnosis& d) {
  h << "<h2>Validation per channel</h2>\n<table><tr><th>channel</th><th>unit</th><th>RMS base</th><th>RMS extended</th>"
       "<th>reduction %</th></tr>\n";
  for (const auto& c : d.channel_gain)
    h << "<tr><td>" << esc(c.channel) << "</td><td>" << esc(channel_unit(d, c.channel)) << "</td><td>" << num(c.before)
      << "</td><td>" << num(c.after) << "</td><td>" << num(reduction(c.before, c.after), 3) << "</td></tr>\n";
  h << "</table>\n";
}

void base_residuals_html(std::ostringstream& h, const Diagnosis& d) {
  h << "<h2>What the base model gets wrong</h2>\n<table><tr><th>channel</th><th>unit</th><th>RMS</th><th>bias</th>"
       "<th>corr. time [samples]</th><th>slow / noise</th><th>strongest correlations (r)</th></tr>\n";
  for (const auto& c : d.before.channels) {
    h << "<tr><td>" << esc(c.name) << "</td><td>" << esc(channel_unit(d, c.name)) << "</td><td>" << num(c.rms) << "</td><td>"
      << num(c.bias) << "</td><td>" << num(c.tau_int, 3)
      << "</td><td>" << num(c.slow_ratio, 3) << "</td><td>";
    for (size_t i = 0; i < c.correlations.size() && i < 3; ++i)
      h << (i ? ", " : "") << esc(c.correlations[i].signal) << " (" << num(c.correlations[i].r, 2) << ")";
    h << "</td></tr>\n";
  }
  h << "</table>\n";
}

void candidates_html(std::ostringstream& h, const Diagnosis& d) {
  h << "<h2>Candidates</h2>\n";
  for (size_t s = 0; s < d.search.steps.size(); ++s) {
    const auto& st = d.search.steps[s];
    h << "<h3>Step " << s + 1 << " (model: base";
    for (const auto& e : st.base_effects) h << " + " << esc(e);
    h << ")</h3>\n<table><tr><th>effect</th><th>LR</th><th>dof</th><th>p</th><th>&Delta;BIC</th><th>&Delta;AIC</th><th>validation gain %</th><th>verdict</th></tr>\n";
    for (const auto& c : st.candidates)
      h << "<tr><td>" << esc(c.effect) << "</td><td>" << num(c.statistic) << "</td><td>" << c.dof << "</td><td>" << num(c.p_value, 3)
        << "</td><td>" << num(c.delta_bic) << "</td><td>" << num(c.delta_aic) << "</td><td>" << num(c.validation_gain_percent, 3)
        << "</td><td class=\"" << (c.significant ? "ok\">significant" : "no\">" + esc(c.why_not))
        << (c.implausible.empty() ? "" : "; implausible here: " + esc(c.implausible)) << "</td></tr>\n";
    h << "</table>\n";
  }
}

void plots_html(std::ostringstream& h, const std::vector<std::pair<std::string, std::string>>& plots) {
  h << "<h2>Plots</h2>\n";
  if (plots.empty()) h << "<p>No plots (gnuplot unavailable).</p>\n";
  for (const auto& [name, svg] : plots) {
    const size_t at = svg.find("<svg");
    const std::string stem = name.substr(0, name.rfind('.'));
    h << "<figure>" << (at == std::string::npos ? "" : svg.substr(at)) << "<figcaption>" << esc(name);
    h << " (data: <a href=\"" << esc(stem) << ".csv\">" << esc(stem) << ".csv</a>)";
    h << "</figcaption></figure>\n";
  }
}

void method_html(std::ostringstream& h) {
  h << "<h2>Method</h2>\n<p>Each candidate is the full-catalogue model with only that effect (and those already found) free; "
       "the statistic is the drop of the residual sum of squares per channel divided by the larger model's noise variance "
       "times its integrated autocorrelation time, compared with chi2 (chi-bar-square for a parameter whose neutral value "
       "is its bound) at a Bonferroni level; a candidate must also lower BIC and the cost on the validation part. "
       "Intervals are profile-likelihood intervals with the same weights, widened on both sides by the change of the "
       "estimate when the interval accelerations use the trapezoid instead of the midpoint rule (discretisation error).</p>\n</body></html>\n";
}

}  // namespace

std::string diagnosis_html(const Diagnosis& d, const std::string& log_path,
                           const std::vector<std::pair<std::string, std::string>>& plots) {
  std::ostringstream h;
  head_html(h, d, log_path);
  in_short_html(h, d);
  findings_html(h, d);
  agreement_html(h, d);
  stand_ins_html(h, d);
  ambiguous_html(h, d);
  unexplained_html(h, d);
  command_gain_html(h, d);
  discovered_terms_html(h, d);
  prediction_html(h, d);
  validation_channels_html(h, d);
  base_residuals_html(h, d);
  candidates_html(h, d);
  plots_html(h, plots);
  method_html(h);
  return h.str();
}

}  // namespace quadgen::diagnose
