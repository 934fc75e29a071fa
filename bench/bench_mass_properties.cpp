// derive_mass_properties against the number of blocks: synthetic vehicles of 10 to 10,000
// blocks built in memory (a grid of small blocks with mixed orientations: plain, 45 deg
// yaw with sqrt(2) in the rotation, 30 deg yaw and a tilted one with all three angles),
// so that the cost per block can be read off and a quadratic term shows at once.
// The Tilted variant turns every block by (30, 20, 10) deg, the costly case: its exact
// values carry sin and cos of Pi/9 and Pi/18, which no block of the bundled vehicles does.
#include <benchmark/benchmark.h>

#include <string>

#include "derive/geometry.hpp"
#include "model/vehicle.hpp"

using namespace quadgen;

namespace {

Vehicle synthetic_vehicle(int n, bool all_tilted) {
  Vehicle v;
  v.name = "synthetic" + std::to_string(n);
  v.source_path = "<synthetic " + std::to_string(n) + " blocks>";
  const Vec3 orientations[] = {{0, 0, 0}, {45, 0, 0}, {30, 0, 0}, {30, 20, 10}};
  int side = 1;
  while (side * side * side < n) ++side;
  for (int k = 0; k < n; ++k) {
    const int i = k % side, j = (k / side) % side, l = k / (side * side);
    Block b;
    b.name = "b" + std::to_string(k);
    b.mass = 0.001 + 0.0001 * (k % 7);
    b.size = {0.01 + 0.001 * (k % 3), 0.012, 0.004 + 0.0005 * (k % 5)};
    b.centre = {0.02 * (i - side / 2), 0.02 * (j - side / 2), 0.01 * l};
    b.yaw_pitch_roll_deg = orientations[all_tilted ? 3 : k % 4];
    b.line = k + 1;
    v.blocks.push_back(b);
  }
  return v;
}

void run(benchmark::State& st, bool all_tilted) {
  const Vehicle v = synthetic_vehicle(static_cast<int>(st.range(0)), all_tilted);
  for (auto _ : st) {
    MassProperties mp = derive_mass_properties(v);
    benchmark::DoNotOptimize(mp.inertia_cog_value);
  }
  st.counters["blocks"] = static_cast<double>(v.blocks.size());
  st.counters["s_per_block"] =
      benchmark::Counter(static_cast<double>(v.blocks.size()), benchmark::Counter::kIsIterationInvariantRate |
                                                                    benchmark::Counter::kInvert);
}

void BM_DeriveMassProperties(benchmark::State& st) { run(st, false); }
void BM_DeriveMassPropertiesTilted(benchmark::State& st) { run(st, true); }

}  // namespace

BENCHMARK(BM_DeriveMassProperties)->Arg(10)->Arg(100)->Unit(benchmark::kMillisecond)->UseRealTime();
// One iteration each: the large vehicles take seconds.
BENCHMARK(BM_DeriveMassProperties)->Arg(1000)->Arg(10000)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK(BM_DeriveMassPropertiesTilted)->Arg(10)->Arg(100)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DeriveMassPropertiesTilted)->Arg(1000)->Arg(10000)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_MAIN();
