// The command-gain check (diagnose/command_gain.hpp): a known gain and delay recovered from
// synthetic signals, and the motor map's slope of a generated closed-loop flight recovered
// through the compiled models of the stock and the NanoBench Crazyflie.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <random>

#include "diagnose/command_gain.hpp"
#include "fit/flight_data.hpp"
#include "generated/crazyflie21/model.hpp"
#include "generated/crazyflie21_nanobench/model.hpp"
#include "runtime/dynamic_model.hpp"
#include "runtime/flight_log.hpp"
#include "tests/test_helpers.hpp"
#include "runtime/portable_random.hpp"

using namespace quadgen;
using namespace quadgen::diagnose;
namespace fs = std::filesystem;

namespace {

// 100 Hz, two stretches of `seconds` with a gap between them. The model's roll, pitch and
// vertical carry a multisine (1-15 Hz) and a slow swing; the measured ones are `gain` times
// the model's `delay` earlier plus a slow disturbance of their own and white noise.
CommandGainInput synthetic(double gain, double delay, double seconds, std::mt19937& rng) {
  quadgen::runtime::Normal noise(0, 0.3);
  CommandGainInput in;
  in.rotors = 4, in.vertical_offset = 9.81;
  const auto drive = [](double t, int axis) {
    double x = 0;
    for (int i = 1; i <= 15; ++i) x += std::sin(2 * M_PI * i * t + 0.7 * i * i + axis);
    return x + 3 * std::sin(2 * M_PI * 0.2 * t + axis);
  };
  for (int stretch = 0; stretch < 2; ++stretch)
    for (double t = 100.0 * stretch; t < 100.0 * stretch + seconds; t += 0.01) {
      in.t.push_back(t);
      double model[6] = {0, 0, 0, 0, 0, 0}, measured[6] = {0, 0, 9.81, 0, 0, 0};
      const int axis_channel[3] = {3, 4, 2};
      for (int a = 0; a < 3; ++a) {
        const int c = axis_channel[a];
        model[c] = drive(t, a) + (c == 2 ? 9.81 : 0.0);
        measured[c] = gain * drive(t - delay, a) + (c == 2 ? 9.81 : 0.0) + 2 * std::sin(2 * M_PI * 0.13 * t + a) + noise(rng);
      }
      for (int c = 0; c < 6; ++c) in.model.push_back(model[c] - (c == 2 ? 9.81 : 0.0)), in.measured.push_back(measured[c] - (c == 2 ? 9.81 : 0.0));
      for (int i = 0; i < 4; ++i) in.commands.push_back(0.6);
    }
  return in;
}

}  // namespace

TEST(CommandGain, RecoversAKnownGainAndDelay) {
  std::mt19937 rng(3);
  const CommandGainInput in = synthetic(0.6, 0.04, 30, rng);
  const CommandGain g = command_gain(in);
  ASSERT_TRUE(g.measured) << g.why_not;
  EXPECT_NEAR(g.thrust_scale, 1.0, 0.02);  // the means of the swings over the rows used
  EXPECT_NEAR(g.hover_command, 0.6, 1e-12);
  ASSERT_EQ(g.axes.size(), 3u);  // roll, pitch, collective: none may go unchecked
  for (const auto& axis : g.axes)
    for (size_t b = 0; b < 3; ++b) {  // the lowest band holds the slow disturbance too
      EXPECT_NEAR(axis.bands[b].gain, 0.6, 0.03) << axis.name << " band " << b;
      EXPECT_NEAR(axis.bands[b].delay_s, 0.04, 1e-9) << axis.name << " band " << b;
    }
  EXPECT_TRUE(g.slope_looks_off());
  EXPECT_NEAR(g.suggested_slope(), 0.6, 0.03);
}

