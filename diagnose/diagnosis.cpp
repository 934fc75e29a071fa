#include "diagnosis.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>

namespace quadgen::diagnose {

namespace {

std::vector<double> channel_rms(const fit::EquationErrorModel& m, const std::vector<fit::FitParameter>& ps) {
  const auto p = fit::parameter_values(ps);
  std::vector<double> r6;
  m.all_channels(p.data(), r6);
  std::vector<double> rms(6, 0.0);
  const size_t ns = r6.size() / 6;
  for (size_t k = 0; k < ns; ++k)
    for (int c = 0; c < 6; ++c) rms[c] += r6[k * 6 + c] * r6[k * 6 + c];
  for (double& v : rms) v = std::sqrt(v / static_cast<double>(std::max<size_t>(1, ns)));
  return rms;
}

}  // namespace

Diagnosis diagnose_flight(const Vehicle& v, const SymbolicModel& all, runtime::DynamicModel& model,
                          const fit::Flight& flight_in, const DiagnoseOptions& opt, fit::Flight* validation_out) {
  const auto clock0 = std::chrono::steady_clock::now();
  Diagnosis d;
  d.vehicle = v.name;
  // Without a battery or pose log, neither battery_sag nor ground_effect is a candidate.
  const fit::Flight flight = predict::fill_missing_signals(flight_in, all.params[all.param_index("vbat_ref")].nominal);
  bool accel = opt.translational == "accelerometer" || (opt.translational == "auto" && !flight.has_pose);
  if (opt.translational == "pose" && !flight.has_pose) throw fit::FitError(flight.source + ": no pose to differentiate");
  d.formulation = accel ? "equation error: accelerometer specific force (body) and gyro derivative"
                        : "equation error: differentiated velocity (world) and gyro derivative";
  d.channel_names = accel ? std::vector<std::string>{"ax", "ay", "az", "pdot", "qdot", "rdot"}
                          : std::vector<std::string>{"ax_world", "ay_world", "az_world", "pdot", "qdot", "rdot"};
  d.channel_units = {"m/s^2", "m/s^2", "m/s^2", "rad/s^2", "rad/s^2", "rad/s^2"};
  const auto parts = fit::split_by_time(flight, 1.0 - opt.validation_fraction);
  const fit::Flight &train = parts.first, &valid = parts.second;  // (lambdas below capture valid)
  if (train.samples.size() < 50 || valid.samples.size() < 50)
    throw fit::FitError(flight.source + ": too short to hold out " + std::to_string(opt.validation_fraction) +
                        " of it for validation (" + std::to_string(flight.samples.size()) + " airborne samples)");
  d.train_samples = train.samples.size();
  d.valid_samples = valid.samples.size();
  d.t_split = valid.samples.front().t;
  *validation_out = valid;
  const fit::EquationErrorModel train_ee(model, train, accel), valid_ee(model, valid, accel),
      all_ee(model, flight, accel);
  CandidateSearch search(all, model, train_ee, valid_ee, opt.search);
  d.candidates = opt.search.candidates.empty() ? applicable_effects(flight) : opt.search.candidates;
  d.search = search.run();
  const SearchResult& s = d.search;
  // What is wrong, before and after, over the whole flight.
  fit::Flight used = flight;  // the samples with residuals (full derivative windows)
  used.samples.clear();
  for (size_t k : all_ee.rows()) used.samples.push_back(flight.samples[k]);
  for (const auto& smp : used.samples) d.t.push_back(smp.t);
  const auto pb = fit::parameter_values(s.base_fit), pa = fit::parameter_values(s.final_fit);
  all_ee.all_channels(pb.data(), d.residual_before);
  all_ee.all_channels(pa.data(), d.residual_after);
  std::vector<std::string> rotors;
  for (const auto& r : v.rotors) rotors.push_back(r.name);
  const SignalSet signals = physical_signals(used, rotors);
  d.before = analyse_residuals(d.residual_before, d.channel_names, d.channel_units, d.t, signals);
  d.after = analyse_residuals(d.residual_after, d.channel_names, d.channel_units, d.t, signals);
  // The gain on the validation part.
  const bool pose = flight.has_pose;
  d.metric = pose ? "validation position RMSE (" + std::to_string(opt.window).substr(0, 3) +
                        " s open-loop windows from measured states) [m]"
                  : "validation equation-error cost (weighted, no pose logged)";
  auto metric = [&](const std::vector<fit::FitParameter>& ps, WindowedSimulation* sim) {
    if (!pose) return search.cost(valid_ee, ps);
    WindowedSimulation w = simulate_windows(model, fit::parameter_values(ps), valid, opt.window);
    if (sim) *sim = w;
    return w.position_rmse;
  };
  std::cerr << "[diagnose] validation of " << s.selected.size() + 1 << " models\n";
  d.metric_before = metric(s.base_fit, &d.sim_before);
  d.metric_after = metric(s.final_fit, &d.sim_after);
  // Without a pose only the one-step view can be measured.
  std::cerr << "[diagnose] prediction error at horizons, before and after\n";
  d.has_prediction = true;
  d.prediction_before = predict::evaluate_prediction(model, fit::parameter_values(s.base_fit), valid, {});
  d.prediction_after = predict::evaluate_prediction(model, fit::parameter_values(s.final_fit), valid, {});
  const auto rb = channel_rms(valid_ee, s.base_fit), ra = channel_rms(valid_ee, s.final_fit);
  for (int c = 0; c < 6; ++c) d.channel_gain.push_back({d.channel_names[c], rb[c], ra[c]});
  std::vector<fit::FitParameter> step_base = s.base_fit;
  double step_metric = d.metric_before;
  for (const auto& step : s.steps) {
    if (step.selected.empty()) continue;
    Finding f;
    f.effect = step.selected;
    f.evidence = step.candidates.front();
    for (const auto& e : s.estimates)
      if (e.name.rfind(f.effect + ".", 0) == 0) f.parameters.push_back(e);
    f.metric = d.metric;
    f.before = step_metric;
    f.after = metric(f.evidence.parameters, nullptr);
    step_metric = f.after;
    step_base = f.evidence.parameters;
    d.findings.push_back(f);
  }
  // Left over: slow structure the noise cannot explain. After an ambiguity, what is left
  // over is judged with the stronger of the two look-alikes in the model (either
  // explains the discrepancy; only the name is open).
  ResidualAnalysis left = d.after;
  if (!s.unresolved.empty()) {
    const auto pu = fit::parameter_values(s.steps.back().candidates.front().parameters);
    std::vector<double> r;
    all_ee.all_channels(pu.data(), r);
    left = analyse_residuals(r, d.channel_names, d.channel_units, d.t, signals);
  }
  for (const auto& c : left.channels) {
    if (!(c.slow_p_value < opt.unexplained_p && c.slow_ratio > opt.unexplained_ratio)) continue;
    Unexplained u{c.name, c.unit, c.slow_rms, c.slow_ratio, c.slow_p_value, c.worst_window_t0, c.worst_window_t1,
                  c.worst_window_mean, "", 0};
    if (!c.correlations.empty()) u.signal = c.correlations.front().signal, u.r = c.correlations.front().r;
    d.unexplained.push_back(u);
  }
  for (const auto& p : s.final_fit)
    if (p.free && fit::on_bound(p)) {
      const bool lower = std::fabs(p.value - p.lower) <= std::fabs(p.value - p.upper);
      d.at_bounds.push_back(p.name + " = " + std::to_string(p.value) + (lower ? " (lower bound)" : " (upper bound)"));
    }
  d.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - clock0).count();
  return d;
}

}  // namespace quadgen::diagnose
