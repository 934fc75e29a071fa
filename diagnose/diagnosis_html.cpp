#include "diagnose/diagnosis_report.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <initializer_list>
#include <map>
#include <optional>
#include <sstream>
#include <string_view>

#include "derive/effects/effect_catalogue.hpp"
#include "diagnose/report_words.hpp"
#include "fit/fit_report.hpp"
#include "output/joined.hpp"
#include "output/estimate.hpp"
#include "output/numbers.hpp"
#include "output/sinks.hpp"
#include "runtime/per_flight_model.hpp"
#include "runtime/plot.hpp"

namespace quadgen::diagnose {

using namespace words;

namespace {

std::string esc(const std::string& s) { return output::html_text(s); }
// A unit on the page as a person reads it ("m/s²"); diagnosis.json keeps the declared "m/s^2".
std::string unit_html(const std::string& unit) { return esc(output::unit_for_reading(unit)); }

// A sentence the terminal shares, for the page: its ASCII arrow and plus-minus as the page's
// tables write them (a review, helper-111: "0.294 -> 0.312" beside "0.401 &rarr; 0.353").
std::string prose(const std::string& s) {
  std::string out = esc(s);
  for (const auto& [ascii, html] : {std::pair<std::string, std::string>{" -&gt; ", " &rarr; "}, {" +- ", " &plusmn; "}})
    for (size_t at = 0; (at = out.find(ascii, at)) != std::string::npos; at += html.size()) out.replace(at, ascii.size(), html);
  return out;
}

// The plots, each beside the section whose numbers it draws (a user trial, helper-106: the
// held-out comparison sat at the page's end, below every candidate's table). A plot no section
// shows (its section is not on this page, or a name this page does not know) goes under "More
// plots" at the end, so that none is lost.
class Figures {
 public:
  explicit Figures(const std::vector<std::pair<std::string, std::string>>& plots)
      : plots_(plots), shown_(plots.size(), false) {}

  // Those of `names` that were drawn, in that order.
  void show(std::ostream& h, std::initializer_list<std::string_view> names) {
    for (const std::string_view name : names)
      for (size_t i = 0; i < plots_.size(); ++i)
        if (!shown_[i] && plots_[i].first == name) figure(h, i);
  }

  void show_rest(std::ostream& h) {
    if (plots_.empty()) h << "<h2>Plots</h2>\n<p>No plots (gnuplot unavailable).</p>\n";
    if (std::find(shown_.begin(), shown_.end(), false) != shown_.end()) h << "<h2>More plots</h2>\n";
    for (size_t i = 0; i < plots_.size(); ++i)
      if (!shown_[i]) figure(h, i);
  }

 private:
  void figure(std::ostream& h, size_t i) {
    shown_[i] = true;
    const auto& [name, svg] = plots_[i];
    const size_t at = svg.find("<svg");
    const std::string stem = name.substr(0, name.rfind('.'));
    const std::string look_for = what_to_look_for(name);
    h << "<figure>" << (at == std::string::npos ? "" : svg.substr(at)) << "<figcaption>"
      << (look_for.empty() ? "" : "<b>What to look for:</b> " + esc(look_for) + ". ") << esc(name);
    h << " (data: <a href=\"" << esc(stem) << ".csv\">" << esc(stem) << ".csv</a>)";
    h << "</figcaption></figure>\n";
  }

  const std::vector<std::pair<std::string, std::string>>& plots_;
  std::vector<bool> shown_;
};

// A flight's log by its file name: the full paths are listed once at the top of the report
// (and on hover), where in every table row they pushed the numbers and the plot aside.
std::string file_name_of(const std::string& path) {
  const std::string name = std::filesystem::path(path).filename().string();
  return name.empty() ? path : name;
}

// Beside a finding of the flight's own (its scope "flight"), in "In short" and its heading.
std::string flights_own_tag(const Diagnosis& d, const std::string& effect) {
  return scope(effect) == "flight" ? " <small>(" + esc(flights_own(d)) + ")</small>" : "";
}

// A discovered term's verdict for the report: its label ("proposed" in bold), then why.
std::string verdict_cell(const DiscoveredTerm& t) {
  return (t.proposed ? "<b>proposed</b>" : esc(t.verdict_label)) + prose(": " + t.verdict_reason);
}

// A check's leads: each claim once, the numbers of each source that shows it below.
void lead_html(std::ostream& h, const std::vector<Lead>& leads, const std::string& css_class) {
  for (const auto& lead : leads) {
    h << "<p" << (css_class.empty() ? "" : " class=\"" + css_class + "\"") << ">" << esc(lead.claim) << "</p>\n<ul>\n";
    for (const auto& [source, numbers] : lead.evidence)
      h << "<li>" << esc(source) << ": " << esc(numbers) << "</li>\n";
    h << "</ul>\n";
  }
}

// The command-gain check as a table: per flight (or the one flight) and axis, the gain,
// correlation and delay in each band; the leads below it.
void command_gain_html(std::ostream& h, const Diagnosis& d, Figures& figures) {
  const auto rows = command_gains_by_flight(d);
  const CommandGain* first = nullptr;
  for (const auto& [flight, g] : rows)
    if (g->measured && !first) first = g;
  if (!first) return;
  h << "<h2>The answer to the commands</h2>\n<p>Gain of the measured on the base model's accelerations, band by band "
       "(1: the motor map's slope at the operating point is right), with the correlation and the delay of the model "
       "that correlates best. The lowest band carries the controller's answer to slow disturbances. A band whose "
       "correlation is below " << significant(CommandGain::kMinR, 2) << " shows no gain: there the commands explain too "
       "little of the measured (a closed loop that only answers disturbances, no excitation) for the gain to mean "
       "the slope. Even well correlated, a closed loop reads low in band (generated flights with an exact map: "
       "0.55-0.8 at 4-8 Hz), so a gain below 1 is a lead, not a measurement of the map.</p>\n"
       "<table><tr>"
    << (d.command_gain_per_flight.empty() ? "" : "<th>flight</th>") << "<th>axis</th>";
  for (const auto& b : first->axes.front().bands) h << "<th>" << significant(b.low_hz, 2) << "&ndash;" << significant(b.high_hz, 2) << " Hz</th>";
  h << "</tr>\n";
  // Flights numbered as in the agreement table and under the title: two logs whose names differ
  // only by a trailing blank read alike (a review, helper-135).
  for (size_t k = 0; k < rows.size(); ++k) {
    const auto& [flight, g] = rows[k];
    if (!g->measured) continue;
    for (const auto& a : g->axes) {
      h << "<tr>"
        << (d.command_gain_per_flight.empty() ? "" : "<td class=\"flight\" title=\"" + esc(flight) + "\">" +
                                                         std::to_string(k + 1) + ".&nbsp;" + esc(file_name_of(flight)) + "</td>")
        << "<td>" << esc(a.name) << "</td>";
      for (const auto& b : a.bands)
        if (b.r < CommandGain::kMinR) h << "<td>&mdash; (r " << significant(b.r, 2) << ")</td>";
        else h << "<td>" << significant(b.gain, 2) << " (r " << significant(b.r, 2) << ", " << significant(1000 * b.delay_s, 2) << " ms)</td>";
      h << "</tr>\n";
    }
  }
  h << "</table>\n";
  figures.show(h, {"command_gain.svg"});
  lead_html(h, command_gain_leads(d), "warn");
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
      h << (i ? "<br>" : "") << esc(c.regressor) << ": " << estimate(c.value, c.lower, c.upper) << " " << unit_html(c.unit);
    }
    h << "</td><td>" << significant(t.valid_rms_before, 3) << " &rarr; " << significant(t.valid_rms_after, 3) << " " << unit_html(t.unit)
      << "</td><td>" << verdict_cell(t) << "</td></tr>\n";
  }
  h << "</table>\n";
  const auto& g = d.terms_gain;
  if (g.measured)
    h << "<p>With the proposed terms regenerated into the model (<code>discovered_model.hpp</code>) and simulated like an "
         "effect: "
      << esc(g.metric) << " " << significant(g.before, 3) << " &rarr; " << significant(g.after, 3) << " (gain per held-out fold "
      << significant(g.gain_mean, 3) << " &plusmn; " << significant(g.gain_standard_error, 3) << ")"
      << esc(terms_gain_verdict(g.gain_mean, g.gain_standard_error)) << ".</p>\n";
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
    h << "<tr><td>" << esc(name) << " [" << unit_html(units[name]) << "]</td>";
    for (const auto* p : row)
      if (p)
        h << "<td>" << estimate(p->value, p->lower, p->upper)
          << (!p->verdict || *p->verdict == fit::Identifiability::kIdentifiable
                  ? ""
                  : " <span class=\"warn\">(" + std::string(fit::identifiability_text(*p->verdict)) + ")</span>") << "</td>";
      else h << "<td>–</td>";
    h << "</tr>\n";
  }
  h << "</table>\n";
}

