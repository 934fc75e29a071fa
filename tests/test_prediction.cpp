// The measuring stick checked against what it must measure: a generated flight predicted by
// its own model (no error but integration), and by a model whose thrust is 5 % too strong,
// whose error has a closed form: with the attitude replayed from the log, the extra
// acceleration is 5 % of the thrust per mass along body z, so the position error at horizon
// h is about 0.5 * 0.05 * (T/m) * h^2, and the one-step vertical residual about 0.05 * T/m.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "generated/finken3_all_effects/model.hpp"
#include "dynamic_model.hpp"
#include "flight_data.hpp"
#include "flight_log.hpp"
#include "prediction.hpp"
#include "test_helpers.hpp"

namespace fs = std::filesystem;
using quadgen::test::source_path;

namespace {

struct GeneratedFlight {
  quadgen::fit::Flight flight;
  double mean_thrust_per_mass = 0;  // m/s^2, over the flight: |a_world + g e_z|
};

const GeneratedFlight& flight() {
  static const GeneratedFlight g = [] {
    const fs::path dir = fs::temp_directory_path() / ("quadgen_prediction_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const std::string csv = (dir / "f.csv").string();
    const std::string cmd = std::string(QUADGEN_BINARY) + " simulate " + source_path("vehicles/finken3.yaml") +
                            " --closed-loop --duration 12 --seed 4 --pose-noise 0 --out " + csv + " > /dev/null 2>&1";
    if (std::system(cmd.c_str()) != 0) throw std::runtime_error("simulate failed");
    GeneratedFlight out;
    out.flight = quadgen::predict::fill_missing_signals(
        quadgen::fit::load_flight(quadgen::runtime::read_csv(csv), {"A", "B", "C", "D"}, {}), 4.0);
    fs::remove_all(dir);
    double sum = 0;
    for (const auto& s : out.flight.samples)
      sum += std::sqrt(std::pow(s.acc_world[0], 2) + std::pow(s.acc_world[1], 2) + std::pow(s.acc_world[2] + 9.81, 2));
    out.mean_thrust_per_mass = sum / static_cast<double>(out.flight.samples.size());
    return out;
  }();
  return g;
}

using Model = quadgen::runtime::CompiledModel<quadgen_generated::finken3_all_effects::Model>;

}  // namespace

TEST(Prediction, OwnModelPredictsItsFlightUpToIntegration) {
  Model m;
  const auto p = quadgen::predict::evaluate_prediction(m, m.params(), flight().flight, {});
  ASSERT_EQ(p.open_loop.size(), 4u);
  EXPECT_GT(p.start_points, 150u);
  for (const auto& h : p.open_loop) {
    EXPECT_GT(h.position.count, 100u);
    EXPECT_LT(h.position.mean(), 2e-3) << h.horizon;
    EXPECT_LT(h.tilt.mean(), 2e-3) << h.horizon;
    EXPECT_EQ(h.diverged, 0u);
  }
  EXPECT_LT(p.attitude_replayed.back().position.mean(), 2e-3);
}

TEST(Prediction, ThrustTooStrongGivesTheClosedFormError) {
  Model m;
  std::vector<double> params = m.params();
  params[m.param_index("c_t")] *= 1.05;
  const auto p = quadgen::predict::evaluate_prediction(m, params, flight().flight, {});
  const double extra = 0.05 * flight().mean_thrust_per_mass;  // m/s^2
  for (const auto& h : p.attitude_replayed) {
    const double expected = 0.5 * extra * h.horizon * h.horizon;
    EXPECT_NEAR(h.position.mean(), expected, 0.15 * expected) << "horizon " << h.horizon;
  }
  // Error at a horizon, not an RMS over a window: quadratic growth between horizons.
  const double ratio = p.attitude_replayed[2].position.mean() / p.attitude_replayed[3].position.mean();
  EXPECT_NEAR(ratio, 0.25, 0.03);
  EXPECT_NEAR(p.one_step.vertical_acceleration_world.rms(), extra, 0.15 * extra);
  // Open loop, the moments are 5 % too strong as well: the error can only be larger.
  EXPECT_GE(p.open_loop[3].position.mean(), 0.9 * p.attitude_replayed[3].position.mean());
}
