// Fit time for a 60 s, 100 Hz flight (6000 samples, equation error, FINken 3 compiled model,
// c_t, c_w and kappa free), for the full profile of one parameter, and for the profiles of
// all three on one thread against two (the ratio of the two is the parallel speed-up on
// this machine).
// One evaluation of what a diagnosis' fits evaluate thousands of times: the filtered
// equation error with its Jacobian in eight free columns, over 40 s at 100 Hz of the
// Crazyflie's model with every effect (45 parameters), against the generated code it calls
// (one rhs_block per sample interval): their ratio is the cost of the equation error's own
// work (commands, filter windows, residual rows) per unit of model evaluation.
#include <benchmark/benchmark.h>

#include <random>

#include "runtime/dynamic_model.hpp"
#include "fit/equation_error.hpp"
#include "fit/evaluation_threads.hpp"
#include "runtime/integrator.hpp"
#include "fit/multiple_shooting.hpp"
#include "generated/crazyflie21_nanobench_all_effects/model.hpp"
#include "generated/finken3/model.hpp"
#include "fit/profile_likelihood.hpp"
#include "runtime/portable_random.hpp"

using namespace quadgen;
using namespace quadgen::fit;

namespace {

struct Setup {
  runtime::CompiledModel<quadgen_generated::finken3::Model> model;
  Flight flight;
  std::vector<FitParameter> params;
  std::vector<double> truth;
  Setup() {
    truth = model.params();
    std::mt19937 rng(1);
    quadgen::runtime::Normal n(0, 1);
    quadgen::runtime::UniformReal u(0.3, 0.5);
    flight.has_pose = flight.has_gyro = flight.has_accelerometer = true;
    for (int k = 0; k < 6000; ++k) {
      FlightSample s;
      s.t = 0.01 * k;
      s.x = {0, 0, 1, n(rng), n(rng), 0.3 * n(rng), 1, 0.05 * n(rng), 0.05 * n(rng), 0.3 * n(rng), 0.5 * n(rng), 0.5 * n(rng), 0.5 * n(rng)};
      double q = 0;
      for (int i = 6; i < 10; ++i) q += s.x[i] * s.x[i];
      for (int i = 6; i < 10; ++i) s.x[i] /= std::sqrt(q);
      for (int i = 0; i < 4; ++i) s.u.push_back(u(rng));
      std::vector<double> f(13);
      model.rhs(s.x.data(), s.u.data(), f.data(), nullptr, nullptr, nullptr);
      for (int i = 0; i < 3; ++i) {
        s.acc_world[i] = f[3 + i] + 0.05 * n(rng);
        s.rate_dot[i] = f[10 + i] + 0.5 * n(rng);
      }
      flight.samples.push_back(s);
    }
    for (int i = 0; i < model.num_params(); ++i) {
      const std::string nm = model.param_names()[i];
      const bool free = nm == "c_t" || nm == "c_w" || nm == "kappa";
      const double v = truth[i];
      params.push_back({nm, "", free ? v * 1.2 : v, free ? v * 0.2 : v, free ? v * 5 : v, free});
    }
  }
};

void BM_FitEquationError60s100Hz(benchmark::State& st) {
  Setup s;
  EquationErrorModel m(s.model, s.flight, false, {}, EquationErrorModel::Derivatives::kPointwise);
  for (auto _ : st) benchmark::DoNotOptimize(fit_least_squares(m, s.params, {}).chi2);
}

void BM_ProfileOneParameter60s100Hz(benchmark::State& st) {
  Setup s;
  EquationErrorModel m(s.model, s.flight, false, {}, EquationErrorModel::Derivatives::kPointwise);
  const FitResult best = fit_least_squares(m, s.params, {});
  const int ct = s.model.param_index("c_t");
  for (auto _ : st) benchmark::DoNotOptimize(profile_parameter(m, best, ct, {}, {}).points.size());
}

void BM_ProfileAllThreads60s100Hz(benchmark::State& st) {
  Setup s;
  EquationErrorModel m(s.model, s.flight, false, {}, EquationErrorModel::Derivatives::kPointwise);
  const FitResult best = fit_least_squares(m, s.params, {});
  ProfileOptions po;
  po.threads = static_cast<int>(st.range(0));
  for (auto _ : st) benchmark::DoNotOptimize(profile_all(m, best, {}, po).size());
}

// 40 s at 100 Hz of random states and commands (the values do not matter for the cost) for
// the Crazyflie's model with every effect; its time and battery voltage inputs are read from
// the samples.
struct CrazyflieSetup {
  runtime::CompiledModel<quadgen_generated::crazyflie21_nanobench_all_effects::Model> model;
  Flight flight;
  std::vector<int> free;
  CrazyflieSetup() {
    std::mt19937 rng(3);
    quadgen::runtime::Normal n(0, 1);
    quadgen::runtime::UniformReal u(0.3, 0.6);
    flight.has_pose = flight.has_gyro = true;
    for (int k = 0; k < 4000; ++k) {
      FlightSample s;
      s.t = 0.01 * k;
      s.vbat = 3.9;
      s.x = {0, 0, 1, n(rng), n(rng), 0.3 * n(rng), 1, 0.05 * n(rng), 0.05 * n(rng), 0.3 * n(rng), n(rng), n(rng), n(rng)};
      double q = 0;
      for (int i = 6; i < 10; ++i) q += s.x[i] * s.x[i];
      for (int i = 6; i < 10; ++i) s.x[i] /= std::sqrt(q);
      for (int i = 0; i < 4; ++i) s.u.push_back(u(rng));
      flight.samples.push_back(s);
    }
    for (const char* name : {"c_t", "kappa", "motor_gain.M2", "motor_gain.M3", "motor_gain.M4", "rotor_drag.k",
                             "blade_flapping.k", "wind.x"})
      free.push_back(model.param_index(name));
  }
};

void BM_EquationErrorJacobianCrazyflie40s(benchmark::State& st) {
  CrazyflieSetup s;
  EquationErrorModel m(s.model, s.flight, false);
  const std::vector<double> p = s.model.params();
  std::vector<double> r(static_cast<size_t>(m.num_residuals())), J(r.size() * s.free.size());
  const OneCorePerFit one_core;  // on one thread, as the reference
  for (auto _ : st) {
    m.evaluate_columns(p, r.data(), J.data(), s.free);
    benchmark::DoNotOptimize(J.data());
  }
}

// The reference: the generated right-hand side with the same block of df/dp, once per
// sample interval of the same flight.
void BM_GeneratedRhsBlockCrazyflie40s(benchmark::State& st) {
  CrazyflieSetup s;
  const std::vector<int> rows = {3, 4, 5, 10, 11, 12};
  const auto block = s.model.param_block(rows, s.free);
  const int n = s.model.num_states();
  std::vector<double> x(n, 0.0), u = {0, 0, 0, 0, 0, 3.9}, f(n), B(rows.size() * s.free.size());
  for (auto _ : st)
    for (size_t k = 0; k + 1 < s.flight.samples.size(); ++k) {
      const FlightSample& sample = s.flight.samples[k];
      std::copy(sample.x.begin(), sample.x.end(), x.begin());
      std::copy(sample.u.begin(), sample.u.end(), u.begin());
      u[4] = sample.t;
      s.model.rhs_block(x.data(), u.data(), f.data(), block, B.data());
      benchmark::DoNotOptimize(B.data());
    }
}

// 60 s of pose at 100 Hz: fifteen 4 s wobbling flights from hover, 0.3 s windows.
void BM_FitMultipleShooting60s100Hz(benchmark::State& st) {
  Setup s;
  Flight f;
  f.has_pose = f.has_gyro = true;
  auto u = [](double t, double* out) {
    for (int i = 0; i < 4; ++i) out[i] = 0.4216 + 0.01 * std::sin((2.5 + 0.3 * i) * t + i);
  };
  std::vector<double> x0(13, 0.0);
  x0[2] = 1;
  x0[6] = 1;
  runtime::IntegratorOptions o;
  o.step = 0.01;
  const auto tr = runtime::integrate_rk4(s.model, x0, u, 0.0, 4.0, o);
  for (int seg = 0; seg < 15; ++seg)
    for (size_t k = 0; k < tr.t.size(); ++k) {
      FlightSample fs;
      fs.t = seg * 4.2 + tr.t[k];  // 0.2 s gaps separate the segments
      fs.x = tr.x[k];
      fs.u.resize(4);
      u(tr.t[k], fs.u.data());
      f.samples.push_back(fs);
    }
  MultipleShootingModel m(s.model, f, 0.3);
  auto ps = s.params;
  for (auto& p : ps)
    if (p.name == "c_w") p.free = false, p.value = s.truth[s.model.param_index("c_w")];
  for (auto _ : st) benchmark::DoNotOptimize(fit_least_squares(m, ps, {}).chi2);
}

BENCHMARK(BM_FitMultipleShooting60s100Hz)->Unit(benchmark::kMillisecond)->Iterations(2);
BENCHMARK(BM_EquationErrorJacobianCrazyflie40s)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_GeneratedRhsBlockCrazyflie40s)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FitEquationError60s100Hz)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_ProfileOneParameter60s100Hz)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_ProfileAllThreads60s100Hz)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->Iterations(2)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
