// quadgen fit VEHICLE.yaml LOG.csv --out DIR
// The kind of fit follows the log's layout: motor step tests (time_ms, throttle_percent,
// rpm) fit the motor map and its lag.
#include <cmath>
#include <algorithm>
#include <chrono>
#include <memory>
#include <iostream>
#include <set>
#include <sstream>

#include "log_reader.hpp"
#include "commands.hpp"
#include "dynamics.hpp"
#include "effects.hpp"
#include "equation_error.hpp"
#include "flight_data.hpp"
#include "geometry.hpp"
#include "json_document.hpp"
#include "options.hpp"
#include "output_set.hpp"
#include "sinks.hpp"
#include "model_registry.hpp"
#include "fit_report.hpp"
#include "flight_log.hpp"
#include "motor_steps.hpp"
#include "multiple_shooting.hpp"
#include "thrust_stand.hpp"
#include "plot.hpp"
#include "vehicle.hpp"

namespace quadgen::cli {

using namespace quadgen::fit;

void add_fit(CLI::App& app, FitArgs& a) {
  CLI::App* c = app.add_subcommand("fit", "estimate parameters from measured data, with profile likelihood");
  c->add_option("vehicle", a.vehicle, "vehicle description (YAML)")->required();
  c->add_option("log", a.log, "measurements (CSV)")->required();
  c->add_option("--out", a.out, "output directory")->required();
  c->add_flag("--robust", a.robust, "Huber loss instead of squares");
  c->add_option("--mapping", a.mapping, "column mapping (YAML) for logs not in the canonical layout, e.g. data/mappings/nanobench.yaml");
  std::string effect_names;  // the catalogue, so --help lists what --effects accepts
  for (const Effect& e : effect_catalogue()) effect_names += (effect_names.empty() ? "" : ", ") + e.name;
  c->add_option("--effects", a.effects, "comma-separated effects to add, or 'all': " + effect_names);
  c->add_option("--validation", a.validation, "fraction of the flight (at its end) held out for validation")
      ->check(finite_range(0.0, 0.9));
  c->add_option("--formulation", a.formulation, "equation_error (IMU, accelerations) or multiple_shooting (pose, windows)")
      ->check(CLI::IsMember({"equation_error", "multiple_shooting"}));
  c->add_option("--window", a.window, "multiple shooting: window length [s]")->check(finite_range(0.01, 100));
  c->add_option("--resample", a.resample, "resample the log onto a uniform grid at this rate [Hz] first")
      ->check(finite_range(0.1, 1e5));
  c->add_option("--channels", a.channels, "residual channels to fit (default all): ax,ay,az,pdot,qdot,rdot");
  c->add_option("--free", a.free, "parameters to fit (comma-separated), overriding the vehicle file's fit flags");
  c->add_option("--profiles", a.profiles,
                "profile likelihood of: all free parameters, none (estimates and standard errors only), or "
                "comma-separated names")
      ->capture_default_str();
  c->add_option("--threads", a.threads, "threads for the profiles (0: one per core)")
      ->check(CLI::Range(0, 256))
      ->capture_default_str();
}

namespace {

std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

// Profiles take minutes: say as each one is done.
ProfileOptions profile_options(const FitArgs& a) {
  ProfileOptions po;
  po.threads = a.threads;
  po.progress = [](const std::string& name, int i, int n, double seconds) {
    std::cerr << "  profile " << i << "/" << n << " done: " << output::printable(name) << " (" << std::round(seconds * 10) / 10
              << " s)\n";
  };
  return po;
}

// --profiles: which free parameters to profile (indices into best.parameters); a name
// that is not a free parameter of this fit is refused, not skipped.
std::vector<int> profile_selection(const FitArgs& a, const FitResult& best) {
  std::vector<int> which;
  if (a.profiles == "none") return which;
  if (a.profiles == "all" || a.profiles.empty()) {
    for (size_t k = 0; k < best.parameters.size(); ++k)
      if (best.parameters[k].free) which.push_back(static_cast<int>(k));
    return which;
  }
  for (const auto& name : split_list(a.profiles)) {
    const auto it = std::find_if(best.parameters.begin(), best.parameters.end(), [&](const auto& p) { return p.name == name; });
    if (it == best.parameters.end())
      throw std::invalid_argument("--profiles: no parameter '" + output::printable(name) + "' in this fit");
    if (!it->free) throw std::invalid_argument("--profiles: '" + output::printable(name) + "' is not a free parameter of this fit");
    which.push_back(static_cast<int>(it - best.parameters.begin()));
  }
  return which;
}

std::vector<Profile> run_profiles(const FitArgs& a, const ResidualModel& m, const FitResult& best, const FitOptions& fo) {
  const auto which = profile_selection(a, best);
  if (which.empty()) return {};
  return profile_all(m, best, fo, profile_options(a), which);
}

// An interval side the profile never crossed is open, not a number.
std::string side(double v, bool open) {
  if (open) return "open";
  std::ostringstream os;
  os.precision(6);
  os << v;
  return os.str();
}

// A plot joins the output set when gnuplot can draw it; without one the fit still counts.
void add_plot(output::OutputDirectory& out, const std::string& file, const std::string& title,
              const std::vector<runtime::Panel>& panels) {
  std::string svg, err;
  if (runtime::render_svg(title, panels, &svg, &err)) out.add(file, svg);
  else std::cerr << "no plot " << file << ": " << err << "\n";
}

void add_profile_plot(output::OutputDirectory& out, const std::string& title, const std::vector<Profile>& profiles) {
  std::string svg, err;
  if (plot_profiles(title, profiles, &svg, &err)) out.add("profiles.svg", svg);
  else std::cerr << "no plot profiles.svg: " << err << "\n";
}

int fit_motor_steps(const FitArgs& a, const Vehicle& v, output::OutputDirectory& out) {
  MotorStepModel model(read_motor_steps(a.log));
  FitOptions fo;
  fo.robust = a.robust;
  std::cerr << "[1/2] fitting motor map and lag to " << model.steps().size() << " steps (" << model.num_residuals()
            << " samples)\n";
  const FitResult best = fit_least_squares(model, model.parameters(), fo);
  std::cerr << "[2/2] profile likelihood\n";
  const auto profiles = run_profiles(a, model, best, fo);
  auto j = fit_json(best, profiles);
  j["kind"] = "motor_steps";
  j["vehicle"] = v.name;
  j["log"] = a.log;
  const Profile* tau = nullptr;
  for (const auto& p : profiles)
    if (p.parameter == "tau") tau = &p;
  j["comparison"] = {{"thesis_tau_s", 0.128},
                     {"thesis_method", "read off one normalised step at 63 % (thesis 2.3.4, Figure 24)"},
                     {"tau_s", best.parameters[3].value},
                     {"tau_ci95", {tau && !tau->lower_open ? nlohmann::ordered_json(tau->lower) : nullptr,
                                   tau && !tau->upper_open ? nlohmann::ordered_json(tau->upper) : nullptr}},
                     {"tau_verdict", tau ? tau->verdict : ""}};
  out.add("fit.json", output::json_document(j));
  add_profile_plot(out, v.name + ": motor step profiles", profiles);
  // Like the thesis' Figure 24: every step normalised to 0..1 and aligned at its fitted
  // step instant; a first-order lag is then one curve, 1 - exp(-t / tau).
  const std::vector<double> pv = parameter_values(best.parameters);
  runtime::Series meas{"Table 2, normalised", {}, {}, true}, fitted{"fitted tau", {}, {}}, thesis{"thesis tau = 0.128 s", {}, {}};
  for (size_t k = 0; k < model.steps().size(); ++k) {
    const auto& s = model.steps()[k];
    const double t0 = s.t_before + pv[4 + k];
    const double y0 = model.predict(pv.data(), k, s.t_before), y1 = model.predict(pv.data(), k, s.t_before + 100);
    for (size_t i = 0; i < s.t.size(); ++i) {
      if (s.t[i] - t0 > 0.5) continue;  // the steady samples seconds later stay off the plot
      meas.x.push_back(s.t[i] - t0);
      meas.y.push_back((s.rpm[i] - y0) / (y1 - y0));
    }
  }
  for (int i = 0; i <= 100; ++i) {
    const double t = 0.5 * i / 100.0;
    fitted.x.push_back(t);
    fitted.y.push_back(1 - std::exp(-t / pv[3]));
    thesis.x.push_back(t);
    thesis.y.push_back(1 - std::exp(-t / 0.128));
  }
  add_plot(out, "fit.svg", v.name + ": motor steps (thesis Table 2)",
           {{"normalised rotor speed after each throttle step", "time after the fitted step instant [s]", "1", {meas, fitted, thesis}}});
  out.commit();
  std::cout << "tau = " << best.parameters[3].value << " s";
  if (tau)
    std::cout << ", 95 % profile interval [" << side(tau->lower, tau->lower_open) << ", " << side(tau->upper, tau->upper_open)
              << "] (" << tau->verdict << ")";
  std::cout << "; thesis: 0.128 s\n";
  return 0;
}

// RMS of each channel of an equation-error model at the given parameters.
std::vector<double> channel_rms(const ResidualModel& m, const std::vector<FitParameter>& ps) {
  const std::vector<double> p = parameter_values(ps);
  std::vector<double> r(m.num_residuals());
  m.evaluate(p.data(), r.data(), nullptr);
  const size_t nc = m.channels().size();
  std::vector<double> ss(nc, 0.0);
  std::vector<int> n(nc, 0);
  for (int i = 0; i < m.num_residuals(); ++i) {
    ss[m.channel_of(i)] += r[i] * r[i];
    ++n[m.channel_of(i)];
  }
  for (size_t c = 0; c < nc; ++c) ss[c] = std::sqrt(ss[c] / std::max(1, n[c]));
  return ss;
}

int fit_flight(const FitArgs& a, const Vehicle& v, output::OutputDirectory& out) {
  const runtime::CsvTable log = read_log(a.log, a.mapping, a.resample);
  std::vector<std::string> rotors;
  for (const auto& r : v.rotors) rotors.push_back(r.name);
  const Flight flight = load_flight(log, rotors, {});
  DeriveOptions opt;
  opt.effects = parse_effect_list(a.effects);
  const SymbolicModel sm = derive_model(v, derive_mass_properties(v), opt);
  bool compiled = false;
  const auto model_ptr = make_model(sm, &compiled);
  runtime::DynamicModel& model = *model_ptr;
  std::cerr << "model: " << (compiled ? "compiled header from generated/" : "interpreted (no matching generated header)") << "\n";
  std::vector<FitParameter> params;
  const auto free_list = split_list(a.free);
  for (const auto& p : sm.params) {
    bool free = p.fit;
    if (!free_list.empty()) free = std::find(free_list.begin(), free_list.end(), p.name) != free_list.end();
    params.push_back({p.name, p.unit, p.nominal, p.lower, p.upper, free});
  }
  if (free_list.empty()) {  // the vehicle's fit flags: only what the data can identify
    std::vector<std::string> names;
    for (const auto& p : params) names.push_back(p.name);
    for (const auto& ref : reference_parameters(names))
      for (auto& p : params)
        if (p.name == ref && p.free) {
          p.free = false;
          std::cerr << "holding " << output::printable(ref)
                    << " at 0: beside c_t only ratios to it are identifiable (--free overrides)\n";
        }
  }
  for (const auto& name : free_list)
    if (sm.params.end() == std::find_if(sm.params.begin(), sm.params.end(), [&](const auto& p) { return p.name == name; }))
      throw std::invalid_argument("--free: no parameter '" + name + "' in the model");
  const auto [train, valid] = split_by_time(flight, 1.0 - a.validation);
  const bool accel = flight.has_accelerometer;
  const auto channels = split_list(a.channels);
  const bool shooting = a.formulation == "multiple_shooting";
  std::unique_ptr<ResidualModel> train_ptr, valid_ptr;
  if (shooting) {
    train_ptr = std::make_unique<MultipleShootingModel>(model, train, a.window);
    valid_ptr = std::make_unique<MultipleShootingModel>(model, valid, a.window);
  } else {
    train_ptr = std::make_unique<EquationErrorModel>(model, train, accel, channels);
    valid_ptr = std::make_unique<EquationErrorModel>(model, valid, accel);
  }
  const ResidualModel& train_m = *train_ptr;
  const ResidualModel& valid_m = *valid_ptr;
  FitOptions fo;
  fo.robust = a.robust;
  std::cerr << "[1/3] " << a.formulation << " fit on " << train.samples.size() << " samples (" << train_m.num_residuals()
            << " residuals), " << std::count_if(params.begin(), params.end(), [](auto& p) { return p.free; })
            << " free parameters\n";
  auto clock0 = std::chrono::steady_clock::now();
  const FitResult best = fit_least_squares(train_m, params, fo);
  const double fit_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - clock0).count();
  std::cerr << "[2/3] profile likelihood (fit took " << fit_seconds << " s)\n";
  clock0 = std::chrono::steady_clock::now();
  const auto profiles = run_profiles(a, train_m, best, fo);
  const double profile_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - clock0).count();
  std::cerr << "[3/3] validation on the last " << valid.samples.size() << " samples\n";
  const auto before = channel_rms(valid_m, params), after = channel_rms(valid_m, best.parameters);
  auto j = fit_json(best, profiles);
  j["kind"] = shooting ? "flight_multiple_shooting" : "flight_equation_error";
  j["vehicle"] = v.name;
  j["log"] = a.log;
  j["mapping"] = a.mapping;
  j["formulation"] = shooting ? "multiple shooting: " + std::to_string(a.window) + " s windows from measured states, pose residuals"
                     : accel  ? "equation error: accelerometer specific force and gyro derivative"
                              : "equation error: differentiated velocity and gyro derivative";
  nlohmann::ordered_json val = nlohmann::ordered_json::array();
  const auto ch = valid_m.channels();
  for (size_t c = 0; c < ch.size(); ++c)
    val.push_back({{"channel", ch[c]}, {"rms_nominal", before[c]}, {"rms_fitted", after[c]},
                   {"reduction_percent", before[c] > 0 ? 100 * (before[c] - after[c]) / before[c] : 0.0}});
  j["validation"] = {{"fraction", a.validation}, {"samples", valid.samples.size()}, {"channels", val}};
  j["fitted_channels"] = train_m.channels();
  j["timing_s"] = {{"fit", fit_seconds}, {"profiles", profile_seconds}};
  out.add("fit.json", output::json_document(j));
  add_profile_plot(out, v.name + ": profile likelihood", profiles);
  // Measured and modelled vertical specific force and roll acceleration over the flight.
  const std::vector<double> pv = parameter_values(best.parameters);
  EquationErrorModel all(model, flight, accel);
  std::vector<double> r;
  all.all_channels(pv.data(), r);
  runtime::Series meas{"measured", {}, {}, true}, fitted{"model (fitted)", {}, {}}, pm{"measured", {}, {}, true},
      pf{"model (fitted)", {}, {}};
  for (size_t row = 0; row < all.rows().size(); ++row) {
    const size_t k = row;  // index into r
    const auto& s = flight.samples[all.rows()[row]];
    const double mz = accel ? s.specific_force[2] : s.acc_world[2];
    meas.x.push_back(s.t);
    meas.y.push_back(mz);
    fitted.x.push_back(s.t);
    fitted.y.push_back(mz + r[6 * k + 2]);
    pm.x.push_back(s.t);
    pm.y.push_back(s.rate_dot[0]);
    pf.x.push_back(s.t);
    pf.y.push_back(s.rate_dot[0] + r[6 * k + 3]);
  }
  const double cut = valid.samples.empty() ? 0 : valid.samples.front().t;
  add_plot(out, "fit.svg", v.name + ": fit vs data (validation from t = " + std::to_string(cut).substr(0, 5) + " s)",
           {{accel ? "vertical specific force (body z)" : "vertical acceleration", "t [s]", "m/s^2", {meas, fitted}},
            {"roll acceleration dp/dt", "t [s]", "rad/s^2", {pm, pf}}});
  out.commit();
  for (const auto& pr : profiles)
    std::cout << pr.parameter << " = " << best.parameters[pr.index].value << " [" << side(pr.lower, pr.lower_open) << ", "
              << side(pr.upper, pr.upper_open)
              << "] " << pr.verdict << "\n";
  return 0;
}