TEST(CommandGain, TheHoverScaleAndTheFilesSlopeAreTakenIntoAccount) {
  std::mt19937 rng(4);
  CommandGainInput in = synthetic(1.0, 0.0, 30, rng);
  const CommandGain right = command_gain(in);
  ASSERT_TRUE(right.measured);
  EXPECT_NEAR(right.roll_pitch_gain(), 1.0, 0.03);
  EXPECT_FALSE(right.slope_looks_off());
  // A model whose thrust constant is twice the hover's: every acceleration twice as large.
  // The gains are relative to the hover, so they stay; the suggestion multiplies the file's slope.
  for (auto& x : in.model) x *= 2;
  for (size_t k = 0; k < in.t.size(); ++k) in.model[k * 6 + 2] += 9.81;  // 2 (a + g) - g
  in.model_slope = 0.5;
  const CommandGain doubled = command_gain(in);
  EXPECT_NEAR(doubled.thrust_scale, 0.5 * right.thrust_scale, 1e-9);
  EXPECT_NEAR(doubled.roll_pitch_gain(), 1.0, 0.03);
  EXPECT_NEAR(doubled.suggested_slope(), 0.5, 0.02);
}

TEST(CommandGain, SaturatedCommandsAndShortLogsAreNotMeasured) {
  std::mt19937 rng(5);
  CommandGainInput in = synthetic(0.6, 0.04, 30, rng);
  std::fill(in.commands.begin(), in.commands.end(), 1.0);
  const CommandGain g = command_gain(in);
  EXPECT_FALSE(g.measured);
  EXPECT_NE(g.why_not.find("saturation"), std::string::npos) << g.why_not;
  EXPECT_FALSE(g.slope_looks_off());
  const CommandGain short_log = command_gain(synthetic(0.6, 0.04, 1, rng));
  EXPECT_FALSE(short_log.measured);
}

TEST(CommandGain, SplitByFlightKeepsEachFlightsRows) {
  std::mt19937 rng(6);
  const CommandGainInput in = synthetic(0.6, 0.04, 30, rng);
  const auto parts = split_by_flight(in, {0.0, 100.0});
  ASSERT_EQ(parts.size(), 2u);
  EXPECT_EQ(parts[0].t.size() + parts[1].t.size(), in.t.size());
  EXPECT_EQ(parts[1].model.size(), 6 * parts[1].t.size());
  EXPECT_EQ(parts[1].commands.size(), 4 * parts[1].t.size());
  EXPECT_NEAR(command_gain(parts[1]).roll_pitch_gain(), 0.6, 0.03);
}

// A closed-loop flight of the NanoBench airframe (its motors at 0.6 of the stock map's
// slope about the hover command 0.86; the thrust constant set so that it hovers there),
// measured through the stock model and through its own. The answer is the slope the
// vehicle file was flown with, not one the check was tuned to: 0.6 against the stock map,
// 1 against its own.
TEST(CommandGain, RecoversTheMotorMapSlopeOfAGeneratedClosedLoopFlight) {
  const fs::path dir = fs::temp_directory_path() / "quadgen_command_gain";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string log = (dir / "flight.csv").string();
  const std::string sim = std::string(QUADGEN_BINARY) + " simulate " + test::source_path("vehicles/crazyflie21_nanobench.yaml") +
                          " --closed-loop --duration 40 --seed 2 --set c_t=0.0139 --excitation 0.3"
                          " --gyro-noise 0.01 --accel-noise 0.05 --out " + log + " > " + (dir / "sim.log").string() + " 2>&1";
  ASSERT_EQ(std::system(sim.c_str()), 0) << sim;
  const auto measure = [&](runtime::DynamicModel& model, const std::string& vehicle_file) {
    const Vehicle v = load_vehicle(test::source_path(vehicle_file));
    std::vector<std::string> rotors;
    for (const auto& r : v.rotors) rotors.push_back(r.name);
    const fit::Flight flight = fit::load_flight(runtime::read_csv(log), rotors, {});
    std::vector<double> p = model.params();
    p[model.param_index("c_t")] = 0.0139;  // the flight's thrust constant
    model.set_params(p);
    const fit::EquationErrorModel ee(model, flight, /*use_accelerometer=*/false);
    std::vector<double> residual;
    ee.all_channels(p.data(), residual);
    return command_gain(command_gain_input(ee, residual, v, p[model.param_index("g")], false));
  };
  runtime::CompiledModel<quadgen_generated::crazyflie21::Model> stock;
  runtime::CompiledModel<quadgen_generated::crazyflie21_nanobench::Model> own;
  const CommandGain through_stock = measure(stock, "vehicles/crazyflie21.yaml");
  const CommandGain through_own = measure(own, "vehicles/crazyflie21_nanobench.yaml");
  ASSERT_TRUE(through_stock.measured) << through_stock.why_not;
  ASSERT_TRUE(through_own.measured) << through_own.why_not;
  EXPECT_NEAR(through_stock.hover_command, 0.86, 0.05);
  for (size_t a = 0; a < 2; ++a) {
    const auto& s = through_stock.axes[a].bands[CommandGain::kLeadBand];
    const auto& o = through_own.axes[a].bands[CommandGain::kLeadBand];
    std::cout << through_stock.axes[a].name << " at " << o.low_hz << "-" << o.high_hz << " Hz: through the stock map " << s.gain
              << " (r " << s.r << "), through its own " << o.gain << " (r " << o.r << ")\n";
    EXPECT_NEAR(s.gain, 0.6, 0.06) << through_stock.axes[a].name;
    EXPECT_NEAR(o.gain, 1.0, 0.06) << through_own.axes[a].name;
    EXPECT_GT(s.r, 0.9);
    EXPECT_NEAR(s.delay_s, 0.0, 0.011);  // the generated motors answer at once
  }
  EXPECT_TRUE(through_stock.slope_looks_off());
  EXPECT_NEAR(through_stock.suggested_slope(), 0.6, 0.06);
  EXPECT_FALSE(through_own.slope_looks_off());
}

