// Integration speed for the FINken 3: right-hand-side evaluations per second and simulated
// seconds per wall-clock second, RK4 at 1 kHz and DOPRI5 at 1e-8, for the compiled header
// and the interpreted tape `quadgen simulate` uses. And the fits' and diagnoses' hot path:
// f with all three Jacobians of the Crazyflie with every effect, every effect switched on,
// and the rotor speeds' rates alone against f in full.
#include <benchmark/benchmark.h>

#include <string>

#include "runtime/dynamic_model.hpp"
#include "derive/dynamics.hpp"
#include "runtime/rigid_body_state.hpp"
#include "generated/crazyflie21_all_effects/model.hpp"
#include "generated/finken3/model.hpp"
#include "derive/effects/effect_catalogue.hpp"
#include "runtime/integrator.hpp"
#include "codegen/tape_builder.hpp"

using namespace quadgen;
using namespace quadgen::runtime;

namespace {

std::unique_ptr<DynamicModel> make(bool compiled) {
  if (compiled) return std::make_unique<CompiledModel<quadgen_generated::finken3::Model>>();
  const Vehicle v = load_vehicle(std::string(QUADGEN_SOURCE_DIR) + "/vehicles/finken3.yaml");
  return std::make_unique<TapeModel>(codegen::build_tape(derive_model(v, derive_mass_properties(v), {})));
}

// Slightly unequal constant commands: a rotating, accelerating 10 s flight.
void inputs(double, double* u) {
  u[0] = 0.40;
  u[1] = 0.42;
  u[2] = 0.41;
  u[3] = 0.43;
}

void run(benchmark::State& st, bool compiled, bool dopri) {
  auto m = make(compiled);
  std::vector<double> x0(13, 0.0);
  x0[6] = 1;
  const double seconds = 10;
  Stats stats;
  for (auto _ : st) {
    IntegratorOptions o;
    o.step = 1e-3;
    o.rtol = o.atol = 1e-8;
    stats = Stats{};
    Trajectory tr = dopri ? integrate_dopri5(*m, x0, inputs, {0.0, seconds}, o, &stats)
                          : integrate_rk4(*m, x0, inputs, 0.0, seconds, o, &stats);
    benchmark::DoNotOptimize(tr.x.back());
  }
  st.counters["rhs_per_s"] = benchmark::Counter(static_cast<double>(stats.rhs_evaluations) * st.iterations(),
                                                benchmark::Counter::kIsRate);
  st.counters["sim_s_per_wall_s"] = benchmark::Counter(seconds * st.iterations(), benchmark::Counter::kIsRate);
}

void BM_Rk4_1kHz_Compiled(benchmark::State& st) { run(st, true, false); }
void BM_Rk4_1kHz_Tape(benchmark::State& st) { run(st, false, false); }
void BM_Dopri5_1e8_Compiled(benchmark::State& st) { run(st, true, true); }
void BM_Dopri5_1e8_Tape(benchmark::State& st) { run(st, false, true); }

// The Crazyflie with every effect, every effect away from its neutral value.
std::unique_ptr<DynamicModel> crazyflie_all_effects(bool compiled) {
  using Crazyflie = CompiledModel<quadgen_generated::crazyflie21_all_effects::Model>;
  std::unique_ptr<DynamicModel> m;
  if (compiled) {
    m = std::make_unique<Crazyflie>();
  } else {
    const Vehicle v = load_vehicle(std::string(QUADGEN_SOURCE_DIR) + "/vehicles/crazyflie21.yaml");
    DeriveOptions o;
    o.effects = parse_effect_list("all");
    m = std::make_unique<TapeModel>(codegen::build_tape(derive_model(v, derive_mass_properties(v), o)));
  }
  std::vector<double> p = m->params();
  for (int i = 0; i < m->num_params(); ++i)
    if (m->param_names()[i].find('.') != std::string::npos && p[i] == 0) p[i] = 1e-3;
  m->set_params(p);
  return m;
}

// A hover-like state with some motion.
std::vector<double> moving_state(const DynamicModel& m) {
  using namespace runtime::rigid_body;
  std::vector<double> x(m.num_states(), 0.0);
  x[kPosition + 2] = 0.5;
  x[kVelocity] = 0.3;
  x[kAttitude] = 1;
  for (int i = kNumStates; i < m.num_states(); ++i) x[i] = 1500;  // rotor speeds [rad/s]
  return x;
}

void jacobians(benchmark::State& st, bool compiled) {
  const auto m = crazyflie_all_effects(compiled);
  const int n = m->num_states(), nu = m->num_inputs(), np = m->num_params();
  std::vector<double> x = moving_state(*m), u(nu, 0.5), f(n), A(n * n), B(n * np), Bu(n * nu);
  for (auto _ : st) {
    m->rhs(x.data(), u.data(), f.data(), A.data(), B.data(), Bu.data());
    benchmark::DoNotOptimize(B.data());
  }
}

// What the equation-error fit asks at every sample to filter the commands through the motor
// lag: the rotor speeds' rates alone (rhs_rows: the generated rotor_speed_rates(), or the
// tape pruned to those rows), against f in full, which it evaluated before.
void rotor_speed_rates(benchmark::State& st, bool compiled, bool rows_only) {
  const auto m = crazyflie_all_effects(compiled);
  const int n = m->num_states(), nu = m->num_inputs();
  std::vector<double> x = moving_state(*m), u(nu, 0.5), f(n);
  const std::vector<int>& speeds = m->rotor_speed_states();
  for (auto _ : st) {
    if (rows_only)
      m->rhs_rows(x.data(), u.data(), speeds, f.data());
    else
      m->rhs(x.data(), u.data(), f.data(), nullptr, nullptr, nullptr);
    benchmark::DoNotOptimize(f.data());
  }
}

void BM_Jacobians_CrazyflieAllEffects_Compiled(benchmark::State& st) { jacobians(st, true); }
void BM_Jacobians_CrazyflieAllEffects_Tape(benchmark::State& st) { jacobians(st, false); }

void BM_RotorSpeedRates_Compiled_FullF(benchmark::State& st) { rotor_speed_rates(st, true, false); }
void BM_RotorSpeedRates_Compiled_RowsOnly(benchmark::State& st) { rotor_speed_rates(st, true, true); }
void BM_RotorSpeedRates_Tape_FullF(benchmark::State& st) { rotor_speed_rates(st, false, false); }
void BM_RotorSpeedRates_Tape_RowsOnly(benchmark::State& st) { rotor_speed_rates(st, false, true); }

BENCHMARK(BM_RotorSpeedRates_Compiled_FullF);
BENCHMARK(BM_RotorSpeedRates_Compiled_RowsOnly);
BENCHMARK(BM_RotorSpeedRates_Tape_FullF);
BENCHMARK(BM_RotorSpeedRates_Tape_RowsOnly);
BENCHMARK(BM_Jacobians_CrazyflieAllEffects_Compiled)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Jacobians_CrazyflieAllEffects_Tape)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Rk4_1kHz_Compiled)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Rk4_1kHz_Tape)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Dopri5_1e8_Compiled)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Dopri5_1e8_Tape)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