// Each named airframe parameter per flight as a forest plot in the table: the flight's 95 %
// interval as a bar, its value as a dot, the joint value as a vertical line; agreeing
// flights' bars all cross the line.
// The joint fit's 95 % interval of `parameter` among the findings (NaN, NaN where none has it).
std::pair<double, double> joint_interval(const std::vector<Finding>& findings, const std::string& parameter) {
  for (const auto& f : findings)
    for (const auto& p : f.parameters)
      if (p.name == parameter) return {p.lower, p.upper};
  return {NAN, NAN};
}

// `joint`: the findings whose intervals are drawn as the reference's band (none against an
// airframe, whose interval this diagnosis does not have).
void agreement_table_html(std::ostringstream& h, const std::vector<ParameterAgreement>& list,
                          const std::vector<std::string>& flights, const std::string& reference_name,
                          const std::vector<Finding>& joint = {}) {
  for (const auto& a : list) {
    const bool alone = !a.base;  // a base parameter has no "off" to test against
    const auto [band_lo, band_hi] = joint_interval(joint, a.parameter);
    double lo = a.joint_value, hi = a.joint_value;
    for (const auto& f : a.flights)
      for (double v : {f.value, f.lower, f.upper, band_lo, band_hi})
        if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
    const double pad = 0.05 * (hi - lo) + 1e-300;
    lo -= pad, hi += pad;
    const auto at = [&](double v) { return significant(100 * (v - lo) / (hi - lo), 4) + "%"; };
    // One precision for the table: each flight's value apart from its interval's sides, and
    // the reference's apart from them too (a review, helper-119: "-0.08 against -0.08").
    int prec = kEstimateDigits;
    for (const auto& f : a.flights)
      prec = std::max({prec, estimate_digits(f.value, f.lower, f.upper), estimate_digits(a.joint_value, f.lower, f.upper)});
    // A suspect's agreement in grey: green read as an endorsement of what is not named.
    h << "<h3>" << esc(a.parameter) << " [" << unit_html(a.unit) << "]" << (a.named ? "" : " (suspected, not named)")
      << ": <span class=\"" << (!a.named ? "no" : a.agree ? "ok" : "warn") << "\">" << agreement_verdict(a)
      << (*agreement_reason(a) ? std::string(" (") + agreement_reason(a) + ")" : "") << "</span></h3>\n<p>"
      << esc(reference_name) << " " << significant(a.joint_value, prec) << ", pooled " << significant(a.pooled, prec) << ", spread "
      << significant(100 * a.spread, 3) << " %" << esc(spread_context(a)) << ", Cochran's Q = " << significant(a.q, 3) << " (" << esc(output::p_is(a.q_p_value))
      << ").</p>\n<table class=\"agreement\"><tr><th>flight</th><th>value</th><th>95 % interval</th>" << (alone ? "<th>alone: p</th>" : "")
      << "<th style=\"width:40%\">at a glance</th></tr>\n";
    for (size_t k = 0; k < a.flights.size(); ++k) {
      const FlightEstimate& f = a.flights[k];
      const std::string path = k < flights.size() ? flights[k] : std::string();
      h << "<tr><td class=\"flight\" title=\"" << esc(path) << "\">" << k + 1 << ".&nbsp;" << esc(file_name_of(path)) << "</td><td>"
        << significant(f.value, prec) << (f.at_bound ? " (on its bound)" : "") << "</td><td>"
        << (f.at_bound ? std::string("none") : interval(f.lower, f.upper, prec))
        << "</td><td>" << (alone ? esc(output::p_value_cell(f.p_value)) + "</td><td>" : "")
        << "<div style=\"position:relative;height:14px\">";
      if (std::isfinite(band_lo) && std::isfinite(band_hi))  // the joint fit's interval, behind
        h << "<div style=\"position:absolute;left:" << at(band_lo) << ";width:calc(" << at(band_hi) << " - " << at(band_lo)
          << ");top:0;bottom:0;background:#f4d6d6\"></div>";
      h << "<div style=\"position:absolute;left:" << at(a.joint_value) << ";top:0;bottom:0;border-left:1px solid #c00\"></div>";
      if (std::isfinite(f.lower) && std::isfinite(f.upper))
        h << "<div style=\"position:absolute;left:" << at(f.lower) << ";width:calc(" << at(f.upper) << " - " << at(f.lower)
          << ");top:5px;height:4px;background:#357\"></div>";
      h << "<div style=\"position:absolute;left:calc(" << at(f.value) << " - 4px);top:3px;width:8px;height:8px;"
        << "border-radius:4px;background:#123\"></div></div></td></tr>\n";
    }
    // The strips' scale (a user trial, helper-106: bars without an axis).
    h << "<tr><td colspan=\"" << (alone ? 4 : 3) << "\"><small>scale of the bars" << (output::unit_after_number(a.unit).empty() ? "" : " [" + unit_html(a.unit) + "]")
      << (std::isfinite(band_lo) && std::isfinite(band_hi) ? "; shaded: the joint fit's 95 % interval" : "")
      << "</small></td><td><div style=\"display:flex;justify-content:space-between\"><small>" << significant(lo, 3)
      << "</small><small>" << significant(hi, 3) << "</small></div></td></tr>\n";
    h << "</table>\n";
  }
}