// The check's limit, measured: a closed loop that answers a disturbance puts into the
// commands what opposes it, and the answer to the commands reads low where the controller
// acts. The stock Crazyflie (slope 1) flown with and without a random roll/pitch
// disturbance: without, every band reads 1; with it, the lowest band reads well below 1.
// So a gain below 1 alone does not tell a slope error from a disturbed closed loop
// (docs/crazyflie_evidence.md section 8; the lead says so).
TEST(CommandGain, ADisturbedClosedLoopReadsLowBelowTheControllersBandwidth) {
  const fs::path dir = fs::temp_directory_path() / "quadgen_command_gain_disturbed";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const Vehicle v = load_vehicle(test::source_path("vehicles/crazyflie21.yaml"));
  std::vector<std::string> rotors;
  for (const auto& r : v.rotors) rotors.push_back(r.name);
  const auto measure = [&](double disturbance) {
    const std::string log = (dir / ("flight_" + std::to_string(disturbance) + ".csv")).string();
    const std::string sim = std::string(QUADGEN_BINARY) + " simulate " + test::source_path("vehicles/crazyflie21.yaml") +
                            " --closed-loop --duration 40 --seed 2 --excitation 0.3 --gyro-noise 0.01 --accel-noise 0.05"
                            " --angular-disturbance " + std::to_string(disturbance) + " --out " + log + " > /dev/null 2>&1";
    EXPECT_EQ(std::system(sim.c_str()), 0) << sim;
    runtime::CompiledModel<quadgen_generated::crazyflie21::Model> model;
    const fit::Flight flight = fit::load_flight(runtime::read_csv(log), rotors, {});
    const fit::EquationErrorModel ee(model, flight, false);
    std::vector<double> residual;
    ee.all_channels(model.params().data(), residual);
    return command_gain(command_gain_input(ee, residual, v, model.params()[model.param_index("g")], false));
  };
  const CommandGain calm = measure(0), disturbed = measure(6);
  ASSERT_TRUE(calm.measured && disturbed.measured);
  for (size_t a = 0; a < 2; ++a) {
    for (const auto& b : calm.axes[a].bands) EXPECT_NEAR(b.gain, 1.0, 0.06) << calm.axes[a].name << " " << b.low_hz << " Hz";
    const double lowest = disturbed.axes[a].bands.back().gain;
    std::cout << disturbed.axes[a].name << ", disturbed: " << lowest << " below 2 Hz, "
              << disturbed.axes[a].bands[CommandGain::kLeadBand].gain << " at 4-8 Hz\n";
    EXPECT_LT(lowest, 0.85) << disturbed.axes[a].name;
  }
  EXPECT_FALSE(calm.slope_looks_off());
}
