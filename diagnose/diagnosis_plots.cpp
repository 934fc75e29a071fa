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

using namespace words;

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

// Joined flights on one clock: each flight's held-out part marked where it starts and labelled
// with the flight's short name (a user trial, helper-106: three flights end to end could not
// be told apart; where a panel holds whole flights, `before` says the label marks the held-out
// part, not the flight's start). One flight: as given.
void mark_flights(const Diagnosis& d, std::vector<runtime::Panel>& panels, const std::string& before = "") {
  if (d.flights.size() < 2) return;
  const std::vector<std::string> names = short_flight_labels(d.flights);
  for (auto& panel : panels) {
    panel.marks = d.validation_starts;
    panel.labels.clear();
    for (size_t k = 0; k < d.validation_starts.size() && k < names.size(); ++k)
      panel.labels.emplace_back(d.validation_starts[k], before + names[k]);
  }
}

// Measured vs simulated positions in the open-loop windows of the validation part.
std::vector<runtime::Panel> validation_panels(const Diagnosis& d, const fit::Flight& valid) {
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
  return panels;
}

// The simulation's error over time, per quantity.
std::vector<runtime::Panel> simulation_error_panels(const Diagnosis& d) {
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
  return errs;
}

// Equation-error residuals over time, every `stride`-th sample (a plot of 3000 points reads as well).
std::vector<runtime::Panel> residual_panels(const Diagnosis& d, size_t stride) {
  std::vector<runtime::Panel> res;
  for (int c = 0; c < 6; ++c) {
    std::vector<double> rb, ra;
    for (size_t k = 0; k < d.t.size(); ++k) rb.push_back(d.residual_before[k * 6 + c]), ra.push_back(d.residual_after[k * 6 + c]);
    res.push_back({d.channel_names[c] + " residual (model - measured; dashed: held-out part starts)", "t [s]",
                   d.channel_units[c], {series("base model", d.t, rb, stride), series("extended model", d.t, ra, stride)},
                   d.validation_starts});
  }
  return res;
}

std::string residuals_title(const Diagnosis& d) {
  return d.vehicle + ": equation-error residuals (" +
         (d.flights.size() > 1 ? std::to_string(d.flights.size()) + " flights joined, 1 s apart; the end of each held out"
                               : "validation from t = " + significant(d.t_split, 4) + " s") +
         ")";
}

// Autocorrelation of each channel's residual with the white-noise band.
std::vector<runtime::Panel> autocorrelation_panels(const Diagnosis& d) {
  std::vector<runtime::Panel> acf;
  for (size_t c = 0; c < d.before.channels.size(); ++c) {
    const auto& b = d.before.channels[c];
    const auto& a = d.after.channels[c];
    std::vector<double> lag, band, nband;
    const double dt = d.t.size() > 1 ? (d.t.back() - d.t.front()) / static_cast<double>(d.t.size() - 1) : 0.01;
    for (size_t k = 0; k < b.acf.size(); ++k) lag.push_back(static_cast<double>(k) * dt), band.push_back(b.acf_band), nband.push_back(-b.acf_band);
    // The band's two lines in one colour, the legend's (the lower one had gnuplot's next).
    runtime::Series upper = series("95 % white-noise band", lag, band), lower = series("", lag, nband);
    upper.color = lower.color = "#7f7f7f";
    acf.push_back({b.name + " autocorrelation", "lag [s]", "correlation",
                   {series("base model", lag, b.acf), series("extended model", lag, a.acf), upper, lower}});
  }
  return acf;
}

// The found parameters' profiles, each axis with its parameter's unit (the profiles carry
// names only; the final fit carries units).
std::vector<runtime::Panel> profile_panels(const Diagnosis& d) {
  std::vector<runtime::Panel> panels = fit::profile_panels(d.search.profiles);
  for (auto& panel : panels) {
    for (const auto& p : d.search.final_fit)  // named and carried
      if (p.name == panel.xlabel && !p.unit.empty() && p.unit != "1") panel.xlabel += " [" + p.unit + "]";
    panel.ylabel = "cost rise (delta chi2)";
  }
  return panels;
}

// The answer to the commands, band by band: one series per flight, 1 where the model is right.
std::vector<runtime::Panel> command_gain_panels(const Diagnosis& d) {
  std::vector<std::pair<std::string, const CommandGain*>> gains;
  const auto by_flight = command_gains_by_flight(d);
  std::vector<std::string> paths;
  for (const auto& [flight, g] : by_flight) paths.push_back(flight);
  // Not a name of the plot's other series, nor of a model's colour (a review: "the model.csv").
  const std::vector<std::string> labels =
      short_flight_labels(paths, {"the model", "this flight", "measured", "base model", "extended model"});
  for (size_t i = 0; i < by_flight.size(); ++i)
    gains.emplace_back(by_flight[i].first.empty() ? "this flight" : labels[i], by_flight[i].second);
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
  return gain_panels;
}