// The base model's shared parameters per flight, after the effects' table (what is named comes first).
void base_agreement_section(std::ostringstream& h, const Diagnosis& d) {
  if (d.base_agreement.empty()) return;
  const std::string names = output::joined(d.base_agreement, ", ", [](const auto& a) { return esc(a.parameter); });
  h << "<h2>Do the flights agree on the base model?</h2>\n<p>The base model's parameters every flight shares and "
       "the joint fit fitted (" << names << ") refitted together on each flight's training part alone, with the named "
       "effects free beside them (their shapes may overlap: a frame's drag and rotor drag at walking speeds) and the "
       "flight's own thrust constant, trims and motor gains free. Bars, intervals and verdicts as for an effect's "
       "agreement; no \"alone\" test, since the base model has no \"off\". A value on its bound has no interval and "
       "cannot say. Flights that disagree here are not one airframe's either: the parameter is carrying something "
       "that differs between them.</p>\n";
  agreement_table_html(h, d.base_agreement, d.flights, "joint");
}

void agreement_html(std::ostringstream& h, const Diagnosis& d) {
  if (!d.airframe_check.empty()) {
    h << "<h2>Against the airframe</h2>\n<p>The named effects of the airframe in " << esc(d.airframe_source)
      << " refitted on this flight's training part (the airframe's other values held, this flight's own thrust "
         "constant and trims free). The flight agrees with the airframe when the difference is within 1.96 of its "
         "standard error (both estimates' errors) and below 30 %; within the errors but 30 % or more apart it is \"too "
         "uncertain\" to agree. Line: the airframe's value.</p>\n";
    if (!words::airframe_from_one_flight(d).empty())
      h << "<p class=\"warn\">Note: " << esc(words::airframe_from_one_flight(d)) << ".</p>\n";
    agreement_table_html(h, d.airframe_check, d.flights, "airframe");
  }
  if (d.agreement.empty()) return base_agreement_section(h, d);
  h << "<h2>Do the flights agree?</h2>\n<p>Each named airframe effect refitted on each flight's training part alone "
       "(the other airframe values held at the joint fit, the flight's own trims and thrust constant free). Bars: "
       "each flight's 95 % interval (Wald); dot: its value; line: the joint value (a suspected candidate's own "
       "joint estimate). \"Alone\": the effect's "
       "likelihood-ratio test on that flight by itself. The flights disagree when Cochran's Q rejects one "
       "value at the 5 % level (one test per parameter) and the values are 1 % or more apart; they agree when "
       "neither holds, every flight can say and the spread (largest &minus; smallest over the joint value) is below 30 %. Beside the spread: the "
       "median spread the flights would show if each measured the pooled value with its own standard error, and the "
       "chance of one at least as large as seen: a limit of 30 % cannot be met by flights whose intervals are much "
       "wider, however well they agree: where Q does not reject one value and only the 30 % is missed, the verdict "
       "is \"too uncertain\", not \"disagree\".</p>\n";
  agreement_table_html(h, d.agreement, d.flights, "joint", d.findings);
  base_agreement_section(h, d);
}

// The page's head, the title (the flights numbered: per-flight values refer to these
// numbers), what was fitted to what, and the screening's warnings.
void head_html(std::ostringstream& h, const Diagnosis& d, const std::string& log_path) {
  h << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>quadgen diagnosis: " << esc(d.vehicle)
    << "</title>\n<style>body{font-family:sans-serif;max-width:1100px;margin:2em auto;color:#222}"
       "table{border-collapse:collapse;margin:1em 0;display:block;max-width:100%;overflow-x:auto}"  // narrow screens scroll a table
       "table.glance td,table.glance th{text-align:left;vertical-align:top}.path{color:#555;overflow-wrap:anywhere}"
       "td,th{border:1px solid #bbb;padding:3px 8px;text-align:right}"
       // A number or an interval is read whole: rotor drag's per-flight values broke as
       // "1.344e-" / "06" beside the bars (a screenshot, sixty-first session).
       "table.agreement td:not(:first-child){white-space:nowrap}"
       // A flight's file name longer than its column breaks anywhere rather than pushing
       // the bars off the page (a review, helper-134); its number stays with it (&nbsp;).
       "td.flight{min-width:8em;overflow-wrap:anywhere}"
       "th{background:#eee}td:first-child{text-align:left}.ok{color:#070}.no{color:#888}.warn{color:#a40}"
       "svg{max-width:100%;height:auto}pre{background:#f6f6f6;padding:.5em;white-space:pre-wrap}"
       ".headline{font-size:1.1em}h1,li{overflow-wrap:anywhere}</style></head><body>\n";  // long paths wrap
  // Several flights: their count in the title (their paths, a wall of text there, numbered
  // below it: the per-flight values refer to these numbers).
  // One flight: its file name, and the path below it (a path broke the title mid-word).
  const std::string one = d.flights.size() == 1 ? d.flights[0] : log_path;  // the others left out, said below
  const std::string subject = d.flights.size() > 1 ? std::to_string(d.flights.size()) + " flights" : file_name_of(one);
  h << "<h1>Diagnosis of " << esc(subject) << " (" << esc(d.vehicle) << ")</h1>\n";
  if (d.flights.size() <= 1 && subject != one) h << "<p class=\"path\">" << esc(one) << "</p>\n";
  if (d.flights.size() > 1) {
    h << "<ol>\n";
    for (const auto& f : d.flights) h << "<li>" << esc(f) << "</li>\n";
    h << "</ol>\n";
  }
  h << "<p>" << esc(d.formulation) << "; " << d.train_samples << " training samples, " << d.valid_samples;
  if (d.flights.size() > 1)
    h << " held-out samples (the end of each of " << d.flights.size() << " flights, diagnosed jointly: one set of "
      << "vehicle parameters)";
  else
    h << " held-out samples from t = " << significant(d.t_split, 4) << " s";
  h << "; diagnosed in " << significant(d.seconds, 3) << " s.</p>\n";
  for (const auto& note : screening_notes(d)) h << "<p class=\"warn\">" << esc(note) << "</p>\n";
  if (const std::string note = environment_note(d); !note.empty()) h << "<p class=\"warn\">" << esc(note) << "</p>\n";
}