// Published Crazyflie 2.x values the stand results are compared with.
nlohmann::ordered_json published_crazyflie() {
  return {{"thrust_coefficient_N_s2",
           {{"2.2e-8", "crazyflie_mhmp simulation model of the Crazyflie 2.0 (k = 2.2e-8 N s^2)"},
            {"2.3e-8", "UPenn MEAM 620 flightsim crazyflie_params.py, inferred from 14.5 g at 2500 rad/s"}}},
          {"torque_to_thrust_m", {{"0.005964552", "Förster 2015 (ETH Zürich), as used in Crazyflie firmware ports"}}}};
}

int fit_thrust_stand(const FitArgs& a, const Vehicle& v, output::OutputDirectory& out) {
  const auto samples = read_thrust_stand(a.log);
  FitOptions fo;
  fo.robust = a.robust;
  std::cerr << "thrust vs rotor speed and rotor speed vs command, " << samples.size() << " samples\n";
  const double vref = param(v, "vbat_ref").value;
  const StandFit f = fit_stand(samples, vref, fo, profile_options(a));
  const bool shared = f.coefficients == ThrustVsSpeed::Coefficients::kShared;
  double k = 0;
  for (int i = 0; i < (shared ? 1 : 4); ++i) k += f.thrust.parameters[i].value / (shared ? 1 : 4);
  const Rotor& r0 = v.rotors.front();
  const double ct = k / (param(v, "rho").value * r0.disc_area * r0.radius * r0.radius);
  nlohmann::ordered_json j;
  j["kind"] = "thrust_stand";
  j["vehicle"] = v.name;
  j["log"] = a.log;
  j["thrust_vs_speed"] = fit_json(f.thrust, f.thrust_profiles);
  j["thrust_vs_speed"]["coefficients"] = shared ? "shared" : "per_motor";
  j["thrust_vs_speed"]["motor_speed_ratio_variation_rms"] = f.ratio_variation;
  if (shared) {
    j["thrust_vs_speed"]["why"] = f.coefficients_reason;
    nlohmann::ordered_json attempt = nlohmann::ordered_json::object();  // verdicts only: no value at a bound is an estimate
    for (const auto& pr : f.per_motor_profiles)
      attempt[pr.parameter] = {{"verdict", pr.verdict},
                               {"at_bound", std::count(f.per_motor.at_bound.begin(), f.per_motor.at_bound.end(), pr.parameter) > 0}};
    j["thrust_vs_speed"]["per_motor_attempt"] = attempt;
  }
  j["speed_vs_command"] = fit_json(f.speed, f.speed_profiles);
  if (!f.voltage_exponent_identified) j["speed_vs_command"]["why"] = f.voltage_reason;
  const Profile* kp = shared ? &f.thrust_profiles.front() : nullptr;
  j["summary"] = {{"k_mean_N_s2", k},
                  {"k_ci95_N_s2", kp ? nlohmann::ordered_json{kp->lower_open ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(kp->lower),
                                                             kp->upper_open ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(kp->upper)}
                                     : nlohmann::ordered_json(nullptr)},
                  {"coefficients", shared ? "one shared by all motors" : "mean of the per-motor coefficients"},
                  {"c_t", ct},
                  {"c_t_in_vehicle_file", param(v, "c_t").value},
                  {"battery_sag_exponent_implied", f.voltage_exponent_identified ? nlohmann::ordered_json(2 * f.speed.parameters[3].value)
                                                                                : nlohmann::ordered_json(nullptr)},
                  {"vbat_ref_V", vref}};
  j["published"] = published_crazyflie();
  out.add("fit.json", output::json_document(j));
  std::vector<Profile> all = f.thrust_profiles;
  all.insert(all.end(), f.speed_profiles.begin(), f.speed_profiles.end());
  add_profile_plot(out, v.name + ": thrust stand profiles", all);
  runtime::Series meas{"measured (all motors)", {}, {}, true},
      model{shared ? "k sum w_i^2 + tare" : "sum k_i w_i^2 + tare", {}, {}, true};
  const ThrustVsSpeed thrust(samples, f.coefficients);
  const std::vector<double> pv = parameter_values(f.thrust.parameters);
  std::vector<double> r(thrust.num_residuals());
  thrust.evaluate(pv.data(), r.data(), nullptr);
  for (size_t i = 0; i < samples.size(); ++i) {
    const double wm = (samples[i].w[0] + samples[i].w[1] + samples[i].w[2] + samples[i].w[3]) / 4;
    meas.x.push_back(wm);
    meas.y.push_back(samples[i].thrust);
    model.x.push_back(wm);
    model.y.push_back(samples[i].thrust + r[i]);
  }
  add_plot(out, "fit.svg", v.name + ": thrust stand", {{"thrust vs mean rotor speed", "rad/s", "N", {meas, model}}});
  out.commit();
  if (shared) {
    std::cout << "k = " << k << " N s^2 [" << side(kp->lower, kp->lower_open) << ", " << side(kp->upper, kp->upper_open)
              << "] (" << kp->verdict << "), shared by all motors: " << f.coefficients_reason << "\n";
  } else {
    std::cout << "k per motor:";
    for (int i = 0; i < 4; ++i) std::cout << " " << f.thrust.parameters[i].value << " (" << f.thrust_profiles[i].verdict << ")";
    std::cout << "; mean " << k << " N s^2\n";
  }
  std::cout << "c_t = " << ct << "; ";
  if (f.voltage_exponent_identified) std::cout << "speed ~ vbat^" << f.speed.parameters[3].value << "\n";
  else std::cout << f.voltage_reason << "\n";
  return 0;
}

