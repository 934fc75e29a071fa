// ns per call of the generated FINken 3 model against the same model written by hand and
// differentiated by Ceres' Jets (the reference), and against central finite differences;
// plus derive + emit time. Prints the ratios after the Google Benchmark table.
#include <benchmark/benchmark.h>

#include <ceres/jet.h>

#include <cstdio>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>

#include "derive/dynamics.hpp"
#include "derive/effects/effect_catalogue.hpp"
#include "codegen/header_writer.hpp"
#include "bench/reference_model.hpp"

namespace gen = quadgen_generated::finken3;
using quadgen::reference::reference_rhs;

namespace {

constexpr int NX = gen::kNumStates, NU = gen::kNumInputs, NP = gen::kNumParams, N = NX + NU + NP;

struct Point {
  double x[NX] = {0.1, -0.2, 1.2, 0.5, -0.3, 0.1, 0.98, 0.1, -0.1, 0.1, 0.4, -0.2, 0.3};
  double u[NU] = {0.4, 0.45, 0.5, 0.42};
  double p[NP];
  Point() {
    for (int i = 0; i < NP; ++i) p[i] = gen::kNominalParams[i];
  }
};

void BM_GeneratedF(benchmark::State& st) {
  Point pt;
  gen::Precomputed<double> pre;
  gen::precompute(pt.p, &pre);
  double f[NX];
  for (auto _ : st) {
    benchmark::DoNotOptimize(pt.x);
    gen::rhs(pt.x, pt.u, pt.p, pre, f, (double*)nullptr, (double*)nullptr, (double*)nullptr);
    benchmark::DoNotOptimize(f);
  }
}

void BM_GeneratedFOnlyEntryPoint(benchmark::State& st) {  // rhs(x, u, p, pre, f)
  Point pt;
  gen::Precomputed<double> pre;
  gen::precompute(pt.p, &pre);
  double f[NX];
  for (auto _ : st) {
    benchmark::DoNotOptimize(pt.x);
    gen::rhs(pt.x, pt.u, pt.p, pre, f);
    benchmark::DoNotOptimize(f);
  }
}

void BM_GeneratedPrecompute(benchmark::State& st) {  // once per parameter vector
  Point pt;
  gen::Precomputed<double> pre;
  for (auto _ : st) {
    benchmark::DoNotOptimize(pt.p);
    gen::precompute(pt.p, &pre);
    benchmark::DoNotOptimize(pre);
  }
}

void BM_GeneratedFAndJacobians(benchmark::State& st) {
  Point pt;
  gen::Precomputed<double> pre;
  gen::precompute(pt.p, &pre);
  double f[NX], dx[gen::kDfdxNnz], du[gen::kDfduNnz], dp[gen::kDfdpNnz];
  for (auto _ : st) {
    benchmark::DoNotOptimize(pt.x);
    gen::rhs(pt.x, pt.u, pt.p, pre, f, dx, du, dp);
    benchmark::DoNotOptimize(dp);
  }
}

void BM_HandWrittenF(benchmark::State& st) {
  Point pt;
  const auto layout = quadgen::reference::finken3_layout();
  double f[NX];
  for (auto _ : st) {
    benchmark::DoNotOptimize(pt.x);
    reference_rhs(pt.x, pt.u, pt.p, layout, f);
    benchmark::DoNotOptimize(f);
  }
}

void BM_CeresAutodiffJacobians(benchmark::State& st) {
  using Jet = ceres::Jet<double, N>;
  Point pt;
  const auto layout = quadgen::reference::finken3_layout();
  Jet x[NX], u[NU], p[NP], f[NX];
  for (auto _ : st) {
    benchmark::DoNotOptimize(pt.x);
    for (int i = 0; i < NX; ++i) x[i] = Jet(pt.x[i], i);
    for (int i = 0; i < NU; ++i) u[i] = Jet(pt.u[i], NX + i);
    for (int i = 0; i < NP; ++i) p[i] = Jet(pt.p[i], NX + NU + i);
    reference_rhs(x, u, p, layout, f);
    benchmark::DoNotOptimize(f);
  }
}

void BM_CentralDifferences(benchmark::State& st) {
  Point pt;
  double f[NX], fp[NX], fm[NX], J[NX * N];
  for (auto _ : st) {
    benchmark::DoNotOptimize(pt.x);
    double* vars[3] = {pt.x, pt.u, pt.p};
    const int sizes[3] = {NX, NU, NP};
    int col = 0;
    gen::Precomputed<double> pre;
    gen::precompute(pt.p, &pre);
    gen::rhs(pt.x, pt.u, pt.p, pre, f, (double*)nullptr, (double*)nullptr, (double*)nullptr);
    for (int b = 0; b < 3; ++b)
      for (int j = 0; j < sizes[b]; ++j, ++col) {
        const double keep = vars[b][j], h = 1e-6 * std::fmax(std::fabs(keep), 1e-3);
        vars[b][j] = keep + h;
        if (b == 2) gen::precompute(pt.p, &pre);
        gen::rhs(pt.x, pt.u, pt.p, pre, fp, (double*)nullptr, (double*)nullptr, (double*)nullptr);
        vars[b][j] = keep - h;
        if (b == 2) gen::precompute(pt.p, &pre);
        gen::rhs(pt.x, pt.u, pt.p, pre, fm, (double*)nullptr, (double*)nullptr, (double*)nullptr);
        vars[b][j] = keep;
        if (b == 2) gen::precompute(pt.p, &pre);
        for (int i = 0; i < NX; ++i) J[i * N + col] = (fp[i] - fm[i]) / (2 * h);
      }
    benchmark::DoNotOptimize(J);
  }
}

void BM_DeriveAndEmitFinken3AllEffects(benchmark::State& st) {
  const quadgen::Vehicle v = quadgen::load_vehicle(std::string(QUADGEN_SOURCE_DIR) + "/vehicles/finken3.yaml");
  quadgen::DeriveOptions o;
  o.effects = quadgen::parse_effect_list("all");
  for (auto _ : st) {
    const auto m = quadgen::derive_model(v, quadgen::derive_mass_properties(v), o);
    auto h = quadgen::codegen::generate_header(m, {"vehicles/finken3.yaml", " --effects all"});
    benchmark::DoNotOptimize(h.content);
  }
}

BENCHMARK(BM_GeneratedF);
BENCHMARK(BM_GeneratedFOnlyEntryPoint);
BENCHMARK(BM_GeneratedPrecompute);
BENCHMARK(BM_GeneratedFAndJacobians);
BENCHMARK(BM_HandWrittenF);
BENCHMARK(BM_CeresAutodiffJacobians);
BENCHMARK(BM_CentralDifferences);
BENCHMARK(BM_DeriveAndEmitFinken3AllEffects)->Unit(benchmark::kMillisecond)->Iterations(3);

// Collects each benchmark's times (ns) to print the ratios: the median over repetitions, from
// the individual runs or, with --benchmark_report_aggregates_only, from the "median"
// aggregate. A benchmark a filter left out has no time, and its ratios are not printed.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const auto& r : runs) {
      const double ns = r.GetAdjustedRealTime() * (r.time_unit == benchmark::kMillisecond ? 1e6 : 1.0);
      if (r.run_type == Run::RT_Iteration) samples_[r.run_name.str()].push_back(ns);
      else if (r.aggregate_name == "median") medians_[r.run_name.str()] = ns;
    }
    ConsoleReporter::ReportRuns(runs);
  }
  // NaN when the benchmark did not run.
  double median_ns(const std::string& name) const {
    if (auto it = samples_.find(name); it != samples_.end()) {
      std::vector<double> v = it->second;
      std::sort(v.begin(), v.end());
      const size_t n = v.size();
      return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    }
    if (auto it = medians_.find(name); it != medians_.end()) return it->second;
    return std::numeric_limits<double>::quiet_NaN();
  }

 private:
  std::map<std::string, std::vector<double>> samples_;
  std::map<std::string, double> medians_;
};