// Up to four of an effect's values, one per line, the rest folded: the glance table's cells
// stay a few lines high where a joint diagnosis has one value per flight, and every value is
// on the page (a review, helper-111: "2 more (below)" pointed at values shown nowhere).
std::string values_cell(const std::vector<std::string>& values) {
  constexpr size_t kShown = 4;
  std::string cell;
  for (size_t i = 0; i < values.size() && i < kShown; ++i) cell += (i ? "<br>" : "") + values[i];
  if (values.size() > kShown) {
    cell += "<details><summary>" + std::to_string(values.size() - kShown) + " more</summary>";
    for (size_t i = kShown; i < values.size(); ++i) cell += (i > kShown ? "<br>" : "") + values[i];
    cell += "</details>";
  }
  return cell.empty() ? "&ndash;" : cell;
}

// An effect's estimates as HTML, each with its 95 % interval where `with_interval`.
std::string estimates_cell(const std::vector<EffectEstimate>& ps, bool with_interval) {
  std::vector<std::string> values;
  for (const auto& p : ps) {
    const int prec = with_interval ? estimate_digits(p.value, p.lower, p.upper) : kEstimateDigits;
    values.push_back(esc(name_value(p.name, p.value, p.unit, prec)) + (with_interval ? " " + interval(p.lower, p.upper, prec) : ""));
  }
  return values_cell(values);
}

// The values the extended model carries for an effect it does not name: the final fit's, a
// joint diagnosis' per-flight copies by their own names ("wind.x@2"; the plain name is flight
// 1's), no interval (the values are not claimed).
std::string carried_values(const Diagnosis& d, const std::string& effect) {
  std::vector<std::string> values;
  for (const auto& p : d.search.final_fit)
    if (p.free && p.name.rfind(effect + ".", 0) == 0) values.push_back(esc(name_value(p.name, p.value, p.unit, kEstimateDigits)));
  return values_cell(values);
}

struct GlanceRow {
  std::string effect, css, verdict, values, held_out;  // verdict, values and held_out: HTML
};

GlanceRow named_row(const Diagnosis& d, const Finding& f) {
  std::string verdict = "named", css = "ok";
  for (const auto& a : d.agreement)
    if (a.effect == f.effect && !a.agree) {
      verdict += std::string("; the flights ") + (flights_disagree(a) ? "disagree on " : "are too uncertain to agree on ") +
                 esc(a.parameter);
      css = "warn";
    }
  return {f.effect, css, verdict, estimates_cell(f.parameters, true),
          significant(f.before) + " &rarr; " + significant(f.after) + " (" + lower_or_higher(f.before, f.after, 3) + ")" +
              (f.metric == d.metric ? "" : "<br><small>" + esc(f.metric) + "</small>")};
}

// Every effect the diagnosis has a verdict on, in one table at the top (a user trial,
// helper-106: how sure, what was rejected and what the model carries unnamed were spread
// over five sections, one of them folded): named; in the model but not named (a stand-in,
// an ambiguous pair's carried member, a carried suspect); suspected; still significant
// where the search stopped; dropped by the backward pass.
std::vector<GlanceRow> glance_rows(const Diagnosis& d) {
  std::vector<GlanceRow> rows;
  for (const auto& f : d.findings) rows.push_back(named_row(d, f));
  for (const auto& st : d.stand_ins)
    rows.push_back({st.candidate.effect, "warn",
                    "in the model, not named: a stand-in for missing physics (" + esc(st.parameter) + " outside [" +
                        significant(st.plausible_lower, 3) + ", " + significant(st.plausible_upper, 3) + "])",
                    carried_values(d, st.candidate.effect), "&ndash;"});
  for (const auto& a : d.search.unresolved)
    rows.push_back({a.a, "warn", "in the model, not named: the data cannot tell it from " + esc(a.b),
                    carried_values(d, a.a), "&ndash;"});
  for (const auto& x : d.suspected)
    rows.push_back({x.candidate.effect, x.carried ? "warn" : "no",
                    std::string(x.carried ? "suspected, carried in the model for a named look-alike's values"
                                          : "suspected, not in the model") + ": " + prose(x.failed) +
                        (x.candidate.evidence.implausible.empty() ? ""
                                                                  : "; implausible here: " + esc(x.candidate.evidence.implausible)),
                    x.carried ? carried_values(d, x.candidate.effect) : estimates_cell(x.candidate.parameters, false),
                    "&ndash;"});
  for (const auto& e : d.search.left_at_limit)
    rows.push_back({e.effect, "no",
                    "not taken: still significant where the search reached its limit (--max-effects; " + esc(output::p_is(e.p_value)) +
                        (e.implausible.empty() ? "" : "; implausible here: " + esc(e.implausible)) + ")",
                    "&ndash;", "&ndash;"});
  for (const auto& r : d.search.removed)
    rows.push_back({r.effect, "no", "dropped by the backward pass: " + prose(r.reason), "&ndash;", "&ndash;"});
  for (const auto& e : d.search.selected)  // anything else the model carries
    if (std::none_of(rows.begin(), rows.end(), [&](const GlanceRow& r) { return r.effect == e; }))
      rows.push_back({e, "warn", "in the model, not named", carried_values(d, e), "&ndash;"});
  return rows;
}

void at_a_glance_html(std::ostringstream& h, const Diagnosis& d) {
  const auto rows = glance_rows(d);
  if (rows.empty()) return;
  const std::string own_weights = own_weights_note(d);
  h << "<table class=\"glance\"><tr><th>effect</th><th>verdict</th><th>values, 95 % interval where named</th>"
       "<th>held out: the final model without it &rarr; with it</th><th>a cause of the</th></tr>\n";
  for (const auto& r : rows)
    h << "<tr><td><b>" << esc(r.effect) << "</b></td><td class=\"" << r.css << "\">" << r.verdict << "</td><td>"
      << r.values << "</td><td>" << r.held_out << "</td><td>" << esc(scope(r.effect)) << "</td></tr>\n";
  h << "</table>\n<p><small>Held out: " << esc(d.metric)
    << ". Each effect's figure is the final model with and without it, not its share of the whole gain: effects "
       "overlap" << (own_weights.empty() ? "" : "; " + esc(own_weights)) << ". \"A cause of the\": the airframe (every flight of it should show it) or this flight"
    << (d.flights.size() > 1 ? "; a value name@k is flight k's, a plain name flight 1's" : "")
    << ". Words: <a href=\"#words\">at the end</a>.</small></p>\n";
}