// The kind of fit follows the log's columns; an option that kind does not use is an error,
// never silently dropped.
void refuse_options(const FitArgs& a, const std::string& kind, const std::set<std::string>& used) {
  for (const auto& opt : a.given)
    if (!used.count(opt)) {
      std::string list;
      for (const auto& u : used) list += (list.empty() ? "" : ", ") + u;
      throw std::invalid_argument(opt + ": not used when fitting " + kind +
                                  " (the log's columns choose the kind of fit); this kind takes " + list);
    }
}

void check_flight_options(const FitArgs& a) {
  const bool shooting = a.formulation == "multiple_shooting";
  if (a.given.count("--window") && !shooting) throw std::invalid_argument("--window: only with --formulation multiple_shooting");
  if (a.given.count("--channels") && shooting)
    throw std::invalid_argument("--channels: only with --formulation equation_error (multiple shooting fits the pose)");
}

}  // namespace

int run_fit(const FitArgs& a) {
  const Vehicle v = load_vehicle(a.vehicle);
  // A ULog is a flight; a CSV is sniffed for the motor-step and thrust-stand layouts.
  const runtime::CsvTable head = is_ulog(a.log) ? runtime::CsvTable{} : runtime::read_csv(a.log);
  output::OutputDirectory out(a.out, {a.vehicle, a.log, a.mapping});  // refused before the work, not after
  if (head.column("throttle_percent") >= 0 && head.column("rpm") >= 0) {
    refuse_options(a, "a motor-step log", {"--out", "--robust", "--profiles", "--threads"});
    return fit_motor_steps(a, v, out);
  }
  if (head.column("weight[g]") >= 0 && head.column("rpm1") >= 0) {
    refuse_options(a, "a thrust-stand log", {"--out", "--robust", "--threads"});
    return fit_thrust_stand(a, v, out);
  }
  check_flight_options(a);
  return fit_flight(a, v, out);
}

}  // namespace quadgen::cli