void print_ratio(const char* what, double numerator, double denominator, const char* format) {
  if (std::isnan(numerator) || std::isnan(denominator)) std::printf("  %s   (not run)\n", what);
  else std::printf(format, what, numerator / denominator);
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  RatioReporter rep;
  benchmark::RunSpecifiedBenchmarks(&rep);
  auto t = [&](const char* n) { return rep.median_ns(n); };
  const double gen_all = t("BM_GeneratedFAndJacobians"), gen_f = t("BM_GeneratedF");
  std::printf("\nFINken 3 base model, same process (ratios of medians, higher = generated code faster):\n");
  print_ratio("Ceres autodiff (hand-written functor) / generated f+Jacobians:", t("BM_CeresAutodiffJacobians"), gen_all,
              "  %s %6.1fx\n");
  print_ratio("central differences (generated f)     / generated f+Jacobians:", t("BM_CentralDifferences"), gen_all,
              "  %s %6.1fx\n");
  print_ratio("hand-written f                        / generated f:          ", t("BM_HandWrittenF"), gen_f,
              "  %s %6.2fx\n");
  print_ratio("generated f+Jacobians                 / generated f:          ", gen_all, gen_f, "  %s %6.1fx\n");
  print_ratio("derive + emit, FINken 3 with all effects [ms]:", t("BM_DeriveAndEmitFinken3AllEffects/iterations:3"), 1e6,
              "  %s %.0f\n");
  return 0;
}