// One line per named cause and the held-out gain, then the command's own printout (for a
// reader who compares it with a terminal) and the overall gain.
void in_short_html(std::ostringstream& h, const Diagnosis& d) {
  h << "<h2>In short</h2>\n<ul class=\"headline\">\n";
  if (d.findings.empty()) h << "<li>No cause named.</li>\n";
  for (const auto& f : d.findings) {
    // The flight's own tag inside the sentence, before its full stop (a review, helper-111).
    const std::string said = headline(f);
    const bool stop = !said.empty() && said.back() == '.';
    h << "<li>" << esc(stop ? said.substr(0, said.size() - 1) : said) << flights_own_tag(d, f.effect) << (stop ? "." : "");
    // A cause named jointly that the flights alone do not agree on is not one value of the
    // airframe: said here, not only in the agreement table further down.
    for (const auto& a : d.agreement)
      if (a.effect == f.effect && flights_disagree(a))
        h << " <span class=\"warn\">The flights disagree on " << esc(a.parameter) << " (Cochran's Q "
          << esc(output::p_is(a.q_p_value)) << "; see <i>Do the flights agree?</i>).</span>";
    h << "</li>\n";
  }
  if (const auto p = point_of_action(d)) h << "<li>" << esc(point_of_action_headline(*p)) << "</li>\n";
  if (!d.search.selected.empty()) {  // the extended model differs from the base model
    // A finding accepted on another held-out test (one step, the force alone) may leave this
    // metric worse: said as worse, not as a negative gain.
    const double gain = reduction(d.metric_before, d.metric_after);
    h << "<li>With " << (d.findings.empty() ? "what it carries unnamed (below)" : d.findings.size() > 1 ? "them" : "it")
      << ", the model predicts the held-out part "
      << significant(std::fabs(gain), 2) << (gain < 0 ? " % worse" : " % better") << " than the base model (" << esc(d.metric) << " "
      << significant(d.metric_before) << " &rarr; " << significant(d.metric_after) << ").</li>\n";
  }
  // Both lines together read as a contradiction ("77 % better", then "the velocity alone
  // comes closer": a newcomer's trial, helper-143) unless the measures are told apart.
  if (d.has_prediction)
    if (const std::string against = predict::open_loop_against_no_model(d.prediction_after); !against.empty())
      h << "<li>" << esc(against)
        << (d.search.selected.empty() || !predict::no_model_closer_at_longest_horizon(d.prediction_after)
                ? ""
                : " (The error at the horizon itself; the line above scores every point of each window, most of them "
                  "nearer its measured start.)")
        << "</li>\n";
  // Where the extended model is worse, said beside the gain (a user trial, helper-106: a
  // channel 44 % worse was only in a table near the end).
  if (const std::string worse = worse_channels(d); !worse.empty())
    h << "<li class=\"warn\">Worse with the extended model on the held-out part: " << prose(worse) << ".</li>\n";
  h << "</ul>\n";
  at_a_glance_html(h, d);
  // The command's own printout, for a reader who compares it with a terminal; the sections
  // below say the same in tables.
  h << "<details><summary>Verdict as the command printed it</summary>\n<pre>" << output::html_preformatted(diagnosis_summary(d))
    << "</pre></details>\n";
}

void findings_html(std::ostringstream& h, const Diagnosis& d, Figures& figures) {
  h << "<h2>Findings</h2>\n";
  for (const auto& note : d.notes) h << "<p class=\"warn\">Caution: " << esc(note) << ".</p>\n";
  if (d.findings.empty()) h << "<p>None.</p>\n";
  if (!d.per_flight_effects.empty()) {
    h << "<p>One value per flight for ";
    h << output::joined(d.per_flight_effects, ", ", [](const std::string& e) { return esc(e); });
    h << " (" << esc(flights_own(d)) << "): a plain name is flight 1's, <i>name</i>@<i>k</i> flight "
         "<i>k</i>'s (flights numbered as under the title).</p>\n";
  }
  for (const auto& f : d.findings) {
    h << "<h3>" << esc(f.effect) << flights_own_tag(d, f.effect)
      << "</h3>\n<p class=\"headline\"><b>" << esc(headline(f)) << "</b> Held out: "
      << esc(f.metric) << " " << significant(f.before) << " without it &rarr; " << significant(f.after) << " with it ("
      << lower_or_higher(f.before, f.after, 3) << ")" << prose(beside_gain_text(f)) << ".</p>\n";
    if (const std::string caveat = one_flight_caveat(d, f.effect); !caveat.empty())
      h << "<p class=\"warn\">" << esc(caveat) << ".</p>\n";
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
      for (const auto& p : f.parameters) {
        const int prec = estimate_digits(p.value, p.lower, p.upper);
        h << "<tr><td>" << esc(p.name) << "</td><td>" << significant(p.value, prec) << "</td><td>" << interval(p.lower, p.upper, prec)
          << "</td><td>" << unit_html(p.unit) << "</td><td>" << fit::identifiability_text(p.verdict) << "</td></tr>\n";
      }
      h << "</table>\n";
    }
    h << "<p>Evidence: LR statistic " << significant(f.evidence.statistic) << " on " << f.evidence.dof << " dof, "
      << esc(output::p_is(f.evidence.p_value)) << " (level " << significant(f.evidence.level, 3) << "), &Delta;BIC " << significant(f.evidence.delta_bic)
      << ".</p>\n";
  }
  figures.show(h, {"profiles.svg"});
}

// A final-fit parameter's Wald interval; a dash where it has none.
std::string wald_cell(const Diagnosis& d, const fit::FitParameter& p) {
  const auto [lower, upper] = wald_interval(d, p);
  return std::isnan(lower) ? "&ndash;" : interval(lower, upper, estimate_digits(p.value, lower, upper));
}

