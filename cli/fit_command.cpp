// quadgen fit VEHICLE.yaml LOG.csv --out DIR
// The kind of fit follows the log's layout: motor step tests (time_ms, throttle_percent,
// rpm) fit the motor map and its lag.
#include <cmath>
#include <iostream>

#include "atomic_output.hpp"
#include "commands.hpp"
#include "fit_report.hpp"
#include "flight_log.hpp"
#include "motor_steps.hpp"
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
}

namespace {

int fit_motor_steps(const FitArgs& a, const Vehicle& v) {
  MotorStepModel model(read_motor_steps(a.log));
  FitOptions fo;
  fo.robust = a.robust;
  std::cerr << "[1/2] fitting motor map and lag to " << model.steps().size() << " steps (" << model.num_residuals()
            << " samples)\n";
  const FitResult best = fit_least_squares(model, model.parameters(), fo);
  std::cerr << "[2/2] profile likelihood of " << best.num_free << " parameters\n";
  const auto profiles = profile_all(model, best, fo, {});
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
  OutputSet out(a.out);
  out.add("fit.json", j.dump(2) + "\n");
  out.commit();
  std::string err;
  if (!plot_profiles(a.out + "/profiles.svg", v.name + ": motor step profiles", profiles, &err))
    std::cerr << "no plot: " << err << "\n";
  // Like the thesis' Figure 24: every step normalised to 0..1 and aligned at its fitted
  // step instant; a first-order lag is then one curve, 1 - exp(-t / tau).
  std::vector<double> pv;
  for (const auto& q : best.parameters) pv.push_back(q.value);
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
  if (!runtime::plot_svg(a.out + "/fit.svg", v.name + ": motor steps (thesis Table 2)",
                         {{"normalised rotor speed after each throttle step", "time after the fitted step instant [s]", "1", {meas, fitted, thesis}}}, &err))
    std::cerr << "no plot: " << err << "\n";
  std::cout << "tau = " << best.parameters[3].value << " s";
  if (tau) std::cout << ", 95 % profile interval [" << tau->lower << ", " << tau->upper << "] (" << tau->verdict << ")";
  std::cout << "; thesis: 0.128 s\n";
  return 0;
}

}  // namespace

int run_fit(const FitArgs& a) {
  const Vehicle v = load_vehicle(a.vehicle);
  const runtime::CsvTable head = runtime::read_csv(a.log);
  if (head.column("throttle_percent") >= 0 && head.column("rpm") >= 0) return fit_motor_steps(a, v);
  throw std::invalid_argument(a.log + ":1: unrecognised log layout (expected motor steps: time_ms, throttle_percent, rpm)");
}

}  // namespace quadgen::cli
