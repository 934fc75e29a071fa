#include "fit/fit_pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <set>
#include <sstream>

#include "runtime/thrust_law.hpp"
#include "runtime/data_side_effects.hpp"
#include "runtime/dynamic_model.hpp"
#include "derive/effects/effect_catalogue.hpp"
#include "fit/equation_error.hpp"
#include "fit/fit_report.hpp"
#include "fit/log_reader.hpp"
#include "fit/read_flight.hpp"
#include "fit/motor_steps.hpp"
#include "fit/multiple_shooting.hpp"
#include "runtime/plot.hpp"
#include "output/joined.hpp"
#include "output/names.hpp"
#include "output/numbers.hpp"
#include "output/progress.hpp"
#include "output/sinks.hpp"
#include "fit/thrust_stand.hpp"

namespace quadgen::fit {

namespace {

// The thesis' motor time constant, read off one normalised step at 63 % (2.3.4, Figure 24).
constexpr double kThesisMotorTau = 0.128;

// Published Crazyflie 2.x values the stand results are compared with.
nlohmann::ordered_json published_crazyflie() {
  return {{"thrust_coefficient_N_s2",
           {{"2.2e-8", "crazyflie_mhmp simulation model of the Crazyflie 2.0 (k = 2.2e-8 N s^2)"},
            {"2.3e-8", "UPenn MEAM 620 flightsim crazyflie_params.py, inferred from 14.5 g at 2500 rad/s"}}},
          {"torque_to_thrust_m", {{"0.005964552", "Förster 2015 (ETH Zürich), as used in Crazyflie firmware ports"}}}};
}

// Profiles take minutes: say as each one is done.
ProfileOptions profile_options(const FitJobOptions& o) {
  ProfileOptions po;
  po.threads = o.threads;
  auto progress = o.progress;
  po.progress = [progress](const std::string& name, int i, int n, double seconds) {
    std::ostringstream line;
    line << "  profile " << i << "/" << n << " done: " << output::printable(name) << " (" << std::round(seconds * 10) / 10
         << " s)";
    progress(line.str());
  };
  return po;
}

// Which free parameters to profile (indices into best.parameters); a name that is not a
// free parameter of this fit is refused, not skipped.
std::vector<int> profile_selection(const FitJobOptions& o, const FitResult& best) {
  std::vector<int> which;
  if (o.profiles.empty()) {
    if (o.profile_all_free)
      for (size_t k = 0; k < best.parameters.size(); ++k)
        if (best.parameters[k].free) which.push_back(static_cast<int>(k));
    return which;
  }
  for (const auto& name : o.profiles) {
    const auto it = std::find_if(best.parameters.begin(), best.parameters.end(), [&](const auto& p) { return p.name == name; });
    if (it == best.parameters.end())
      throw std::invalid_argument("--profiles: no parameter '" + output::printable(name) + "' in this fit");
    if (!it->free) throw std::invalid_argument("--profiles: '" + output::printable(name) + "' is not a free parameter of this fit");
    which.push_back(static_cast<int>(it - best.parameters.begin()));
  }
  return which;
}

std::vector<Profile> run_profiles(const FitJobOptions& o, const ResidualModel& m, const FitResult& best, const FitOptions& fo) {
  const auto which = profile_selection(o, best);
  if (which.empty()) return {};
  return profile_all(m, best, fo, profile_options(o), which);
}

// An interval side the profile never crossed is open, not a number.
std::string side(double v, bool open) {
  if (open) return "open";
  std::ostringstream os;
  os.precision(6);
  os << v;
  return os.str();
}

// A profile's 95 % interval as printed: "[lower, upper]", an open side as side() says it.
std::string interval_of(const Profile& pr) {
  return "[" + side(pr.lower, pr.lower_open) + ", " + side(pr.upper, pr.upper_open) + "]";
}

// fit.json's kind of fit, the vehicle and the log.
void add_what_was_fitted(nlohmann::ordered_json& j, const std::string& kind, const Vehicle& v, const std::string& path) {
  j["kind"] = kind;
  j["vehicle"] = v.name;
  j["log"] = path;
}

// Beside a verdict whose interval holds zero (interval_holds_zero).
std::string holds_zero_note(const Profile& pr, const FitParameter& p) {
  return interval_holds_zero(pr, p) ? " (its interval holds 0)" : "";
}

// The motor map's three terms as the vehicle file's motor_map section takes them (values
// with their unit, to copy), with their intervals; `where`: at which command scale and voltage.
std::string motor_map_lines(const std::vector<FitParameter>& ps, const std::vector<Profile>& profiles,
                            const std::string& where) {
  std::ostringstream s;
  s << "motor_map (for the vehicle file; " << where << "):\n";
  for (const char* term : {"a0", "a1", "a2"}) {
    const auto p = std::find_if(ps.begin(), ps.end(), [&](const FitParameter& q) { return q.name == term; });
    if (p == ps.end()) continue;
    s << "  " << term << ": {value: " << p->value << ", unit: " << p->unit << "}";
    for (const auto& pr : profiles)
      if (pr.parameter == term)
        s << "  # " << interval_of(pr) << " " << identifiability_text(pr.verdict) << holds_zero_note(pr, *p);
    s << "\n";
  }
  return s.str();
}

// A plot's data always joins the outputs as CSV beside it (fit.csv for fit.svg); the plot
// itself when gnuplot can draw it, and without one the fit still counts.
void add_plot(FitOutputs& out, const std::string& file, const std::string& title, const std::vector<runtime::Panel>& panels) {
  out.plots.emplace_back(file.substr(0, file.rfind('.')) + ".csv", runtime::panels_csv(title, panels));
  std::string svg, err;
  if (runtime::render_svg(title, panels, &svg, &err)) out.plots.emplace_back(file, svg);
  else out.plot_errors.push_back(file + ": " + err);
}

void add_profile_plot(FitOutputs& out, const std::string& title, const std::vector<Profile>& profiles) {
  if (!profiles.empty()) add_plot(out, "profiles.svg", title, profile_panels(profiles));
}

FitOptions fit_options(const FitJobOptions& o) {
  FitOptions fo;
  fo.robust = o.robust;
  return fo;
}

// Like the thesis' Figure 24: every step normalised to 0..1 and aligned at its fitted step
// instant; a first-order lag is then one curve, 1 - exp(-t / tau). The thesis' tau beside it
// for the thesis' vehicle only.
std::vector<runtime::Panel> normalised_steps(const MotorStepModel& model, const std::vector<double>& p, bool with_thesis) {
  runtime::Series meas{"steps, normalised", {}, {}, true}, fitted{"fitted tau", {}, {}},
      thesis{"thesis tau = 0.128 s", {}, {}};
  const double tau = p[MotorStepModel::kTau];
  for (size_t k = 0; k < model.steps().size(); ++k) {
    const auto& s = model.steps()[k];
    const double t0 = s.t_before + p[MotorStepModel::kFirstStepTime + k];
    const double y0 = model.predict(p.data(), k, s.t_before), y1 = model.predict(p.data(), k, s.t_before + 100);
    for (size_t i = 0; i < s.t.size(); ++i) {
      if (s.t[i] - t0 > 0.5) continue;  // the steady samples seconds later stay off the plot
      meas.x.push_back(s.t[i] - t0);
      meas.y.push_back((s.rpm[i] - y0) / (y1 - y0));
    }
  }
  for (int i = 0; i <= 100; ++i) {
    const double t = 0.5 * i / 100.0;
    fitted.x.push_back(t);
    fitted.y.push_back(1 - std::exp(-t / tau));
    thesis.x.push_back(t);
    thesis.y.push_back(1 - std::exp(-t / kThesisMotorTau));
  }
  std::vector<runtime::Series> series{meas, fitted};
  if (with_thesis) series.push_back(thesis);
  return {{"normalised rotor speed after each throttle step", "time after the fitted step instant [s]", "1", series}};
}

}  // namespace

bool FitJobOptions::IsValid(std::string* error) const {
  const auto fail = [&](const std::string& why) {
    if (error) *error = why;
    return false;
  };
  if (threads < 0 || threads > kMaxThreads) return fail("threads: 0 (one per core) to " + std::to_string(kMaxThreads));
  if (!valid_resample_rate(resample)) return fail("resample: 0 or " + kResampleRange.text("Hz"));
  if (!kFitValidationRange.contains(validation)) return fail("validation fraction: " + kFitValidationRange.text());
  if (!output::is_one_of(formulation, kFitFormulations)) return fail("formulation: " + output::joined(kFitFormulations));
  if (!kFitWindowRange.contains(window)) return fail("window: " + kFitWindowRange.text("s"));
  if (!translational.empty() && !output::is_one_of(translational, kTranslationalSources))
    return fail("translational: " + output::joined(kTranslationalSources) + " (empty: the accelerometer where logged)");
  return true;
}

bool FitJobOptions::IsValidFor(LogKind kind, std::string* error) const {
  if (!IsValid(error)) return false;
  for (const auto& name : options_set(*this))
    if (const std::string why = why_unused(name, kind, formulation); !why.empty()) {
      if (error) *error = name + ": " + why;
      return false;
    }
  return true;
}

std::string why_unused(const std::string& option, LogKind kind, const std::string& formulation, const std::string& prefix) {
  // A new option or flag must say here which kinds read it (a name unknown here was let
  // through on a flight log: a review, helper-142).
  if (!output::is_one_of(option, kFitOptionNames)) throw std::logic_error("fit: no rule for the option '" + option + "'");
  // Motor steps fit a map and a lag, profiled; a thrust stand two laws whose intervals come
  // from its own profiles of every coefficient. Neither has channels, a model or a hold-out.
  const auto takes = [&](const std::string& what, const std::vector<std::string>& read) -> std::string {
    if (output::is_one_of(option, read)) return "";
    std::vector<std::string> flags;
    for (const auto& r : read) flags.push_back(prefix + r);
    return "not used when fitting " + what + " (the log's columns choose the kind of fit); this kind takes " +
           output::joined(flags);
  };
  if (kind == LogKind::kMotorSteps) return takes("a motor-step log", {"robust", "profiles", "threads"});
  if (kind == LogKind::kThrustStand) return takes("a thrust-stand log", {"robust", "threads"});
  const bool shooting = formulation == "multiple_shooting";
  if (option == "window" && !shooting) return "only with " + prefix + "formulation multiple_shooting";
  if ((option == "translational" || option == "channels") && shooting)
    return "only with " + prefix + "formulation equation_error (multiple shooting fits the pose)";
  return "";
}

std::vector<std::string> options_set(const FitJobOptions& o) {
  const FitJobOptions d;
  std::vector<std::string> set;
  const auto add = [&](const char* name, bool differs) {
    if (differs) set.push_back(name);
  };
  add("robust", o.robust != d.robust);
  add("profiles", o.profile_all_free != d.profile_all_free || !o.profiles.empty());
  add("threads", o.threads != d.threads);
  add("mapping", o.mapping != d.mapping);
  add("resample", o.resample != d.resample);
  add("validation", o.validation != d.validation);
  add("formulation", o.formulation != d.formulation);
  add("window", o.window != d.window);
  add("channels", !o.channels.empty());
  add("translational", o.translational != d.translational);
  add("free", !o.free.empty());
  return set;
}

LogKind log_kind(const std::string& path) {
  if (is_topic_log(path)) return LogKind::kFlight;
  const runtime::CsvTable head = runtime::read_csv_header(path);
  if (head.column("throttle_percent") >= 0 && head.column("rpm") >= 0) return LogKind::kMotorSteps;
  if (head.column("weight[g]") >= 0 && head.column("rpm1") >= 0) return LogKind::kThrustStand;
  return LogKind::kFlight;
}

// Every fit's first step: options no fit can use, or that this kind does not read, refused.
static void check_options(const FitJobOptions& o, LogKind kind) {
  if (std::string error; !o.IsValidFor(kind, &error)) throw std::invalid_argument("fit: " + error);
}

FitOutputs fit_motor_steps_log(const std::string& path, const Vehicle& v, const FitJobOptions& o) {
  check_options(o, LogKind::kMotorSteps);
  MotorStepModel model(read_motor_steps(path));
  const FitOptions fo = fit_options(o);
  o.progress("[1/2] fitting motor map and lag to " + std::to_string(model.steps().size()) + " steps (" +
             std::to_string(model.num_residuals()) + " samples)");
  const FitResult best = fit_least_squares(model, model.parameters(), fo);
  o.progress("[2/2] profile likelihood");
  const auto profiles = run_profiles(o, model, best, fo);
  const Profile* tau = nullptr;
  for (const auto& p : profiles)
    if (p.parameter == "tau") tau = &p;
  const double tau_s = best.parameters[MotorStepModel::kTau].value;
  FitOutputs out;
  auto& j = out.json = fit_json(best, profiles);
  add_what_was_fitted(j, "motor_steps", v, path);
  const bool thesis = is_thesis_vehicle(v);  // the thesis' value belongs to its vehicle only
  if (thesis)
    j["comparison"] = {{"thesis_tau_s", kThesisMotorTau},
                       {"thesis_method", "read off one normalised step at 63 % (thesis 2.3.4, Figure 24)"},
                       {"tau", j["estimates"]["tau"]}};
  add_profile_plot(out, v.name + ": motor step profiles", profiles);
  add_plot(out, "fit.svg", v.name + ": motor steps", normalised_steps(model, parameter_values(best.parameters), thesis));
  std::ostringstream s;
  s << "tau = " << tau_s << " s";
  if (tau)
    s << ", 95 % profile interval " << interval_of(*tau) << " (" << identifiability_text(tau->verdict) << ")";
  if (thesis) s << "; thesis: " << kThesisMotorTau << " s";
  s << "\n" << motor_map_lines(best.parameters, profiles, "over the command throttle_percent / 100, a fraction 0..1 as the flight log's u_<rotor>");
  out.summary = s.str();
  return out;
}

namespace {

// The model's parameters with --free applied, or else the vehicle's fit flags less the
// reference parameters (beside c_t only ratios to them are identifiable).
std::vector<FitParameter> starting_parameters(const runtime::DynamicModel& model, const FitJobOptions& o) {
  std::vector<FitParameter> params = model.parameters();
  for (const auto& name : o.free)
    if (std::none_of(params.begin(), params.end(), [&](const auto& p) { return p.name == name; }))
      throw std::invalid_argument("--free: no parameter '" + output::printable(name) + "' in the model" +
                                  output::printable(missing_parameter_hint(name, model.param_names())));
  if (!o.free.empty()) {
    for (auto& p : params) p.free = std::find(o.free.begin(), o.free.end(), p.name) != o.free.end();
    return params;
  }
  std::vector<std::string> names;
  std::set<std::string> fitted;
  for (const auto& p : params) {
    names.push_back(p.name);
    if (p.free) fitted.insert(p.name);
  }
  for (const auto& ref : reference_parameters(names, fitted))
    for (auto& p : params)
      if (p.name == ref && p.free) {
        p.free = false;
        o.progress("holding " + output::printable(ref) + " at 0: beside " + find_effect(effect_of_parameter(ref)).ratios_only_beside +
                   " only ratios to it are identifiable (--free overrides)");
      }
  return params;
}

// Measured and modelled vertical specific force and roll acceleration over the flight.
std::vector<runtime::Panel> flight_panels(runtime::DynamicModel& model, const Flight& flight, const std::vector<double>& p) {
  const bool accel = flight.has_accelerometer;
  EquationErrorModel all(model, flight, accel);
  std::vector<double> r;
  all.all_channels(p.data(), r);
  runtime::Series meas{"measured", {}, {}, true}, fitted{"model (fitted)", {}, {}}, pm{"measured", {}, {}, true},
      pf{"model (fitted)", {}, {}};
  constexpr size_t kAz = 2, kPdot = 3, kChannels = 6;  // all_channels: ax ay az pdot qdot rdot per row
  for (size_t row = 0; row < all.rows().size(); ++row) {
    const auto& s = flight.samples[all.rows()[row]];
    const double mz = accel ? s.specific_force[2] : s.acc_world[2];
    meas.x.push_back(s.t);
    meas.y.push_back(mz);
    fitted.x.push_back(s.t);
    fitted.y.push_back(mz + r[kChannels * row + kAz]);
    pm.x.push_back(s.t);
    pm.y.push_back(s.rate_dot[0]);
    pf.x.push_back(s.t);
    pf.y.push_back(s.rate_dot[0] + r[kChannels * row + kPdot]);
  }
  return {{accel ? "vertical specific force (body z)" : "vertical acceleration", "t [s]", "m/s^2", {meas, fitted}},
          {"roll acceleration dp/dt", "t [s]", "rad/s^2", {pm, pf}}};
}

}  // namespace

namespace {

// The training and the validation part's residual models of the chosen formulation; no
// validation model where nothing is held out (--validation 0).
struct FlightResiduals {
  std::unique_ptr<ResidualModel> train, valid;
};
FlightResiduals flight_residuals(runtime::DynamicModel& model, const Flight& train, const Flight& valid, bool accel,
                                 const FitJobOptions& o) {
  const bool shooting = o.formulation == "multiple_shooting";
  FlightResiduals m;
  m.train = shooting ? std::unique_ptr<ResidualModel>(std::make_unique<MultipleShootingModel>(model, train, o.window))
                     : std::make_unique<EquationErrorModel>(model, train, accel, o.channels);
  if (o.validation == 0) return m;
  // A held-out part too short to evaluate is said to be that, not a fault of the log (its
  // error read "is t in seconds?" for --validation 0.001; a review, helper-135).
  try {
    m.valid = shooting ? std::unique_ptr<ResidualModel>(std::make_unique<MultipleShootingModel>(model, valid, o.window))
                       : std::make_unique<EquationErrorModel>(model, valid, accel);
  } catch (const FitError& e) {
    throw FitError("the held-out part (--validation " + output::short_number(o.validation) + ": the last " +
                   std::to_string(valid.samples.size()) + " samples) cannot be evaluated; give a larger --validation, "
                   "or 0 to hold nothing out. " + e.what());
  }
  return m;
}

// fit.json's "validation": each channel's RMS on the held-out part, nominal and fitted.
nlohmann::ordered_json validation_json(const ResidualModel& valid_m, const std::vector<FitParameter>& nominal,
                                       const FitResult& best, double fraction, size_t samples) {
  const auto before = channel_rms(valid_m, nominal), after = channel_rms(valid_m, best.parameters);
  nlohmann::ordered_json val = nlohmann::ordered_json::array();
  const auto ch = valid_m.channels();
  for (size_t c = 0; c < ch.size(); ++c)
    val.push_back({{"channel", ch[c]}, {"rms_nominal", before[c]}, {"rms_fitted", after[c]},
                   {"reduction_percent", before[c] > 0 ? 100 * (before[c] - after[c]) / before[c] : 0.0}});
  return {{"fraction", fraction}, {"samples", samples}, {"channels", val}};
}

// Whether the translational channels come from the accelerometer (FitJobOptions::translational).
bool uses_accelerometer(const Flight& flight, const FitJobOptions& o) {
  if (o.translational == "accelerometer" && !flight.has_accelerometer)
    throw std::invalid_argument("--translational accelerometer: " + output::printable(flight.source) +
                                " has no accelerometer columns ax, ay, az");
  if (o.translational == "pose" && !flight.has_pose)
    throw std::invalid_argument("--translational pose: " + output::printable(flight.source) + " has no pose");
  return o.translational == "accelerometer" || (o.translational.empty() && flight.has_accelerometer);
}

// An input delay fitted to the accelerometer's samples: between samples the model
// interpolates the logged commands, while commands held between samples (a generated flight;
// a logger that repeats its last value) change the force once per interval. A delay between
// two whole numbers of intervals then comes out at one, with an interval far narrower than
// the data can support. The differentiated velocity averages over each interval and has no
// such preference. Said when the three signs meet: the accelerometer's channels fitted, the
// delay within 5 % of a whole number (one or more) of intervals, and its 95 % interval (the
// profile's, else 1.96 standard errors a side) within a tenth of an interval.
std::string delay_resolution_warning(const Flight& flight, const FitResult& best, const std::vector<Profile>& profiles,
                                     bool accelerometer_fitted) {
  const auto it = std::find_if(best.parameters.begin(), best.parameters.end(),
                               [](const FitParameter& p) { return p.name == "input_delay.seconds" && p.free; });
  if (!accelerometer_fitted || it == best.parameters.end() || flight.samples.size() < 3) return "";
  std::vector<double> times;
  for (const auto& s : flight.samples) times.push_back(s.t);
  const double dt = runtime::median_interval(times), intervals = it->value / dt;
  if (!(dt > 0) || std::round(intervals) < 1 || std::fabs(intervals - std::round(intervals)) > 0.05) return "";
  const size_t index = static_cast<size_t>(it - best.parameters.begin());
  double width = 2 * 1.96 * (index < best.standard_errors.size() ? best.standard_errors[index] : NAN);
  for (const auto& pr : profiles)
    if (pr.parameter == it->name && std::isfinite(pr.lower) && std::isfinite(pr.upper)) width = pr.upper - pr.lower;
  if (!(width < 0.1 * dt)) return "";
  std::ostringstream os;
  os.precision(3);
  os << "input_delay.seconds = " << it->value << " s is a whole number of the accelerometer's sample intervals ("
     << dt * 1e3 << " ms) with a 95 % interval " << width * 1e3
     << " ms wide: with commands held between samples, a delay between two whole numbers comes out at one, its "
        "interval too narrow; --translational pose fits the differentiated velocity, which resolves it within an "
        "interval";
  return os.str();
}

// One line a profiled parameter: "name = value [lower, upper] verdict".
std::string profile_summary(const FitResult& best, const std::vector<Profile>& profiles) {
  std::ostringstream s;
  for (const auto& pr : profiles)
    s << pr.parameter << " = " << best.parameters[pr.index].value << " " << interval_of(pr) << " " << identifiability_text(pr.verdict)
      << holds_zero_note(pr, best.parameters[pr.index]) << "\n";
  return s.str();
}

}  // namespace

FitOutputs fit_flight_log(const std::string& path, const Vehicle& v, runtime::DynamicModel& model, const FitJobOptions& o) {
  check_options(o, LogKind::kFlight);
  const Flight flight = read_flight(path, o.mapping, o.resample, v);
  const std::vector<FitParameter> params = starting_parameters(model, o);
  const auto [train, valid] = o.validation > 0 ? split_by_time(flight, 1.0 - o.validation) : std::pair<Flight, Flight>(flight, Flight{});
  const bool accel = uses_accelerometer(flight, o);
  const bool shooting = o.formulation == "multiple_shooting";
  const FlightResiduals m = flight_residuals(model, train, valid, accel, o);
  const FitOptions fo = fit_options(o);
  o.progress("[1/3] " + o.formulation + " fit on " + std::to_string(train.samples.size()) + " samples (" +
             std::to_string(m.train->num_residuals()) + " residuals), " +
             std::to_string(std::count_if(params.begin(), params.end(), [](auto& p) { return p.free; })) + " free parameters");
  auto clock0 = std::chrono::steady_clock::now();
  const FitResult best = fit_least_squares(*m.train, params, fo);
  const double fit_seconds = output::seconds_since(clock0);
  o.progress("[2/3] profile likelihood (fit took " + output::short_number(fit_seconds) + " s)");
  clock0 = std::chrono::steady_clock::now();
  const auto profiles = run_profiles(o, *m.train, best, fo);
  const double profile_seconds = output::seconds_since(clock0);
  o.progress(m.valid ? "[3/3] validation on the last " + std::to_string(valid.samples.size()) + " samples"
                     : std::string("[3/3] no validation: nothing held out (--validation 0)"));
  FitOutputs out;
  out.warnings = flight.notes;
  auto& j = out.json = fit_json(best, profiles);
  add_what_was_fitted(j, shooting ? "flight_multiple_shooting" : "flight_equation_error", v, path);
  j["mapping"] = o.mapping;
  j["formulation"] = shooting ? "multiple shooting: " + output::short_number(o.window) + " s windows from measured states, pose residuals"
                     : accel  ? "equation error: accelerometer specific force and gyro derivative"
                              : "equation error: differentiated velocity and gyro derivative";
  j["validation"] = m.valid ? validation_json(*m.valid, params, best, o.validation, valid.samples.size())
                            : nlohmann::ordered_json{{"fraction", 0}, {"samples", 0}, {"channels", nlohmann::ordered_json::array()}};
  j["fitted_channels"] = m.train->channels();
  j["timing_s"] = {{"fit", fit_seconds}, {"profiles", profile_seconds}};
  add_profile_plot(out, v.name + ": profile likelihood", profiles);
  const std::string held_out = valid.samples.empty() ? std::string("nothing held out")
                                                     : "validation from t = " + output::six_digits(valid.samples.front().t) + " s";
  add_plot(out, "fit.svg", v.name + ": fit vs data (" + held_out + ")",
           flight_panels(model, flight, parameter_values(best.parameters)));
  out.summary = profile_summary(best, profiles);
  const auto fitted = m.train->channels();
  const bool accelerometer_fitted = accel && !shooting && std::any_of(fitted.begin(), fitted.end(), [](const std::string& c) {
    return c == "ax" || c == "ay" || c == "az";
  });
  if (const std::string w = delay_resolution_warning(flight, best, profiles, accelerometer_fitted); !w.empty())
    out.warnings.push_back(w);
  // A model parameter on its bound is not an estimate: on a flight log most often the log's
  // scale or units are off. (A motor-step or stand fit's nuisance timing may sit on its bound
  // by design; their reports say so.)
  for (const std::string& name : best.at_bound)
    out.warnings.push_back(name +
                           " ended on a bound of the fit, so its value is not an estimate (check the log's units and "
                           "scales, and the vehicle file's bounds)");
  return out;
}

namespace {

nlohmann::ordered_json per_motor_attempt(const StandFit& f) {  // verdicts only: no value at a bound is an estimate
  nlohmann::ordered_json attempt = nlohmann::ordered_json::object();
  for (const auto& pr : f.per_motor_profiles)
    attempt[pr.parameter] = {{"identifiability", identifiability_text(pr.verdict)},
                             {"at_bound", std::count(f.per_motor.at_bound.begin(), f.per_motor.at_bound.end(), pr.parameter) > 0}};
  return attempt;
}

// Measured thrust and the fitted law against the mean rotor speed.
std::vector<runtime::Panel> stand_panels(const std::vector<StandSample>& samples, const StandFit& f, bool shared) {
  runtime::Series meas{"measured (all motors)", {}, {}, true},
      model{shared ? "k sum w_i^2 + tare" : "sum k_i w_i^2 + tare", {}, {}, true};
  const ThrustVsSpeed thrust(samples, f.coefficients);
  const std::vector<double> pv = parameter_values(f.thrust.parameters);
  std::vector<double> r(thrust.num_residuals());
  thrust.evaluate(pv.data(), r.data(), nullptr);
  for (size_t i = 0; i < samples.size(); ++i) {
    const double wm = samples[i].mean_speed();
    meas.x.push_back(wm);
    meas.y.push_back(samples[i].thrust);
    model.x.push_back(wm);
    model.y.push_back(samples[i].thrust + r[i]);
  }
  return {{"thrust vs mean rotor speed", "rad/s", "N", {meas, model}}};
}

// How many thrust constants the stand fit has: one shared, or one per motor (the first
// parameters of its thrust law).
size_t thrust_constants(const StandFit& f, size_t motors) {
  return f.coefficients == ThrustVsSpeed::Coefficients::kShared ? 1 : motors;
}

// The thrust constant k the stand gives: the shared one, or the mean of the motors' own.
double stand_thrust_constant(const StandFit& f, size_t motors) {
  const size_t n_k = thrust_constants(f, motors);
  double k = 0;
  for (size_t i = 0; i < n_k; ++i) k += f.thrust.parameters[i].value / static_cast<double>(n_k);
  return k;
}

// fit.json of a stand fit: both laws with their profiles, and the summary a vehicle file takes.
nlohmann::ordered_json stand_json(const std::string& path, const Vehicle& v, const StandFit& f, double k, double ct,
                                  double vref) {
  const bool shared = f.coefficients == ThrustVsSpeed::Coefficients::kShared;
  nlohmann::ordered_json j;
  add_what_was_fitted(j, "thrust_stand", v, path);
  j["thrust_vs_speed"] = fit_json(f.thrust, f.thrust_profiles);
  j["thrust_vs_speed"]["coefficients"] = shared ? "shared" : "per_motor";
  j["thrust_vs_speed"]["motor_speed_ratio_variation_rms"] = f.ratio_variation;
  if (shared) {
    j["thrust_vs_speed"]["why"] = f.coefficients_reason;
    j["thrust_vs_speed"]["per_motor_attempt"] = per_motor_attempt(f);
  }
  j["speed_vs_command"] = fit_json(f.speed, f.speed_profiles);
  if (!f.voltage_exponent_identified) j["speed_vs_command"]["why"] = f.voltage_reason;
  // k as an estimate: with its profile when one coefficient is shared, else the plain mean.
  output::Estimate k_estimate{k, "N s^2", NAN, NAN, "", false};
  if (shared) {
    const FitParameter& shared_k = f.thrust.parameters.front();
    k_estimate = estimate_of(shared_k, &f.thrust_profiles.front(),
                             std::count(f.thrust.at_bound.begin(), f.thrust.at_bound.end(), shared_k.name) > 0);
  }
  j["summary"] = {{"k", output::estimate_json(k_estimate)},
                  {"coefficients", shared ? "one shared by all motors" : "mean of the per-motor coefficients"},
                  {"c_t", ct},
                  {"c_t_in_vehicle_file", param(v, "c_t").nominal},
                  {"battery_sag_exponent_implied", f.voltage_exponent_identified ? nlohmann::ordered_json(2 * f.speed.parameters[3].value)
                                                                                : nlohmann::ordered_json(nullptr)},
                  {"vbat_ref_V", vref}};
  j["published"] = published_crazyflie();
  return j;
}

// What the terminal prints of a stand fit: k, c_t, the voltage law and the motor map's lines.
std::string stand_summary(const StandFit& f, size_t motors, double k, double ct, double vref) {
  std::ostringstream s;
  if (f.coefficients == ThrustVsSpeed::Coefficients::kShared) {
    const Profile& kp = f.thrust_profiles.front();
    s << "k = " << k << " N s² " << interval_of(kp) << " (" << identifiability_text(kp.verdict) << "), shared by all motors: "
      << f.coefficients_reason << "\n";
  } else {
    s << "k per motor:";
    for (size_t i = 0; i < thrust_constants(f, motors); ++i)
      s << " " << f.thrust.parameters[i].value << " (" << identifiability_text(f.thrust_profiles[i].verdict) << ")";
    s << "; mean " << k << " N s²\n";
  }
  s << "c_t = " << ct << "; ";
  if (f.voltage_exponent_identified) s << "speed ~ vbat^" << f.speed.parameters[3].value << "\n";
  else s << f.voltage_reason << "\n";
  std::ostringstream where;
  where << "over the command pwm / 65535, ";
  if (f.voltage_exponent_identified) where << "at vbat_ref = " << vref << " V";
  else where << "at the stand's voltage at each command";
  s << motor_map_lines(f.speed.parameters, f.speed_profiles, where.str());
  return s.str();
}

}  // namespace

FitOutputs fit_thrust_stand_log(const std::string& path, const Vehicle& v, const FitJobOptions& o) {
  check_options(o, LogKind::kThrustStand);
  const auto samples = read_thrust_stand(path);
  o.progress("thrust vs rotor speed and rotor speed vs command, " + std::to_string(samples.size()) + " samples");
  const double vref = param(v, "vbat_ref").nominal;
  const StandFit f = fit_stand(samples, vref, fit_options(o), profile_options(o));
  const size_t motors = samples.front().w.size();
  const double k = stand_thrust_constant(f, motors);
  const Rotor& r0 = v.rotors.front();
  const double ct = runtime::thrust_coefficient_c_t(k, param(v, "rho").nominal, r0.disc_area, r0.radius);
  FitOutputs out;
  out.json = stand_json(path, v, f, k, ct, vref);
  std::vector<Profile> all = f.thrust_profiles;
  all.insert(all.end(), f.speed_profiles.begin(), f.speed_profiles.end());
  add_profile_plot(out, v.name + ": thrust stand profiles", all);
  const bool shared = f.coefficients == ThrustVsSpeed::Coefficients::kShared;
  add_plot(out, "fit.svg", v.name + ": thrust stand", stand_panels(samples, f, shared));
  out.summary = stand_summary(f, motors, k, ct, vref);
  return out;
}

}  // namespace quadgen::fit