// The base model's parameters the fit freed (the thrust constant, kappa, c_w, ...), as the
// final fit has them, with those on a bound marked as the summary's caution marks them (a
// user trial, helper-106: the baseline every gain is measured against was not shown, and its
// c_w sat on a bound). A joint diagnosis' per-flight copies ("c_t@2") are one row each.
void base_parameters_html(std::ostringstream& h, const Diagnosis& d) {
  const std::vector<const fit::FitParameter*> base = base_parameters(d);
  const auto on_bound = [&](const fit::FitParameter& p) {
    return std::any_of(d.at_bounds.begin(), d.at_bounds.end(), [&](const fit::FitParameter& b) { return b.name == p.name; });
  };
  if (base.empty()) return;
  // Each sentence only where it applies (a review, helper-111: a single flight's page spoke of
  // per-flight copies, and of a bound no row was on).
  h << "<h2>The vehicle's own parameters, as fitted</h2>\n<p>The vehicle file's parameters the fit freed, at their "
       "values in the final fit"
    << (d.flights.size() > 1 ? " (each flight's own copy: name@k; the extended model's header carries their mean)" : "")
    << "."
    << (std::any_of(base.begin(), base.end(), [&](const fit::FitParameter* p) { return on_bound(*p); })
            ? " One on its bound was held there: the model is strained, and a finding may stand in for what it lacks."
            : "")
    << "</p>\n<table><tr><th>parameter</th><th>fitted</th><th>95 % interval</th><th>in the vehicle file</th><th>unit</th><th>bounds</th><th>note</th></tr>\n";
  // Where the flights, each refitted alone, do not agree on it: the joint value is no one
  // airframe's measurement (a review, helper-131: c_w 0.563 stood here without a caveat).
  const auto flights_say = [&](const fit::FitParameter& p) -> std::string {
    for (const auto& a : d.base_agreement)
      if (a.parameter == p.name && !a.agree)
        return std::string("the flights: ") + (unmeasured_base_parameter(a) ? "none tells it from zero" : agreement_verdict(a)) +
               " (<i>Do the flights agree on the base model?</i>)";
    return "";
  };
  for (const auto* p : base) {
    std::string note = on_bound(*p) ? "on its bound" : "";
    if (const std::string said = flights_say(*p); !said.empty()) note += (note.empty() ? "" : "; ") + said;
    const auto file = d.file_values.find(runtime::shared_name(p->name));  // a flight's copy: the file's one value
    h << "<tr><td>" << esc(p->name) << "</td><td>" << significant(p->value, kEstimateDigits) << "</td><td>"
      << wald_cell(d, *p) << "</td><td>" << (file == d.file_values.end() ? "&ndash;" : significant(file->second, kEstimateDigits)) << "</td><td>" << unit_html(p->unit) << "</td><td>"
      << interval(p->lower, p->upper, kEstimateDigits) << "</td><td" << (note.empty() ? ">" : " class=\"warn\">" + note) << "</td></tr>\n";
  }
  h << "</table>\n";
}

void next_steps_html(std::ostringstream& h, const Diagnosis& d) {
  const auto steps = next_steps(d);
  if (steps.empty()) return;
  h << "<h2>What to do next</h2>\n<ul>\n";
  for (const auto& step : steps) h << "<li>" << esc(step) << "</li>\n";
  h << "</ul>\n";
}

void stand_ins_html(std::ostringstream& h, const Diagnosis& d) {
  if (!d.stand_ins.empty()) {
    h << "<h2>Stand-ins for missing physics</h2>\n<p>Each passed every statistical test, but its value lies outside "
         "what its physics can produce here: it absorbs an error of something the model lacks. It stays in the "
         "extended model and is not named.</p>\n<table><tr><th>effect</th><th>value</th><th>plausible</th><th>why</th>"
         "<th>training residual RMS it absorbs (without &rarr; with)</th></tr>\n";
    for (const auto& st : d.stand_ins) {
      h << "<tr><td>" << esc(st.candidate.effect) << flights_own_tag(d, st.candidate.effect) << "</td><td>" << esc(st.parameter) << " = " << significant(st.value, kEstimateDigits) << " "
        << unit_html(st.unit) << "</td><td>[" << significant(st.plausible_lower) << ", " << significant(st.plausible_upper) << "]</td><td>"
        << prose(st.why) << "</td><td>";
      for (size_t c = 0; c < st.channels.size(); ++c)
        h << (c ? "; " : "") << esc(st.channels[c]) << " " << significant(st.rms_without[c], 3) << " &rarr; "
          << significant(st.rms_with[c], 3);
      h << "</td></tr>\n";
    }
    h << "</table>\n";
  }
}

void ambiguous_html(std::ostringstream& h, const Diagnosis& d) {
  bool carried = false;
  for (const auto& x : d.suspected) carried = carried || x.carried;
  if (!d.search.unresolved.empty() || carried) {
    h << "<h2>Ambiguous</h2>\n";
    for (const auto& x : d.suspected)
      if (x.carried)
        h << "<p class=\"warn\"><b>" << esc(x.candidate.effect) << "</b>" << flights_own_tag(d, x.candidate.effect) << " (suspected: " << prose(x.failed) << ") is "
          << esc(words::carried_suspect(*x.carried)) << ".</p>\n";
    for (const auto& a : d.search.unresolved)
      if (a.absorbed)
        h << "<p class=\"warn\"><b>" << esc(a.a) << "</b> or <b>" << esc(a.b) << "</b>: " << esc(a.b)
          << " explains the discrepancy on its own (" << esc(a.b_own_estimate) << ") and adds nothing beside " << esc(a.a)
          << " (" << esc(output::p_is(a.b_given_a_p)) << "), and the model fits as well with it held there ("
          << esc(output::p_is(a.b_at_own_estimate_p)) << "): " << esc(a.a) << " can reproduce it, so how much of the discrepancy is "
          << esc(a.b) << " the data cannot say (with it held there: " << esc(a.a_with_b_held) << "). " << esc(a.a)
          << " is carried, its values not named. To separate them: "
          << esc(a.manoeuvre) << ".</p>\n";
      else
        h << "<p class=\"warn\"><b>" << esc(a.a) << "</b> or <b>" << esc(a.b)
          << "</b>: both explain the discrepancy and neither adds anything significant to the other ("
          << esc(a.b) << " beside " << esc(a.a) << ": " << esc(output::p_is(a.b_given_a_p)) << "; " << esc(a.a) << " beside "
          << esc(a.b) << ": " << esc(output::p_is(a.a_given_b_p)) << "). Not named. To separate them: " << esc(a.manoeuvre)
          << ".</p>\n";
  }
}

