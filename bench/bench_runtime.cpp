// Integration speed for the FINken 3: right-hand-side evaluations per second and simulated
// seconds per wall-clock second, RK4 at 1 kHz and DOPRI5 at 1e-8, for the compiled header
// and the interpreted tape `quadgen simulate` uses.
#include <benchmark/benchmark.h>

#include <string>

#include "runtime/dynamic_model.hpp"
#include "derive/dynamics.hpp"
#include "generated/finken3/model.hpp"
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

BENCHMARK(BM_Rk4_1kHz_Compiled)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Rk4_1kHz_Tape)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Dopri5_1e8_Compiled)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Dopri5_1e8_Tape)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