// Renders panels as SVG (and, where asked, their data as CSV), one colour per model in every
// plot: measured black, base model red, extended model blue.
class PlotRenderer {
 public:
  PlotRenderer(std::vector<std::string>* errors, std::vector<std::pair<std::string, std::string>>* data)
      : errors_(errors), data_(data) {}

  void render(const std::string& name, const std::string& title, std::vector<runtime::Panel> panels) {
    for (auto& p : panels)
      for (auto& s : p.series)
        for (const auto& [model, colour] : kColours)  // "base model, tilt" is the base model's too
          if (!model.empty() && (s.label == model || s.label.rfind(model + ",", 0) == 0)) s.color = colour;
    if (data_) data_->emplace_back(name.substr(0, name.rfind('.')) + ".csv", runtime::panels_csv(title, panels));
    std::string svg, error;
    if (runtime::render_svg(title, panels, &svg, &error)) svgs_.emplace_back(name, svg);
    else if (errors_) errors_->push_back(name + ": " + error);
  }
  std::vector<std::pair<std::string, std::string>> svgs() && { return std::move(svgs_); }

 private:
  inline static const std::map<std::string, std::string> kColours = {{"measured", "#000000"},
                                                                     {"base model", "#d62728"},
                                                                     {"extended model", "#1f77b4"}};
  std::vector<std::string>* errors_;
  std::vector<std::pair<std::string, std::string>>* data_;
  std::vector<std::pair<std::string, std::string>> svgs_;
};

}  // namespace

std::string what_to_look_for(const std::string& plot_name) {
  // One entry per plot diagnosis_plots renders, by the name it renders it under (a user trial,
  // helper-106: every caption was the file name alone); a test asks each plot a diagnosis
  // writes for its caption.
  static const std::map<std::string, std::string> kLookFor = {
      {"validation.svg",
       "the held-out part: the measured position (black dots) against the base model (red) and the extended model "
       "(blue), each simulated open loop from measured states in windows; the closer a model's line stays on the "
       "dots, the better it predicts"},
      {"simulation_errors.svg",
       "how far each model's simulation has drifted within each window of the held-out part: the extended model's "
       "error (blue) should stay below the base model's (red)"},
      {"residuals.svg",
       "what each model gets wrong sample by sample (the equation error) over the whole flight: structure left in "
       "the extended model's residual (blue) is what it still lacks; dashed: where the held-out part starts"},
      {"autocorrelation.svg",
       "how long each residual stays correlated with itself: a model that explains the flight leaves white noise, "
       "inside the grey band after a few samples; a slow decay is structure the model does not explain"},
      {"command_gain.svg",
       "how strongly the vehicle answered a change of command, band by band, over the base model's answer: 1 where "
       "the motor map's slope is right (a closed loop reads low in band, so below 1 is a lead, not a measurement)"},
      {"prediction.svg",
       "position and attitude error against the prediction horizon, mean over start points on the held-out part, "
       "for each model and the baselines; lower is better. A tilt or heading error is an angle, at most pi: a "
       "model that has turned over can read lower at a longer horizon"},
      {"profiles.svg",
       "the profile likelihood of each parameter of the extended model's effects, named or carried (a joint "
       "diagnosis' per-flight copies have Wald intervals instead): the 95 % interval is where the curve stays "
       "below the pointwise line; a flat curve means the data barely decide the value"},
  };
  const auto it = kLookFor.find(plot_name);
  return it == kLookFor.end() ? "" : it->second;
}


std::vector<std::pair<std::string, std::string>> diagnosis_plots(
    const Diagnosis& d, const fit::Flight& valid, std::vector<std::string>* errors,
    std::vector<std::pair<std::string, std::string>>* data) {
  PlotRenderer plots(errors, data);
  if (!d.sim_before.t.empty()) {
    auto validation = validation_panels(d, valid), errors = simulation_error_panels(d);
    mark_flights(d, validation);
    mark_flights(d, errors);
    plots.render("validation.svg", d.vehicle + ": measured vs simulated, before and after", validation);
    plots.render("simulation_errors.svg", d.vehicle + ": simulation error over time (held-out part)", errors);
  }
  auto residuals = residual_panels(d, std::max<size_t>(1, d.t.size() / 3000));
  mark_flights(d, residuals, "held out: ");
  plots.render("residuals.svg", residuals_title(d), residuals);
  plots.render("autocorrelation.svg", d.vehicle + ": residual autocorrelation", autocorrelation_panels(d));
  const auto gain_panels = command_gain_panels(d);
  if (!gain_panels.empty()) plots.render("command_gain.svg", d.vehicle + ": the answer to the commands, band by band", gain_panels);
  if (d.has_prediction && !d.prediction_after.open_loop.empty())  // no pose logged: no rollout to draw
    plots.render("prediction.svg", d.vehicle + ": prediction error against horizon (held-out part)",
                 predict::horizon_panels({{"base model", &d.prediction_before}, {"extended model", &d.prediction_after}}));
  if (!d.search.profiles.empty())
    plots.render("profiles.svg", d.vehicle + ": profile likelihood of the effects' parameters", profile_panels(d));
  return std::move(plots).svgs();
}

}  // namespace quadgen::diagnose