// Slow structure the catalogue leaves, and the draft check's leads.
void unexplained_html(std::ostringstream& h, const Diagnosis& d) {
  if (!d.unexplained.empty()) {
    h << "<h2>Unexplained discrepancies</h2>\n<table><tr><th>channel</th><th>slow RMS</th><th>x noise</th><th>largest in [s]</th><th>most correlated with</th><th>r</th></tr>\n";
    for (const auto& u : d.unexplained)
      h << "<tr><td>" << esc(u.channel) << "</td><td>" << significant(u.slow_rms) << " " << unit_html(u.unit) << "</td><td>" << significant(u.ratio, 3)
        << "</td><td>" << (u.flight ? "flight " + std::to_string(u.flight) + ": " : "") << significant(u.t0, 4) << "&ndash;" << significant(u.t1, 4) << "</td><td>" << esc(u.signal) << "</td><td>" << significant(u.r, 2)
        << "</td></tr>\n";
    h << "</table>\n";
  }
  lead_html(h, draft_leads(d), "");
}

// The open-loop errors per horizon, base and extended model, beside the extended model's views
// that say where its error comes from.
void horizon_table_html(std::ostringstream& h, const Diagnosis& d) {
  h << "<table><tr><th>horizon [s]</th><th>position, base [m]</th>"
       "<th>position, extended [m]</th><th>tilt, extended [rad]</th><th>heading, extended [rad]</th>"
       "<th>position, attitude replayed [m]</th><th>tilt, translation replayed [rad]</th>"
       "<th>position, past disturbance held, extended [m]</th><th>position, body rates held, extended [m]</th>"
       "<th>position, attitude held, extended [m]</th><th>position, constant velocity (no model) [m]</th></tr>\n";
  const auto& b = d.prediction_before;
  const auto& a = d.prediction_after;
  // The mean of `quantity` at the i-th horizon of a view, "–" where the view has no such row.
  const auto mean_at = [](const std::vector<predict::HorizonErrors>& rows, size_t i,
                          predict::ErrorStats predict::HorizonErrors::*quantity) -> std::string {
    return i < rows.size() ? significant((rows[i].*quantity).mean()) : "–";
  };
  using H = predict::HorizonErrors;
  for (size_t i = 0; i < a.open_loop.size() && i < b.open_loop.size(); ++i)
    h << "<tr><td>" << significant(a.open_loop[i].horizon) << "</td><td>" << mean_at(b.open_loop, i, &H::position) << "</td><td>"
      << mean_at(a.open_loop, i, &H::position) << "</td><td>" << mean_at(a.open_loop, i, &H::tilt) << "</td><td>"
      << mean_at(a.open_loop, i, &H::heading) << "</td><td>" << mean_at(a.attitude_replayed, i, &H::position)
      << "</td><td>" << mean_at(a.translation_replayed, i, &H::tilt) << "</td><td>"
      << mean_at(a.open_loop_past_disturbance, i, &H::position) << "</td><td>" << mean_at(a.body_rates_held, i, &H::position)
      << "</td><td>" << mean_at(a.attitude_held, i, &H::position) << "</td><td>"
      << mean_at(a.constant_velocity, i, &H::position) << "</td></tr>\n";
  h << "</table>\n";
}

void prediction_html(std::ostringstream& h, const Diagnosis& d, Figures& figures) {
  if (!d.has_prediction) return;
  // Comparable with published models: the error AT a horizon, averaged over start points.
  const auto& a = d.prediction_after;
  h << "<h2>Prediction on the held-out part</h2>\n";
  // Without a pose no rollout starts (each starts from a measured state): no empty table
  // (a review, helper-111: an ARPL report showed one, "over 0 start points").
  if (a.open_loop.empty()) h << "<p>No pose logged: no open-loop rollouts (each starts from a measured state). ";
  else {
    horizon_table_html(h, d);
    h << "<p>Means over " << a.start_points << " start points. ";
  }
  h << "One step (extended model), RMS: " << esc(predict::one_step_text(a.one_step)) << ".</p>\n";
  if (const std::string limits = predict::what_limits_prediction(a); !limits.empty())
    h << "<p>What limits it (extended model): " << esc(limits) << "</p>\n";
  figures.show(h, {"validation.svg", "simulation_errors.svg", "prediction.svg"});
}

void validation_channels_html(std::ostringstream& h, const Diagnosis& d) {
  h << "<h2>Held-out error per channel</h2>\n<table><tr><th>channel</th><th>unit</th><th>RMS base</th><th>RMS extended</th>"
       "<th>reduction %</th></tr>\n";
  for (const auto& c : d.channel_gain)
    h << "<tr><td>" << esc(c.channel) << "</td><td>" << unit_html(channel_unit(d, c.channel)) << "</td><td>" << significant(c.before)
      << "</td><td>" << significant(c.after) << "</td><td" << (got_worse(c) ? " class=\"warn\"" : "") << ">"
      << significant(reduction(c.before, c.after), 3) << "</td></tr>\n";
  h << "</table>\n";
}

void base_residuals_html(std::ostringstream& h, const Diagnosis& d, Figures& figures) {
  h << "<h2>What the base model gets wrong</h2>\n<table><tr><th>channel</th><th>unit</th><th>RMS</th><th>bias</th>"
       "<th>corr. time [samples]</th><th>slow / noise</th><th>strongest correlations (r)</th></tr>\n";
  for (const auto& c : d.before.channels) {
    h << "<tr><td>" << esc(c.name) << "</td><td>" << unit_html(channel_unit(d, c.name)) << "</td><td>" << significant(c.rms) << "</td><td>"
      << significant(c.bias) << "</td><td>" << significant(c.tau_int, 3)
      << "</td><td>" << significant(c.slow_ratio, 3) << "</td><td>";
    for (size_t i = 0; i < c.correlations.size() && i < 3; ++i)
      h << (i ? ", " : "") << esc(c.correlations[i].signal) << " (" << significant(c.correlations[i].r, 2) << ")";
    h << "</td></tr>\n";
  }
  h << "</table>\n";
  figures.show(h, {"residuals.svg", "autocorrelation.svg"});
}

void candidates_html(std::ostringstream& h, const Diagnosis& d) {
  // Folded: the verdicts are at the top; these tables are for a reader who asks why (a user
  // trial, helper-106: they filled screens between the findings and the plots).
  h << "<h2>Candidates</h2>\n<p>Every effect the search tried at each step, with its evidence; open a step to "
       "read its table.</p>\n";
  for (size_t s = 0; s < d.search.steps.size(); ++s) {
    const auto& st = d.search.steps[s];
    h << "<details><summary>Step " << s + 1 << " (model: base";
    for (const auto& e : st.base_effects) h << " + " << esc(e);
    // A step after a place the backward pass gave back: its model lacks an earlier step's pick.
    std::vector<std::string> dropped;
    for (size_t before = 0; before < s; ++before) {
      const std::string& e = d.search.steps[before].selected;
      if (!e.empty() && std::find(st.base_effects.begin(), st.base_effects.end(), e) == st.base_effects.end() &&
          std::find(dropped.begin(), dropped.end(), e) == dropped.end())
        dropped.push_back(e);
    }
    if (!dropped.empty()) h << "; after the backward pass dropped " << esc(output::joined(dropped));
    h << "): " << (st.selected.empty() ? "nothing taken" : "took " + esc(st.selected)) << "</summary>\n<p>" << (st.selected.empty() ? "Nothing taken (" + esc(st.outcome) + ")." : "Taken: <b>" + esc(st.selected) + "</b>" + (st.outcome == "selected" ? "." : " (" + esc(st.outcome) + ")."))
      << " Ranked: the significant first, among them the plausible before the implausible, then by LR statistic. "
         "Held-out gain: how much lower the equation error (the one-step accelerations' weighted cost) is on the "
         "held-out part with the candidate than without; not the open-loop position error of the findings above.</p>\n"
      << "<table><tr><th>effect</th><th>LR</th><th>dof</th><th>p</th><th>&Delta;BIC</th><th>&Delta;AIC</th><th>held-out gain % "
         "(equation error)</th><th>verdict</th></tr>\n";
    for (const auto& c : st.candidates)
      h << "<tr><td>" << (c.effect == st.selected ? "<b>" + esc(c.effect) + "</b> (taken)" : esc(c.effect)) << "</td><td>" << significant(c.statistic) << "</td><td>" << c.dof << "</td><td>" << esc(output::p_value_cell(c.p_value))
        << "</td><td>" << significant(c.delta_bic) << "</td><td>" << significant(c.delta_aic) << "</td><td>" << significant(c.validation_gain_percent, 3)
        // significant but implausible in orange: a stand-in, not a cause (a user trial, helper-106)
        << "</td><td class=\"" << (!c.significant ? "no\">" + esc(c.why_not) : c.implausible.empty() ? "ok\">significant" : "warn\">significant")
        << (c.implausible.empty() ? "" : "; implausible here: " + esc(c.implausible)) << "</td></tr>\n";
    h << "</table>\n</details>\n";
  }
}

// The words a reader meets in this page, each in a line (a user trial, helper-106: LR
// statistic, carried, stand-in, x noise were used undefined). docs/diagnosis.md, "Reading the
// output", has the longer table.
void words_html(std::ostringstream& h) {
  static const std::pair<const char*, const char*> kWords[] = {
      {"training part, held-out part", "the first part of each flight, which the fit sees, and the rest, which only "
                                       "judges (also called the validation part): 70 % and 30 % unless --validation "
                                       "says otherwise"},
      {"equation error, one step", "the model's accelerations against the measured ones, sample by sample, no "
                                   "simulation: what the fit minimises"},
      {"open loop", "the model run forward from a measured state, fed only the logged commands"},
      {"named", "significant on the training part, better on the held-out part, its interval closed and excluding "
                "\"off\", its value plausible: a cause"},
      {"suspected", "significant on the training part, but it failed a later test (the reason is given); not named"},
      {"ambiguous", "two effects the flight cannot tell apart: neither is named, one of them stays in the extended "
                    "model, and the manoeuvre that separates them is given"},
      {"carried", "in the extended model, its values fitted but not claimed: an ambiguous pair's member, a stand-in, "
                  "or a suspect a named effect's values need"},
      {"stand-in", "passed every test, but its value is beyond what its physics gives here (a steady wind indoors): "
                   "it absorbs something the model lacks; carried, not named"},
      {"of the airframe, of the flight", "a property every flight of the vehicle shares, or a condition of this "
                                         "flight (motor trims, the marker frame, a wind)"},
      {"LR statistic, p, level", "how much adding the effect lowers the noise-weighted residual (likelihood ratio), "
                                 "its p-value, and the level it must beat (corrected for the candidates tried)"},
      {"&Delta;BIC, &Delta;AIC", "the change of the Bayesian and Akaike information criteria with the effect: "
                                 "negative favours it"},
      {"identifiable", "its profile likelihood closes on both sides: the data decide its value"},
      {"slow RMS, x noise", "the RMS of a residual's slow part, and how many times what white noise of the same "
                            "size would leave there"},
      {"Wald interval, Cochran's Q", "value plus or minus 1.96 standard errors; a test of whether the flights' "
                                     "values are one (a small p: they differ beyond their errors)"},
  };
  h << "<h2 id=\"words\">Words used here</h2>\n<table class=\"glance\">\n";
  for (const auto& [word, meaning] : kWords) h << "<tr><td><b>" << word << "</b></td><td>" << meaning << "</td></tr>\n";
  h << "</table>\n";
}

void method_html(std::ostringstream& h) {
  h << "<h2>Method</h2>\n<p>Each candidate is the full-catalogue model with only that effect (and those already taken) free; "
       "the statistic is the drop of the residual sum of squares per channel divided by the larger model's noise variance "
       "times its integrated autocorrelation time, compared with chi2 (chi-bar-square for a parameter whose neutral value "
       "is its bound) at a Bonferroni level; a candidate must also lower BIC and the cost on the held-out part. "
       "Intervals are profile-likelihood intervals with the same weights, widened on both sides by the change of the "
       "estimate when the interval accelerations use the trapezoid instead of the midpoint rule (discretisation error).</p>\n</body></html>\n";
}

}  // namespace

std::string diagnosis_html(const Diagnosis& d, const std::string& log_path,
                           const std::vector<std::pair<std::string, std::string>>& plots) {
  // In the order a reader asks: what was found, does it predict better on data the fit did not
  // see, do the flights agree, what is not a cause, what is still wrong, then the evidence.
  std::ostringstream h;
  Figures figures(plots);
  head_html(h, d, log_path);
  in_short_html(h, d);
  next_steps_html(h, d);
  findings_html(h, d, figures);
  prediction_html(h, d, figures);
  validation_channels_html(h, d);
  agreement_html(h, d);
  stand_ins_html(h, d);
  ambiguous_html(h, d);
  base_parameters_html(h, d);
  unexplained_html(h, d);
  base_residuals_html(h, d, figures);
  command_gain_html(h, d, figures);
  discovered_terms_html(h, d);
  candidates_html(h, d);
  figures.show_rest(h);
  words_html(h);
  method_html(h);
  return h.str();
}

}  // namespace quadgen::diagnose
