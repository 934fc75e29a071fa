// The hidden-effect suite: closed-loop flights with an effect hidden in the "true" model
// (quadgen simulate --closed-loop), diagnosed end to end by the CLI; diagnosis.json must
// name the effect, estimate its parameters within tolerance with the truth inside the
// reported interval, find nothing in clean flights, report look-alikes as ambiguous when
// the flight cannot separate them, find two effects at once, and report an effect outside
// the catalogue as unexplained instead of naming a wrong cause.
//
// Magnitudes (docs/validation.md "Hidden-effect suite" cites where they come from): 8 % thrust loss on
// one rotor, 50 ms rotor lag, 25 ms delay, 1 cm CoG offset, rotor drag 2e-5, 1.8 m/s wind,
// blade flapping 2e-6 N s^2 (about 2 rad/s^2 of pitch per m/s), 1.7 deg attitude offset,
// 12 % thrust decay per minute, exponent 1.5 battery sag, ground effect with the true
// rotor radius, flying at 0.1-0.3 m.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <memory>
#include <tuple>
#include <sstream>
#include <string>
#include <vector>

#include <boost/math/distributions/chi_squared.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app/diagnose_job.hpp"
#include "app/extended_model.hpp"
#include "app/model_registry.hpp"
#include "output/numbers.hpp"
#include "output/sinks.hpp"
#include "derive/dynamics.hpp"
#include "derive/effects/effect_catalogue.hpp"
#include "derive/geometry.hpp"
#include "fit/log_reader.hpp"
#include "diagnose/candidate_search.hpp"
#include "diagnose/command_gain.hpp"
#include "diagnose/diagnosis_report.hpp"
#include "diagnose/flight_screening.hpp"
#include "diagnose/held_out_gain.hpp"
#include "diagnose/residual_analysis.hpp"
#include "diagnose/validation.hpp"
#include "diagnose/report_words.hpp"
#include "model/sha256.hpp"
#include "generated/finken3/model.hpp"
#include "runtime/dynamic_model.hpp"
#include "tests/estimate_shape.hpp"
#include "tests/shared_data.hpp"
#include "runtime/portable_random.hpp"

namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

struct HiddenCase {
  std::string name;
  std::string effects;                   // injected in the true model ("" = clean)
  std::map<std::string, double> truth;   // parameter -> value
  std::map<std::string, double> tolerance;  // parameter -> absolute tolerance
  std::string flight_flags;              // extra simulate flags
  unsigned seed = 1;
  std::string vehicle = "finken3";       // vehicles/<vehicle>.yaml
};

void PrintTo(const HiddenCase& c, std::ostream* os) { *os << c.name << " seed " << c.seed; }

std::string run(const std::string& cmd) {
  const int rc = std::system(cmd.c_str());
  return rc == 0 ? "" : "command failed (" + std::to_string(rc) + "): " + cmd;
}

std::string vehicle_file(const HiddenCase& c) { return std::string(QUADGEN_SOURCE_DIR) + "/vehicles/" + c.vehicle + ".yaml"; }

// Flies the case closed loop for `duration` seconds into dir/file.
fs::path fly(const HiddenCase& c, const fs::path& dir, const std::string& file, double duration = 60) {
  std::string sim = std::string(QUADGEN_BINARY) + " simulate " + vehicle_file(c) + " --closed-loop --duration " +
                    std::to_string(duration) + " --seed " + std::to_string(c.seed) +
                    " --gyro-noise 0.01 --accel-noise 0.05 --out " + (dir / file).string() + " " + c.flight_flags;
  if (!c.effects.empty()) sim += " --effects " + c.effects;
  // Every digit of the truth: std::to_string writes 6 decimals (1.1e-6 became 0.000001, and
  // the Crazyflie rotor-drag flight flew with 1e-6 while the test checked against 1.1e-6).
  for (const auto& [name, value] : c.truth) {
    std::ostringstream v;
    v << std::setprecision(17) << value;
    sim += " --set " + name + "=" + v.str();
  }
  EXPECT_EQ(run(sim + " > " + (dir / (file + ".log")).string() + " 2>&1"), "");
  return dir / file;
}

// Every candidate's evidence, recomputed here from what diagnosis.json reports beside it:
// the p-value from the likelihood-ratio statistic under the null it names (chi2 with dof
// degrees of freedom, or the chi-bar-square 0.5 chi2_0 + 0.5 chi2_1 of a neutral value on
// its bound), AIC's -statistic + 2 dof, one Bonferroni level alpha / (candidates considered)
// for all, and the first of the four gates it fails (significance, BIC, the held-out
// cost, a physically negligible size), none exactly when it is significant. A candidate
// whose fit failed has no evidence to check.
void expect_evidence_holds_together(const json& j) {
  ASSERT_TRUE(j.contains("selection") && !j["selection"].empty());
  const double alpha = 0.01, negligible = 2e-4;  // SearchOptions' defaults; these tests set neither
  // Every candidate considered, tested at a step or not (a refinement waits for what it refines).
  const size_t first_step = j["candidates_considered"].size();
  for (const auto& step : j["selection"])
    for (const auto& c : step["candidates"]) {
      const std::string why_not = c["why_not"];
      if (why_not.rfind("the fit failed", 0) == 0) continue;
      const double x = c["statistic"], p = c["p_value"], level = c["level"];
      const int dof = c["dof"];
      const bool bar = c["null_distribution"].get<std::string>().rfind("chi-bar-square", 0) == 0;
      const auto upper = [](double s, int k) {
        return s <= 0 ? 1.0 : boost::math::cdf(boost::math::complement(boost::math::chi_squared(k), s));
      };
      const double expected = bar && x > 0 ? 0.5 * upper(x, 1) : upper(x, std::max(1, dof));
      EXPECT_NEAR(p, expected, 1e-12 + 1e-9 * expected) << c["effect"] << " " << c["null_distribution"];
      EXPECT_NEAR(c["delta_aic"].get<double>(), -x + 2.0 * dof, 1e-9 * (1 + std::fabs(x))) << c["effect"];
      EXPECT_NEAR(level * static_cast<double>(first_step), alpha, 1e-15) << c["effect"];
      const bool relevant = c["size_fraction_of_g"].get<double>() >= negligible ||
                            c["size_fraction_of_rotation_scale"].get<double>() >= negligible;
      std::string gate;  // the first gate failed, as the search words it
      if (!(p < level)) gate = "not significant";
      else if (!(c["delta_bic"].get<double>() < 0)) gate = "BIC does not improve";
      else if (!(c["validation_cost_after"].get<double>() < c["validation_cost_before"].get<double>()))
        gate = "no gain on the validation part";
      else if (!relevant) gate = "physically negligible size";
      EXPECT_EQ(why_not.substr(0, gate.size()), gate) << c.dump(1);
      EXPECT_EQ(why_not.empty(), gate.empty()) << c.dump(1);
      EXPECT_EQ(c["significant"].get<bool>(), gate.empty()) << c.dump(1);
    }
}

// Diagnoses a log (or several, space-separated) into dir/out; returns diagnosis.json.
json diagnose_log(const std::string& vehicle, const fs::path& log, const fs::path& dir) {
  EXPECT_EQ(run(std::string(QUADGEN_BINARY) + " diagnose " + vehicle + " " + log.string() + " --out " + (dir / "out").string() +
                " > " + (dir / "diagnose.log").string() + " 2>&1"),
            "");
  std::ifstream in(dir / "out" / "diagnosis.json");
  EXPECT_TRUE(in.good()) << "no diagnosis.json in " << dir;
  json j;
  if (in.good()) in >> j;
  for (const char* f : {"report.html", "extended_model.hpp", "fitted_parameters.yaml"})
    EXPECT_TRUE(fs::exists(dir / "out" / f)) << f;
  // Every plotted series is also data a Python or MATLAB user can load: a CSV beside each plot.
  int tables = 0;
  for (const auto& e : fs::directory_iterator(dir / "out")) {
    if (e.path().extension() == ".csv") ++tables;
    if (e.path().extension() == ".svg") {
      EXPECT_TRUE(fs::exists(fs::path(e.path()).replace_extension(".csv"))) << e.path() << " has no CSV beside it";
      // and a caption in the report that says what to look for in it
      EXPECT_NE(quadgen::diagnose::what_to_look_for(e.path().filename().string()), "") << e.path();
    }
  }
  EXPECT_GE(tables, 3);
  expect_evidence_holds_together(j);
  return j;
}

fs::path fresh_directory(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// Flies the case and diagnoses it; returns diagnosis.json.
json diagnose(const HiddenCase& c) {
  const fs::path dir = fresh_directory("quadgen_hidden_" + c.name + "_" + std::to_string(c.seed));
  return diagnose_log(vehicle_file(c), fly(c, dir, "flight.csv"), dir);
}

std::vector<std::string> named(const json& j) {
  std::vector<std::string> out;
  for (const auto& f : j["findings"]) out.push_back(f["effect"]);
  return out;
}

// The named effect's estimate of a parameter: within the tolerance of the truth, the truth
// inside its closed interval.
void expect_estimate(const json& j, const std::string& effect, const std::string& name, double truth, double tolerance) {
  const json* ps = nullptr;
  for (const auto& f : j["findings"])
    if (f["effect"] == effect) ps = &f["parameters"];
  ASSERT_TRUE(ps && ps->contains(name)) << effect << " " << name << " not among " << j["findings"].dump(1);
  const json& e = (*ps)[name];
  EXPECT_TRUE(quadgen::test::has_estimate_shape(e)) << name;
  EXPECT_NEAR(e["value"].get<double>(), truth, tolerance) << name;
  const json& ci = e["ci95"];
  ASSERT_TRUE(ci[0].is_number() && ci[1].is_number()) << name << " interval open: " << ci.dump();
  EXPECT_LE(ci[0].get<double>(), truth) << name << " " << ci.dump();
  EXPECT_GE(ci[1].get<double>(), truth) << name << " " << ci.dump();
}

// Every free parameter of the final fit has a standard error and one interval: a named
// effect's its finding's, any other the Wald interval value +- 1.96 standard errors. The
// errors are checked against two independent things: each named parameter's profile-
// likelihood interval (refits, not the curvature), whose width 2 x 1.96 errors must match;
// and the base parameters' truth (the vehicle file's values, which the flight was simulated
// with), which their intervals must hold.
void expect_final_fit_intervals(const json& j, const HiddenCase& c) {
  const quadgen::Vehicle v = quadgen::load_vehicle(vehicle_file(c));
  const json& fits = j["final_fit"];
  for (const auto& [name, e] : fits.items()) {
    ASSERT_TRUE(e.contains("standard_error") && e.contains("interval_method")) << name;
    // A base parameter off its bounds is determined by these flights: it has its Wald interval.
    if (name.find('.') == std::string::npos && !e["at_bound"].get<bool>()) EXPECT_EQ(e["interval_method"], "wald") << name;
    if (e["interval_method"] != "wald") continue;
    const double value = e["value"], se = e["standard_error"], lower = e["ci95"][0], upper = e["ci95"][1];
    EXPECT_GT(se, 0) << name;
    EXPECT_NEAR(upper - value, 1.959963984540054 * se, 1e-9 * std::fabs(value) + 1e-12 * se) << name;
    EXPECT_NEAR(value - lower, upper - value, 1e-9 * (std::fabs(value) + upper - value)) << name;
    if (name.find('.') == std::string::npos && v.params.count(name)) {
      const double truth = quadgen::param(v, name).nominal;
      EXPECT_LE(lower, truth) << name << " " << e.dump();
      EXPECT_GE(upper, truth) << name << " " << e.dump();
    }
  }
  for (const auto& f : j["findings"])
    for (const auto& [name, e] : f["parameters"].items()) {
      // A motor gain's reference rotor is held (not in final_fit), an open side has no width.
      if (e.value("interval_method", "") != "profile" || !fits.contains(name)) continue;
      if (!e["ci95"][0].is_number() || !e["ci95"][1].is_number()) continue;
      const json& fitted = fits[name];
      EXPECT_EQ(fitted["interval_method"], "profile") << name;
      EXPECT_EQ(fitted["ci95"], e["ci95"]) << name << ": one parameter, one interval in a file";
      const double profile_width = e["ci95"][1].get<double>() - e["ci95"][0].get<double>();
      const double wald_width = 2 * 1.959963984540054 * fitted["standard_error"].get<double>();
      EXPECT_NEAR(wald_width / profile_width, 1.0, 0.05) << name << ": standard error " << fitted.dump() << ", profile " << e.dump();
    }
}

class HiddenEffect : public ::testing::TestWithParam<HiddenCase> {};

TEST_P(HiddenEffect, IsNamedWithItsParameters) {
  const HiddenCase& c = GetParam();
  const json j = diagnose(c);
  ASSERT_TRUE(j.contains("findings"));
  ASSERT_EQ(named(j), std::vector<std::string>{c.effects}) << j["findings"].dump(1) << j["ambiguous"].dump(1);
  for (const auto& [name, truth] : c.truth) expect_estimate(j, c.effects, name, truth, c.tolerance.at(name));
  const json& gain = j["findings"][0]["gain"];
  EXPECT_TRUE(gain["before"].is_number() && gain["after"].is_number());
  for (const char* fit : {"base_fit", "final_fit", "airframe_fit"})
    for (const auto& [name, e] : j[fit].items()) EXPECT_TRUE(quadgen::test::has_estimate_shape(e)) << fit << " " << name;
  for (const auto& name : j["parameters_at_bounds"]) EXPECT_TRUE(j["final_fit"].contains(name.get<std::string>())) << name;
  expect_final_fit_intervals(j, c);
}

std::vector<HiddenCase> single_effects() {
  const std::string excite = "--excitation 0.2";  // separates lag from delay
  std::vector<HiddenCase> base = {
      {"motor_gain", "motor_gain", {{"motor_gain.C", -0.08}}, {{"motor_gain.C", 0.01}}, ""},
      {"motor_lag", "motor_lag", {{"motor_lag.tau", 0.05}}, {{"motor_lag.tau", 0.01}}, excite},
      {"input_delay", "input_delay", {{"input_delay.seconds", 0.025}}, {{"input_delay.seconds", 0.005}}, excite},
      {"cog_offset", "cog_offset", {{"cog_offset.x", 0.01}, {"cog_offset.y", -0.005}},
       {{"cog_offset.x", 0.002}, {"cog_offset.y", 0.002}}, ""},
      {"rotor_drag", "rotor_drag", {{"rotor_drag.k", 2e-5}}, {{"rotor_drag.k", 4e-6}}, ""},
      {"blade_flapping", "blade_flapping", {{"blade_flapping.k", 2e-6}}, {{"blade_flapping.k", 4e-7}}, ""},
      {"wind", "wind", {{"wind.x", 1.5}, {"wind.y", -1.0}}, {{"wind.x", 0.4}, {"wind.y", 0.4}}, ""},
      {"attitude_bias", "attitude_bias", {{"attitude_bias.roll", 0.03}, {"attitude_bias.pitch", -0.02}},
       {{"attitude_bias.roll", 0.005}, {"attitude_bias.pitch", 0.005}}, ""},
      {"thrust_decay", "thrust_decay", {{"thrust_decay.rate", 0.002}}, {{"thrust_decay.rate", 3e-4}}, ""},
      {"battery_sag", "battery_sag", {{"battery_sag.exponent", 1.5}}, {{"battery_sag.exponent", 0.2}}, ""},
      {"ground_effect", "ground_effect", {{"ground_effect.radius", 0.0635}}, {{"ground_effect.radius", 0.02}},
       "--height 0.2 --height-amplitude 0.1"},  // low and varied enough for the held-out prediction to gain
      // The size blade-element theory gives a small rotor (derive/effects/inflow.cpp).
      {"inflow", "inflow", {{"inflow.k", 3.0}}, {{"inflow.k", 0.6}}, ""},
  };
  std::vector<HiddenCase> all;
  for (unsigned seed : {1u, 2u})
    for (HiddenCase c : base) {
      c.seed = seed;
      all.push_back(c);
    }
  return all;
}

INSTANTIATE_TEST_SUITE_P(Catalogue, HiddenEffect, ::testing::ValuesIn(single_effects()),
                         [](const auto& info) { return info.param.name + "_seed" + std::to_string(info.param.seed); });

// Motors that follow a command at different speeds (issue: "per-motor lag where the data
// support it"): motor C's time constant 80 % longer than the others' 50 ms. The spread
// scales motor_lag's time constant, so both are named, with the truth inside each interval
// and the motors that do not differ within theirs of the reference. A flight with one lag
// for all (HiddenEffect motor_lag) names no spread. Before the rotor-speed filter of the
// equation error took each rotor's own time constant, this flight named the lag alone and
// carried the spread as ambiguous with motor gains (it acted as a gain there).
class HiddenLagSpread : public ::testing::TestWithParam<unsigned> {};
TEST_P(HiddenLagSpread, IsNamedBesideTheLagWithEachMotorsValue) {
  HiddenCase c{"motor_lag_spread", "motor_lag,motor_lag_spread",
               {{"motor_lag.tau", 0.05}, {"motor_lag_spread.C", 0.8}}, {}, "--excitation 0.2", GetParam()};
  const json j = diagnose(c);
  std::vector<std::string> names = named(j);
  std::sort(names.begin(), names.end());
  ASSERT_EQ(names, (std::vector<std::string>{"motor_lag", "motor_lag_spread"})) << j["findings"].dump(1)
                                                                                << j["ambiguous"].dump(1);
  expect_estimate(j, "motor_lag", "motor_lag.tau", 0.05, 0.005);
  expect_estimate(j, "motor_lag_spread", "motor_lag_spread.C", 0.8, 0.1);
  for (const char* other : {"motor_lag_spread.B", "motor_lag_spread.D"})
    expect_estimate(j, "motor_lag_spread", other, 0.0, 0.05);
}
INSTANTIATE_TEST_SUITE_P(Seeds, HiddenLagSpread, ::testing::Values(1u, 2u));

// False-positive control: flights of the base model itself.
class CleanFlight : public ::testing::TestWithParam<unsigned> {};
TEST_P(CleanFlight, GivesNoFinding) {
  const json j = diagnose({"clean", "", {}, {}, "", GetParam()});
  EXPECT_TRUE(j["findings"].empty()) << j["findings"].dump(1);
  EXPECT_TRUE(j["ambiguous"].empty()) << j["ambiguous"].dump(1);
  EXPECT_TRUE(j["unexplained"].empty()) << j["unexplained"].dump(1);
  // Nor a stand-in, and the extended model is the base model (helper-126: a spurious stand-in
  // carried into the extended model would have passed).
  EXPECT_TRUE(j["stand_ins"].empty()) << j["stand_ins"].dump(1);
  EXPECT_TRUE(j["extended_model"]["effects"].empty()) << j["extended_model"].dump(1);
  // Nor a term beyond the catalogue: every channel examined, none proposed.
  ASSERT_EQ(j["discovered_terms"].size(), 6u);
  for (const auto& t : j["discovered_terms"]) EXPECT_FALSE(t["proposed"].get<bool>()) << t.dump(1);
  EXPECT_FALSE(j["discovered_terms_gain"]["measured"].get<bool>());
}
INSTANTIATE_TEST_SUITE_P(Seeds, CleanFlight, ::testing::Values(1u, 2u, 3u));

bool ambiguous_between(const json& j, const std::string& a, const std::string& b) {
  for (const auto& amb : j["ambiguous"]) {
    const auto& e = amb["effects"];
    if ((e[0] == a && e[1] == b) || (e[0] == b && e[1] == a)) return !amb["separating_manoeuvre"].get<std::string>().empty();
  }
  return false;
}

// Hovering at one heading, an attitude offset and a steady wind both need the same
// constant horizontal force: not separable, so not named.
TEST(LookAlikes, AttitudeBiasAndWindAmbiguousInAFixedHeadingHover) {
  const json j = diagnose({"bias_hover", "attitude_bias", {{"attitude_bias.roll", 0.03}}, {}, "--amplitude 0 --height-amplitude 0 --yaw-amplitude 0", 1});
  EXPECT_TRUE(ambiguous_between(j, "attitude_bias", "wind")) << j["ambiguous"].dump(1) << j["findings"].dump(1);
  EXPECT_TRUE(j["findings"].empty()) << j["findings"].dump(1);
}

// In a level hover at constant thrust a weak motor's roll/pitch torque is what a CoG
// offset gives; the regular flight (thrust and heading changes) separates them (above).
TEST(LookAlikes, MotorGainAndCogOffsetAmbiguousInAHover) {
  const json j = diagnose({"gain_hover", "motor_gain", {{"motor_gain.C", -0.08}}, {}, "--amplitude 0 --height-amplitude 0 --yaw-amplitude 0", 1});
  EXPECT_TRUE(ambiguous_between(j, "motor_gain", "cog_offset")) << j["ambiguous"].dump(1) << j["findings"].dump(1);
  EXPECT_TRUE(j["findings"].empty()) << j["findings"].dump(1);
}

// Five motor gains of a hexacopter copy a CoG offset's torque at every thrust level and under
// every command of its mixer, and still fit a weak motor besides: the offset adds nothing
// beside them (the reviewer's flight: dropped by the backward pass at p = 0.116, and gains of
// +20 % and +27 % named with 0.3 % wide intervals). Either both are named, each with the
// truth in its interval, or the pair is reported ambiguous and no motor gain is named.
TEST(LookAlikes, HexacopterMotorGainsDoNotStandForACogOffsetUnsaid) {
  const HiddenCase c{"hexa_gain_cog", "motor_gain,cog_offset", {{"motor_gain.R5", -0.06}, {"cog_offset.x", 0.015}}, {},
                     "--pose-noise 1e-3", 3, "hexa_plus"};
  const json j = diagnose(c);
  const auto n = named(j);
  const bool gain_named = std::count(n.begin(), n.end(), "motor_gain") > 0;
  const bool cog_named = std::count(n.begin(), n.end(), "cog_offset") > 0;
  if (gain_named && cog_named) {
    expect_estimate(j, "cog_offset", "cog_offset.x", 0.015, 0.002);
    expect_estimate(j, "motor_gain", "motor_gain.R5", -0.06, 0.01);
  } else {
    EXPECT_FALSE(gain_named) << j["findings"].dump(1);
    EXPECT_TRUE(ambiguous_between(j, "motor_gain", "cog_offset")) << j["ambiguous"].dump(1);
    // A CoG offset named here must not carry the weak motor's torque (helper-126: unchecked).
    if (cog_named) expect_estimate(j, "cog_offset", "cog_offset.x", 0.015, 0.002);
  }
}

// The same vehicle, excited: the pair separates, but the weak motor failed the open-loop test
// (rollouts that tilt 0.8 rad in 0.5 s say little) and was taken out, and the CoG offset took
// up its torque: 13.7 mm [13.6, 13.8] was named for 15 mm (helper-41's finding). A named value
// must not hold only without a suspect the training data want: the suspect is carried and the
// offset's interval holds the truth, or the offset is not named.
TEST(LookAlikes, ASuspectedWeakMotorDoesNotBiasANamedCogOffset) {
  const HiddenCase c{"hexa_gain_cog_excited", "motor_gain,cog_offset",
                     {{"motor_gain.R5", -0.06}, {"cog_offset.x", 0.015}}, {}, "--pose-noise 1e-3 --excitation 0.2", 3,
                     "hexa_plus"};
  const json j = diagnose(c);
  const auto n = named(j);
  if (std::count(n.begin(), n.end(), "cog_offset")) expect_estimate(j, "cog_offset", "cog_offset.x", 0.015, 0.002);
  if (std::count(n.begin(), n.end(), "motor_gain")) {
    expect_estimate(j, "motor_gain", "motor_gain.R5", -0.06, 0.01);
  } else {
    bool carried = false;
    for (const auto& x : j["suspected"])
      if (x["effect"] == "motor_gain") carried = x["carried_beside"].is_object() && x["carried_beside"]["effect"] == "cog_offset";
    EXPECT_TRUE(carried || ambiguous_between(j, "motor_gain", "cog_offset")) << j["suspected"].dump(1);
  }
  const auto model = j["extended_model"]["effects"].get<std::vector<std::string>>();
  EXPECT_TRUE(std::count(model.begin(), model.end(), "motor_gain")) << j["extended_model"].dump(1);
}

// One ambiguity does not end the search: in a fixed-heading hover the attitude offset is
// reported with its look-alike (wind), the model carries one of them, and a distinct third
// effect (a rotor lag, told from a delay by the rate excitation) is still found and named.
TEST(LookAlikes, AmbiguousPairDoesNotHideADistinctEffect) {
  const json j = diagnose({"bias_lag_hover", "attitude_bias,motor_lag",
                           {{"attitude_bias.roll", 0.03}, {"motor_lag.tau", 0.05}}, {},
                           "--amplitude 0 --height-amplitude 0 --yaw-amplitude 0 --excitation 0.2", 1});
  EXPECT_TRUE(ambiguous_between(j, "attitude_bias", "wind")) << j["ambiguous"].dump(1) << j["findings"].dump(1);
  EXPECT_EQ(named(j), std::vector<std::string>{"motor_lag"}) << j["findings"].dump(1) << j["suspected"].dump(1);
  expect_estimate(j, "motor_lag", "motor_lag.tau", 0.05, 0.01);  // the single-effect case's tolerance
  bool outcome_ambiguous = false;
  for (const auto& step : j["selection"]) outcome_ambiguous = outcome_ambiguous || step["outcome"] == "ambiguous";
  EXPECT_TRUE(outcome_ambiguous) << j["selection"].dump(1).substr(0, 2000);
}

// A pure input delay in a flight without rate excitation: a lag of the rotors looks the same
// there, so the two are reported as look-alikes with the manoeuvre that separates them, and
// the model carries one of them - never delay plus a small lag (issue 14, item 6).
TEST(LookAlikes, PureDelayWithoutExcitationIsNotDelayPlusLag) {
  const json j = diagnose({"delay_no_excitation", "input_delay", {{"input_delay.seconds", 0.025}}, {}, "", 1});
  EXPECT_TRUE(ambiguous_between(j, "input_delay", "motor_lag") || named(j) == std::vector<std::string>{"input_delay"})
      << j["ambiguous"].dump(1) << j["findings"].dump(1);
  for (const auto& f : j["findings"]) EXPECT_NE(f["effect"], "motor_lag") << j["findings"].dump(1);
  const auto carried = j["extended_model"]["effects"].get<std::vector<std::string>>();
  EXPECT_FALSE(std::count(carried.begin(), carried.end(), "input_delay") &&
               std::count(carried.begin(), carried.end(), "motor_lag"))
      << j["extended_model"].dump(1);
}

// Rotor drag acting at the hubs, 50 mm above the CoG: a force and the moment of that force.
// Both halves are named, with their own coefficients, and their ratio - the point of action -
// comes out as the hub height instead of the force being dropped for conflicting with the gyro.
TEST(LookAlikes, RotorDragAboveTheCogIsForceAndMomentWithItsPointOfAction) {
  const double k = 2e-5, height = 0.05;
  const json j = diagnose({"drag_at_hub", "rotor_drag,blade_flapping",
                           {{"rotor_drag.k", k}, {"blade_flapping.k", k * height}}, {}, "", 1});
  auto sorted = named(j);
  std::sort(sorted.begin(), sorted.end());
  ASSERT_EQ(sorted, (std::vector<std::string>{"blade_flapping", "rotor_drag"})) << j["findings"].dump(1);
  const json& p = j["point_of_action"];
  ASSERT_TRUE(p.is_object()) << j.dump(1).substr(0, 1000);
  const json& h = p["height_above_cog"];
  ASSERT_TRUE(quadgen::test::has_estimate_shape(h));
  EXPECT_EQ(h["unit"], "m");
  EXPECT_NEAR(h["value"].get<double>(), height, 0.01) << p.dump(1);
  ASSERT_TRUE(h["ci95"][0].is_number() && h["ci95"][1].is_number()) << p.dump(1);
  EXPECT_LE(h["ci95"][0].get<double>(), height) << p.dump(1);
  EXPECT_GE(h["ci95"][1].get<double>(), height) << p.dump(1);
  EXPECT_NE(p["headline"].get<std::string>().find("50 mm above"), std::string::npos) << p.dump(1);
}

// Negligible is relative to the vehicle: rotor drag of a 30 g Crazyflie at its published
// size (linear drag ~1e-2 N s/m for the airframe, i.e. k ~ 1.1e-6 per rad/s of summed rotor
// speed near 9,000 rad/s) is a real force for it, and is named.
TEST(Negligibility, CrazyflieRotorDragAtItsPublishedSizeIsNamed) {
  HiddenCase c{"cf_rotor_drag", "rotor_drag", {{"rotor_drag.k", 1.1e-6}}, {}, "--amplitude 1.2", 1, "crazyflie21"};
  const json j = diagnose(c);
  EXPECT_EQ(named(j), std::vector<std::string>{"rotor_drag"}) << j["findings"].dump(1) << j["suspected"].dump(1)
                                                               << j["selection"].dump(1).substr(0, 3000);
  expect_estimate(j, "rotor_drag", "rotor_drag.k", 1.1e-6, 0.2 * 1.1e-6);  // 20 %, as for the FINken's 2e-5
}

// Two effects at once: forward selection finds both.
TEST(TwoEffects, MotorGainAndThrustDecayBothFound) {
  const json j = diagnose({"two", "motor_gain,thrust_decay", {{"motor_gain.C", -0.08}, {"thrust_decay.rate", 0.002}}, {}, "", 1});
  auto n = named(j);
  std::sort(n.begin(), n.end());
  EXPECT_EQ(n, (std::vector<std::string>{"motor_gain", "thrust_decay"})) << j["findings"].dump(1);
  // Each with its own value, not one absorbing the other (the single-effect tolerances).
  expect_estimate(j, "motor_gain", "motor_gain.C", -0.08, 0.01);
  expect_estimate(j, "thrust_decay", "thrust_decay.rate", 0.002, 3e-4);
}

// A search stopped by --max-effects says what was still significant: with one step allowed,
// the second of two hidden effects is listed (before, nothing showed it had been left).
TEST(TwoEffects, WhatTheLimitLeftOutIsReported) {
  const HiddenCase c{"two_limit", "motor_gain,thrust_decay", {{"motor_gain.C", -0.08}, {"thrust_decay.rate", 0.002}}, {}, "", 1};
  const fs::path dir = fresh_directory("quadgen_two_limit");
  const fs::path log = fly(c, dir, "flight.csv");
  const json j = diagnose_log(vehicle_file(c), log.string() + " --max-effects 1", dir);
  ASSERT_EQ(j["selection"].size(), 1u);
  const std::string taken = j["selection"][0]["selected"];
  const std::string other = taken == "motor_gain" ? "thrust_decay" : "motor_gain";
  bool listed = false;
  for (const auto& e : j["left_at_max_effects"]) listed = listed || e["effect"] == other;
  EXPECT_TRUE(listed) << taken << " taken; left: " << j["left_at_max_effects"].dump(1);
  std::ifstream printed(dir / "diagnose.log");
  const std::string text((std::istreambuf_iterator<char>(printed)), {});
  const size_t line = text.find("the search stopped with its model full (--max-effects 1: the effects it selected, before the "
                                "held-out tests); still significant in its last step:");
  ASSERT_NE(line, std::string::npos) << text;
  EXPECT_NE(text.substr(line, text.find('\n', line) - line).find(" " + other + " (p "), std::string::npos) << text;
  // Without the limit nothing is left over.
  const fs::path dir2 = fresh_directory("quadgen_two_limit_none");
  EXPECT_TRUE(diagnose_log(vehicle_file(c), log, dir2)["left_at_max_effects"].empty());
}

// A tether pulling the vehicle back is in no effect's vocabulary: the diagnosis must say
// that something is left unexplained, and where, rather than name a wrong cause.
TEST(OutOfCatalogue, TetherIsReportedAsUnexplained) {
  const json j = diagnose({"tether", "", {}, {}, "--tether 0.15", 1});
  EXPECT_TRUE(j["findings"].empty()) << j["findings"].dump(1);
  ASSERT_FALSE(j["unexplained"].empty());
  bool horizontal = false;
  for (const auto& u : j["unexplained"]) horizontal = horizontal || u["channel"] == "ax_world" || u["channel"] == "ay_world";
  EXPECT_TRUE(horizontal) << j["unexplained"].dump(1);
}

// A yaw acceleration in proportion to forward body speed is no catalogue effect but lies in
// the term discovery's vocabulary: nothing is named, the rdot term is proposed alone with the
// truth in its interval, and the model with it is written. (Seed 1. On seed 2 the base fit's
// yaw-torque factor kappa absorbs most of it through the yaw controller's commands: what is
// left, slope 0.17 of the 1.0, is reported as unexplained and not proposed.)
TEST(OutOfCatalogue, YawWithForwardSpeedIsProposedAsATermNotNamed) {
  const HiddenCase c{"yaw_per_speed", "", {}, {}, "--yaw-per-speed 1.0", 1};
  const fs::path dir = fresh_directory("quadgen_hidden_yaw_per_speed");
  const json j = diagnose_log(vehicle_file(c), fly(c, dir, "flight.csv"), dir);
  EXPECT_TRUE(j["findings"].empty()) << j["findings"].dump(1);
  int proposed = 0;
  for (const auto& t : j["discovered_terms"]) {
    if (!t["proposed"].get<bool>()) continue;
    ++proposed;
    ASSERT_EQ(t["channel"], "rdot") << t.dump(1);
    ASSERT_EQ(t["coefficients"].size(), 1u) << t.dump(1);
    EXPECT_EQ(t["coefficients"][0]["regressor"], "v_bx");
    EXPECT_TRUE(quadgen::test::has_estimate_shape(t["coefficients"][0]));
    EXPECT_LT(t["coefficients"][0]["ci95"][0].get<double>(), 1.0) << t.dump(1);
    EXPECT_GT(t["coefficients"][0]["ci95"][1].get<double>(), 1.0) << t.dump(1);
  }
  EXPECT_EQ(proposed, 1) << j["discovered_terms"].dump(1);
  EXPECT_TRUE(j["discovered_terms_gain"]["measured"].get<bool>());
  EXPECT_TRUE(fs::exists(dir / "out" / "discovered_model.hpp"));
}

// Bad input ends in one line and a non-zero exit, without outputs; an interrupted write
// leaves the previous diagnosis as it was.
TEST(DiagnoseInput, BadInputAndInterruptedWrite) {
  const fs::path dir = fs::temp_directory_path() / "quadgen_diagnose_input";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string bin = QUADGEN_BINARY, veh = std::string(QUADGEN_SOURCE_DIR) + "/vehicles/finken3.yaml";
  const std::string flight = (dir / "flight.csv").string(), out = (dir / "out").string();
  ASSERT_EQ(run(bin + " simulate " + veh + " --closed-loop --duration 12 --out " + flight + " > /dev/null 2>&1"), "");
  // A log shorter than the derivative window and the validation split need.
  {
    std::ifstream in(flight);
    std::ofstream shortlog(dir / "short.csv");
    std::string line;
    for (int i = 0; i < 25 && std::getline(in, line); ++i) shortlog << line << "\n";
  }
  const std::string err = (dir / "err.txt").string();
  // The refusal is one line, saying `why` where given.
  auto one_line_error = [&](const std::string& args, const std::string& why = "") {
    const int rc = std::system((bin + " diagnose " + args + " > /dev/null 2> " + err).c_str());
    std::ifstream in(err);
    const std::string text((std::istreambuf_iterator<char>(in)), {});
    EXPECT_NE(rc, 0) << args;
    const auto pos = text.find("quadgen: error: ");
    ASSERT_NE(pos, std::string::npos) << text;
    EXPECT_EQ(std::count(text.begin() + static_cast<long>(pos), text.end(), '\n'), 1) << text;
    EXPECT_NE(text.find(why), std::string::npos) << args << ": " << text;
  };
  one_line_error(veh + " " + (dir / "missing.csv").string() + " --out " + out);
  one_line_error(veh + " " + (dir / "short.csv").string() + " --out " + out);
  one_line_error(veh + " " + flight + " --out " + out + " --candidates motor_gain,nonsense");
  one_line_error(veh + " " + flight + " --out /proc/quadgen_cannot_write_here");
  // --airframe: a missing file, not JSON, JSON that is no diagnosis, a parameter the
  // vehicle's model lacks (with a hostile name), and several logs at once.
  const auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return (dir / name).string();
  };
  const std::string bad_names = write("names.json", R"({"airframe_fit": {"x\u001b[31m</td>": {"value": 1}},
                                                         "findings": [], "flight_parameters": []})");
  // Each refusal says its own reason (helper-126: the several logs' case, given the same log
  // twice and a refused file, was refused for those instead).
  const std::pair<std::string, std::string> airframes[] = {
      {(dir / "none.json").string(), ""},
      {write("text.json", "not json"), "not JSON"},
      {write("other.json", R"({"findings": []})"), "not a diagnosis.json of quadgen"},
      {bad_names, "is no parameter of this vehicle's model"}};
  for (const auto& [airframe, why] : airframes)
    one_line_error(veh + " " + flight + " --airframe " + airframe + " --out " + out, why);
  fs::copy_file(flight, dir / "flight_again.csv", fs::copy_options::overwrite_existing);
  one_line_error(veh + " " + flight + " " + (dir / "flight_again.csv").string() + " --airframe " +
                     write("airframe.json", R"({"airframe_fit": {}, "findings": [], "flight_parameters": []})") + " --out " + out,
                 "several logs are diagnosed jointly instead");
  EXPECT_FALSE(fs::exists(out));
  // A complete run, then one killed between writing and renaming.
  ASSERT_EQ(run(bin + " diagnose " + veh + " " + flight + " --out " + out + " > /dev/null 2>&1"), "");
  std::ifstream first(fs::path(out) / "diagnosis.json");
  const std::string before((std::istreambuf_iterator<char>(first)), {});
  const int rc = std::system(("QUADGEN_TEST_DIE_BEFORE_COMMIT=1 " + bin + " diagnose " + veh + " " + flight + " --out " + out +
                              " --max-effects 1 > /dev/null 2>&1").c_str());
  EXPECT_NE(rc, 0);
  std::ifstream again(fs::path(out) / "diagnosis.json");
  EXPECT_EQ(std::string((std::istreambuf_iterator<char>(again)), {}), before);
}

// Same flight, two processes: the same diagnosis.json (timing aside).
TEST(Determinism, SameFlightGivesTheSameDiagnosis) {
  const HiddenCase c{"determinism", "motor_gain", {{"motor_gain.B", 0.05}}, {}, "", 3};
  json a = diagnose(c);
  json b = diagnose(c);
  a.erase("timing_s");
  b.erase("timing_s");
  EXPECT_EQ(a.dump(), b.dump());
}

// One log from several: each next flight continues the previous one's clock after a 1 s
// gap (derivative windows do not cross a gap), as a log of two flights would.
void join_logs(const std::vector<fs::path>& parts, const fs::path& out) {
  std::ofstream o(out);
  double offset = 0, last = 0;
  for (size_t k = 0; k < parts.size(); ++k) {
    std::ifstream in(parts[k]);
    std::string line;
    std::getline(in, line);
    if (k == 0) o << line << "\n";
    while (std::getline(in, line)) {
      const size_t comma = line.find(',');
      const double t = std::stod(line.substr(0, comma)) + offset;
      last = t;
      std::ostringstream ts;
      ts.precision(10);
      ts << t;
      o << ts.str() << line.substr(comma) << "\n";
    }
    offset = last + 1.0;
  }
}

// A cause present only in the training part: it improves the training data, not the
// held-out part, so it is listed as suspected with the test it failed, never named. The
// log is 60 s with a weak rotor, then 26 s of the same vehicle without (the held-out 30 %).
TEST(Acceptance, CauseOnlyInTheTrainingPartIsSuspectedNotNamed) {
  const fs::path dir = fresh_directory("quadgen_training_only");
  const HiddenCase weak{"weak", "motor_gain", {{"motor_gain.C", -0.08}}, {}, "", 1};
  const HiddenCase clean{"clean", "", {}, {}, "", 2};
  join_logs({fly(weak, dir, "weak.csv", 60), fly(clean, dir, "clean.csv", 26)}, dir / "joined.csv");
  const json j = diagnose_log(vehicle_file(weak), dir / "joined.csv", dir);
  EXPECT_TRUE(named(j).empty()) << j["findings"].dump(1);
  bool suspected = false;
  for (const auto& x : j["suspected"])
    if (x["effect"] == "motor_gain") {
      suspected = true;
      EXPECT_NE(x["failed"].get<std::string>().find("held-out"), std::string::npos) << x["failed"];
    }
  EXPECT_TRUE(suspected) << j["suspected"].dump(1) << j["selection"].dump(1).substr(0, 3000);
  // The search's own route (judge_held_out_as_own_model): candidates whose screen under the
  // step's weights found no held-out gain are asked again under their own weights; here some
  // (a wind, an attitude bias standing in for the weak rotor) still find none, and each is
  // set aside as a suspect by the search itself, never named.
  int rejudged = 0;
  for (const auto& step : j["selection"])
    for (const auto& c : step["candidates"]) {
      if (!c["validation_rejudged_as_own_model"].get<bool>()) continue;
      ++rejudged;
      EXPECT_FALSE(c["significant"].get<bool>()) << c.dump(1);
      EXPECT_EQ(c["why_not"], "no gain on the validation part") << c.dump(1);
      EXPECT_GE(c["validation_cost_after"].get<double>(), c["validation_cost_before"].get<double>()) << c.dump(1);
      bool set_aside = false;
      for (const auto& x : j["suspected"])
        set_aside |= x["effect"] == c["effect"] &&
                     x["failed"].get<std::string>().find("improves the training data") != std::string::npos;
      EXPECT_TRUE(set_aside) << c["effect"] << " " << j["suspected"].dump(1);
    }
  EXPECT_GT(rejudged, 0) << j["selection"].dump(1).substr(0, 3000);
  // Each such suspect carries the values of a step where it had no held-out gain (the one
  // with the strongest evidence, which the search keeps), not profiled: its headline once
  // read zeros.
  for (const auto& x : j["suspected"]) {
    if (x["failed"].get<std::string>().find("improves the training data") == std::string::npos) continue;
    bool from_a_step = false;
    for (const auto& step : j["selection"])
      for (const auto& c : step["candidates"]) {
        if (c["effect"] != x["effect"] || c["why_not"] != "no gain on the validation part" ||
            c["estimates"].size() != x["parameters"].size())
          continue;
        bool same = true;
        for (const auto& [name, value] : c["estimates"].items())
          same = same && x["parameters"].contains(name) && x["parameters"][name]["value"] == value;
        from_a_step |= same;
      }
    EXPECT_TRUE(from_a_step) << x.dump(1);
    for (const auto& [name, p] : x["parameters"].items()) {
      EXPECT_TRUE(p["ci95"][0].is_null()) << name;
      EXPECT_EQ(p["interval_method"], "none") << name;
    }
  }
}

// The integrated autocorrelation time that discounts autocorrelated residuals in every
// likelihood-ratio test, against its closed form: an AR(1) series x_k = rho x_(k-1) + e_k has
// tau = 1 + 2 sum rho^k = (1 + rho) / (1 - rho), 9 for rho = 0.8; white noise has 1.
TEST(Acceptance, AutocorrelationTimeOfAnAr1SeriesIsItsClosedForm) {
  std::mt19937 rng(11);
  quadgen::runtime::Normal e(0.0, 1.0);
  const size_t n = 200000;
  std::vector<double> ar(n), white(n);
  double x = 0;
  for (size_t k = 0; k < n; ++k) {
    x = 0.8 * x + e(rng);
    ar[k] = x;
    white[k] = e(rng);
  }
  EXPECT_NEAR(quadgen::diagnose::integrated_autocorrelation_time(ar), 9.0, 0.05 * 9.0);
  EXPECT_NEAR(quadgen::diagnose::integrated_autocorrelation_time(white), 1.0, 0.02);
}

namespace {
// r_i = p x_i - y_i; residuals 0, 1 in channel 0, residuals 2, 3 in channel 1.
class TwoChannelLine : public quadgen::fit::ResidualModel {
 public:
  int num_residuals() const override { return 4; }
  void evaluate(const double* p, double* r, double* J) const override {
    for (int i = 0; i < 4; ++i) {
      r[i] = p[0] * x_[i] - y_[i];
      if (J) J[i] = x_[i];
    }
  }
  int channel_of(int residual) const override { return residual < 2 ? 0 : 1; }
  std::vector<std::string> channels() const override { return {"a", "b"}; }

 private:
  const double x_[4] = {1, 2, 1, 3}, y_[4] = {0, 1, 2, 1};
};

std::vector<quadgen::fit::FitParameter> line_at(double p) {
  quadgen::fit::FitParameter fp;
  fp.name = "p";
  fp.value = p;
  return {fp};
}
}  // namespace

// The second asking's comparison (judge_held_out_as_own_model): both models scored under
// sqrt(w_base w_own) per channel, here (sqrt(1*9), sqrt(4*1)) = (3, 2). By hand: at p = 0.5
// the residuals are 0.5, 0, -1.5, 0.5, so 9*0.25 + 0 + 4*2.25 + 4*0.25 = 12.25; at p = 1 they
// are 1, 1, -1, 2, so 9 + 9 + 4 + 16 = 38.
TEST(Acceptance, TheSecondAskingScoresBothModelsUnderTheGeometricMeanOfTheirWeights) {
  const TwoChannelLine m;
  const auto c = quadgen::diagnose::CandidateSearch::held_out_costs_between(m, line_at(0.5), {1, 4}, line_at(1.0), {9, 1});
  EXPECT_DOUBLE_EQ(c.before, 12.25);
  EXPECT_DOUBLE_EQ(c.after, 38.0);
  // Fair to both: swapping the models' roles swaps the costs.
  const auto swapped = quadgen::diagnose::CandidateSearch::held_out_costs_between(m, line_at(1.0), {9, 1}, line_at(0.5), {1, 4});
  EXPECT_DOUBLE_EQ(swapped.before, 38.0);
  EXPECT_DOUBLE_EQ(swapped.after, 12.25);
  // Under equal weights it is the plain weighted cost: weights (2, 1) give 4*0.25 + 2.25 + 0.25.
  const auto same = quadgen::diagnose::CandidateSearch::held_out_costs_between(m, line_at(0.5), {2, 1}, line_at(0.5), {2, 1});
  EXPECT_DOUBLE_EQ(same.before, 3.5);
  EXPECT_DOUBLE_EQ(same.after, 3.5);
}

// Replaces a log's battery voltage by vref (1 - rate t) GE(z) exp(sigma e(t)): the thrust
// scale of a thrust decay and a ground effect, as if the battery followed both, times a
// ripple e = sqrt(2) sin(2 pi t / 7 s) that the thrust does not have, with sigma = 0.9 x the
// spread of the ground-effect part. battery_sag then explains both effects at once, but
// only up to the ripple.
void design_battery_voltage(const fs::path& in, const fs::path& out, double rate, double radius) {
  std::ifstream f(in);
  std::string header, line;
  std::getline(f, header);
  std::vector<std::string> names;
  for (std::stringstream hs(header); std::getline(hs, line, ',');) names.push_back(line);
  const auto column = [&](const std::string& n) { return std::find(names.begin(), names.end(), n) - names.begin(); };
  const auto it = column("t"), iz = column("z"), iv = column("vbat");
  std::vector<std::vector<std::string>> rows;
  while (std::getline(f, line)) {
    rows.emplace_back();
    for (std::stringstream ls(line); std::getline(ls, header, ',');) rows.back().push_back(header);
  }
  const auto ground = [&](double z) { return 1 / (1 - std::pow(radius / (4 * std::max(z, 0.05)), 2)); };
  double sum = 0, sum2 = 0;
  for (const auto& r : rows) {
    const double g = std::log(ground(std::stod(r[iz])));
    sum += g, sum2 += g * g;
  }
  const double n = static_cast<double>(rows.size()), sigma = 0.9 * std::sqrt(std::max(0.0, sum2 / n - sum * sum / n / n));
  std::ofstream o(out);
  for (size_t i = 0; i < names.size(); ++i) o << (i ? "," : "") << names[i];
  o << "\n";
  for (auto& r : rows) {
    const double t = std::stod(r[it]), z = std::stod(r[iz]);
    const double e = std::sqrt(2.0) * std::sin(2 * M_PI * t / 7.0);
    std::ostringstream v;
    v << std::setprecision(10) << 4.0 * (1 - rate * t) * ground(z) * std::exp(sigma * e);  // finken3: vbat_ref 4 V
    r[iv] = v.str();
    for (size_t i = 0; i < r.size(); ++i) o << (i ? "," : "") << r[i];
    o << "\n";
  }
}

// An early pick that later ones make redundant is removed by the backward pass: the
// battery voltage is built to follow a thrust decay and a ground effect at once, so
// battery_sag explains most in step 1; thrust_decay and ground_effect, the true causes, come
// next, and against them battery_sag adds nothing.
TEST(BackwardPass, EarlyPickMadeRedundantIsRemoved) {
  const fs::path dir = fresh_directory("quadgen_redundant");
  const HiddenCase c{"redundant", "thrust_decay,ground_effect", {{"thrust_decay.rate", 0.0005}, {"ground_effect.radius", 0.0635}},
                     {}, "--height 0.2 --height-amplitude 0.1", 1};
  design_battery_voltage(fly(c, dir, "flight.csv"), dir / "designed.csv", 0.0005, 0.0635);
  const json j = diagnose_log(vehicle_file(c), dir / "designed.csv", dir);
  ASSERT_FALSE(j["selection"].empty());
  EXPECT_EQ(j["selection"][0]["selected"], "battery_sag") << j["selection"].dump(1).substr(0, 2000);
  bool removed = false;
  for (const auto& r : j["removed_by_backward_pass"])
    removed = removed || (r["effect"] == "battery_sag" && r["reason"].get<std::string>().find("no longer significant") == 0);
  EXPECT_TRUE(removed) << j["removed_by_backward_pass"].dump(1);
  auto n = named(j);
  std::sort(n.begin(), n.end());
  EXPECT_EQ(n, (std::vector<std::string>{"ground_effect", "thrust_decay"})) << j["findings"].dump(1);
  // Each finding says what it was compared with: with two findings, the other one's model
  // under its own weights, whether those settled; the extended model the same.
  for (const auto& f : j["findings"]) {
    EXPECT_EQ(f["compared_with"]["model"], "refitted under the weights of its own residuals") << f["compared_with"].dump();
    EXPECT_GE(f["compared_with"]["refits"].get<int>(), 1);
    EXPECT_TRUE(f["compared_with"]["weights_settled"].is_boolean());
  }
  EXPECT_GE(j["extended_model"]["weights"]["refits"].get<int>(), 1) << j["extended_model"].dump();
  // With the search limited to three effects the three picks fill the model; battery_sag's
  // place, given back by the backward pass, goes to a fourth step (until 2026-12-07 the limit
  // counted steps and the search ended there), which does not try battery_sag again.
  const fs::path dir3 = fresh_directory("quadgen_redundant_three");
  const json three = diagnose_log(vehicle_file(c) + " --max-effects 3", dir / "designed.csv", dir3);
  EXPECT_EQ(three["max_effects"], 3);
  ASSERT_GE(three["selection"].size(), 3u);
  std::vector<std::string> first_three;
  for (size_t k = 0; k < 3; ++k) first_three.push_back(three["selection"][k]["selected"]);
  std::sort(first_three.begin(), first_three.end());
  ASSERT_EQ(first_three, (std::vector<std::string>{"battery_sag", "ground_effect", "thrust_decay"}))
      << "the case no longer fills a model of three: " << three["selection"].dump(1).substr(0, 2000);
  ASSERT_EQ(three["removed_by_backward_pass"].size(), 1u) << three["removed_by_backward_pass"].dump(1);
  EXPECT_EQ(three["removed_by_backward_pass"][0]["effect"], "battery_sag");
  ASSERT_GE(three["selection"].size(), 4u) << "no step after the place was given back";
  for (size_t k = 3; k < three["selection"].size(); ++k) {
    for (const auto& cand : three["selection"][k]["candidates"]) EXPECT_NE(cand["effect"], "battery_sag") << k;
    const auto& model = three["selection"][k]["base_effects"];
    EXPECT_EQ(std::find(model.begin(), model.end(), "battery_sag"), model.end()) << model.dump();
  }
  auto named_three = named(three);
  std::sort(named_three.begin(), named_three.end());
  EXPECT_EQ(named_three, (std::vector<std::string>{"ground_effect", "thrust_decay"})) << three["findings"].dump(1);
  // The report says where a step's model lost an earlier pick.
  std::ifstream report(dir3 / "out" / "report.html");
  const std::string html((std::istreambuf_iterator<char>(report)), {});
  EXPECT_NE(html.find("; after the backward pass dropped battery_sag): "), std::string::npos);
}

// A removal's reason says "beside the other effects" only where the model keeps some: an
// effect dropped with nothing beside it but its own refinements (which go with it) was
// tested against the bare base model (until 2026-12-08 the words stood whenever the model
// held more than the effect, its refinements counted).
TEST(BackwardPass, ARemovalSaysBesideOtherEffectsOnlyWhereThereAreSome) {
  using quadgen::diagnose::no_longer_significant_reason;
  const std::string alone = no_longer_significant_reason({}, 0.3);
  EXPECT_EQ(alone.find("beside"), std::string::npos) << alone;
  EXPECT_EQ(alone.find("no longer significant ("), 0u) << alone;
  const std::string beside = no_longer_significant_reason({"rotor_drag"}, 0.3);
  EXPECT_NE(beside.find("beside the other effects of the final model ("), std::string::npos) << beside;
  EXPECT_NE(alone.find(quadgen::output::p_is(0.3)), std::string::npos) << alone;
}

// Several flights of one vehicle diagnosed jointly: the weak motor of two flights with
// different trajectories is named once, with one estimate that holds for both, and the
// end of each flight is held out.
// A steady wind of 1.8 m/s (the suite's case) passes every statistical test, but indoors it is not physics: a
// stand-in for something the model lacks. It stays in the extended model and is not named;
// the same flight flown "outdoors" names it.
TEST(Plausibility, SteadyWindIndoorsIsAStandInNotACause) {
  const fs::path dir = fresh_directory("quadgen_wind_indoors");
  const HiddenCase c{"wind", "wind", {{"wind.x", -1.0}, {"wind.y", 1.5}}, {}, "", 1};
  const fs::path log = fly(c, dir, "wind.csv", 60);
  for (const std::string where : {"indoor", "outdoor"}) {
    const fs::path out = dir / where;
    ASSERT_EQ(run(std::string(QUADGEN_BINARY) + " diagnose " + vehicle_file(c) + " " + log.string() +
                  " --candidates wind,motor_gain --environment " + where + " --out " + out.string() + " > " +
                  (dir / (where + ".log")).string() + " 2>&1"),
              "");
    std::ifstream in(out / "diagnosis.json");
    json j;
    in >> j;
    EXPECT_EQ(j["environment"], where);
    // The search saw the environment: the wind's evidence says it is implausible indoors only.
    ASSERT_FALSE(j["selection"].empty());
    const auto& first = j["selection"][0]["candidates"];
    const auto wind = std::find_if(first.begin(), first.end(), [](const json& c) { return c["effect"] == "wind"; });
    ASSERT_NE(wind, first.end());
    EXPECT_EQ((*wind)["implausible"].get<std::string>().empty(), where == "outdoor") << wind->dump(1);
    // Both components are outside indoors: the farther (y, 1.5 m/s against x's -1; not the
    // first) is said, and that one more is out.
    if (where == "indoor") {
      const std::string said = (*wind)["implausible"];
      EXPECT_EQ(said.rfind("wind.y = 1.", 0), 0u) << said;
      EXPECT_EQ(said.substr(said.size() - std::min(said.size(), std::string(" (and 1 more)").size())), " (and 1 more)") << said;
    }
    if (where == "outdoor") {
      EXPECT_EQ(named(j), std::vector<std::string>{"wind"}) << j["stand_ins"].dump(1);
      EXPECT_TRUE(j["stand_ins"].empty());
      continue;
    }
    EXPECT_TRUE(named(j).empty()) << j["findings"].dump(1);
    ASSERT_EQ(j["stand_ins"].size(), 1u) << j["suspected"].dump(1);
    const json& st = j["stand_ins"][0];
    EXPECT_EQ(st["effect"], "wind");
    EXPECT_EQ(st["parameter"], "wind.y");  // the farther out of the two, as the suspect's words say
    EXPECT_EQ(st["plausible"], json({-0.5, 0.5}));
    EXPECT_GT(std::fabs(st["value"].get<double>()), 0.5);
    double without = 0, with = 0;  // what it absorbs: part of the (noise-dominated) translational residual
    for (const auto& a : st["absorbs"])
      if (a["channel"] == "ax_world" || a["channel"] == "ay_world" || a["channel"] == "ax" || a["channel"] == "ay")
        without += a["training_rms_without"].get<double>(), with += a["training_rms_with"].get<double>();
    EXPECT_LT(with, 0.98 * without) << st["absorbs"].dump(1);
    const auto& model = j["extended_model"]["effects"];
    EXPECT_NE(std::find(model.begin(), model.end(), "wind"), model.end());  // kept in the model
  }
}

// A stand-in for missing physics (a steady wind indoors) may explain more of a flight than the
// plausible cause does, and once in the model it absorbs that cause's residual: on the
// NanoBench helix a 2 m/s "wind" took the first step and blade flapping then failed its
// held-out test. A step takes the strongest plausible significant candidate; a stand-in only
// when nothing plausible is significant (then it is carried and reported, as before).
TEST(Plausibility, APlausibleCauseTakesTheStepBeforeAStrongerStandIn) {
  using quadgen::diagnose::CandidateEvidence;
  const auto candidate = [](const std::string& effect, double statistic, bool significant, const std::string& implausible) {
    CandidateEvidence e;
    e.effect = effect, e.statistic = statistic, e.significant = significant, e.implausible = implausible;
    return e;
  };
  const auto order = [](const std::vector<CandidateEvidence>& cs) {
    std::vector<std::string> out;
    for (const auto& c : cs) out.push_back(c.effect);
    return out;
  };
  std::vector<CandidateEvidence> step{candidate("motor_lag", 1000, false, ""),
                                      candidate("wind", 900, true, "wind.x = -1.98 m/s outside [-0.5, 0.5]"),
                                      candidate("thrust_decay", 100, true, ""),
                                      candidate("blade_flapping", 600, true, ""),
                                      candidate("cog_offset", 50, false, "cog_offset.x = 0.02 m outside [-0.0092, 0.0092]")};
  quadgen::diagnose::rank_candidates(step);
  EXPECT_EQ(order(step),
            (std::vector<std::string>{"blade_flapping", "thrust_decay", "wind", "motor_lag", "cog_offset"}));
  // Nothing plausible significant: the stand-in takes the step; among candidates that are
  // not significant plausibility does not matter (the statistic orders them).
  step = {candidate("blade_flapping", 600, false, ""), candidate("motor_lag", 400, false, ""),
          candidate("wind", 900, true, "wind.x = -1.98 m/s outside [-0.5, 0.5]"),
          candidate("cog_offset", 700, false, "cog_offset.x = 0.02 m outside [-0.0092, 0.0092]")};
  quadgen::diagnose::rank_candidates(step);
  EXPECT_EQ(order(step), (std::vector<std::string>{"wind", "cog_offset", "blade_flapping", "motor_lag"}));
}

// A motor trim belongs to the flight (docs/crazyflie_evidence.md): flight a flies with motor
// C 8 % weak, flight b with motor B 6 % strong. One cause, named once, with each flight's
// own values (motor_gain is per flight in a joint diagnosis).
// A copy of a canonical log with every motor command at its limit, as in a flight whose
// battery could no longer give what the controller asked (NanoBench B6).
fs::path saturated_copy(const fs::path& log, const fs::path& out) {
  std::ifstream in(log);
  std::ofstream o(out);
  std::string line;
  std::getline(in, line);
  o << line << "\n";
  std::vector<bool> command;
  std::stringstream header(line);
  for (std::string c; std::getline(header, c, ',');) command.push_back(c.rfind("u_", 0) == 0);
  while (std::getline(in, line)) {
    std::stringstream row(line);
    size_t k = 0;
    for (std::string v; std::getline(row, v, ','); ++k) o << (k ? "," : "") << (k < command.size() && command[k] ? "1" : v);
    o << "\n";
  }
  return out;
}

// Two flights with each its own trim, and a third whose commands sit at their limit: the third
// is left out (and said so), and the two give what they give alone.
TEST(MultiFlight, OneCauseNamedOnceWithEachFlightsOwnTrim) {
  const fs::path dir = fresh_directory("quadgen_two_flights");
  const HiddenCase a{"a", "motor_gain", {{"motor_gain.C", -0.08}}, {}, "", 1};
  HiddenCase b{"b", "motor_gain", {{"motor_gain.B", 0.06}}, {}, "", 2};
  const fs::path fa = fly(a, dir, "a.csv", 40), fb = fly(b, dir, "b.csv", 40);
  const fs::path fc = saturated_copy(fa, dir / "c_saturated.csv");
  const json j = diagnose_log(vehicle_file(a), fs::path(fa.string() + " " + fb.string() + " " + fc.string()), dir);
  ASSERT_EQ(j["flights"].size(), 2u) << j["flights"].dump();
  ASSERT_EQ(j["flight_screening"].size(), 3u) << j["flight_screening"].dump(1);
  EXPECT_FALSE(j["flight_screening"][0]["left_out"].get<bool>());
  EXPECT_TRUE(j["flight_screening"][2]["left_out"].get<bool>());
  EXPECT_DOUBLE_EQ(j["flight_screening"][2]["commands_at_limit_share"].get<double>(), 1.0);
  EXPECT_LT(j["flight_screening"][0]["commands_at_limit_share"].get<double>(), 0.5);
  ASSERT_EQ(named(j), std::vector<std::string>{"motor_gain"}) << j["findings"].dump(1) << j["suspected"].dump(1);
  EXPECT_EQ(j["per_flight_effects"], json({"motor_gain", "wind", "attitude_bias"}));
  const json& ps = j["findings"][0]["parameters"];
  for (const auto& [name, truth] : std::vector<std::pair<std::string, double>>{
           {"motor_gain.C", -0.08}, {"motor_gain.B", 0.0}, {"motor_gain.C@2", 0.0}, {"motor_gain.B@2", 0.06}}) {
    ASSERT_TRUE(ps.contains(name)) << ps.dump(1);
    EXPECT_NEAR(ps[name]["value"].get<double>(), truth, 0.01) << name;
    EXPECT_LE(ps[name]["ci95"][0].get<double>(), truth) << name << " " << ps[name].dump();
    EXPECT_GE(ps[name]["ci95"][1].get<double>(), truth) << name << " " << ps[name].dump();
  }
  {  // the report shows each flight's trim side by side: one row per rotor, one column per flight
    std::ifstream in(dir / "out" / "report.html");
    const std::string html((std::istreambuf_iterator<char>(in)), {});
    EXPECT_NE(html.find("left out: "), std::string::npos);  // and says which flight it left out, and why
    EXPECT_NE(html.find("<th>flight 2</th>"), std::string::npos);
    EXPECT_NE(html.find("<td>motor_gain.B [1]</td>"), std::string::npos);
    EXPECT_EQ(html.find("<td>motor_gain.B@2"), std::string::npos);  // no copy names in the table
  }
  ASSERT_FALSE(j["candidates_considered"].empty());
  for (const auto& e : j["candidates_considered"]) EXPECT_NE(e, "thrust_decay");  // a per-flight state
  // about 30 % of each flight held out, both flights in the validation part
  const double train = j["samples"]["training"], valid = j["samples"]["validation"];
  EXPECT_NEAR(valid / (train + valid), 0.3, 0.05);
  // The extended header is the fitted model, and says so.
  std::ifstream h(dir / "out" / "extended_model.hpp");
  const std::string header((std::istreambuf_iterator<char>(h)), {});
  EXPECT_NE(header.find("Parameter values (kNominalParams): fitted by quadgen diagnose to"), std::string::npos);
  // and derive regenerates the same fitted values from the vehicle file and fitted_parameters.yaml
  ASSERT_EQ(run(std::string(QUADGEN_BINARY) + " derive " + vehicle_file(a) + " --params " +
                (dir / "out" / "fitted_parameters.yaml").string() + " --out " + (dir / "regenerated").string() +
                " > /dev/null 2>&1"),
            "");
  std::ifstream r(dir / "regenerated" / "model.hpp");
  const std::string regenerated((std::istreambuf_iterator<char>(r)), {});
  const auto nominal = [](const std::string& text) {
    const auto at = text.find("kNominalParams[kNumParams] = ");
    return at == std::string::npos ? std::string() : text.substr(at, text.find('\n', at) - at);
  };
  EXPECT_FALSE(nominal(header).empty());
  EXPECT_EQ(nominal(regenerated), nominal(header));
  // fitted_vehicle.yaml: the vehicle file with the fitted values in it; derive alone builds
  // the same fitted model, and refuses a second source of fitted values
  ASSERT_EQ(run(std::string(QUADGEN_BINARY) + " derive " + (dir / "out" / "fitted_vehicle.yaml").string() + " --out " +
                (dir / "from_vehicle").string() + " > /dev/null 2>&1"),
            "");
  std::ifstream fv(dir / "from_vehicle" / "model.hpp");
  EXPECT_EQ(nominal(std::string((std::istreambuf_iterator<char>(fv)), {})), nominal(header));
  EXPECT_NE(run(std::string(QUADGEN_BINARY) + " derive " + (dir / "out" / "fitted_vehicle.yaml").string() + " --params " +
                (dir / "out" / "fitted_parameters.yaml").string() + " --out " + (dir / "both").string() +
                " > /dev/null 2>&1"),
            "");
  // predict reads the file's own values, not `fitted:`, and says so with what to pass instead
  ASSERT_EQ(run(std::string(QUADGEN_BINARY) + " predict " + (dir / "out" / "fitted_vehicle.yaml").string() + " " +
                fa.string() + " --out " + (dir / "predicted").string() + " > /dev/null 2> " + (dir / "predict.err").string()),
            "");
  std::ifstream pe(dir / "predict.err");
  const std::string said((std::istreambuf_iterator<char>(pe)), {});
  EXPECT_NE(said.find(": its `fitted:` section is read only by `quadgen derive`; predict uses the file's own values (to "
                      "predict with a diagnosis' values, pass its diagnosis.json with --params)"),
            std::string::npos)
      << said;
}

// Two flights of one airframe: each flight alone must show the named airframe effect with the
// value the joint fit gives (agreement), and a value that differs between the flights must be
// reported as disagreement - the check that keeps a flight-to-flight stand-in from passing as a
// property of the airframe.
// `b_flags`: the second flight's extra simulate flags (its marker noise, say).
json rotor_drag_on_two_flights(const std::string& name, double k_a, double k_b, const std::string& b_flags = "") {
  const fs::path dir = fresh_directory(name);
  const HiddenCase a{"a", "rotor_drag,motor_gain", {{"rotor_drag.k", k_a}, {"motor_gain.C", -0.05}}, {}, "", 1};
  const HiddenCase b{"b", "rotor_drag,motor_gain", {{"rotor_drag.k", k_b}, {"motor_gain.B", 0.04}}, {}, b_flags, 2};
  const fs::path fa = fly(a, dir, "a.csv", 40), fb = fly(b, dir, "b.csv", 40);
  return diagnose_log(vehicle_file(a), fs::path(fa.string() + " " + fb.string()), dir);
}

const json* agreement_of(const json& j, const std::string& parameter) {
  for (const auto& a : j["agreement"])
    if (a["parameter"] == parameter) return &a;
  return nullptr;
}

// The spread agreeing flights would show: the range of independent normals with the flights'
// standard errors. Checked against the closed form for two (|X1 - X2| is half-normal with
// sd sqrt(s1^2 + s2^2)) and against a simulation for five of different widths.
TEST(MultiFlight, TheSpreadOfAgreeingFlightsIsTheRangeOfTheirNormals) {
  using quadgen::diagnose::range_cdf;
  for (double r : {0.3, 1.0, 2.5, 6.0}) {
    const double closed = std::erf(r / std::sqrt(2 * (1.0 + 4.0)));  // 2 Phi(r / s) - 1
    EXPECT_NEAR(range_cdf({1.0, 2.0}, r), closed, 1e-6) << r;
  }
  const std::vector<double> sd = {0.5, 1.0, 1.5, 1.0, 2.0};
  std::mt19937_64 rng(7);
  quadgen::runtime::Normal z(0.0, 1.0);
  constexpr int kDraws = 200000;
  std::vector<double> ranges;
  for (int n = 0; n < kDraws; ++n) {
    double lo = INFINITY, hi = -INFINITY;
    for (double s : sd) {
      const double v = s * z(rng);
      lo = std::min(lo, v), hi = std::max(hi, v);
    }
    ranges.push_back(hi - lo);
  }
  for (double r : {1.0, 3.0, 5.0}) {
    const double simulated = static_cast<double>(std::count_if(ranges.begin(), ranges.end(), [&](double x) { return x <= r; })) / kDraws;
    EXPECT_NEAR(range_cdf(sd, r), simulated, 0.004) << r;  // 3.5 binomial standard errors at most
  }
}

TEST(MultiFlight, EachFlightAloneShowsTheSameAirframeEffect) {
  const double truth = 2e-5;
  const json j = rotor_drag_on_two_flights("quadgen_agree", truth, truth);
  const auto n = named(j);
  ASSERT_NE(std::find(n.begin(), n.end(), "rotor_drag"), n.end()) << j["findings"].dump(1);
  const json* a = agreement_of(j, "rotor_drag.k");
  ASSERT_NE(a, nullptr) << j["agreement"].dump(1);
  EXPECT_TRUE((*a)["agree"].get<bool>()) << a->dump(1);
  ASSERT_EQ((*a)["flights"].size(), 2u);
  for (const auto& f : (*a)["flights"]) {
    // each flight's own estimate within 4 of its standard errors of the truth, and the effect
    // significant on each flight by itself
    const double v = f["value"], se = f["standard_error"];
    EXPECT_LT(std::fabs(v - truth), 4 * se + 1e-7) << f.dump();
    EXPECT_LT(f["alone"]["p_value"].get<double>(), 1e-3) << f.dump();
  }
  EXPECT_LT((*a)["spread"].get<double>(), 0.3);
  EXPECT_GT((*a)["spread_if_agree"].get<double>(), 0.0);  // two flights with standard errors
  EXPECT_GT((*a)["spread_p_value"].get<double>(), 0.01) << "agreeing flights whose spread looks unusual";
  // The base model's shared parameter (the FINken 3 fits kappa; c_t is each flight's, c_w
  // fixed) refitted on each flight with the effects held: each flight near the truth the
  // flights were flown with, within its own interval's reach, and no test alone.
  ASSERT_EQ(j["base_agreement"].size(), 1u) << j["base_agreement"].dump(1);
  const json& kappa = j["base_agreement"][0];
  EXPECT_EQ(kappa["parameter"], "kappa");
  EXPECT_EQ(kappa["effect"], "");
  EXPECT_NE(kappa["verdict"], "disagree") << kappa.dump(1);
  ASSERT_EQ(kappa["flights"].size(), 2u);
  for (const auto& f : kappa["flights"]) {
    ASSERT_TRUE(f["standard_error"].is_number()) << f.dump();
    const double v = f["value"], se = f["standard_error"];
    EXPECT_GT(se, 0.0);
    EXPECT_LT(se, 0.1 * 0.01) << "kappa is measured on each flight";
    EXPECT_LT(std::fabs(v - 0.01), 4 * se + 1e-5) << f.dump();  // vehicles/finken3.yaml: kappa 0.01 m
    EXPECT_TRUE(f["alone"].is_null()) << f.dump();
  }
  const fs::path dir = fs::temp_directory_path() / "quadgen_agree";
  {  // the report's agreement table names each flight by its file, the whole path on hover
    std::ifstream in(dir / "out" / "report.html");
    const std::string html((std::istreambuf_iterator<char>(in)), {});
    const std::string whole = (dir / "b.csv").string();
    EXPECT_NE(html.find("<td class=\"flight\" title=\"" + quadgen::output::html_text(whole) + "\">2.&nbsp;b.csv</td>"), std::string::npos)
        << html.substr(html.find("Do the flights agree?"), 3000);
  }

  // Flights no fit saw, checked against that airframe (diagnose LOG --airframe): one with the
  // same rotor drag and a trim of its own agrees, one with 2.5 times the drag does not.
  const fs::path airframe = dir / "out" / "diagnosis.json";
  const auto check = [&](const std::string& name, double k, unsigned seed) {
    const HiddenCase c{name, "rotor_drag,motor_gain", {{"rotor_drag.k", k}, {"motor_gain.D", -0.06}}, {}, "", seed};
    const fs::path sub = fresh_directory("quadgen_agree_" + name);
    const fs::path log = fly(c, sub, "flight.csv", 40);
    EXPECT_EQ(run(std::string(QUADGEN_BINARY) + " diagnose " + vehicle_file(c) + " " + log.string() + " --airframe " +
                  airframe.string() + " --out " + (sub / "out").string() + " > " + (sub / "diagnose.log").string() + " 2>&1"),
              "");
    std::ifstream in(sub / "out" / "diagnosis.json");
    json j;
    if (in.good()) in >> j;
    return j;
  };
  const json same = check("same", truth, 3), other = check("other", 2.5 * truth, 4);
  for (const json* j : {&same, &other}) {
    ASSERT_TRUE(j->contains("airframe_check") && (*j)["airframe_check"].is_object()) << j->dump(1).substr(0, 2000);
    ASSERT_EQ((*j)["airframe_check"]["parameters"].size(), 1u) << (*j)["airframe_check"].dump(1);
  }
  EXPECT_EQ(same["airframe_check"]["airframe_flights"], 2);  // a joint airframe: no note
  const json& s = same["airframe_check"]["parameters"][0];
  const json& o = other["airframe_check"]["parameters"][0];
  EXPECT_EQ(s["parameter"], "rotor_drag.k");
  EXPECT_TRUE(s["agree"].get<bool>()) << s.dump(1);
  EXPECT_FALSE(o["agree"].get<bool>()) << o.dump(1);
  EXPECT_EQ(s["verdict"], "agree") << s.dump(1);
  EXPECT_EQ(o["verdict"], "disagree") << o.dump(1);
  EXPECT_NEAR(o["flights"][0]["value"].get<double>(), 2.5 * truth, 0.2 * truth) << o.dump(1);
  EXPECT_LT(o["q_p_value"].get<double>(), 1e-3) << o.dump(1);
}

// Flights within their errors (Cochran's Q does not reject one value) but 30 % or more apart
// are not said to disagree (a user trial: an --airframe check said "disagrees" at p = 0.18): the verdict
// says they are too uncertain to agree. Closed forms: two flights, the pooled value their
// inverse-variance mean.
TEST(MultiFlight, FlightsTooUncertainToAgreeAreNotSaidToDisagree) {
  using quadgen::diagnose::ParameterAgreement;
  const auto judged = [](double v1, double v2, double se) {
    ParameterAgreement a;
    a.joint_value = 0.5 * (v1 + v2);
    for (double v : {v1, v2}) {
      quadgen::diagnose::FlightEstimate f;
      f.value = v, f.standard_error = se, f.lower = v - 1.96 * se, f.upper = v + 1.96 * se;
      a.flights.push_back(f);
    }
    quadgen::diagnose::summarise_agreement(a);
    return a;
  };
  const ParameterAgreement close = judged(1.0, 1.1, 0.05), loose = judged(1.0, 1.5, 0.5), apart = judged(1.0, 1.5, 0.05);
  EXPECT_NEAR(loose.pooled, 1.25, 1e-12);
  EXPECT_NEAR(loose.spread, 0.4, 1e-12);
  EXPECT_STREQ(quadgen::diagnose::agreement_verdict(close), "agree");
  EXPECT_STREQ(quadgen::diagnose::agreement_verdict(loose), "too uncertain");
  EXPECT_FALSE(loose.agree);  // the 30 % is still not met: nothing is named on it
  EXPECT_STREQ(quadgen::diagnose::agreement_verdict(apart), "disagree");
  // A flight without a standard error cannot disagree.
  ParameterAgreement unsure = judged(1.0, 1.02, 0.05);
  unsure.flights[1].standard_error = NAN;
  quadgen::diagnose::summarise_agreement(unsure);
  EXPECT_STREQ(quadgen::diagnose::agreement_verdict(unsure), "too uncertain");
  EXPECT_STREQ(quadgen::diagnose::why_too_uncertain(unsure), "a flight without a standard error cannot say");
  // Intervals of +-40 %: agreeing flights would spread by more than 30 % (median 38 %), so
  // the flights cannot measure it that well (a review, helper-131); intervals of +-26 %
  // (standard errors 0.16) for values 33 % apart are within the errors only (Q p = 0.08).
  EXPECT_GT(loose.spread_if_agree, 0.3);
  EXPECT_STREQ(quadgen::diagnose::why_too_uncertain(loose),
               "the flights cannot measure it to 30 %: agreeing flights would spread as far");
  // (Two flights 0.4 apart with errors of 0.12 each hold the pooled 1.2 in both intervals,
  // yet differ by 2.4 standard errors of their difference: Q says disagree, p = 0.018.)
  EXPECT_STREQ(quadgen::diagnose::agreement_verdict(judged(1.0, 1.4, 0.12)), "disagree");
  const ParameterAgreement tight_apart = judged(1.0, 1.4, 0.16);
  EXPECT_LT(tight_apart.spread_if_agree, 0.3);
  EXPECT_STREQ(quadgen::diagnose::agreement_verdict(tight_apart), "too uncertain");
  EXPECT_STREQ(quadgen::diagnose::why_too_uncertain(tight_apart), "within the errors, but 30 % or more apart");
  // A flight whose value ended on its bound has no interval (Wald's would cross the bound):
  // it cannot disagree, however narrow the standard error at the bound reads.
  ParameterAgreement bound = judged(1.0, 3.0, 0.05);
  EXPECT_STREQ(quadgen::diagnose::agreement_verdict(bound), "disagree");
  bound.flights[1].at_bound = true;
  quadgen::diagnose::summarise_agreement(bound);
  EXPECT_STREQ(quadgen::diagnose::agreement_verdict(bound), "too uncertain");
  EXPECT_STREQ(quadgen::diagnose::why_too_uncertain(bound), "a flight's value on its bound cannot say");
  // Which bound cannot say: not the one that is the effect's "off" (the effect absent from
  // that flight, a value that may disagree; a review, helper-132), any other, and any bound
  // of a base parameter (no "off").
  using quadgen::diagnose::on_a_bound_that_is_not_off;
  const quadgen::fit::FitParameter drag_off{"rotor_drag.k", "N s^2/m", 0.0, 0.0, 1e-3, true},
      drag_top{"rotor_drag.k", "N s^2/m", 1e-3, 0.0, 1e-3, true}, drag_inside{"rotor_drag.k", "N s^2/m", 1e-5, 0.0, 1e-3, true},
      lag_floor{"motor_lag.tau", "s", 1e-6, 1e-6, 1.0, true}, gain_edge{"motor_gain.B", "1", -0.5, -0.5, 0.5, true},
      c_w_floor{"c_w", "1", 0.05, 0.05, 3.0, true};
  EXPECT_FALSE(on_a_bound_that_is_not_off(drag_off, 0.0));
  EXPECT_TRUE(on_a_bound_that_is_not_off(drag_top, 0.0));
  EXPECT_FALSE(on_a_bound_that_is_not_off(drag_inside, 0.0));
  EXPECT_FALSE(on_a_bound_that_is_not_off(lag_floor, 1e-6));  // off_at_lower_bound: the lag's off is its floor
  EXPECT_TRUE(on_a_bound_that_is_not_off(gain_edge, 0.0));
  EXPECT_TRUE(on_a_bound_that_is_not_off(c_w_floor, NAN));
  // No flight measures it: each value on its bound or its interval holding zero (c_w on the
  // NanoBench flights: 0.05 on the bound, 0.25 [-4.8, 5.3], 2.3 [-2.3, 6.8]). One flight
  // whose interval clears zero measures it, and the reason is the bound's again.
  ParameterAgreement unmeasured = judged(0.25, 2.3, 2.3);
  unmeasured.base = true;
  unmeasured.flights.push_back(bound.flights[1]);
  quadgen::diagnose::summarise_agreement(unmeasured);
  EXPECT_EQ(quadgen::diagnose::flights_measuring(unmeasured), 0u);
  EXPECT_STREQ(quadgen::diagnose::agreement_verdict(unmeasured), "too uncertain");
  const char* no_flight = "no flight tells it from zero: each value is on its bound or its interval holds zero";
  EXPECT_STREQ(quadgen::diagnose::why_too_uncertain(unmeasured), no_flight);
  EXPECT_TRUE(quadgen::diagnose::unmeasured_base_parameter(unmeasured));
  // An effect's parameter is judged against its "off" by its test, not here.
  ParameterAgreement effect = unmeasured;
  effect.base = false;
  EXPECT_STRNE(quadgen::diagnose::why_too_uncertain(effect), no_flight);
  EXPECT_FALSE(quadgen::diagnose::unmeasured_base_parameter(effect));
  // A flight without a standard error says nothing either way: its own reason stands.
  ParameterAgreement no_error = unmeasured;
  for (auto& f : no_error.flights) f.standard_error = NAN, f.lower = f.upper = NAN, f.at_bound = false;
  quadgen::diagnose::summarise_agreement(no_error);
  EXPECT_STREQ(quadgen::diagnose::why_too_uncertain(no_error), "a flight without a standard error cannot say");
  EXPECT_FALSE(quadgen::diagnose::unmeasured_base_parameter(no_error));
  // One flight that tells it from zero: the bound's reason again.
  unmeasured.flights[1].standard_error = 1.0, unmeasured.flights[1].lower = 0.34, unmeasured.flights[1].upper = 4.26;
  quadgen::diagnose::summarise_agreement(unmeasured);
  EXPECT_EQ(quadgen::diagnose::flights_measuring(unmeasured), 1u);
  EXPECT_STREQ(quadgen::diagnose::why_too_uncertain(unmeasured), "a flight's value on its bound cannot say");
  EXPECT_FALSE(quadgen::diagnose::unmeasured_base_parameter(unmeasured));
  // Eight flights at 0.8-1.2, each +- 0.65 (standard error), hold zero, but together (1.0 +-
  // 0.23) they tell it from zero: no flight alone does, the flights do, nothing says to hold it.
  ParameterAgreement together;
  together.base = true, together.joint_value = 1.0;
  for (int k = 0; k < 8; ++k) {
    const double v = 0.8 + 0.4 * k / 7;
    together.flights.push_back({v, 0.65, v - 1.96 * 0.65, v + 1.96 * 0.65, NAN, NAN});
  }
  quadgen::diagnose::summarise_agreement(together);
  EXPECT_STREQ(quadgen::diagnose::why_too_uncertain(together), no_flight);
  EXPECT_FALSE(quadgen::diagnose::unmeasured_base_parameter(together));
  // A negative value measured as such counts.
  EXPECT_TRUE(quadgen::diagnose::flight_measures({-1.0, 0.1, -1.2, -0.8, NAN, NAN}));
  EXPECT_STREQ(quadgen::diagnose::why_too_uncertain(close), "");
  EXPECT_STREQ(quadgen::diagnose::why_too_uncertain(apart), "");
  ParameterAgreement against = loose;  // an airframe value without a standard error
  against.reference_without_error = true;
  EXPECT_STREQ(quadgen::diagnose::why_too_uncertain(against), "the airframe's value has no standard error");
  // The printout says it, and that an airframe's value was refitted on this flight.
  quadgen::diagnose::Diagnosis d;
  ParameterAgreement check = loose;
  check.parameter = "rotor_drag.k";
  check.spread_if_agree = NAN;  // as judge_against_airframe leaves it: one flight has no spread
  d.airframe_check = {check};
  const std::string said = quadgen::diagnose::diagnosis_summary(d);
  EXPECT_NE(said.find("this flight is too uncertain to agree with the airframe on rotor_drag.k (refitted here, the "
                      "airframe's other values held): here "),
            std::string::npos)
      << said;
  EXPECT_NE(said.find(" against the airframe's "), std::string::npos) << said;  // which value is which
  EXPECT_NE(said.find("p = 0.48: within the errors, but 30 % or more apart)"), std::string::npos) << said;
  check.flights[0].standard_error = NAN;
  d.airframe_check = {check};
  const std::string unsaid = quadgen::diagnose::diagnosis_summary(d);
  EXPECT_NE(unsaid.find(": a flight without a standard error cannot say)"), std::string::npos) << unsaid;
  EXPECT_EQ(unsaid.find("30 % or more apart"), std::string::npos) << unsaid;
  const std::string page = quadgen::diagnose::diagnosis_html(d, "flight.csv", {});
  EXPECT_NE(page.find("too uncertain (a flight without a standard error cannot say)</span>"), std::string::npos);
  // Summarised again, the same Q (a second call doubled it; a statistics review, helper-128).
  ParameterAgreement twice = apart;
  quadgen::diagnose::summarise_agreement(twice);
  EXPECT_DOUBLE_EQ(twice.q, apart.q);
  EXPECT_NEAR(apart.q, 2 * std::pow(0.25 / 0.05, 2), 1e-9);  // each value 0.25 from the pooled 1.25
}

// Of flights diagnosed together, an unexplained window is told on the clock of the flight it
// lies in, from that log's first row, and ends with it (a researcher's trial, helper-148: the
// joined clock's "t = 54.1..55.1 s" of two 30 s flights; then a review, helper-149: the time
// since the first kept sample is not the log's own clock, which a take-off delays).
TEST(MultiFlight, AnUnexplainedWindowIsToldOnItsFlightsClock) {
  const auto flight_from = [](double first, double last) {
    quadgen::fit::Flight f;
    for (double t = first; t <= last + 1e-9; t += 0.5) {
      quadgen::fit::FlightSample s;
      s.t = t;
      f.samples.push_back(s);
    }
    return f;
  };
  // Flight 2 is kept from 2 s of its own clock on; joined 1 s after flight 1's last sample
  // (10 s), its 2 s read 11 s there: its own time is the joined time less 9 s.
  const std::vector<quadgen::fit::Flight> flights = {flight_from(0.5, 10.0), flight_from(2.0, 6.0)};
  // Windows are cut by sample count over the joined log, so one may reach over the join (10 to
  // 11 joined): it belongs to the flight its middle lies in, cut to that flight's samples.
  struct Case {
    double joined_t0, joined_t1;  // as cut
    int flight;
    double t0, t1;  // on that flight's own clock
  };
  const Case cases[] = {
      {5.0, 6.0, 1, 5.0, 6.0},    // in flight 1
      {12.0, 13.5, 2, 3.0, 4.5},  // in flight 2
      {9.5, 11.5, 1, 9.5, 10.0},  // middle 10.5, in flight 1 (or the gap): cut at its last sample
      {10.5, 12.5, 2, 2.0, 3.5},  // middle 11.5, in flight 2: from its first sample
  };
  std::vector<quadgen::diagnose::Unexplained> windows;
  for (const Case& c : cases) {
    windows.emplace_back();
    windows.back().t0 = c.joined_t0, windows.back().t1 = c.joined_t1;
  }
  std::vector<quadgen::diagnose::Unexplained> one = windows;
  quadgen::diagnose::place_on_their_flights(windows, flights);
  for (size_t i = 0; i < std::size(cases); ++i) {
    SCOPED_TRACE("window " + std::to_string(i));
    EXPECT_EQ(windows[i].flight, cases[i].flight);
    EXPECT_DOUBLE_EQ(windows[i].t0, cases[i].t0);
    EXPECT_DOUBLE_EQ(windows[i].t1, cases[i].t1);
    EXPECT_DOUBLE_EQ(windows[i].t0_joined, cases[i].joined_t0);  // where the plots show it
  }
  quadgen::diagnose::place_on_their_flights(one, {flights[0]});  // one flight: its own clock already
  EXPECT_EQ(one[1].flight, 0);
  EXPECT_DOUBLE_EQ(one[1].t0, 12.0);
}

// Noise-free generated flights carry standard errors near machine precision, and the bias
// each flight's model error gives its estimate then decides Cochran's Q: kappa "disagreed"
// at a spread of 0.0002 % (sixty-second session). Values within 1 % agree whatever Q says,
// with the reason beside the verdict; 2 % apart at the same errors still disagree, and an
// airframe check judges one flight alike.
TEST(MultiFlight, ValuesWithinOnePercentAgreeWhateverQSays) {
  using quadgen::diagnose::ParameterAgreement;
  const auto judged = [](std::vector<double> values, double se) {
    ParameterAgreement a;
    a.joint_value = values.front();
    for (double v : values) {
      quadgen::diagnose::FlightEstimate f;
      f.value = v, f.standard_error = se, f.lower = v - 1.96 * se, f.upper = v + 1.96 * se;
      a.flights.push_back(f);
    }
    quadgen::diagnose::summarise_agreement(a);
    return a;
  };
  const ParameterAgreement noise_free = judged({0.01, 0.010000015, 0.01000002}, 1e-12);
  EXPECT_LT(noise_free.q_p_value, 1e-100);
  EXPECT_STREQ(quadgen::diagnose::agreement_verdict(noise_free), "agree");
  EXPECT_NE(std::string(quadgen::diagnose::agreement_reason(noise_free)).find("within 1 %"), std::string::npos);
  const ParameterAgreement two_percent = judged({1.0, 1.02}, 1e-6);
  EXPECT_STREQ(quadgen::diagnose::agreement_verdict(two_percent), "disagree");
  EXPECT_STREQ(quadgen::diagnose::agreement_reason(two_percent), "");
  const ParameterAgreement tested = judged({1.0, 1.1}, 0.2);  // Q does not reject: no margin note
  EXPECT_STREQ(quadgen::diagnose::agreement_verdict(tested), "agree");
  EXPECT_STREQ(quadgen::diagnose::agreement_reason(tested), "");
  quadgen::diagnose::FlightEstimate here;
  here.value = 1.005, here.standard_error = 1e-9, here.lower = here.value - 2e-9, here.upper = here.value + 2e-9;
  EXPECT_TRUE(quadgen::diagnose::judge_against_airframe(here, 1.0, 1e-9).agree);
  here.value = 1.05;
  EXPECT_FALSE(quadgen::diagnose::judge_against_airframe(here, 1.0, 1e-9).within_errors);
  // A "too uncertain" verdict keeps its own reason, whatever the test says (a review,
  // helper-144: the margin's words stood beside values 20 % apart): an airframe value
  // without a standard error, 20 % off with p = 6e-5; a flight on its bound among flights
  // whose test rejects one value.
  here.value = 1.2, here.standard_error = 0.05;
  const ParameterAgreement no_reference = quadgen::diagnose::judge_against_airframe(here, 1.0, 0.0);
  EXPECT_LT(no_reference.q_p_value, 0.05);
  EXPECT_STREQ(quadgen::diagnose::agreement_reason(no_reference), "the airframe's value has no standard error");
  ParameterAgreement bound = judged({0.01, 0.010000015, 0.01000002}, 1e-12);
  bound.flights.push_back(bound.flights.front());
  bound.flights.back().at_bound = true;
  quadgen::diagnose::summarise_agreement(bound);
  EXPECT_STREQ(quadgen::diagnose::agreement_verdict(bound), "too uncertain");
  EXPECT_STREQ(quadgen::diagnose::agreement_reason(bound), "a flight's value on its bound cannot say");
}

// Flights that measure one value, each with its own error, are said to disagree at the test's
// level (5 %), however many they are: the verdict rests on Cochran's Q, one test per parameter.
// The rule before the sixty-first session (every flight's 95 % interval holds the pooled
// value) tested each flight and said "disagree" 14 % of the time for five flights and 32 % for
// ten: this test failed with it. And a flight 4 standard errors off is found.
TEST(MultiFlight, AgreeingFlightsAreSaidToDisagreeAtTheTestsLevel) {
  using quadgen::diagnose::ParameterAgreement;
  std::mt19937 rng(61);
  quadgen::runtime::Normal unit(0.0, 1.0);
  const auto draw = [&](size_t flights, double shift_of_last) {
    ParameterAgreement a;
    a.joint_value = 1.0;
    for (size_t k = 0; k < flights; ++k) {
      quadgen::diagnose::FlightEstimate f;
      f.standard_error = 0.02 * (1 + 2.0 * k / (flights - 1));  // unequal errors, 0.02-0.06
      f.value = 1.0 + f.standard_error * (unit(rng) + (k + 1 == flights ? shift_of_last : 0.0));
      f.lower = f.value - 1.96 * f.standard_error, f.upper = f.value + 1.96 * f.standard_error;
      a.flights.push_back(f);
    }
    quadgen::diagnose::judge_heterogeneity(a);  // the verdict, without the spread's integral
    return a;
  };
  constexpr int kDraws = 4000;  // 5 % of them: 200 +- 14
  for (size_t flights : {2u, 5u, 10u}) {
    int disagree = 0, found = 0;
    for (int i = 0; i < kDraws; ++i) {
      disagree += quadgen::diagnose::flights_disagree(draw(flights, 0.0));
      found += quadgen::diagnose::flights_disagree(draw(flights, 4.0));
    }
    EXPECT_NEAR(static_cast<double>(disagree) / kDraws, 0.05, 0.015) << flights << " flights";
    EXPECT_GT(static_cast<double>(found) / kDraws, 0.5) << flights << " flights";
  }
}

// A flight checked against an airframe (diagnose --airframe): a flight without a standard
// error (a confounded parameter: NaN; or 0) is "too uncertain" with no Q and no p-value. Such a
// flight made Q infinite, and the p-value's Boost call threw and aborted the run (a
// statistics review, helper-128).
TEST(MultiFlight, AFlightWithoutAStandardErrorCannotSayAgainstAnAirframe) {
  using quadgen::diagnose::judge_against_airframe;
  quadgen::diagnose::FlightEstimate f;
  f.value = 1.2, f.lower = NAN, f.upper = NAN;
  for (double se : {std::numeric_limits<double>::quiet_NaN(), 0.0}) {
    f.standard_error = se;
    const auto a = judge_against_airframe(f, 1.0, 0.05);
    EXPECT_STREQ(quadgen::diagnose::agreement_verdict(a), "too uncertain") << se;
    EXPECT_STREQ(quadgen::diagnose::why_too_uncertain(a), "a flight without a standard error cannot say");
    EXPECT_TRUE(std::isnan(a.q) && std::isnan(a.q_p_value)) << a.q << " " << a.q_p_value;
    EXPECT_NEAR(a.spread, 0.2, 1e-12);
  }
  f.standard_error = 0.05;  // z = 0.2 / hypot(0.05, 0.05)
  const auto apart = judge_against_airframe(f, 1.0, 0.05);
  EXPECT_NEAR(apart.q, 8.0, 1e-9);
  EXPECT_NEAR(apart.q_p_value, boost::math::cdf(boost::math::complement(boost::math::chi_squared(1), 8.0)), 1e-15);
  EXPECT_STREQ(quadgen::diagnose::agreement_verdict(apart), "disagree");
  // z on the flight's error alone; the reader of --airframe gives 0 where a diagnosis has none
  // (a review, helper-130: a 0 was taken as an exact value).
  for (double none : {std::numeric_limits<double>::quiet_NaN(), 0.0}) {
    const auto no_reference = judge_against_airframe(f, 1.0, none);
    EXPECT_NEAR(no_reference.q, 16.0, 1e-9);
    EXPECT_STREQ(quadgen::diagnose::agreement_verdict(no_reference), "too uncertain") << none;
    EXPECT_STREQ(quadgen::diagnose::why_too_uncertain(no_reference), "the airframe's value has no standard error");
  }
  f.value = 1.02;
  EXPECT_STREQ(quadgen::diagnose::agreement_verdict(judge_against_airframe(f, 1.0, 0.05)), "agree");
  EXPECT_EQ(quadgen::diagnose::chi2_upper(INFINITY, 1.0), 0.0);
  EXPECT_TRUE(std::isnan(quadgen::diagnose::chi2_upper(NAN, 1.0)));
}

// The held-out part is cut into four folds of equal held-out time. Two joined flights hold
// theirs 42 s apart on the joined clock (the second's training part between): cut by that
// clock, the folds were [1800, 0, 0, 1800] samples and two of them were dropped (a statistics
// review, helper-128). A short dropout counts as held-out time; a second flight sampled half
// as often gets folds of half the samples (folds of equal sample counts would not). A single
// contiguous part is cut as before, in equal durations; a log sampled at 5 Hz is no gap.
TEST(HeldOut, FoldsHoldEqualHeldOutTimeAcrossJoinedFlights) {
  // Spans [from, to] sampled every `step` s, less the samples in (drop_from, drop_to).
  struct Span {
    double from, to, step, drop_from = 0, drop_to = 0;
  };
  const auto part = [](std::vector<Span> spans) {
    quadgen::fit::Flight f;
    for (const auto& sp : spans)
      for (int k = 0; sp.from + sp.step * k <= sp.to + 1e-9; ++k) {
        quadgen::fit::FlightSample s;
        s.t = sp.from + sp.step * k;
        if (s.t > sp.drop_from + 1e-9 && s.t < sp.drop_to - 1e-9) continue;
        f.samples.push_back(s);
      }
    return f;
  };
  const auto sizes = [](const std::vector<quadgen::fit::Flight>& folds) {
    std::vector<size_t> n;
    for (const auto& f : folds) n.push_back(f.samples.size());
    return n;
  };
  // 50.00-50.05 s dropped: a 0.06 s interval, within a stretch.
  const auto joined = quadgen::diagnose::validation_folds(part({{42, 60, 0.01, 50.0, 50.06}, {102, 120, 0.02}}), 4);
  ASSERT_EQ(joined.size(), 4u);
  const std::vector<size_t> n = sizes(joined);
  EXPECT_NEAR(static_cast<double>(n[0]), 895, 2.0) << ::testing::PrintToString(n);
  EXPECT_NEAR(static_cast<double>(n[1]), 901, 2.0) << ::testing::PrintToString(n);
  EXPECT_NEAR(static_cast<double>(n[2]), 450, 2.0) << ::testing::PrintToString(n);
  EXPECT_NEAR(static_cast<double>(n[3]), 451, 2.0) << ::testing::PrintToString(n);
  EXPECT_NEAR(joined[1].samples.front().t, 51.0, 0.011);
  EXPECT_NEAR(joined[3].samples.front().t, 111.0, 0.021);
  // Folds 1-2 the first flight's (the second's first sample, at the same held-out time as the
  // first's last, may close fold 2), folds 3-4 the second's.
  EXPECT_EQ(joined[0].samples.front().t, 42.0);
  EXPECT_GE(joined[1].samples.back().t, 60.0);
  EXPECT_LE(joined[1].samples.back().t, 102.0);
  EXPECT_GE(joined[2].samples.front().t, 102.0);
  EXPECT_EQ(joined[3].samples.back().t, 120.0);
  const auto single = quadgen::diagnose::validation_folds(part({{42, 60, 0.01}}), 4);
  ASSERT_EQ(single.size(), 4u);
  for (size_t i = 0; i < 4; ++i) EXPECT_NEAR(single[i].samples.front().t, 42 + 4.5 * i, 0.011) << i;
  const auto slow = quadgen::diagnose::validation_folds(part({{42, 60, 0.2}}), 4);
  ASSERT_EQ(slow.size(), 4u);
  for (size_t i = 0; i < 4; ++i) EXPECT_NEAR(slow[i].samples.front().t, 42 + 4.5 * i, 0.21) << i;
}

// Each flight is refitted alone under its own noise's weights: a flight with ten times the
// marker noise measures the rotor drag (a horizontal force, read from the differentiated pose)
// several times less precisely, and its standard error says so. Under the joint fit's
// weights, as until the fifty-ninth session, the two errors came out alike (the same
// manoeuvres), and Cochran's Q charged the noisy flight's scatter as disagreement (a
// statistics review, helper-128).
TEST(MultiFlight, EachFlightIsRefittedUnderItsOwnNoise) {
  const json j = rotor_drag_on_two_flights("quadgen_own_noise", 2e-5, 2e-5, "--pose-noise 1e-2");
  const json* k = agreement_of(j, "rotor_drag.k");
  ASSERT_NE(k, nullptr) << j["agreement"].dump(1);
  ASSERT_EQ((*k)["flights"].size(), 2u);
  const double quiet = (*k)["flights"][0]["standard_error"], noisy = (*k)["flights"][1]["standard_error"];
  EXPECT_GT(noisy, 3 * quiet) << k->dump(1);
  // Each flight's own test against "off" (k = 0, its lower bound) takes the chi-bar-square
  // null, as the search does: half the chi2_1 tail (it took the whole tail until the
  // fifty-ninth session). Here the statistics are moderate (about 30), so the p-values are not 0.
  for (const auto& f : (*k)["flights"]) {
    const double statistic = f["alone"]["statistic"], p = f["alone"]["p_value"];
    ASSERT_GT(p, 0.0) << f.dump();
    EXPECT_NEAR(p / (0.5 * boost::math::cdf(boost::math::complement(boost::math::chi_squared(1), statistic))), 1.0, 1e-9);
  }
}

TEST(MultiFlight, AnEffectThatChangesBetweenFlightsIsReportedAsDisagreement) {
  const json j = rotor_drag_on_two_flights("quadgen_disagree", 1e-5, 4e-5);
  // One joint value fits neither flight: named or suspected, it is checked flight by flight.
  const json* a = agreement_of(j, "rotor_drag.k");
  ASSERT_NE(a, nullptr) << j["findings"].dump(1) << j["suspected"].dump(1) << j["agreement"].dump(1);
  EXPECT_FALSE((*a)["agree"].get<bool>()) << a->dump(1);
  EXPECT_LT((*a)["q_p_value"].get<double>(), 0.01) << a->dump(1);
  const double v1 = (*a)["flights"][0]["value"], v2 = (*a)["flights"][1]["value"];
  EXPECT_GT(v2, 2 * v1) << a->dump(1);  // each flight shows its own value
}

// An effect absent from one flight ends there on its "off", which is also its bound (rotor
// drag 0): a value like any other, which disagrees with the other flight's, not a flight
// that "cannot say" as one on another bound (a review, helper-132: present on four flights
// and absent on a fifth read "too uncertain"). The second flight also yaws against a torque
// ratio half as large again (kappa 0.015 m where the file and the first flight have 0.01 m):
// a base parameter that changes is a disagreement too.
TEST(MultiFlight, AnEffectAbsentFromOneFlightAndAnotherTorqueRatioAreDisagreements) {
  const json j = rotor_drag_on_two_flights("quadgen_absent", 3e-5, 0.0, "--set kappa=0.015");
  const json* a = agreement_of(j, "rotor_drag.k");
  ASSERT_NE(a, nullptr) << j["findings"].dump(1) << j["suspected"].dump(1) << j["agreement"].dump(1);
  EXPECT_EQ((*a)["verdict"], "disagree") << a->dump(1);
  EXPECT_LT((*a)["flights"][1]["value"].get<double>(), 0.3 * (*a)["flights"][0]["value"].get<double>()) << a->dump(1);
  EXPECT_FALSE((*a)["flights"][1]["at_bound"].get<bool>()) << a->dump(1);
  ASSERT_EQ(j["base_agreement"].size(), 1u) << j["base_agreement"].dump(1);
  const json& kappa = j["base_agreement"][0];
  EXPECT_EQ(kappa["verdict"], "disagree") << kappa.dump(1);
  EXPECT_TRUE(kappa["base"].get<bool>());
  const double k1 = kappa["flights"][0]["value"], k2 = kappa["flights"][1]["value"];
  EXPECT_NEAR(k1, 0.010, 0.001) << kappa.dump(1);
  EXPECT_NEAR(k2, 0.015, 0.0015) << kappa.dump(1);
}

}  // namespace

// The diagnosis as a library call checks its options itself (Ceres-style IsValid), so a
// caller that is not the command line gets the same refusals, with the reason.
TEST(DiagnoseJob, RefusesOptionsNoDiagnosisCanUse) {
  quadgen::app::DiagnoseJob job;
  std::string why;
  EXPECT_FALSE(job.IsValid(&why));
  EXPECT_NE(why.find("vehicle"), std::string::npos) << why;
  job.vehicle = "vehicles/finken3.yaml";
  job.logs = {"flight.csv"};
  EXPECT_TRUE(job.IsValid(&why)) << why;  // the library's defaults are valid
  job.options.validation_fraction = 0.9;
  EXPECT_FALSE(job.IsValid(&why));
  EXPECT_NE(why.find("validation"), std::string::npos) << why;
  job.options.validation_fraction = 0.3;
  job.options.search.alpha = std::nan("");
  EXPECT_FALSE(job.IsValid(&why));
  EXPECT_NE(why.find("alpha"), std::string::npos) << why;
  job.options.search.alpha = 1e-12;  // the command line refused it and the library did not (one range now)
  EXPECT_FALSE(job.IsValid(&why));
  EXPECT_NE(why.find("alpha: 1e-09 to 0.2"), std::string::npos) << why;
  job.options.search.alpha = 0.01;
  job.options.window_stride = 0.001;  // a hundred thousand windows in a 100 s held-out part
  EXPECT_FALSE(job.IsValid(&why));
  EXPECT_NE(why.find("window stride"), std::string::npos) << why;
  job.options.window_stride = 1.0;  // as long as the window: no overlap, say 0 for that
  EXPECT_FALSE(job.IsValid(&why));
  job.options.window_stride = 0;  // consecutive windows
  EXPECT_TRUE(job.IsValid(&why)) << why;
  job.environment = "orbit";
  EXPECT_FALSE(job.IsValid(&why));
  EXPECT_THROW(quadgen::app::run_diagnose_job(job), std::invalid_argument);  // refused before reading any file
}

// A flight with a motor command at its limit in more than half of its samples is unusable;
// the printout says so, with the path made printable (a log's name is hostile input).
TEST(FlightScreening, CommandsAtTheirLimitMakeAFlightUnusable) {
  const auto flight = [](int at_limit, const std::string& source) {
    quadgen::fit::Flight f;
    f.source = source;
    for (int k = 0; k < 10; ++k) {
      quadgen::fit::FlightSample s;
      s.u = {0.5, 0.6, 0.55, k < at_limit ? 1.0 : 0.7};
      f.samples.push_back(s);
    }
    return f;
  };
  const quadgen::diagnose::FlightScreening ok = quadgen::diagnose::screen_flight(flight(4, "a.csv"));
  EXPECT_TRUE(ok.usable);
  EXPECT_DOUBLE_EQ(ok.saturated_share, 0.4);
  quadgen::diagnose::Diagnosis d;
  d.screening.push_back(quadgen::diagnose::screen_flight(flight(6, "b\x1b[2J.csv")));
  EXPECT_FALSE(d.screening[0].usable);
  EXPECT_DOUBLE_EQ(d.screening[0].saturated_share, 0.6);
  EXPECT_NE(d.screening[0].reason.find("60 %"), std::string::npos) << d.screening[0].reason;
  std::string text = quadgen::diagnose::diagnosis_summary(d);
  EXPECT_NE(text.find("caution: b"), std::string::npos) << text;  // diagnosed alone: a caution
  EXPECT_EQ(text.find('\x1b'), std::string::npos);
  d.screening[0].left_out = true;
  text = quadgen::diagnose::diagnosis_summary(d);
  EXPECT_NE(text.find("left out: b"), std::string::npos) << text;
  EXPECT_EQ(quadgen::diagnose::diagnosis_json(d, "b.csv")["flight_screening"][0]["left_out"], true);
}

// The command-gain table numbers its flights as the agreement table and the title do: two logs
// whose names differ only by a trailing blank read alike there otherwise (a review, helper-135).
TEST(DiagnosisReport, TheCommandGainTableNumbersItsFlights) {
  quadgen::diagnose::Diagnosis d;
  d.flights = {"x.csv", "x.csv "};
  quadgen::diagnose::CommandGain g;
  g.measured = true;
  g.axes.push_back({"roll", {{0.8, 2.0, 0.9, 0.7, 0.01}}});
  d.command_gain_per_flight = {g, g};
  d.command_gain = g;
  const std::string html = quadgen::diagnose::diagnosis_html(d, "x.csv", {});
  EXPECT_NE(html.find(">1.&nbsp;x.csv</td><td>roll</td>"), std::string::npos) << html;
  EXPECT_NE(html.find(">2.&nbsp;x.csv </td><td>roll</td>"), std::string::npos) << html;
}

// An interval side the profile never closed is printed as "open", in the terminal summary
// and in the report, never as a number or a bare dash (#16).
TEST(DiagnosisReport, AnOpenIntervalSideReadsOpen) {
  quadgen::diagnose::Diagnosis d;
  quadgen::diagnose::Finding f;
  f.effect = "motor_lag";
  quadgen::diagnose::EffectEstimate tau;
  tau.name = "motor_lag.tau", tau.unit = "s", tau.value = 0.05, tau.lower = 0.03, tau.upper = NAN;
  tau.verdict = quadgen::fit::Identifiability::kPracticallyNonIdentifiable;
  f.parameters.push_back(tau);
  f.metric = "position RMSE [m]", f.before = 0.2, f.after = 0.1;
  d.findings.push_back(f);
  const std::string text = quadgen::diagnose::diagnosis_summary(d);
  EXPECT_NE(text.find("motor_lag.tau = 0.05 [0.03, open]"), std::string::npos) << text;
  const std::string html = quadgen::diagnose::diagnosis_html(d, "log.csv", {});
  EXPECT_NE(html.find("[0.03, open]"), std::string::npos);
  EXPECT_EQ(html.find("nan"), std::string::npos);
}

// A discovered term's verdict says its label once in each sink: "proposed" (bold in the
// report) or "not proposed" or "no term", then why; diagnosis.json keeps label and reason in
// one string. (The terminal and the report each stripped the label from that string their own
// way, and the report wrote "not proposed: no term: ...".)
TEST(DiagnosisReport, ADiscoveredTermsVerdictSaysItsLabelOnce) {
  quadgen::diagnose::Diagnosis d;
  const std::vector<std::pair<std::string, std::string>> verdicts{
      {"proposed", "held-out RMS 2 -> 1"}, {"not proposed", "no held-out gain beyond its spread: held-out RMS 2 -> 2"},
      {"no term", "cross-validation finds none"}};
  for (const auto& [label, reason] : verdicts) {
    quadgen::diagnose::DiscoveredTerm t;
    t.channel = "pdot", t.unit = "rad/s^2", t.proposed = label == "proposed";
    t.verdict_label = label, t.verdict_reason = reason;
    if (t.proposed) t.coefficients.push_back({"v_bx", "rad/s^2/(m/s)", 0.5, 0.4, 0.6});
    d.discovered.push_back(t);
  }
  const auto j = quadgen::diagnose::diagnosis_json(d, "log.csv");
  ASSERT_EQ(j["discovered_terms"].size(), 3u);
  EXPECT_EQ(j["discovered_terms"][0]["verdict"], "proposed: held-out RMS 2 -> 1");
  EXPECT_EQ(j["discovered_terms"][1]["verdict"], "not proposed: no held-out gain beyond its spread: held-out RMS 2 -> 2");
  EXPECT_EQ(j["discovered_terms"][2]["verdict"], "no term: cross-validation finds none");
  const std::string summary = quadgen::diagnose::diagnosis_summary(d);
  const size_t line = summary.find("proposed term");
  ASSERT_NE(line, std::string::npos) << summary;
  const std::string proposed_line = summary.substr(line, summary.find('\n', line) - line);
  EXPECT_NE(proposed_line.find(" [rad/s²]; held-out RMS 2 -> 1"), std::string::npos) << proposed_line;
  EXPECT_EQ(proposed_line.find("proposed", 1), std::string::npos) << proposed_line;
  const std::string html = quadgen::diagnose::diagnosis_html(d, "log.csv", {});
  EXPECT_NE(html.find("<b>proposed</b>: held-out RMS 2 &rarr; 1"), std::string::npos);
  EXPECT_NE(html.find("v_bx: 0.5 [0.4, 0.6] rad/s²/(m/s)"), std::string::npos) << html;
  EXPECT_NE(html.find(">not proposed: no held-out gain beyond its spread"), std::string::npos);
  EXPECT_NE(html.find(">no term: cross-validation finds none"), std::string::npos);
  EXPECT_EQ(html.find("proposed: no term"), std::string::npos);
}

// Each finding says whether it describes the airframe or the flight, as its catalogue entry
// declares (`per_flight`), in diagnosis.json, the terminal summary and the report: diagnoses of
// several flights of one vehicle must agree on the first kind, not on the second.
TEST(DiagnosisReport, EachFindingSaysWhetherItIsTheAirframesOrTheFlights) {
  quadgen::diagnose::Diagnosis d;
  d.metric = "position RMSE [m]";
  for (const std::string e : {"blade_flapping", "motor_gain", "attitude_bias", "cog_offset", "wind"}) {
    quadgen::diagnose::Finding f;
    f.effect = e, f.metric = d.metric, f.before = 0.3, f.after = 0.2;
    d.findings.push_back(f);
    d.candidates.push_back(e);
  }
  const auto j = quadgen::diagnose::diagnosis_json(d, "log.csv");
  const std::string summary = quadgen::diagnose::diagnosis_summary(d);
  const std::string html = quadgen::diagnose::diagnosis_html(d, "log.csv", {});
  const std::string tag = "(a property of the flight, not of the airframe)";
  for (size_t i = 0; i < d.findings.size(); ++i) {
    const std::string& e = d.findings[i].effect;
    const std::string expected = quadgen::find_effect(e).per_flight ? "flight" : "airframe";
    EXPECT_EQ(j["findings"][i]["scope"], expected) << e;
    EXPECT_EQ(j["effect_scopes"][e], expected) << e;
    const bool tagged = summary.find("named " + e + " " + tag + ":") != std::string::npos;
    EXPECT_EQ(tagged, expected == "flight") << summary;
    const size_t h3 = html.find("<h3>" + e);
    ASSERT_NE(h3, std::string::npos) << e;
    const std::string tagged_heading = "<h3>" + e + " <small>" + tag;
    EXPECT_EQ(html.compare(h3, tagged_heading.size(), tagged_heading) == 0, expected == "flight") << e;
  }
  // Said in "In short" and in the finding's heading, for each of the three flight's own.
  size_t tags = 0;
  for (size_t at = html.find("<small>" + tag + "</small>"); at != std::string::npos;
       at = html.find("<small>" + tag + "</small>", at + 1))
    ++tags;
  EXPECT_EQ(tags, 6u) << html;
  d.flights = {"a.csv", "b.csv"};  // jointly: each flight has its own value
  EXPECT_NE(quadgen::diagnose::diagnosis_summary(d).find("named wind (a property of each flight, not of the airframe):"),
            std::string::npos);
  // The catalogue's own declarations, written down independently: trims, the marker frame
  // and a wind belong to the flight; blade flapping and a CoG offset to the airframe.
  EXPECT_EQ(j["effect_scopes"]["motor_gain"], "flight");
  EXPECT_EQ(j["effect_scopes"]["attitude_bias"], "flight");
  EXPECT_EQ(j["effect_scopes"]["wind"], "flight");
  EXPECT_EQ(j["effect_scopes"]["blade_flapping"], "airframe");
  EXPECT_EQ(j["effect_scopes"]["cog_offset"], "airframe");
}

// A suspect or a stand-in that is the flight's own says so too, in the summary and the
// report (a wind standing in indoors is the flight's; a suspected rotor drag the airframe's).
TEST(DiagnosisReport, SuspectsAndStandInsSayWhetherTheyAreTheFlightsOwn) {
  quadgen::diagnose::Diagnosis d;
  d.metric = "position RMSE [m]";
  quadgen::diagnose::StandIn wind;
  wind.candidate.effect = "wind", wind.parameter = "wind.v_x", wind.unit = "m/s", wind.value = 2.5;
  wind.plausible_lower = -0.3, wind.plausible_upper = 0.3, wind.why = "indoors";
  d.stand_ins.push_back(wind);
  for (const std::string e : {"rotor_drag", "motor_gain"}) {
    quadgen::diagnose::Suspected x;
    x.candidate.effect = e, x.failed = "no held-out gain";
    d.suspected.push_back(x);
  }
  d.suspected.front().candidate.parameters.push_back({"rotor_drag.k", "N s^2/m", 1.25e-6});  // said with its value
  d.suspected.front().candidate.parameters.back().at_bound = true;
  quadgen::diagnose::CarriedSuspect carried;
  carried.effect = "motor_gain", carried.beside = "cog_offset";
  d.suspected.back().carried = carried;  // the trims, carried: shown in the report's "Ambiguous"
  const std::string tag = " (a property of the flight, not of the airframe)";
  const std::string summary = quadgen::diagnose::diagnosis_summary(d);
  EXPECT_NE(summary.find("not named: wind" + tag + " (wind.v_x"), std::string::npos) << summary;
  EXPECT_NE(summary.find("suspected, not named: motor_gain" + tag + " (no held-out gain)"), std::string::npos) << summary;
  EXPECT_NE(summary.find("suspected, not named: rotor_drag at rotor_drag.k = 1.25e-06 N s²/m (on its bound) (no held-out gain)"),
            std::string::npos)
      << summary;
  const std::string html = quadgen::diagnose::diagnosis_html(d, "log.csv", {});
  const std::string small = " <small>(a property of the flight, not of the airframe)</small>";
  EXPECT_NE(html.find("<td>wind" + small + "</td>"), std::string::npos) << html;
  EXPECT_NE(html.find("<b>motor_gain</b>" + small + " (suspected"), std::string::npos) << html;
}

// An estimate's interval is printed apart from its value: more digits where three would print
// a side as the value (a weak motor read "-0.08 [-0.08, -0.08]"), never more than twelve, and
// no more where a side is the value (an estimate at its bound).
TEST(DiagnosisReport, AnIntervalIsPrintedApartFromItsValue) {
  namespace words = quadgen::diagnose::words;
  EXPECT_EQ(words::estimate(0.0409, 0.0377, 0.0439), "0.0409 [0.0377, 0.0439]");
  EXPECT_EQ(words::estimate(-0.0800024, -0.080044, -0.07996), "-0.08 [-0.08004, -0.07996]");
  EXPECT_EQ(words::estimate(3.0, 2.5, 3.0), "3 [2.5, 3]");
  EXPECT_EQ(words::estimate(-0.07999999988112305, -0.08000000414517501, -0.07999999561707391),
            "-0.08 [-0.080000004, -0.079999996]");  // a noiseless flight: 7 digits print -0.08 thrice
  EXPECT_EQ(words::estimate(1.0, 1.0 - 1e-14, 1.0 + 1e-14), "1 [1, 1]");
  EXPECT_EQ(words::estimate(0.5, NAN, 0.7), "0.5 [open, 0.7]");
  // against a value it is compared with: that value apart from the sides too
  EXPECT_EQ(words::estimate_against(-0.08, -0.08004, -0.07996, -0.0802), "-0.08 [-0.08004, -0.07996] against -0.0802");
  EXPECT_EQ(words::estimate_against(0.0409, 0.0377, 0.0439, 0.04), "0.0409 [0.0377, 0.0439] against 0.04");
}

// A dimensionless value ("1", as the symbols declare it) is said without a unit in every
// sentence: a stand-in, a suspect and a parameter at its bound once read "0.45 1".
TEST(DiagnosisReport, ADimensionlessValueIsSaidWithoutAUnit) {
  EXPECT_EQ(quadgen::output::unit_after_number("1"), "");
  EXPECT_EQ(quadgen::output::unit_after_number(""), "");
  EXPECT_EQ(quadgen::output::unit_after_number("m/s"), " m/s");
  EXPECT_EQ(quadgen::output::unit_after_number("m/s^2"), " m/s²");  // as a person reads it
  quadgen::diagnose::Diagnosis d;
  quadgen::diagnose::StandIn gain;
  gain.candidate.effect = "motor_gain", gain.parameter = "motor_gain.A", gain.unit = "1", gain.value = 0.45;
  gain.plausible_lower = -0.35, gain.plausible_upper = 0.35, gain.why = "a rotor's spread";
  d.stand_ins.push_back(gain);
  quadgen::diagnose::Suspected x;
  x.candidate.effect = "motor_gain", x.failed = "no held-out gain";
  x.candidate.parameters.push_back({"motor_gain.B", "1", -0.125});
  d.suspected.push_back(x);
  d.at_bounds.push_back({"motor_lag_spread.A", "1", -0.5});
  d.at_bounds.back().lower = -0.5, d.at_bounds.back().upper = 1;
  d.at_bounds.push_back({"thrust_decay.rate", "", 0.005});  // no unit at all: no double blank
  d.at_bounds.back().lower = -1e-4, d.at_bounds.back().upper = 0.005;
  const std::string summary = quadgen::diagnose::diagnosis_summary(d);
  EXPECT_NE(summary.find("(motor_gain.A = 0.45 lies outside [-0.35, 0.35]"), std::string::npos) << summary;
  EXPECT_NE(summary.find("at motor_gain.B = -0.125 (no held-out gain)"), std::string::npos) << summary;
  EXPECT_NE(summary.find("caution: motor_lag_spread.A = -0.5 (lower bound)"), std::string::npos) << summary;
  EXPECT_NE(summary.find("caution: thrust_decay.rate = 0.005 (upper bound)"), std::string::npos) << summary;
}

// An airframe's effect named on one flight, with a look-alike that is the flight's own (a CoG
// offset and motor trims), says that several flights tell them apart, in all three outputs;
// one without such a look-alike (blade flapping) does not, nor does a joint diagnosis.
TEST(DiagnosisReport, AnAirframesCauseWithAFlightsOwnLookAlikeNamedOnOneFlightSaysSo) {
  quadgen::diagnose::Diagnosis d;
  d.metric = "position RMSE [m]";
  for (const std::string e : {"cog_offset", "blade_flapping"}) {
    quadgen::diagnose::Finding f;
    f.effect = e, f.metric = d.metric, f.before = 0.3, f.after = 0.2;
    d.findings.push_back(f);
  }
  const std::string caveat = "named on one flight: motor_gain, a property of the flight, can give the same residual";
  auto j = quadgen::diagnose::diagnosis_json(d, "log.csv");
  EXPECT_EQ(j["findings"][0]["flights_own_look_alikes"].dump(), "[\"motor_gain\"]");
  EXPECT_EQ(j["findings"][1]["flights_own_look_alikes"].dump(), "[]");
  std::string summary = quadgen::diagnose::diagnosis_summary(d);
  const size_t cog = summary.find("named cog_offset"), flapping = summary.find("named blade_flapping");
  ASSERT_TRUE(cog != std::string::npos && flapping != std::string::npos) << summary;
  const size_t said = summary.find(caveat);
  EXPECT_TRUE(said > cog && said < flapping) << summary;  // beside the CoG offset's finding
  EXPECT_EQ(summary.find("named on one flight", said + 1), std::string::npos) << summary;
  std::string html = quadgen::diagnose::diagnosis_html(d, "log.csv", {});
  EXPECT_NE(html.find("<p class=\"warn\">" + caveat), std::string::npos) << html;
  d.flights = {"a.csv", "b.csv"};
  j = quadgen::diagnose::diagnosis_json(d, "log.csv");
  EXPECT_EQ(j["findings"][0]["flights_own_look_alikes"].dump(), "[]");
  EXPECT_EQ(quadgen::diagnose::diagnosis_summary(d).find("named on one flight"), std::string::npos);
  EXPECT_EQ(quadgen::diagnose::diagnosis_html(d, "log.csv", {}).find("named on one flight"), std::string::npos);
  // The catalogue's declarations: only the CoG offset has a look-alike of the flight's own.
  for (const auto& e : quadgen::effect_catalogue())
    EXPECT_EQ(quadgen::flights_own_look_alikes(e.name).empty(), e.name != "cog_offset") << e.name;
}

// Where no environment is declared, the summary and the report say what counted as a plausible
// wind and how to say "indoor" (a user's own mapping may lack the key); not once it is said,
// nor where no candidate's range depends on it.
TEST(DiagnosisReport, AnUndeclaredEnvironmentIsSaidWithTheWindItAllows) {
  quadgen::diagnose::Diagnosis d;
  d.environment = "unknown";
  d.candidates = {"motor_gain", "wind"};
  d.flights = {"a.csv", "b.csv"};
  d.search.final_fit = {{"wind.x", "m/s", 0.1, -20, 20, true}};
  const std::string note = "note: where the flights were flown is unknown";
  const std::string summary = quadgen::diagnose::diagnosis_summary(d);
  EXPECT_NE(summary.find(note), std::string::npos) << summary;
  EXPECT_NE(summary.find("wind counts as plausible within [-15, 15] m/s; indoors only [-0.5, 0.5] m/s would"),
            std::string::npos)
      << summary;
  quadgen::diagnose::Diagnosis one = d;
  one.flights = {"a.csv"};
  EXPECT_NE(quadgen::diagnose::diagnosis_summary(one).find("note: where the flight was flown is unknown"), std::string::npos);
  EXPECT_NE(quadgen::diagnose::diagnosis_html(d, "log.csv", {}).find("<p class=\"warn\">" + note), std::string::npos);
  d.environment = "indoor";
  EXPECT_EQ(quadgen::diagnose::diagnosis_summary(d).find(note), std::string::npos);
  d.environment = "unknown";
  d.candidates = {"motor_gain", "rotor_drag"};
  EXPECT_EQ(quadgen::diagnose::diagnosis_summary(d).find(note), std::string::npos);
}

// What to do next, one line per outcome present, in the summary and the report: the pair's
// manoeuvre, a second flight for an airframe's finding (not in a joint diagnosis), a suspect
// kept out of the vehicle file, a stand-in's value distrusted, the cap raised.
TEST(DiagnosisReport, WhatToDoNextFollowsTheOutcomes) {
  quadgen::diagnose::Diagnosis d;
  d.metric = "position RMSE [m]";
  EXPECT_TRUE(quadgen::diagnose::words::next_steps(d).empty());
  quadgen::diagnose::Finding f;
  f.effect = "blade_flapping", f.metric = d.metric;
  d.findings.push_back(f);
  quadgen::diagnose::Ambiguity a;
  a.a = "input_delay", a.b = "motor_lag", a.manoeuvre = "fast throttle steps";
  d.search.unresolved.push_back(a);
  quadgen::diagnose::Suspected x;
  x.candidate.effect = "ground_effect", x.failed = "no held-out gain";
  d.suspected.push_back(x);
  quadgen::diagnose::StandIn st;
  st.candidate.effect = "wind", st.parameter = "wind.x";
  d.stand_ins.push_back(st);
  d.search.steps.resize(6);  // one more step than the limit: a place given back by the backward pass
  d.search.max_effects = 5;
  d.search.left_at_limit.resize(2);
  const std::string summary = quadgen::diagnose::diagnosis_summary(d);
  for (const std::string said :
       {"next: fly this to tell input_delay from motor_lag, and diagnose that flight with this one: fast throttle steps",
        "next: diagnose this flight with other flights of the vehicle", "next: do not put ground_effect in the vehicle file",
        "next: do not believe wind.x", "next: rerun with --max-effects 7", "next: the fitted model"})
    EXPECT_NE(summary.find(said), std::string::npos) << said << "\n" << summary;
  const std::string html = quadgen::diagnose::diagnosis_html(d, "log.csv", {});
  EXPECT_NE(html.find("<h2>What to do next</h2>\n<ul>\n<li>fly this to tell input_delay from motor_lag"), std::string::npos)
      << html;
  EXPECT_EQ(summary.find("implausible here"), std::string::npos);
  // A suspect whose value is implausible here says so, in the line, the next step and the
  // report's table (the joint NanoBench diagnosis suspected a 4.6 m/s wind indoors, and said
  // only that it failed held out).
  quadgen::diagnose::Diagnosis implausible = d;
  implausible.suspected.front().candidate.evidence.implausible = "ground_effect.radius = 0.113 m outside [0, 0.0675]";
  implausible.suspected.front().candidate.effect = "ground_effect";
  const std::string implausible_summary = quadgen::diagnose::diagnosis_summary(implausible);
  EXPECT_NE(implausible_summary.find("suspected, not named: ground_effect (no held-out gain); implausible here: "
                                     "ground_effect.radius = 0.113 m outside [0, 0.0675]\n"),
            std::string::npos)
      << implausible_summary;
  EXPECT_NE(implausible_summary.find("next: do not put ground_effect in the vehicle file (suspected: no held-out gain); "
                                     "its value is implausible here too: ground_effect.radius = 0.113 m outside [0, 0.0675]\n"),
            std::string::npos)
      << implausible_summary;
  EXPECT_NE(quadgen::diagnose::diagnosis_html(implausible, "log.csv", {})
                .find("suspected, not in the model: no held-out gain; implausible here: ground_effect.radius = 0.113 m "
                      "outside [0, 0.0675]"),
            std::string::npos);
  // Escaped in the report (the text carries a parameter's name, from the vehicle file).
  implausible.suspected.front().candidate.evidence.implausible = "<b>x</b> = 1 outside [0, 0.5]";
  const std::string escaped = quadgen::diagnose::diagnosis_html(implausible, "log.csv", {});
  EXPECT_EQ(escaped.find("<b>x</b>"), std::string::npos);
  EXPECT_NE(escaped.find("implausible here: &lt;b&gt;x&lt;/b&gt; = 1 outside [0, 0.5]"), std::string::npos);
  d.airframe_source = "joint/diagnosis.json", d.airframe_flights = 5;  // checked against a joint airframe already
  EXPECT_EQ(quadgen::diagnose::diagnosis_summary(d).find("with other flights of the vehicle"), std::string::npos);
  d.airframe_flights = 1;  // an airframe from one flight's diagnosis: still worth a joint one
  EXPECT_NE(quadgen::diagnose::diagnosis_summary(d).find("with other flights of the vehicle"), std::string::npos);
  d.airframe_source.clear(), d.airframe_flights = 0;
  d.flights = {"a.csv", "b.csv"};  // jointly: the airframe's findings already hold across flights
  EXPECT_EQ(quadgen::diagnose::diagnosis_summary(d).find("with other flights of the vehicle"), std::string::npos);
  // The limit suggested is one --max-effects accepts (at most 10), and at 10 none is.
  d.search.left_at_limit.resize(7);
  EXPECT_NE(quadgen::diagnose::diagnosis_summary(d).find("next: rerun with --max-effects 10 "), std::string::npos);
  d.search.max_effects = 10;
  const std::string at_largest = quadgen::diagnose::diagnosis_summary(d);
  EXPECT_EQ(at_largest.find("next: rerun with --max-effects"), std::string::npos) << at_largest;
  EXPECT_NE(at_largest.find("--max-effects is at its largest"), std::string::npos) << at_largest;
}

// Each step's table of candidates says which it took and by what rule they are ranked (a
// reader saw two significant candidates and could only infer the pick from the next step).
TEST(DiagnosisReport, EachStepSaysWhichCandidateItTook) {
  quadgen::diagnose::Diagnosis d;
  quadgen::diagnose::SelectionStep step;
  for (const std::string e : {"blade_flapping", "wind"}) {
    quadgen::diagnose::CandidateEvidence c;
    c.effect = e, c.significant = true;
    step.candidates.push_back(c);
  }
  step.candidates.back().implausible = "wind.x = 2 m/s outside [-0.5, 0.5]";
  step.selected = "blade_flapping", step.outcome = "selected";
  d.search.steps.push_back(step);
  const std::string html = quadgen::diagnose::diagnosis_html(d, "log.csv", {});
  EXPECT_NE(html.find("<p>Taken: <b>blade_flapping</b>. Ranked: the significant first"), std::string::npos) << html;
  EXPECT_NE(html.find("<tr><td><b>blade_flapping</b> (taken)</td>"), std::string::npos) << html;
  EXPECT_NE(html.find("<tr><td>wind</td>"), std::string::npos) << html;
  // significant but implausible: not in a cause's green (a user trial, helper-106)
  EXPECT_NE(html.find("<td class=\"warn\">significant; implausible here: wind.x = 2 m/s outside [-0.5, 0.5]</td>"),
            std::string::npos) << html;
}

// A cause named jointly that the flights alone disagree on is flagged where it is named (the
// summary's line and the report's "In short"), not only in the agreement table; one they
// agree on is not.
TEST(DiagnosisReport, AJointCauseTheFlightsDisagreeOnIsFlaggedWhereItIsNamed) {
  quadgen::diagnose::Diagnosis d;
  quadgen::diagnose::Finding f;
  f.effect = "rotor_drag";
  f.metric = d.metric = "position RMSE [m]", f.before = 0.27, f.after = 0.26;
  d.findings.push_back(f);
  quadgen::diagnose::ParameterAgreement a;
  a.parameter = "rotor_drag.k", a.effect = "rotor_drag", a.named = true, a.agree = false, a.q_p_value = 0.0016;
  d.agreement.push_back(a);
  const std::string says = "the flights disagree on rotor_drag.k", says_html = "The flights disagree on rotor_drag.k";
  EXPECT_NE(quadgen::diagnose::diagnosis_summary(d).find("0.26; " + says), std::string::npos)
      << quadgen::diagnose::diagnosis_summary(d);
  const std::string html = quadgen::diagnose::diagnosis_html(d, "log.csv", {});
  const size_t in_short = html.find("<h2>In short</h2>"), findings = html.find("<h2>Findings</h2>");
  ASSERT_NE(in_short, std::string::npos);
  const size_t flagged = html.find(says_html, in_short);
  EXPECT_TRUE(flagged != std::string::npos && flagged < findings) << html.substr(in_short, 600);
  d.agreement.front().agree = true;
  EXPECT_EQ(quadgen::diagnose::diagnosis_summary(d).find(says), std::string::npos);
  EXPECT_EQ(quadgen::diagnose::diagnosis_html(d, "log.csv", {}).find(says_html), std::string::npos);
}

// The base model's shared parameters per flight have a section of their own, after the named
// effects' agreement, and one the flights disagree on is a next step and a summary line; a
// diagnosis with no effect named still shows them (the section is not the effects' appendix).
TEST(DiagnosisReport, TheBaseModelsAgreementIsShownAndADisagreementIsANextStep) {
  namespace dg = quadgen::diagnose;
  dg::Diagnosis d;
  d.flights = {"a.csv", "b.csv"};
  dg::ParameterAgreement c_w;
  c_w.parameter = "c_w", c_w.named = true, c_w.base = true, c_w.agree = false, c_w.within_errors = false, c_w.q_p_value = 1e-4;
  c_w.joint_value = 0.5;
  dg::FlightEstimate e1{0.2, 0.05, 0.1, 0.3, NAN, NAN}, e2{1.5, 0.1, 1.3, 1.7, NAN, NAN};
  c_w.flights = {e1, e2};
  d.base_agreement.push_back(c_w);
  const std::string html = dg::diagnosis_html(d, "log.csv", {});
  const size_t section = html.find("<h2>Do the flights agree on the base model?</h2>");
  ASSERT_NE(section, std::string::npos);
  EXPECT_NE(html.find("<h3>c_w [", section), std::string::npos) << html.substr(section, 1500);
  // Its numbers are read whole, never broken as "1.344e-" / "06" beside the bars.
  EXPECT_NE(html.find("<table class=\"agreement\"><tr><th>flight</th>", section), std::string::npos);
  EXPECT_NE(html.find("table.agreement td:not(:first-child){white-space:nowrap}"), std::string::npos);
  EXPECT_NE(html.find("<li>the flights disagree on the base model&#39;s c_w"), std::string::npos) << html;
  EXPECT_NE(dg::diagnosis_summary(d).find("flights disagree on the base model's c_w (spread"), std::string::npos)
      << dg::diagnosis_summary(d);
  // The fitted parameters' table says it beside the joint value (no longer a bare 0.5).
  d.search.final_fit = {{"c_w", "1", 0.5, 0.05, 3, true}};
  const std::string with_table = dg::diagnosis_html(d, "log.csv", {});
  const size_t row = with_table.find("<tr><td>c_w</td><td>0.5</td>");
  ASSERT_NE(row, std::string::npos) << with_table;
  const std::string row_text = with_table.substr(row, with_table.find("</tr>", row) - row);
  EXPECT_NE(row_text.find("<td class=\"warn\">the flights: disagree"), std::string::npos) << row_text;
  // A flight on its bound is shown without an interval, in the printout and the table.
  dg::Diagnosis bound = d;
  bound.base_agreement.front().flights[0] = dg::FlightEstimate{0.05, 0.5, NAN, NAN, NAN, NAN, true};
  dg::summarise_agreement(bound.base_agreement.front());
  EXPECT_NE(dg::diagnosis_summary(bound).find(": 1: 0.05 (on its bound: no interval), 2: 1.5 [1.3, 1.7]"), std::string::npos)
      << dg::diagnosis_summary(bound);
  EXPECT_NE(dg::diagnosis_html(bound, "log.csv", {}).find("<td>0.05 (on its bound)</td><td>none</td>"), std::string::npos);
  EXPECT_EQ(dg::diagnosis_json(d, "log.csv")["base_agreement"][0]["flights_measuring"], 2);
  EXPECT_EQ(with_table.find("tells it from zero"), std::string::npos);
  // No flight tells it from zero (on its bound, or an interval holding zero), nor do the
  // flights together: the fit chose the value; a next step says to hold it inside every
  // flight's interval, and the table says none tells it from zero.
  dg::Diagnosis unmeasured = d;
  unmeasured.base_agreement.front().flights = {dg::FlightEstimate{0.05, 0.5, NAN, NAN, NAN, NAN, true, 0.05, 3},
                                               dg::FlightEstimate{1.5, 1.0, -0.46, 3.46, NAN, NAN, false, 0.05, 3},
                                               dg::FlightEstimate{0.3, 1.5, -2.64, 3.24, NAN, NAN, false, 0.05, 3}};
  dg::summarise_agreement(unmeasured.base_agreement.front());
  EXPECT_EQ(dg::diagnosis_json(unmeasured, "log.csv")["base_agreement"][0]["flights_measuring"], 0);
  const std::string step = "no flight tells the base model's c_w from zero, nor do the flights together (each value on "
                           "its bound or its interval holding zero): the joint value is the fit's choice, not a "
                           "measurement; hold it in the vehicle file (fit: false) at a value inside every flight's "
                           "interval and its bounds ([0.05, 3]) that you can defend, or fly what would measure it (for the "
                           "frame's drag: faster)";
  const std::string unmeasured_summary = dg::diagnosis_summary(unmeasured);
  EXPECT_NE(unmeasured_summary.find("next: " + step + "\n"), std::string::npos) << unmeasured_summary;
  const std::string unmeasured_html = dg::diagnosis_html(unmeasured, "log.csv", {});
  EXPECT_NE(unmeasured_html.find("<li>no flight tells the base model&#39;s c_w from zero"), std::string::npos)
      << unmeasured_html;
  EXPECT_NE(unmeasured_html.find("<td class=\"warn\">the flights: none tells it from zero"), std::string::npos);
  EXPECT_NE(unmeasured_summary.find("too uncertain to agree on the base model's c_w"), std::string::npos);
  EXPECT_NE(unmeasured_summary.find("no flight tells it from zero: each value is on its bound or its interval holds zero"),
            std::string::npos)
      << unmeasured_summary;
  // A flight on the far bound (c_w at 3 of [0.05, 3]: the fit wanted more) is no sign of zero.
  dg::Diagnosis far_bound = unmeasured;
  far_bound.base_agreement.front().flights[0].value = 3;
  EXPECT_FALSE(dg::measured_by_no_flight(far_bound.base_agreement.front()));
  EXPECT_EQ(dg::diagnosis_summary(far_bound).find("no flight tells the base model"), std::string::npos);
  // Flights that agree on it, or disagree, get no such step, nor the table's note.
  for (const bool agree : {true, false}) {
    dg::Diagnosis judged = unmeasured;
    judged.base_agreement.front().agree = agree, judged.base_agreement.front().within_errors = agree;
    EXPECT_EQ(dg::diagnosis_summary(judged).find("no flight tells the base model"), std::string::npos) << agree;
    EXPECT_EQ(dg::diagnosis_html(judged, "log.csv", {}).find("none tells it from zero"), std::string::npos) << agree;
  }
  EXPECT_EQ(dg::diagnosis_html(d, "log.csv", {}).find("tells it from zero"), std::string::npos);
  d.base_agreement.front().agree = d.base_agreement.front().within_errors = true;
  EXPECT_EQ(dg::diagnosis_html(d, "log.csv", {}).find("the flights: "), std::string::npos);
  EXPECT_EQ(dg::diagnosis_html(d, "log.csv", {}).find("the flights disagree on the base model&#39;s c_w"), std::string::npos);
}

// Each plot beside the section whose numbers it draws, the candidates' tables folded, and a p
// below a double's reach never printed as 0 (a user trial, helper-106; a real flight's finding
// read "p = 0" and its candidates "p = 0.500000" beside "p = 0.5").
TEST(DiagnosisReport, EachPlotIsBesideItsSectionAndTheCandidatesAreFolded) {
  namespace dg = quadgen::diagnose;
  dg::Diagnosis d;
  d.has_prediction = true;
  dg::Finding f;
  f.effect = "rotor_drag", f.evidence.p_value = 0;
  d.findings.push_back(f);
  dg::CandidateEvidence tried;
  tried.effect = "rotor_drag", tried.p_value = 0, tried.significant = true;
  dg::SelectionStep step;
  step.candidates = {tried}, step.selected = "rotor_drag", step.outcome = "selected";
  d.search.steps.push_back(step);
  const std::string html = dg::diagnosis_html(
      d, "f.csv", {{"residuals.svg", "<svg>R</svg>"}, {"profiles.svg", "<svg>P</svg>"}, {"new.svg", "<svg>N</svg>"},
                   {"prediction.svg", "<svg>Q</svg>"}, {"autocorrelation.svg", "<svg>A</svg>"},
                   {"validation.svg", "<svg>V</svg>"}, {"simulation_errors.svg", "<svg>S</svg>"}});
  const auto at = [&](const std::string& s) { return html.find(s); };
  const size_t findings = at("<h2>Findings</h2>"), prediction = at("<h2>Prediction on the held-out part</h2>"),
               channels = at("<h2>Held-out error per channel</h2>"), base = at("<h2>What the base model gets wrong</h2>"),
               candidates = at("<h2>Candidates</h2>"), more = at("<h2>More plots</h2>");
  ASSERT_TRUE(findings < prediction && prediction < channels && channels < base && base < candidates && candidates < more &&
              more != std::string::npos) << html;
  EXPECT_TRUE(at("<svg>P</svg>") > findings && at("<svg>P</svg>") < prediction);
  // the held-out comparison first, then its errors over time, then the error against horizon
  EXPECT_TRUE(prediction < at("<svg>V</svg>") && at("<svg>V</svg>") < at("<svg>S</svg>") &&
              at("<svg>S</svg>") < at("<svg>Q</svg>") && at("<svg>Q</svg>") < channels);
  EXPECT_TRUE(base < at("<svg>R</svg>") && at("<svg>R</svg>") < at("<svg>A</svg>") && at("<svg>A</svg>") < candidates);
  for (const char* svg : {"<svg>P</svg>", "<svg>V</svg>", "<svg>S</svg>", "<svg>Q</svg>", "<svg>R</svg>", "<svg>A</svg>", "<svg>N</svg>"})
    EXPECT_EQ(html.find(svg, html.find(svg) + 1), std::string::npos) << svg;  // each once
  EXPECT_GT(at("<svg>N</svg>"), more);  // a plot no section knows is not lost
  EXPECT_NE(html.find("<details><summary>Step 1 (model: base): took rotor_drag</summary>", candidates), std::string::npos);
  EXPECT_NE(html.find("dof, p &lt; 1e-300 (level"), std::string::npos);
  EXPECT_NE(html.find("<td>&lt; 1e-300</td>", candidates), std::string::npos);
  const std::string none = dg::diagnosis_html(d, "f.csv", {});
  EXPECT_NE(none.find("<h2>Plots</h2>\n<p>No plots (gnuplot unavailable).</p>"), std::string::npos);
  EXPECT_EQ(none.find("More plots"), std::string::npos);
  namespace out = quadgen::output;
  EXPECT_EQ(out::p_is(0.0028751), "p = 0.00288");
  EXPECT_EQ(out::p_is(0.5), "p = 0.5");
  EXPECT_EQ(out::p_is(1e-310), "p < 1e-300");
  EXPECT_EQ(out::p_value_cell(1.08e-143), "1.08e-143");
  EXPECT_EQ(out::p_value_cell(NAN), "–");
}

// One final model, two findings, two different "with it" costs (no pose: each comparison is
// refitted under its own weights): the summary and the page say the lines do not compare
// across; where the figures are one (a position RMSE) nothing is said.
TEST(DiagnosisReport, CostsUnderEachComparisonsOwnWeightsAreSaidSo) {
  namespace dg = quadgen::diagnose;
  dg::Diagnosis d;
  d.metric = "validation equation-error cost (weighted, no pose logged)";
  dg::Finding a, b;
  a.effect = "motor_gain", a.metric = d.metric, a.before = 1162, a.after = 1087;
  b.effect = "motor_lag", b.metric = d.metric, b.before = 1554, b.after = 1303;
  d.findings = {a, b};
  const std::string said = "each line's costs are weighted by its own comparison's refit";
  EXPECT_NE(dg::diagnosis_summary(d).find("without it -> with it; " + said), std::string::npos) << dg::diagnosis_summary(d);
  const std::string said_html = "each line&#39;s costs are weighted by its own comparison&#39;s refit";
  EXPECT_NE(dg::diagnosis_html(d, "f.csv", {}).find("effects overlap; " + said_html), std::string::npos);
  d.findings[1].after = 1087;
  EXPECT_EQ(dg::diagnosis_summary(d).find(said), std::string::npos);
  dg::Finding other = a;  // judged by its own measure, first: not what the others compare with
  other.metric = "held-out equation-error cost (weighted), reduction per validation fold [%]", other.after = 3.5;
  d.findings.insert(d.findings.begin(), other);
  EXPECT_EQ(dg::diagnosis_summary(d).find(said), std::string::npos);
  EXPECT_EQ(dg::diagnosis_html(d, "f.csv", {}).find(said_html), std::string::npos);
}

// What a reader needs within the first screen (a user trial, helper-106): every verdict in one
// table (named with its interval and held-out figures, carried unnamed with its values, a
// stand-in, a suspect), the channels the extended model made worse, and the whole gain in
// the terminal summary too; the words and plots explained; the base model's freed parameters
// with the one on its bound marked; a named cause the flights disagree on gets a next step.
TEST(DiagnosisReport, EveryVerdictIsInOneTableAtTheTop) {
  namespace dg = quadgen::diagnose;
  const auto estimate = [](const std::string& name, const std::string& unit, double value, double lower, double upper) {
    dg::EffectEstimate e;
    e.name = name, e.unit = unit, e.value = value, e.lower = lower, e.upper = upper;
    return e;
  };
  dg::Diagnosis d;
  d.metric = "position RMSE [m]", d.metric_before = 1.2, d.metric_after = 0.45;
  dg::Finding f;
  f.effect = "rotor_drag", f.metric = d.metric, f.before = 0.48, f.after = 0.45;
  f.parameters.push_back(estimate("rotor_drag.k", "N s^2/m", 1.28e-6, 1.11e-6, 1.35e-6));
  d.findings.push_back(f);
  dg::Ambiguity a;
  a.a = "wind", a.b = "attitude_bias";
  d.search.unresolved.push_back(a);
  dg::Suspected x;
  x.candidate.effect = "motor_gain", x.failed = "improves the training data (p = 1e-9) but not the held-out part";
  x.candidate.parameters.push_back(estimate("motor_gain.M2", "1", 0.027, NAN, NAN));
  d.suspected.push_back(x);
  d.search.selected = {"rotor_drag", "wind"};
  // a joint fit's copies by their own names: the plain name is flight 1's
  d.flights = {"dir/B3.csv"};
  d.search.final_fit = {{"wind.x", "m/s", -0.296, -5, 5, true}, {"wind.x@2", "m/s", 0.1, -5, 5, true},
                        {"c_w", "1", 3.0, 0, 3, true}, {"mass", "kg", 0.03, 0, 0, false}, {"kappa", "<b>m^2", 0.5, 0, 1, true}};
  d.at_bounds = {d.search.final_fit[2]};
  d.channel_names = {"az_world"}, d.channel_units = {"m/s^2"};
  d.channel_gain = {{"az_world", 0.2575, 0.371}};
  d.file_values["c_w"] = 1.1;  // beside the fitted value; kappa's is not given: a dash
  d.final_standard_errors = {{"c_w", 0.2}, {"kappa", 0.1}};  // c_w's on its bound: no interval
  const std::string html = dg::diagnosis_html(d, "dir/B3.csv", {{"validation.svg", "<svg></svg>"}});
  const size_t glance = html.find("<table class=\"glance\">"), findings = html.find("<h2>Findings</h2>");
  ASSERT_NE(glance, std::string::npos);
  EXPECT_LT(glance, findings);
  const std::string table = html.substr(glance, html.find("</table>", glance) - glance);
  EXPECT_NE(table.find("<td><b>rotor_drag</b></td><td class=\"ok\">named</td><td>rotor_drag.k = 1.28e-06 N s²/m "
                       "[1.11e-06, 1.35e-06]</td><td>0.48 &rarr; 0.45 (6.25 % lower)</td><td>airframe</td>"),
            std::string::npos) << table;
  EXPECT_NE(table.find("<td><b>wind</b></td><td class=\"warn\">in the model, not named: the data cannot tell it from "
                       "attitude_bias</td><td>wind.x = -0.296 m/s<br>wind.x@2 = 0.1 m/s</td>"),
            std::string::npos) << table;
  EXPECT_NE(table.find("<td class=\"no\">suspected, not in the model: improves the training data (p = 1e-9) but not the "
                       "held-out part</td><td>motor_gain.M2 = 0.027</td>"),
            std::string::npos) << table;
  EXPECT_NE(html.find("Worse with the extended model on the held-out part: az_world 0.2575 &rarr; 0.371 m/s² (44.1 % higher)"),
            std::string::npos);
  EXPECT_EQ(html.find("Overall gain"), std::string::npos);  // said once, in "In short"
  EXPECT_NE(html.find("<h1>Diagnosis of B3.csv ("), std::string::npos);
  EXPECT_NE(html.find("<p class=\"path\">dir/B3.csv</p>"), std::string::npos);
  EXPECT_NE(html.find("<h2 id=\"words\">Words used here</h2>"), std::string::npos);
  EXPECT_NE(html.find("<figcaption><b>What to look for:</b> the held-out part"), std::string::npos);
  const size_t base = html.find("<h2>The vehicle's own parameters, as fitted</h2>");
  ASSERT_NE(base, std::string::npos);
  EXPECT_NE(html.find("<tr><td>c_w</td><td>3</td><td>&ndash;</td><td>1.1</td><td>1</td><td>[0, 3]</td><td class=\"warn\">on "
                      "its bound</td></tr>",
                      base),
            std::string::npos);
  EXPECT_EQ(html.find("<tr><td>mass</td>", base), std::string::npos);  // held, not fitted
  EXPECT_NE(html.find("<tr><td>kappa</td><td>0.5</td><td>[0.304, 0.696]</td><td>&ndash;</td><td>&lt;b&gt;m²</td>", base),
            std::string::npos);  // raised, then escaped
  const auto fits = dg::diagnosis_json(d, "dir/B3.csv")["final_fit"];
  EXPECT_TRUE(fits["c_w"]["ci95"][0].is_null() && fits["c_w"]["ci95"][1].is_null()) << fits["c_w"];  // on its bound
  EXPECT_TRUE(fits["c_w"]["interval_method"].is_null());
  EXPECT_EQ(fits["c_w"]["standard_error"], 0.2);
  EXPECT_NEAR(fits["kappa"]["ci95"][0].get<double>(), 0.5 - 1.959963984540054 * 0.1, 1e-12) << fits["kappa"];
  EXPECT_EQ(fits["kappa"]["interval_method"], "wald");
  EXPECT_TRUE(fits["wind.x"]["standard_error"].is_null());  // none known: null, as the interval
  // The airframe's wind is the mean of the flights' copies: its error and interval null, the keys there.
  d.airframe_fit = {{"wind.x", "m/s", -0.098, -5, 5, true}, {"c_w", "1", 3.0, 0, 3, true}};
  d.final_standard_errors["wind.x"] = 0.01;
  d.final_standard_errors["wind.x@2"] = 0.02;
  // A selected effect's parameter keeps its own interval (a profile here); a flight's copy the
  // data cannot separate has none (add_wald_estimates' NaN), and no method either.
  dg::EffectEstimate own = estimate("wind.x", "m/s", -0.296, -0.31, -0.28);
  dg::EffectEstimate lost = estimate("wind.x@2", "m/s", 0.1, NAN, NAN);
  lost.interval = "wald";
  d.search.estimates = {own, lost};
  d.final_standard_errors["wind.x@2"] = INFINITY;
  const auto with_own = dg::diagnosis_json(d, "dir/B3.csv")["final_fit"];
  EXPECT_EQ(with_own["wind.x"]["interval_method"], "profile") << with_own;
  EXPECT_EQ(with_own["wind.x"]["ci95"][0], -0.31) << with_own;
  EXPECT_TRUE(with_own["wind.x@2"]["interval_method"].is_null()) << with_own;
  EXPECT_TRUE(with_own["wind.x@2"]["standard_error"].is_null()) << with_own;
  dg::Diagnosis joint = d;  // a base parameter per flight: the summary says what @k means
  joint.search.final_fit = {{"c_t", "1", 0.014, 0.002, 0.2, true}, {"c_t@2", "1", 0.0143, 0.002, 0.2, true}};
  EXPECT_EQ(dg::diagnosis_summary(d).find("name@k: flight k's own copy"), std::string::npos);
  EXPECT_NE(dg::diagnosis_summary(joint).find("name@k: flight k's own copy, the plain name flight 1's): c_t = 0.014"),
            std::string::npos)
      << dg::diagnosis_summary(joint);
  const auto airframe = dg::diagnosis_json(d, "dir/B3.csv")["airframe_fit"];
  EXPECT_TRUE(airframe["wind.x"]["standard_error"].is_null() && airframe["wind.x"]["ci95"][0].is_null()) << airframe;
  EXPECT_TRUE(airframe["wind.x"]["interval_method"].is_null()) << airframe;
  EXPECT_EQ(airframe["c_w"]["standard_error"], 0.2) << airframe;  // shared: the final fit's own
  const std::string summary = dg::diagnosis_summary(d);
  EXPECT_NE(summary.find("the vehicle's own parameters, as fitted (95 % Wald interval; the vehicle file's value): c_w = 3 "
                         "(on its bound) (1.1); kappa = 0.5 [0.304, 0.696]\n"),
            std::string::npos)
      << summary;
  EXPECT_NE(summary.find("held out, the extended model against the base model: position RMSE [m] 1.2 -> 0.45 (62.5 % lower)\n"
                         "worse with the extended model on the held-out part: az_world 0.2575 -> 0.371 m/s² (44.1 % higher)\n"),
            std::string::npos) << summary;
  // The page and the console raise the unit's power (above); the file read again keeps it as declared.
  EXPECT_EQ(dg::diagnosis_json(d, "dir/B3.csv")["findings"][0]["parameters"]["rotor_drag.k"]["unit"], "N s^2/m");
  // A stand-in, what the search's limit left and the backward pass dropped have rows too;
  // a hostile name in a reason arrives as text.
  dg::StandIn st;
  st.candidate.effect = "attitude_bias", st.parameter = "attitude_bias.roll", st.plausible_lower = -0.05,
  st.plausible_upper = 0.05;
  d.stand_ins.push_back(st);
  dg::CandidateEvidence left;
  left.effect = "inflow", left.p_value = 1e-3, left.implausible = "<b>x</b>";
  d.search.left_at_limit.push_back(left);
  d.search.removed.push_back({"ground_effect", "its held-out gain <script> vanished", 0.5, 0});
  const std::string more = dg::diagnosis_html(d, "dir/B3.csv", {});
  EXPECT_NE(more.find("<td><b>attitude_bias</b></td><td class=\"warn\">in the model, not named: a stand-in for missing "
                      "physics (attitude_bias.roll outside [-0.05, 0.05])</td>"),
            std::string::npos);
  EXPECT_NE(more.find("<td><b>inflow</b></td><td class=\"no\">not taken: still significant where the search reached its limit "
                      "(--max-effects; p = 0.001; implausible here: &lt;b&gt;x&lt;/b&gt;)</td>"),
            std::string::npos);
  EXPECT_NE(more.find("dropped by the backward pass: its held-out gain &lt;script&gt; vanished"), std::string::npos);
  EXPECT_EQ(more.find("<script>"), std::string::npos);
  // No cause named, an effect carried: the whole gain is still said, and the summary does
  // not call the base model enough.
  dg::Diagnosis carried = d;
  carried.findings.clear();
  const std::string unnamed = dg::diagnosis_html(carried, "dir/B3.csv", {});
  EXPECT_NE(unnamed.find("<li>With what it carries unnamed (below), the model predicts the held-out part "),
            std::string::npos);
  EXPECT_EQ(dg::diagnosis_summary(carried).find("no significant discrepancy"), std::string::npos);
  // A named cause the flights are too uncertain to agree on is said so, not "disagree".
  dg::ParameterAgreement loose;
  loose.parameter = "rotor_drag.k", loose.effect = "rotor_drag", loose.named = true, loose.within_errors = true;
  dg::Diagnosis uncertain_flights = d;
  uncertain_flights.agreement.push_back(loose);
  const std::string loose_html = dg::diagnosis_html(uncertain_flights, "dir/B3.csv", {});
  EXPECT_NE(loose_html.find("<td class=\"warn\">named; the flights are too uncertain to agree on rotor_drag.k</td>"),
            std::string::npos);
  EXPECT_EQ(loose_html.find("disagree on rotor_drag.k"), std::string::npos);
  // A named cause the flights disagree on: a next step; one too uncertain to agree: none.
  dg::ParameterAgreement disagree;
  disagree.parameter = "rotor_drag.k", disagree.effect = "rotor_drag", disagree.named = true;
  disagree.joint_value = 1.0;
  for (double v : {1.0, 1.2, 1.0, 0.8}) disagree.flights.push_back({v, 0.05, v - 0.098, v + 0.098, NAN, NAN});
  dg::summarise_agreement(disagree);
  ASSERT_TRUE(dg::flights_disagree(disagree));
  d.agreement.push_back(disagree);
  const auto steps = dg::words::next_steps(d);
  EXPECT_TRUE(std::any_of(steps.begin(), steps.end(), [](const std::string& s) {
    return s.rfind("the flights disagree on rotor_drag.k: its joint value is no one airframe's", 0) == 0 &&
           // which flights, by the numbers of the agreement lines (4 standard errors each way)
           s.find("lie apart from the pooled value, flights 2 (high) and 4 (low), and the others") != std::string::npos;
  })) << steps.size();
  // A flight with a tiny error sets the pooled value: against its residual's own error (not
  // its standard error) it lies far off, and is named with the others.
  dg::Diagnosis tiny = d;
  dg::ParameterAgreement& t = tiny.agreement.back();
  t.flights.clear();
  for (double v : {1.0, 1.3, 1.3, 1.3, 1.3}) {
    const double se = v == 1.0 ? 0.01 : 0.1;
    t.flights.push_back({v, se, v - 1.96 * se, v + 1.96 * se, NAN, NAN});
  }
  dg::summarise_agreement(t);
  const auto tiny_steps = dg::words::next_steps(tiny);
  EXPECT_TRUE(std::any_of(tiny_steps.begin(), tiny_steps.end(), [](const std::string& s) {
    return s.find("flights 1 (low), 2 (high), 3 (high), 4 (high) and 5 (high), and the others") != std::string::npos;
  }));
  d.agreement.back().within_errors = true;
  const auto uncertain = dg::words::next_steps(d);
  EXPECT_TRUE(std::none_of(uncertain.begin(), uncertain.end(),
                           [](const std::string& s) { return s.find("the flights disagree") != std::string::npos; }));
}

// Joined flights hold their held-out parts apart in time, so a block of equal duration may
// hold no sample; simulating such a flight gives no windows (it read the first sample of an
// empty flight, and a two-flight diagnosis crashed).
TEST(Validation, AFlightWithoutAWindowSimulatesNothing) {
  quadgen::runtime::CompiledModel<quadgen_generated::finken3::Model> model;
  const std::vector<double> p = model.params();
  const quadgen::fit::Flight empty;
  const auto w = quadgen::diagnose::simulate_windows(model, p, empty, {1.0, 0, /*keep_trace=*/true});
  EXPECT_TRUE(w.t.empty());
  EXPECT_EQ(w.position_rmse, 0.0);
}

// How simulate_windows' windows end: run their whole length (one ending exactly at the part's
// end too), cut short by the part's end, cut short by a gap; a start just before a gap scores
// nothing and is no window.
TEST(Validation, WindowsCutShortByTheEndOrAGapAreCounted) {
  quadgen::runtime::CompiledModel<quadgen_generated::finken3::Model> model;
  const auto flight = [](double end, double gap_from, double gap_to) {
    std::string text = "t,u_A,u_B,u_C,u_D,x,y,z,qw,qx,qy,qz,p,q,r\n";
    for (int k = 0; 0.01 * k <= end + 1e-9; ++k)
      if (!(0.01 * k > gap_from + 1e-9 && 0.01 * k < gap_to - 1e-9))
        text += std::to_string(0.01 * k) + ",0.5,0.5,0.5,0.5,0,0,1,1,0,0,0,0,0,0\n";
    quadgen::fit::FlightOptions all_rows;
    all_rows.airborne_only = false;
    all_rows.edge_trim = 0;
    return quadgen::fit::load_flight(quadgen::runtime::parse_csv(text, "w.csv"), {"A", "B", "C", "D"}, all_rows);
  };
  // consecutive windows from 0.3 s (the rotor speeds settle first): 0.3-1.3, 1.3-2.3, 2.3-3.3
  const auto whole = quadgen::diagnose::simulate_windows(model, model.params(), flight(3.3, 9, 9), {1.0, 0, /*keep_trace=*/false});
  EXPECT_EQ(whole.windows, 3u);
  EXPECT_EQ(whole.cut_short, 0u);
  const auto end = quadgen::diagnose::simulate_windows(model, model.params(), flight(3.0, 9, 9), {1.0, 0, /*keep_trace=*/false});
  EXPECT_EQ(end.windows, 3u);  // the last one, 2.3-3.0, cut by the end
  EXPECT_EQ(end.cut_short, 1u);
  // a 0.2 s gap after 1.9 s: 0.3-1.3, 1.3-1.9 (cut by the gap), 2.1-3.1 (the rotors carried
  // across so short a gap), 3.1-3.3 (cut by the end); the start at 1.9 s scores nothing
  const auto gap = quadgen::diagnose::simulate_windows(model, model.params(), flight(3.3, 1.9, 2.1), {1.0, 0, /*keep_trace=*/false});
  EXPECT_EQ(gap.windows, 4u);
  EXPECT_EQ(gap.cut_short, 2u);
  // Held-out folds from 0, 1 and 2 s, windows started every 0.5 s: 0.3 and 0.8 count toward
  // the first fold, 1.3 and 1.8 the second, 2.3 and 2.8 the third. The window from 0.8 s runs
  // on to 1.8 s across the first fold's end, whole; only the last (2.8-3.3) is cut short.
  quadgen::diagnose::WindowOptions folded{1.0, 0.5, /*keep_trace=*/false};
  folded.fold_starts = {0.0, 1.0, 2.0};
  const auto folds = quadgen::diagnose::simulate_windows(model, model.params(), flight(3.3, 9, 9), folded);
  ASSERT_EQ(folds.folds.size(), 3u);
  for (size_t k = 0; k < 3; ++k) EXPECT_EQ(folds.folds[k].windows, 2u) << k;
  EXPECT_EQ(folds.folds[0].cut_short + folds.folds[1].cut_short, 0u);
  EXPECT_EQ(folds.folds[2].cut_short, 1u);
  // The whole part is the folds' windows pooled: the same as without folds.
  const auto unfolded = quadgen::diagnose::simulate_windows(model, model.params(), flight(3.3, 9, 9), {1.0, 0.5, /*keep_trace=*/false});
  EXPECT_EQ(unfolded.windows, 6u);
  EXPECT_NEAR(folds.position_rmse, unfolded.position_rmse, 1e-12 * unfolded.position_rmse);
  double lowest = folds.folds[0].position_rmse, highest = lowest;
  for (const auto& f : folds.folds) lowest = std::min(lowest, f.position_rmse), highest = std::max(highest, f.position_rmse);
  EXPECT_GT(highest, lowest);  // the vehicle drifts off: later windows start further from hover
  EXPECT_GE(folds.position_rmse, lowest);
  EXPECT_LE(folds.position_rmse, highest);
  // Consecutive windows (0.3, 1.3, 2.3 s) under folds from 0, 0.75, 1.3 and 1.5 s: the
  // window from 1.3 s starts exactly at its fold's start; no window starts in the second
  // fold, which has no score and no gain.
  quadgen::diagnose::WindowOptions consecutive{1.0, 0, /*keep_trace=*/false};
  consecutive.fold_starts = {0.0, 0.75, 1.3, 1.5};
  const auto sparse = quadgen::diagnose::simulate_windows(model, model.params(), flight(3.3, 9, 9), consecutive);
  ASSERT_EQ(sparse.folds.size(), 4u);
  for (size_t k : {0, 2, 3}) EXPECT_EQ(sparse.folds[k].windows, 1u) << k;
  EXPECT_EQ(sparse.folds[1].windows, 0u);
  EXPECT_TRUE(std::isnan(sparse.folds[1].position_rmse));
  const auto rmses = quadgen::diagnose::fold_position_rmses(sparse);
  std::vector<double> lower = rmses;
  for (double& x : lower) x *= 0.5;
  const auto gains = quadgen::diagnose::fold_gains(rmses, lower);
  ASSERT_EQ(gains.size(), 3u);
  EXPECT_DOUBLE_EQ(gains[1], 0.5 * rmses[2]);
  // A fold where both models diverged says nothing (its inf - inf made every mean NaN); where
  // one alone did, the gain is infinite for or against it.
  const auto diverged = quadgen::diagnose::fold_gains({0.3, INFINITY, INFINITY, 0.2}, {0.1, INFINITY, 0.5, INFINITY});
  ASSERT_EQ(diverged.size(), 3u);
  EXPECT_DOUBLE_EQ(diverged[0], 0.2);
  EXPECT_EQ(diverged[1], INFINITY);
  EXPECT_EQ(diverged[2], -INFINITY);
}

// The folds and the whole part judge the same windows (each fold those starting in it, run
// their whole second), so a finding's per-fold gain and its before -> after agree. Until
// they did, a contract audit's flight (10 s with rate steps: 3 s held out, four folds of
// 0.75 s against 1 s windows, each fold's windows cut short at its end) named a true motor
// trim on per-fold gains of +0.018 m while its before -> after rose 0.94 -> 0.97 m. Now
// its 1 s windows do not show the trim there: it is reported, with its value, as suspected;
// on a 45 s flight of the same kind it is named by its open-loop gain. Nothing is cautioned.
TEST(Validation, PerFoldGainsAndTheWholePartJudgeTheSameWindows) {
  HiddenCase c;
  c.name = "short_folds";
  c.effects = "motor_gain";
  c.truth = {{"motor_gain.C", -0.08}};
  c.flight_flags = "--excitation 1";  // rate steps: the open loop departs within a window
  for (const double duration : {10.0, 45.0}) {
    const fs::path dir = fresh_directory("quadgen_short_folds_" + std::to_string(static_cast<int>(duration)));
    const json j = diagnose_log(vehicle_file(c), fly(c, dir, "f.csv", duration), dir);
    ASSERT_TRUE(j.contains("notes")) << duration;
    for (const auto& n : j["notes"])
      EXPECT_EQ(n.get<std::string>().find("accepted on its open-loop gain per held-out fold"), std::string::npos) << n;
    bool trim_by_open_loop = false;
    int judged = 0;  // findings accepted by their open-loop gain, whose two numbers are compared
    for (const auto& f : j["findings"]) {
      const auto& g = f["gain"];
      if (f["accepted_by"] != "open-loop position") continue;
      ++judged;
      trim_by_open_loop = trim_by_open_loop || f["effect"] == "motor_gain";
      ASSERT_TRUE(g["before"].is_number() && g["after"].is_number()) << duration << " s: " << f.dump(1);
      EXPECT_LT(g["after"].get<double>(), g["before"].get<double>()) << duration << " s: " << f["effect"];
    }
    // On either flight the trim is reported with its value, named or suspected.
    const json* trim = nullptr;
    for (const char* list : {"findings", "suspected"})
      for (const auto& f : j[list])
        if (f["effect"] == "motor_gain") trim = &f;
    ASSERT_NE(trim, nullptr) << duration << " s: " << j["suspected"].dump(1);
    EXPECT_NEAR((*trim)["parameters"]["motor_gain.C"]["value"].get<double>(), -0.08, 0.005) << duration;
    if (duration > 40) EXPECT_TRUE(trim_by_open_loop && judged > 0) << j["findings"].dump(1);
    std::ifstream summary(dir / "diagnose.log");
    const std::string printed((std::istreambuf_iterator<char>(summary)), {});
    EXPECT_EQ(printed.find("caution: motor_gain"), std::string::npos) << printed;
    fs::remove_all(dir);
  }
}

// The caution, where it is still due: a finding accepted by its per-fold gain whose whole
// part's before -> after rose (the whole part pools the folds' squares, the mean of the
// gains weighs each fold alike), or diverged. It names exactly those findings, asks how the
// windows end only then, and is empty otherwise.
TEST(Validation, TheCautionNamesTheFindingsWhoseTwoNumbersDisagree) {
  using quadgen::diagnose::Finding;
  const auto finding = [](const std::string& effect, const std::string& accepted_by, double before, double after) {
    Finding f;
    f.effect = effect, f.accepted_by = accepted_by, f.before = before, f.after = after;
    return f;
  };
  int asked = 0;
  const auto windows = [&] { return ++asked, std::string("WINDOWS"); };
  std::vector<Finding> findings = {finding("rotor_drag", Finding::kByOpenLoopPosition, 0.30, 0.25),
                                   finding("motor_gain", Finding::kByOpenLoopPosition, 0.94, 0.97),
                                   finding("wind", Finding::kByForceModelAlone, 0.30, 0.31)};
  EXPECT_EQ(quadgen::diagnose::gains_that_disagree_note(findings, windows),
            "motor_gain: accepted on its open-loop gain per held-out fold, while its before -> after over the whole "
            "held-out part rose; WINDOWS; a longer flight or a larger --validation judges more surely");
  findings.push_back(finding("input_delay", Finding::kByOpenLoopPosition, 0.25, std::numeric_limits<double>::infinity()));
  EXPECT_EQ(quadgen::diagnose::gains_that_disagree_note(findings, windows).rfind("motor_gain, input_delay: each accepted", 0),
            0u);
  EXPECT_EQ(asked, 2);
  findings.erase(findings.begin() + 1), findings.pop_back();
  EXPECT_EQ(quadgen::diagnose::gains_that_disagree_note(findings, windows), "");
  EXPECT_EQ(asked, 2);
}

// The acceptance takes out one failed effect at a time, the one the held-out part speaks most
// clearly against: a stand-in whose gain is negative beyond its spread before a cause whose
// gain is merely within its spread (which may pay once the stand-in is gone), and before one
// that failed on its interval with a clear gain.
TEST(Acceptance, TheClearestFailureIsTakenOutFirst) {
  using quadgen::diagnose::Finding;
  const auto failure = [](const std::string& effect, double gain, double se) {
    Finding f;
    f.effect = effect, f.gain_mean = gain, f.gain_standard_error = se;
    return std::pair<Finding, std::string>{f, "failed"};
  };
  std::vector<std::pair<Finding, std::string>> failed = {failure("motor_lag", 0.014, 0.016),
                                                         failure("rotor_drag", 0.885, 0.06),
                                                         failure("attitude_bias", -0.008, 0.0037)};
  EXPECT_EQ(quadgen::diagnose::clearest_failure(failed), 2u);
  failed.pop_back();
  EXPECT_EQ(quadgen::diagnose::clearest_failure(failed), 0u);
  failed.push_back(failure("wind", -0.001, 0.0));  // one fold: no spread, the sign decides
  EXPECT_EQ(quadgen::diagnose::clearest_failure(failed), 2u);
  // The one-step cost speaks too: rollouts better (+1.6 standard errors) but the one-step
  // cost higher (-0.8) goes before rollouts merely unchanged (-0.04) with a lower cost.
  auto thrust_decay = failure("thrust_decay", 0.0074, 0.0045);
  thrust_decay.first.one_step.cost.per_fold = {-10, 2, 5, -12};
  thrust_decay.first.one_step.cost.mean = -3.9, thrust_decay.first.one_step.cost.standard_error = 4.8;
  auto marker_frame = failure("attitude_bias", -0.0005, 0.012);
  marker_frame.first.one_step.cost.per_fold = {24, 24, 20, 8};
  marker_frame.first.one_step.cost.mean = 18.9, marker_frame.first.one_step.cost.standard_error = 3.7;
  EXPECT_EQ(quadgen::diagnose::clearest_failure({marker_frame, thrust_decay}), 1u);
  EXPECT_EQ(quadgen::diagnose::clearest_failure({thrust_decay, marker_frame}), 0u);
}

// Rollouts better beyond their spread do not stand behind an effect with which the held-out
// one-step cost rises: on the helix a thrust decay bettered the 1 s rollouts by 7 mm +- 4 mm
// while the held-out vertical one-step error doubled (cost 3.9 % +- 4.8 % higher).
TEST(Acceptance, RolloutsAloneDoNotStandBehindAHigherOneStepCost) {
  using quadgen::diagnose::Finding;
  using quadgen::diagnose::held_out_test;
  Finding f;
  f.effect = "thrust_decay";
  f.gain_mean = 0.0074, f.gain_standard_error = 0.0045;
  f.one_step.cost.per_fold = {-10, 2, 5, -12};
  f.one_step.cost.mean = -3.9, f.one_step.cost.standard_error = 4.8;
  EXPECT_EQ(held_out_test(f), "");
  f.one_step.cost.mean = 0.5;  // not higher: the rollouts stand behind it
  EXPECT_EQ(held_out_test(f), Finding::kByOpenLoopPosition);
  f.one_step.cost.per_fold.clear();  // no pose: the rollouts are the one-step cost
  f.one_step.cost.mean = -3.9;
  EXPECT_EQ(held_out_test(f), Finding::kByOpenLoopPosition);
}

// A motor lag sharpens every one-step prediction while open-loop rollouts, dominated by an
// attitude drift it does not cause, stay as they were: the one-step gain may stand behind it,
// but only where the rollouts do not speak against it.
TEST(Acceptance, AOneStepGainCountsOnlyWhereTheRolloutsDoNotSpeakAgainstIt) {
  using quadgen::diagnose::Finding;
  using quadgen::diagnose::held_out_test;
  Finding f;
  f.effect = "motor_lag";
  f.gain_mean = 0.02, f.gain_standard_error = 0.01;  // the rollouts better beyond their spread
  EXPECT_EQ(held_out_test(f), Finding::kByOpenLoopPosition);
  f.gain_mean = -0.001, f.gain_standard_error = 0.004;  // the rollouts unchanged within their spread
  EXPECT_EQ(held_out_test(f), "") << "no one-step folds: nothing stands behind it";
  f.one_step.cost.per_fold = {6, 8, 7, 9};
  f.one_step.cost.mean = 7.5, f.one_step.cost.standard_error = 0.6;
  EXPECT_EQ(held_out_test(f), Finding::kByOneStep);
  f.effect = "wind";  // a flight's own quantity: not the one step alone (no force-alone folds here)
  EXPECT_EQ(held_out_test(f), "");
  f.effect = "motor_lag";
  f.one_step.translation.mean = -12, f.one_step.translation.standard_error = 3;
  EXPECT_EQ(held_out_test(f), "") << "the moments bought with a worse force";
  f.one_step.translation.mean = -1;  // within its spread
  EXPECT_EQ(held_out_test(f), Finding::kByOneStep);
  // The vertical residual dominates the sum: a better vertical force can hide a worse
  // horizontal one in it.
  f.one_step.translation.mean = 10, f.one_step.vertical.mean = 15, f.one_step.vertical.standard_error = 3;
  f.one_step.horizontal.mean = -20, f.one_step.horizontal.standard_error = 5;
  EXPECT_EQ(held_out_test(f), "") << "the sum better, the horizontal force worse";
  // The vertical force, set by the flight's thrust constant that every refit moves, counts in
  // the sum only (B2's rotor drag: horizontal 56 % +- 21 % better, vertical 24 % +- 11 % worse).
  f.one_step.translation.mean = 32, f.one_step.translation.standard_error = 17;
  f.one_step.horizontal.mean = 56, f.one_step.horizontal.standard_error = 21;
  f.one_step.vertical.mean = -24, f.one_step.vertical.standard_error = 11;
  EXPECT_EQ(held_out_test(f), Finding::kByOneStep);
  f.one_step.translation.mean = -1, f.one_step.translation.standard_error = 3;
  f.one_step.rotation.mean = -12, f.one_step.rotation.standard_error = 3;
  EXPECT_EQ(held_out_test(f), "") << "the force bought with worse moments";
  f.one_step.rotation.mean = 20;
  EXPECT_EQ(held_out_test(f), Finding::kByOneStep);
  // Roll and pitch dominate the rotational sum: a better one can hide a worse yaw in it.
  f.one_step.yaw.mean = -15, f.one_step.yaw.standard_error = 4;
  EXPECT_EQ(held_out_test(f), "") << "the moments better, the yaw worse";
  EXPECT_NE(quadgen::diagnose::one_step_summary(f).find("bought with worse yaw"), std::string::npos)
      << quadgen::diagnose::one_step_summary(f);
  f.one_step.yaw.mean = -2;  // within its spread
  EXPECT_EQ(held_out_test(f), Finding::kByOneStep);
  f.one_step.yaw.mean = -0.05, f.one_step.yaw.standard_error = 0.02;  // beyond its spread, but negligible
  EXPECT_EQ(held_out_test(f), Finding::kByOneStep) << "a change of hundredths of a per cent is no price";
  f.one_step.yaw.mean = -1.5, f.one_step.yaw.standard_error = 0.2;
  EXPECT_EQ(held_out_test(f), "") << "1.5 % worse beyond its spread";
  f.one_step.yaw.mean = 0;
  f.gain_mean = -0.02;  // the rollouts worse beyond their spread: they refute it
  EXPECT_EQ(held_out_test(f), "");
  f.gain_mean = -0.001;
  f.one_step.cost.mean = 0.5, f.one_step.cost.standard_error = 2;  // one step within its spread
  EXPECT_EQ(held_out_test(f), "");
  f.one_step.cost.mean = -3, f.one_step.cost.standard_error = 0.5;  // one step worse
  EXPECT_EQ(held_out_test(f), "");
}

// A flight's own quantity that acts on the force (the marker frame's tilt) may stand on the
// force model alone: open-loop windows are dominated by the moment model's attitude drift and
// may even get worse (the numbers are B3 rep 2's attitude bias), but with the measured
// attitude replayed its held-out position gain must be beyond its spread, with the one-step
// cost lower beyond its spread and neither kind of channel worse beyond its spread. Motor
// trims act on the moments: this route is not theirs.
TEST(Acceptance, AFlightsOwnQuantityMayStandOnTheForceModelAlone) {
  using quadgen::diagnose::Finding;
  using quadgen::diagnose::held_out_test;
  Finding f;
  f.effect = "attitude_bias";
  f.gain_mean = -0.037, f.gain_standard_error = 0.010;  // the open loop worse beyond its spread
  f.one_step.cost.per_fold = {64, 79, 68, 75};
  f.one_step.cost.mean = 71.5, f.one_step.cost.standard_error = 3.4;
  EXPECT_EQ(held_out_test(f), "") << "the one step alone does not count for a flight's own quantity";
  f.force_alone.per_fold = {0.05, 0.09, 0.11, 0.07};
  f.force_alone.mean = 0.08, f.force_alone.standard_error = 0.013;
  EXPECT_EQ(held_out_test(f), Finding::kByForceModelAlone);
  f.one_step.translation.mean = -12, f.one_step.translation.standard_error = 3;
  EXPECT_EQ(held_out_test(f), "") << "bought with worse translational channels";
  f.one_step.translation.mean = 40;
  f.one_step.horizontal.mean = -30, f.one_step.horizontal.standard_error = 6;
  EXPECT_EQ(held_out_test(f), "") << "the sum better, the horizontal force worse beyond its spread";
  f.one_step.horizontal.mean = 60;
  f.one_step.rotation.mean = -28, f.one_step.rotation.standard_error = 8;  // B3 rep 2's moments
  EXPECT_EQ(held_out_test(f), "") << "bought with worse rotational channels";
  f.one_step.horizontal.mean = -11.4, f.one_step.horizontal.standard_error = 10.9;  // and its horizontal force
  EXPECT_NE(quadgen::diagnose::one_step_summary(f).find("force model alone: 0.08 m +- 0.013 m lower, bought with worse "
                                                       "horizontal force and rotational channels"),
            std::string::npos)
      << quadgen::diagnose::one_step_summary(f);
  f.one_step.horizontal.mean = 60;
  f.one_step.rotation.mean = 1, f.one_step.rotation.standard_error = 2;
  EXPECT_EQ(held_out_test(f), Finding::kByForceModelAlone);
  f.effect = "motor_gain";  // a flight's own quantity on the moments
  EXPECT_EQ(held_out_test(f), "") << "trims are not judged by the force model";
  f.effect = "attitude_bias";
  f.one_step.cost.mean = 1, f.one_step.cost.standard_error = 2;
  EXPECT_EQ(held_out_test(f), "") << "no one-step gain beyond its spread";
  f.one_step.cost.mean = 71.5, f.one_step.cost.standard_error = 3.4;
  f.force_alone.mean = 0.01, f.force_alone.standard_error = 0.013;
  EXPECT_EQ(held_out_test(f), "") << "the force model alone not better beyond its spread";
  f.force_alone.mean = 0.08;
  f.effect = "cog_offset";  // the airframe's: its routes are the open loop and the one step
  EXPECT_EQ(held_out_test(f), "") << "the rollouts refute an airframe effect";
}

// End to end, the route the test above decides: a 50 ms motor lag in a flight whose mocap is
// noisy (6 cm, 0.06 rad, 0.6 m/s) so that 1 s rollouts from its measured states cannot see the
// lag beyond their spread, while gyro and accelerometer show it plainly one step at a time
// (held-out cost about 25 % lower per fold). It must be named, by its one-step gain, with the
// truth inside its interval. (Excluded from the sanitizer run: the acceptance code it reaches
// is the one Acceptance.* runs instrumented.)
TEST(OneStep, ALagTheRolloutsCannotSeeIsNamedByItsOneStepGain) {
  const HiddenCase c{"lag_noisy_pose", "motor_lag", {{"motor_lag.tau", 0.05}}, {}, "--pose-noise 0.06", 1};
  const json j = diagnose(c);
  const json* lag = nullptr;
  for (const auto& f : j["findings"])
    if (f["effect"] == "motor_lag") lag = &f;
  ASSERT_NE(lag, nullptr) << j["findings"].dump(1) << j["suspected"].dump(1);
  const json& g = (*lag)["gain"];
  EXPECT_LT(g["gain_mean"].get<double>(), g["gain_standard_error"].get<double>())
      << "the premise: the rollouts alone would not have named it";
  EXPECT_EQ((*lag)["accepted_by"], quadgen::diagnose::Finding::kByOneStep);
  const auto ci = (*lag)["parameters"]["motor_lag.tau"]["ci95"];
  EXPECT_LT(ci[0].get<double>(), 0.05);
  EXPECT_GT(ci[1].get<double>(), 0.05);
}

// The model a finding is compared with is the one a user would fit without the effect: under
// the weights of its own residuals, not under those of the model with the effect. Here the
// model with a weak motor is the final one; without the motor gain, the search's own base
// fit (fitted, reweighted by its residuals, refitted) is what one would fit: its weights are
// those of its own residuals within 0.3 %. Starting from the final model and its weights
// (a channel's weight 366 times the base fit's), or from weights that exaggerate one channel
// 30-fold, the model without the effect must come back with the base fit's weights and
// thrust constant. One reweighting left them a factor 2 apart and c_t 3-5 % off.
// A 30 s flight with a weak motor (8 % less thrust), diagnosed only as far as the search:
// the final model names the motor gain; the base model is the one without it.
class WeakMotorSearch : public ::testing::Test {
 protected:
  void SetUp() override {
    // A directory per test: ctest runs the fixture's tests in parallel.
    const fs::path dir =
        fresh_directory(std::string("quadgen_weak_motor_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    const HiddenCase c{"own_weights", "motor_gain", {{"motor_gain.C", -0.08}}, {}, "", 1};
    const fs::path log = fly(c, dir, "flight.csv", 30);
    const quadgen::Vehicle v = quadgen::load_vehicle(vehicle_file(c));
    quadgen::DeriveOptions all_opt;
    all_opt.effects = quadgen::parse_effect_list("all");
    all_ = std::make_unique<quadgen::SymbolicModel>(quadgen::derive_model(v, quadgen::derive_mass_properties(v), all_opt));
    model_ = quadgen::app::make_model(*all_);
    std::vector<std::string> rotors;
    for (const auto& r : v.rotors) rotors.push_back(r.name);
    const auto flight = quadgen::fit::load_flight(quadgen::fit::read_log(log.string(), nullptr, 0), rotors, {});
    std::tie(train_, valid_) = quadgen::fit::split_by_time(flight, 0.7);
    train_ee_ = std::make_unique<quadgen::fit::EquationErrorModel>(*model_, train_, true);
    valid_ee_ = std::make_unique<quadgen::fit::EquationErrorModel>(*model_, valid_, true);
    quadgen::diagnose::SearchOptions so;
    so.candidates = {"motor_gain"};
    search_ = std::make_unique<quadgen::diagnose::CandidateSearch>(*all_, *model_, *train_ee_, *valid_ee_, so);
    result_ = search_->run();
    ASSERT_EQ(result_.named(), std::vector<std::string>{"motor_gain"});
  }
  std::unique_ptr<quadgen::SymbolicModel> all_;
  std::unique_ptr<quadgen::runtime::DynamicModel> model_;
  quadgen::fit::Flight train_, valid_;
  std::unique_ptr<quadgen::fit::EquationErrorModel> train_ee_, valid_ee_;
  std::unique_ptr<quadgen::diagnose::CandidateSearch> search_;
  quadgen::diagnose::SearchResult result_;
};

TEST_F(WeakMotorSearch, TheModelWithoutAnEffectIsFittedUnderItsOwnWeights) {
  const auto& r = result_;
  auto& search = *search_;
  const auto& model = model_;
  const auto relative_distance = [](const std::vector<double>& a, const std::vector<double>& b) {
    double worst = 0;
    for (size_t k = 0; k < a.size(); ++k) worst = std::max(worst, std::abs(a[k] / b[k] - 1));
    return worst;
  };
  const double final_from_base = relative_distance(r.final_weights, r.base_weights);
  EXPECT_GT(final_from_base, 0.3) << "the two models' weights hardly differ: the test shows nothing";
  std::vector<double> skewed = r.final_weights;
  skewed[0] *= 30;
  for (const auto& start : {r.final_weights, skewed}) {
    std::vector<double> own;
    quadgen::diagnose::Settling settling;
    const auto without = search.fit_as_own_model({}, r.final_fit, start, &own, &settling);
    EXPECT_LT(relative_distance(own, r.base_weights), 0.02);  // settled within 1 %, the base fit within 0.3 %
    // What the report says of it: settled, after more than one reweighting, the last within 1 %.
    EXPECT_TRUE(settling.settled);
    EXPECT_GT(settling.refits, 1);
    EXPECT_LT(settling.last_change_percent, 1.0);
    EXPECT_NEAR(without[model->param_index("c_t")].value, r.base_fit[model->param_index("c_t")].value,
                1e-3 * r.base_fit[model->param_index("c_t")].value);
  }
}

// Intervals are profiled under the final model's weights, whatever weights the search last
// used: after remove_effects the two differ (the smaller model is refitted under its own),
// and a profile measured from a cost under the search's weights never closed on a real
// flight (B3 rep 2: every interval open or containing "off"). Doubling the final weights
// halves a Wald interval; the profile must follow it.
TEST_F(WeakMotorSearch, IntervalsAreProfiledUnderTheFinalModelsOwnWeights) {
  quadgen::diagnose::SearchResult doubled = result_;
  for (double& w : doubled.final_weights) w *= 2;
  search_->profile_intervals(doubled);
  search_->profile_intervals(result_);
  ASSERT_EQ(doubled.estimates.size(), result_.estimates.size());
  ASSERT_FALSE(result_.estimates.empty());
  const auto width = [](const quadgen::diagnose::EffectEstimate& e) {
    return e.upper - e.lower - 2 * e.numerical_allowance;
  };
  for (size_t k = 0; k < result_.estimates.size(); ++k) {
    const auto& a = result_.estimates[k];
    const auto& b = doubled.estimates[k];
    ASSERT_TRUE(std::isfinite(width(a)) && std::isfinite(width(b))) << a.name << ": an interval is open";
    // The quadrature allowance added to both sides does not scale with the weights.
    ASSERT_NEAR(a.numerical_allowance, b.numerical_allowance, 1e-3 * width(a)) << a.name;
    EXPECT_NEAR(width(b) / width(a), 0.5, 0.05) << a.name;
    EXPECT_NEAR(width(a), 2 * 1.96 * a.standard_error, 0.2 * width(a)) << a.name << ": profile and Wald disagree";
    // The quadrature rules differ little at 100 Hz: their allowance is a small part of the
    // interval (here 1e-8 beside 1e-4 to 1e-3), so an allowance grown by a slip (a part of the
    // value added, say) shows (a review of the tests, helper-126: nothing bounded a width).
    EXPECT_LT(a.numerical_allowance, 0.1 * width(a)) << a.name;
  }
}

// What a finding is compared with, end to end: the held-out gain of the lone motor gain is
// measured against the search's base fit, the model the report shows when nothing is named
// (refitted under the final model's weights instead, its rollouts were 1.5 % off).
TEST_F(WeakMotorSearch, ALoneEffectIsComparedWithTheBaseFit) {
  const quadgen::diagnose::HeldOutGain held_out(*model_, *search_, valid_, *valid_ee_, true, 1.0, 0.1);
  const quadgen::diagnose::Finding f = held_out.finding_for("motor_gain", result_);
  const double base = held_out.metric(result_.base_fit, result_.final_weights, nullptr);
  EXPECT_NEAR(f.before, base, 1e-9 * base);  // the same model, not one near it (a refit was 1.5 % off)
  EXPECT_GT(f.before - f.after, 0.1 * base) << "the weak motor must pay on held-out data";
  ASSERT_TRUE(f.comparison.has_value());
  EXPECT_TRUE(f.comparison->base_fit) << "the report must say it was compared with the base fit";
}

// The comparison model is cached per final model: asked again after the final model lost an
// effect (acceptance's remove_effects), it must be fitted anew, not returned from the cache.
TEST_F(WeakMotorSearch, TheComparisonModelFollowsTheFinalModel) {
  const quadgen::diagnose::HeldOutGain held_out(*model_, *search_, valid_, *valid_ee_, true, 1.0, 0.1);
  quadgen::diagnose::SearchResult two = result_;
  two.selected = {"motor_gain", "motor_lag"};
  std::vector<double> w;
  quadgen::diagnose::Settling with_lag, alone, again;
  held_out.model_without("motor_gain", two, &w, &with_lag);
  EXPECT_FALSE(with_lag.base_fit) << "the model without the trims but with the lag is refitted";
  held_out.model_without("motor_gain", result_, &w, &alone);
  EXPECT_TRUE(alone.base_fit) << "a cached model of another final model was returned";
  held_out.model_without("motor_gain", two, &w, &again);
  EXPECT_FALSE(again.base_fit);
}

// A refinement leaves the model with what it refines: motor_lag_spread scales motor_lag's
// time constant and changes nothing without it. remove_effects takes it out with the lag
// (carried or named).
TEST_F(WeakMotorSearch, ARefinementLeavesTheModelWithWhatItRefines) {
  quadgen::diagnose::SearchResult r = result_;
  r.selected = {"motor_gain", "motor_lag", "motor_lag_spread"};
  r.carried = {"motor_lag_spread"};
  search_->remove_effects(r, {"motor_lag"});
  EXPECT_EQ(r.selected, std::vector<std::string>{"motor_gain"});
  EXPECT_TRUE(r.carried.empty());
}

// The net behind the look-alike checks: a spread left named without its lag (no step makes
// one today, so the state is built by hand) is listed as suspected with the reason, loses
// its look-alike pairs and leaves the model; the other finding stays, with fresh values.
TEST_F(WeakMotorSearch, ARefinementLeftWithoutItsEffectIsDroppedAndSuspected) {
  quadgen::diagnose::Diagnosis d;
  d.search = result_;
  d.search.selected = {"motor_gain", "motor_lag_spread"};
  d.search.unresolved = {{"motor_lag_spread", "motor_gain"}, {"motor_gain", "cog_offset"}};
  quadgen::diagnose::Finding gain, spread;
  gain.effect = "motor_gain";
  spread.effect = "motor_lag_spread";
  d.findings = {gain, spread};
  d.search.estimates.clear();  // so that only profiling them again can fill them
  d.search.profiles.clear();
  quadgen::diagnose::drop_refinements_without_their_effect(d, *search_);
  ASSERT_EQ(d.findings.size(), 1u);
  EXPECT_EQ(d.findings[0].effect, "motor_gain");
  EXPECT_FALSE(d.findings[0].parameters.empty()) << "the remaining finding's values are not filled in again";
  ASSERT_EQ(d.suspected.size(), 1u);
  EXPECT_EQ(d.suspected[0].candidate.effect, "motor_lag_spread");
  EXPECT_EQ(d.suspected[0].failed, "motor_lag, whose terms it scales, left the model");
  EXPECT_EQ(d.search.selected, std::vector<std::string>{"motor_gain"});
  ASSERT_EQ(d.search.unresolved.size(), 1u);
  EXPECT_EQ(d.search.unresolved[0].b, "cog_offset");
  EXPECT_FALSE(d.search.estimates.empty()) << "the intervals are not profiled again";
  EXPECT_FALSE(d.search.profiles.empty()) << "the intervals are not profiled again";
  for (const auto& e : d.search.estimates) EXPECT_EQ(e.name.rfind("motor_lag_spread", 0), std::string::npos) << e.name;
  // Nothing to drop: nothing changes.
  const auto before = d.search.selected;
  quadgen::diagnose::drop_refinements_without_their_effect(d, *search_);
  EXPECT_EQ(d.search.selected, before);
  EXPECT_EQ(d.suspected.size(), 1u);
}

// A joint diagnosis refits a named lag spread per flight without its reference rotor (held at
// 0, the others relative to it); before, the reference's missing estimate left the spread out
// of the agreement check altogether. A spread whose lag is not named is left out: with the lag
// off it scales nothing, and each flight's value would be its start.
TEST_F(WeakMotorSearch, TheAgreementCheckRefitsASpreadWithItsLagButNotItsReference) {
  const auto spread_params = quadgen::diagnose::effect_parameters(*all_, "motor_lag_spread");
  ASSERT_GE(spread_params.size(), 4u);
  quadgen::diagnose::Finding lag, spread, gain;
  lag.effect = "motor_lag";
  lag.parameters.push_back({"motor_lag.tau", "s", 0.05, 0.001, 0.04, 0.06});
  spread.effect = "motor_lag_spread";
  for (size_t i = 1; i < spread_params.size(); ++i)  // the first rotor is the reference: no estimate
    spread.parameters.push_back({spread_params[i], "1", 0.1 * static_cast<double>(i), 0.01, 0.0, 0.5});
  gain.effect = "motor_gain";  // a flight's own quantity: each flight has its own value anyway
  quadgen::diagnose::Diagnosis d;
  d.search = result_;
  d.findings = {lag, spread, gain};
  const auto in = quadgen::diagnose::agreement_inputs(d, *all_, *model_, {}, 0.3, false, {});
  ASSERT_EQ(in.effects.size(), 2u);
  EXPECT_EQ(in.effects[0].name, "motor_lag");
  EXPECT_EQ(in.effects[1].name, "motor_lag_spread");
  EXPECT_EQ(in.effects[1].parameters, std::vector<std::string>(spread_params.begin() + 1, spread_params.end()));
  EXPECT_DOUBLE_EQ(in.effects[1].start[1], 0.2);
  // The lag gone (suspected, say): a suspected spread without it is not refitted either.
  d.findings = {gain};
  quadgen::diagnose::Suspected suspect;
  suspect.candidate = spread;
  d.suspected = {suspect};
  EXPECT_TRUE(quadgen::diagnose::agreement_inputs(d, *all_, *model_, {}, 0.3, false, {}).effects.empty());
}

// A comparison whose weights had not settled is said beside the gain, in the summary the
// command prints (and the report quotes); a settled one adds nothing.
TEST(Acceptance, AnUnsettledComparisonIsSaidBesideTheGain) {
  quadgen::diagnose::Diagnosis d;
  quadgen::diagnose::Finding f;
  f.effect = "motor_lag";
  f.metric = "m";
  f.comparison = quadgen::diagnose::Settling{false, 10, false, 12.3};
  d.findings.push_back(f);
  EXPECT_NE(quadgen::diagnose::diagnosis_summary(d).find("had not settled its weights after 10 refits (last change 12"),
            std::string::npos)
      << quadgen::diagnose::diagnosis_summary(d);
  d.findings.front().comparison->settled = true;
  EXPECT_EQ(quadgen::diagnose::diagnosis_summary(d).find("had not settled"), std::string::npos);
}

// The reference files are the bytes the README's real-data results were measured on
// (data/reference_data.sha256, docs/reference_data.md): a later commit of a dataset, or a
// file converted again, would change the numbers without a word otherwise.
TEST(RealData, TheReferenceFilesAreTheOnesTheResultsWereMeasuredOn) {
  std::ifstream list(fs::path(QUADGEN_SOURCE_DIR) / "data/reference_data.sha256");
  ASSERT_TRUE(list.good());
  std::string line;
  int checked = 0;
  while (std::getline(list, line)) {
    if (line.empty() || line[0] == '#') continue;
    const std::string hash = line.substr(0, 64), relative = line.substr(line.find_first_not_of(' ', 64));
    const fs::path file = quadgen::test::shared_data(relative);
    QUADGEN_NEEDS_SHARED_DATA(file);
    std::ifstream in(file, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(quadgen::sha256_hex(bytes), hash) << relative;
    ++checked;
  }
  EXPECT_EQ(checked, 15);  // six flights with their metadata, the ARPL log, two stand runs
}

// A log without a pose (an IMU and the commands, as the ARPL log): no rollouts, so the
// held-out gain is the one-step cost's, judged on four folds of equal held-out time (until
// the fifty-ninth session on one fold, by its sign; a statistics review, helper-128), its
// per-fold gains the one-step route's own, and no line speaks of rollouts it has not got. A
// weak motor hidden in a generated flight, its pose left out by the mapping.
TEST(NoPose, AGainIsJudgedOnFourFoldsOfTheOneStepCost) {
  const fs::path dir = fresh_directory("quadgen_no_pose");
  const HiddenCase c{"weak_motor", "motor_gain", {{"motor_gain.C", -0.08}}, {}, "", 1};
  const fs::path log = fly(c, dir, "flight.csv", 40);
  // x alone of the pose: not read, and the flight's note says why.
  std::ofstream(dir / "imu_only.yaml") << "name: imu_only\ncolumns:\n"
                                       << "  t: {source: t, unit: s}\n  x: {source: x, unit: m}\n"
                                       << "  p: {source: p, unit: rad/s}\n  q: {source: q, unit: rad/s}\n  r: {source: r, unit: rad/s}\n"
                                       << "  ax: {source: ax, unit: m/s^2}\n  ay: {source: ay, unit: m/s^2}\n  az: {source: az, unit: m/s^2}\n"
                                       << "  u_A: {source: u_A, unit: \"1\"}\n  u_B: {source: u_B, unit: \"1\"}\n"
                                       << "  u_C: {source: u_C, unit: \"1\"}\n  u_D: {source: u_D, unit: \"1\"}\n";
  ASSERT_EQ(run(std::string(QUADGEN_BINARY) + " diagnose " + vehicle_file(c) + " " + log.string() + " --mapping " +
                (dir / "imu_only.yaml").string() + " --out " + (dir / "out").string() + " > " +
                (dir / "diagnose.log").string() + " 2>&1"),
            "");
  std::ifstream in(dir / "out" / "diagnosis.json");
  json j;
  in >> j;
  ASSERT_FALSE(j["findings"].empty()) << j["selection"].dump(1);
  for (const auto& f : j["findings"]) {
    EXPECT_NE(f["gain"]["metric"].get<std::string>().find("no pose logged"), std::string::npos) << f["gain"].dump();
    EXPECT_EQ(f["gain"]["fold_gains"].size(), 4u) << f["effect"];
    EXPECT_EQ(f["gain"]["fold_gains"], f["one_step_gain"]["fold_gains"]) << f["effect"];
    EXPECT_EQ(f["accepted_by"], "one-step equation error") << f["effect"];
  }
  // Why the x logged is not read is the log's note: said before the work, and kept in the
  // diagnosis (diagnosis.json "notes", the report's cautions), which had it on the terminal only.
  ASSERT_FALSE(j["notes"].empty());
  EXPECT_EQ(j["notes"][0].get<std::string>().find(log.string() + " (columns named by "), 0u) << j["notes"].dump(1);
  EXPECT_NE(j["notes"][0].get<std::string>().find("no pose is read, only the accelerometer"), std::string::npos);
  std::ifstream report_in(dir / "out" / "report.html");
  const std::string report((std::istreambuf_iterator<char>(report_in)), std::istreambuf_iterator<char>());
  EXPECT_NE(report.find("Caution: " + log.string()), std::string::npos);
  std::ifstream said_in(dir / "diagnose.log");
  const std::string said((std::istreambuf_iterator<char>(said_in)), std::istreambuf_iterator<char>());
  EXPECT_NE(said.find("lower per fold (no pose logged: no rollouts)"), std::string::npos) << said;
  EXPECT_EQ(said.find("rollouts unchanged"), std::string::npos) << said;
}

// --max-effects counts the final model's effects: one the backward pass drops gives its place
// back, and the search goes on without it (never tried again). On NanoBench's B3 figure-8
// rep 2 the pass drops the motor lag beside the input delay; until 2026-12-07 the search
// then ended with four effects while rotor drag, which every other usable flight of the
// airframe names, was still significant (p = 1e-11), and the ay_world residual that follows
// the body velocity (r = 0.92) was left unexplained.
TEST(RealData, APlaceTheBackwardPassGivesBackIsTakenAgain) {
  const fs::path log = quadgen::test::shared_data("crazyflie/nanobench/B3_figure8_medium_rep2.csv");
  QUADGEN_NEEDS_SHARED_DATA(log);
  const fs::path dir = fresh_directory("quadgen_place_given_back");
  const std::string source = QUADGEN_SOURCE_DIR;
  const json j = diagnose_log(source + "/vehicles/crazyflie21_nanobench.yaml --mapping " + source + "/data/mappings/nanobench.yaml",
                              log, dir);
  ASSERT_FALSE(j["removed_by_backward_pass"].empty()) << "nothing dropped: this flight no longer tests the rule";
  EXPECT_EQ(j["max_effects"], 5);
  std::set<std::string> in_model;
  for (const auto& e : j["extended_model"]["effects"]) in_model.insert(e.get<std::string>());
  EXPECT_GT(j["selection"].size(), 5u) << "no step after the place was given back";
  // The selection's model: one effect a step that took one, less those dropped.
  size_t selected = 0;
  for (const auto& step : j["selection"]) selected += step["outcome"] == "nothing significant" ? 0 : 1;
  EXPECT_LE(selected - j["removed_by_backward_pass"].size(), 5u);
  EXPECT_TRUE(in_model.count("rotor_drag")) << j["extended_model"].dump();
  // A dropped effect is not a candidate again (the search cannot cycle) and not in the model.
  for (const auto& r : j["removed_by_backward_pass"]) {
    const std::string dropped = r["effect"];
    EXPECT_FALSE(in_model.count(dropped)) << dropped;
    int taken = 0;
    for (const auto& step : j["selection"]) taken += step["selected"] == dropped ? 1 : 0;
    EXPECT_EQ(taken, 1) << dropped;
    // Tested beside the model of its round, which the search then changed: the reason says so.
    const std::string reason = r["reason"];
    EXPECT_EQ(reason.find("of the final model"), std::string::npos) << reason;
    EXPECT_NE(reason.find("(the model then; the search went on after it)"), std::string::npos) << reason;
  }
}

// A real log as the issue's target states it: the ARPL log's motor time constant, whose
// 95 % interval must contain its authors' published 0.072 s. It guards the fits against
// changes that pass on generated flights: settling the base model's weights to their fixed
// point let this log's vertical weight run down, halved c_t and named an input delay
// instead of the lag (fifteenth session).
TEST(RealData, ArplMotorLagIntervalContainsTheAuthorsValue) {
  const fs::path log = quadgen::test::shared_data("crazyflie/arpl/log10.csv");
  QUADGEN_NEEDS_SHARED_DATA(log);
  const fs::path dir = fresh_directory("quadgen_arpl_lag");
  const std::string source = QUADGEN_SOURCE_DIR;
  ASSERT_EQ(run(std::string(QUADGEN_BINARY) + " diagnose " + source + "/vehicles/crazyflie21.yaml " + log.string() +
                " --mapping " + source + "/data/mappings/arpl.yaml --resample 200 --out " + (dir / "out").string() +
                " > " + (dir / "diagnose.log").string() + " 2>&1"),
            "");
  std::ifstream in(dir / "out" / "diagnosis.json");
  json j;
  in >> j;
  const json* tau = nullptr;
  for (const auto& f : j["findings"])
    if (f["effect"] == "motor_lag") tau = &f["parameters"]["motor_lag.tau"];
  ASSERT_NE(tau, nullptr) << "the motor lag is not named: " << named(j).size() << " findings";
  EXPECT_LE((*tau)["ci95"][0].get<double>(), 0.072);
  EXPECT_GE((*tau)["ci95"][1].get<double>(), 0.072);
  // No pose: its held-out gain is judged on four folds of the one-step cost, as with a pose on
  // four of the rollouts (until the fifty-ninth session on one, by its sign; helper-128), and
  // no line speaks of rollouts it has not got.
  for (const auto& f : j["findings"]) EXPECT_EQ(f["gain"]["fold_gains"].size(), 4u) << f["effect"];
  std::ifstream said_in(dir / "diagnose.log");
  const std::string said((std::istreambuf_iterator<char>(said_in)), std::istreambuf_iterator<char>());
  EXPECT_NE(said.find("lower per fold (no pose logged: no rollouts)"), std::string::npos) << said;
  EXPECT_EQ(said.find("the rollouts unchanged"), std::string::npos) << said;
}

// The command-gain table shows no gain where the commands explain too little of the measured
// (a user trial: an exact model flown without excitation read 0.23-0.41 in roll and pitch,
// at r 0.04-0.1, under "1: the slope is right").
TEST(ReportWords, ACommandGainTheCommandsDoNotExplainIsNotShown) {
  quadgen::diagnose::Diagnosis d;
  d.command_gain.measured = true;
  using Band = quadgen::diagnose::CommandGain::Band;
  d.command_gain.axes = {{"roll", {Band{8.3, 17, 0.234, 0.098, 0.08}, Band{4.2, 8.3, 0.987, 0.91, 0.04}}}};
  const std::string html = quadgen::diagnose::diagnosis_html(d, "f.csv", {});
  EXPECT_NE(html.find("<td>&mdash; (r 0.098)</td>"), std::string::npos);
  EXPECT_EQ(html.find("0.23 (r"), std::string::npos);
  EXPECT_NE(html.find("<td>0.99 (r 0.91, 40 ms)</td>"), std::string::npos);
}

// A held-out metric that rose is said as a rise (a user trial read "-3.8 % better" in the
// report's summary of a finding accepted on its one-step gain).
TEST(ReportWords, AMetricThatRoseIsSaidAsARise) {
  EXPECT_EQ(quadgen::diagnose::words::lower_or_higher(1.081, 0.2646, 3), "75.5 % lower");
  EXPECT_EQ(quadgen::diagnose::words::lower_or_higher(0.5984, 0.6213, 3), "3.83 % higher");
  EXPECT_EQ(quadgen::diagnose::words::lower_or_higher(0, 1, 3), "0 % lower");  // undefined: no claim
}

// An airframe from one flight's diagnosis is said to be that flight's values.
TEST(ReportWords, AnAirframeOfOneFlightIsSaidToBeThatFlights) {
  quadgen::diagnose::Diagnosis d;
  EXPECT_EQ(quadgen::diagnose::words::airframe_from_one_flight(d), "");  // no --airframe
  d.airframe_source = "a/diagnosis.json";
  d.airframe_flights = 5;
  EXPECT_EQ(quadgen::diagnose::words::airframe_from_one_flight(d), "");
  d.airframe_flights = 1;
  EXPECT_NE(quadgen::diagnose::words::airframe_from_one_flight(d).find("one flight"), std::string::npos);
  // and the summary says it beside the check
  quadgen::diagnose::ParameterAgreement a;
  a.parameter = "rotor_drag.k";
  a.flights.resize(1);
  d.airframe_check = {a};
  EXPECT_NE(quadgen::diagnose::diagnosis_summary(d).find("note: the airframe comes from the diagnosis of one flight"),
            std::string::npos)
      << quadgen::diagnose::diagnosis_summary(d);
  EXPECT_EQ(quadgen::diagnose::diagnosis_json(d, "f.csv")["airframe_check"]["airframe_flights"], 1);
}

// The motor-gain sentence names the gains told apart from the reference and says what it
// leaves out, instead of "motor M2 gives 1.2 % more thrust" for a gain whose interval holds 0.
TEST(ReportWords, TheMotorGainSentenceNamesOnlyGainsToldApartFromTheReference) {
  using namespace quadgen::diagnose;
  Finding f;
  f.effect = "motor_gain";
  // M1 held beside a fitted c_t: the reference (reference_parameters).
  f.evidence.parameters = {{"c_t", "1", 0.14, 0.01, 1, true}, {"motor_gain.M1", "1", 0, -0.5, 0.5, false}};
  const auto gain = [](const char* name, double value, double lower, double upper) {
    EffectEstimate e;
    e.name = name, e.value = value, e.lower = lower, e.upper = upper;
    return e;
  };
  f.parameters = {gain("motor_gain.M2", 0.012, -0.004, 0.028), gain("motor_gain.M3", -0.08, -0.09, -0.07),
                  gain("motor_gain.M4", 0.002, -0.01, 0.014)};
  EXPECT_EQ(words::headline(f),
            "Motor M3 gives 8.0 % less thrust than motor M1. The others are within their intervals of the reference.");
  // Its interval widened by the numerical allowance to reach 0: left out, too.
  f.parameters[1].numerical_allowance = 0.075;
  const std::string none_apart = words::headline(f);
  EXPECT_NE(none_apart.find("Each interval holds 0: the values are significant only together."), std::string::npos)
      << none_apart;
  EXPECT_NE(none_apart.find("Motor M2 gives 1.2 % more thrust than motor M1"), std::string::npos) << none_apart;
  // Every gain told apart: the sentence as the effect words it, nothing added.
  f.parameters[1].numerical_allowance = 0;
  f.parameters[0].lower = 0.002;
  f.parameters[2].lower = 0.001;
  EXPECT_EQ(words::headline(f), "Motor M2 gives 1.2 % more thrust than motor M1; motor M3 8.0 % less; motor M4 0.20 % more.");
  // Two flights of a joint diagnosis, each its own trims: one sentence per flight, not their
  // mean (which read "M3 4 % less" for 8 % on one flight and none on the other).
  f.parameters = {gain("motor_gain.M2", 0.001, -0.01, 0.012), gain("motor_gain.M3", -0.08, -0.09, -0.07),
                  gain("motor_gain.M2@2", 0.002, -0.01, 0.014), gain("motor_gain.M3@2", 0.001, -0.01, 0.012)};
  EXPECT_EQ(words::headline(f),
            "Flight 1: Motor M3 gives 8.0 % less thrust than motor M1. The others are within their intervals of the "
            "reference. Flight 2: none told apart from 0 (each interval holds it).");
}

// fitted_vehicle.yaml is the vehicle file as the diagnosis read it, with the fitted values
// appended: read again at the end, a file edited (or swapped) during a diagnosis of minutes
// mixed another vehicle's text with this one's values (hostile-input audit, 2026-12-03).
TEST(FittedVehicle, IsTheFileAsItWasReadNotAsItIsNow) {
  const fs::path dir = fs::temp_directory_path() / "quadgen_fitted_vehicle_as_read";
  fs::create_directories(dir);
  const fs::path file = dir / "v.yaml";
  fs::copy_file(std::string(QUADGEN_SOURCE_DIR) + "/vehicles/finken3.yaml", file, fs::copy_options::overwrite_existing);
  const quadgen::Vehicle v = quadgen::load_vehicle(file.string());
  std::ifstream in(file);
  const std::string as_read((std::istreambuf_iterator<char>(in)), {});
  { std::ofstream(file) << "name: another\n"; }
  const std::string fitted = "effects: [motor_gain]\nparameters:\n  motor_gain.C: {value: -0.08, unit: \"1\"}\n";
  const std::string y = quadgen::diagnose::fitted_vehicle_yaml(v, fitted);
  ASSERT_FALSE(y.empty());
  EXPECT_EQ(y.substr(0, as_read.size()), as_read);
  EXPECT_EQ(y.find("name: another"), std::string::npos);
  EXPECT_NE(y.find("\nfitted:\n  effects: [motor_gain]"), std::string::npos) << y;
  // A top level indented as a whole is valid YAML, but a `fitted:` key cannot be appended to it.
  std::string indented;
  std::istringstream lines(as_read);
  for (std::string line; std::getline(lines, line);) indented += (line.empty() ? "" : "  ") + line + "\n";
  { std::ofstream(dir / "indented.yaml") << indented; }
  EXPECT_EQ(quadgen::diagnose::fitted_vehicle_yaml(quadgen::load_vehicle((dir / "indented.yaml").string()), fitted), "");
  fs::remove_all(dir);
}

// Beside a fitted c_t only the motor gains' ratios are identifiable and the first rotor's is
// held at 0; beside a held c_t every gain is free (a researcher's trial, helper-148: a common
// thrust change came out as three motors stronger than the first). The lag spread's reference
// follows motor_lag.tau, which a derived lag always fits. The diagnosis' finding then says
// which, if any, was held.
TEST(ExtendedModel, TheMotorGainsReferenceIsHeldOnlyWhereCtIsFitted) {
  quadgen::Vehicle v = quadgen::load_vehicle(std::string(QUADGEN_SOURCE_DIR) + "/vehicles/finken3.yaml");
  const quadgen::MassProperties mp = quadgen::derive_mass_properties(v);
  const quadgen::DeriveOptions gains{{"motor_gain", "motor_lag", "motor_lag_spread"}, {}};
  ASSERT_TRUE(v.params.at("c_t").fit);
  EXPECT_EQ(quadgen::diagnose::reference_parameters(quadgen::derive_model(v, mp, gains)),
            (std::vector<std::string>{"motor_gain.A", "motor_lag_spread.A"}));
  v.params.at("c_t").fit = false;
  EXPECT_EQ(quadgen::diagnose::reference_parameters(quadgen::derive_model(v, mp, gains)),
            (std::vector<std::string>{"motor_lag_spread.A"}));
  // A finding with every gain free has no reference row and no note; one with M1 held has both.
  quadgen::diagnose::Diagnosis d;
  d.vehicle = "finken3";
  quadgen::diagnose::Finding f;
  f.effect = "motor_gain";
  f.evidence.parameters = {{"c_t", "1", 0.14, 0.01, 1, true},
                           {"motor_gain.A", "1", 0.01, -0.5, 0.5, true},
                           {"motor_gain.B", "1", 0.02, -0.5, 0.5, true}};
  d.findings = {f};
  const auto all_free = quadgen::diagnose::diagnosis_json(d, "log.csv")["findings"][0];
  EXPECT_FALSE(all_free.contains("note"));
  EXPECT_FALSE(all_free["parameters"].contains("motor_gain.A"));  // no estimates given: no rows but a reference's
  d.findings[0].evidence.parameters[1].free = false;
  const auto one_held = quadgen::diagnose::diagnosis_json(d, "log.csv")["findings"][0];
  ASSERT_TRUE(one_held["parameters"].contains("motor_gain.A"));
  EXPECT_EQ(one_held["parameters"]["motor_gain.A"]["reference"], true);
  ASSERT_TRUE(one_held.contains("note"));
  EXPECT_NE(one_held["note"].get<std::string>().find("c_t is fitted"), std::string::npos);
  EXPECT_EQ(quadgen::diagnose::words::held_reference(d.findings[0]), "motor_gain.A");
  // A gain held beside a held c_t is no reference (the rule that holds it in the fit, not
  // any held parameter of the effect): no reference row, no note, no "than motor A".
  d.findings[0].evidence.parameters[0].free = false;
  const auto ct_held = quadgen::diagnose::diagnosis_json(d, "log.csv")["findings"][0];
  EXPECT_FALSE(ct_held["parameters"].contains("motor_gain.A"));
  EXPECT_FALSE(ct_held.contains("note"));
  EXPECT_EQ(quadgen::diagnose::words::held_reference(d.findings[0]), "");
}

// Every plot a diagnosis did not draw is said, one note each; gnuplot missing, once (a
// label gnuplot refused lost three of six plots without a word: helper-146).
TEST(ExtendedModel, EveryPlotNotDrawnIsSaid) {
  EXPECT_EQ(quadgen::app::plot_notes({}, false), (std::vector<std::string>{}));
  EXPECT_EQ(quadgen::app::plot_notes({"a.svg: gnuplot is not installed", "b.svg: gnuplot is not installed"}, true),
            (std::vector<std::string>{"no plots: gnuplot is not installed"}));
  EXPECT_EQ(quadgen::app::plot_notes({"a.svg: gnuplot failed: x"}, false), (std::vector<std::string>{"no plot a.svg: gnuplot failed: x"}));
  EXPECT_EQ(quadgen::app::plot_notes({"a.svg: one", "b.svg: two"}, true),
            (std::vector<std::string>{"no plot a.svg: one", "no plot b.svg: two"}));
}

// The extended model's derivation shows the value the diagnosis fitted; the vehicle file's
// value as written ("1674.0 rpm") stays only beside a parameter the fit held (hostile-input
// audit, helper-105: a fitted 6 mm kappa read "(the vehicle file: 9 mm)").
TEST(ExtendedModel, AFittedValueIsNotShownBesideTheFilesValue) {
  const quadgen::Vehicle v = quadgen::load_vehicle(std::string(QUADGEN_SOURCE_DIR) + "/vehicles/finken3.yaml");
  const quadgen::MassProperties mp = quadgen::derive_mass_properties(v);
  quadgen::diagnose::Diagnosis d;
  d.airframe_fit.push_back({"motor_a0", "rad/s", 180.0, 0.0, 1000.0, false});
  const std::string held = quadgen::diagnose::extended_model(v, mp, d, "finken3.yaml", "log.csv").derivation_markdown;
  EXPECT_NE(held.find(" (the vehicle file: 1674.0 rpm) |\n"), std::string::npos);
  d.airframe_fit.back().free = true;
  const std::string fitted = quadgen::diagnose::extended_model(v, mp, d, "finken3.yaml", "log.csv").derivation_markdown;
  EXPECT_EQ(fitted.find("(the vehicle file: 1674.0 rpm)"), std::string::npos);
  EXPECT_NE(fitted.find("| `motor_a0` | rad/s | 180 |"), std::string::npos);
}

// A plot's legend names each flight by its file; two logs of one name in two folders shared
// one series name in the command-gain plot (hostile-input audit, 2026-12-03).
TEST(ReportWords, FlightsOfOneFileNameGetTheirNumber) {
  using quadgen::diagnose::words::short_flight_labels;
  EXPECT_EQ(short_flight_labels({"data/B2.csv", "B3.csv"}), (std::vector<std::string>{"B2", "B3"}));
  EXPECT_EQ(short_flight_labels({"day1/log.csv", "B3.csv", "day2/log.csv"}),
            (std::vector<std::string>{"flight 1 (log)", "B3", "flight 3 (log)"}));
  // Names that differ only where a sink shows nothing or a blank (a tab where a space is, a
  // zero-width space, a bidi mark) read the same there: numbered too (a red-team review:
  // two flights were one series of command_gain.csv).
  const auto labels = short_flight_labels({"x y.csv", "x\ty.csv", "flight.csv", "flight\xE2\x80\x8B.csv", "a.csv"});
  EXPECT_EQ(labels[0].rfind("flight 1 (", 0), 0u) << labels[0];
  EXPECT_EQ(labels[1].rfind("flight 2 (", 0), 0u) << labels[1];
  EXPECT_EQ(labels[2].rfind("flight 3 (", 0), 0u) << labels[2];
  EXPECT_EQ(labels[3].rfind("flight 4 (", 0), 0u) << labels[3];
  EXPECT_EQ(labels[4], "a");
  // A log named as a numbered label is: every flight numbered (a review).
  EXPECT_EQ(short_flight_labels({"a/x.csv", "b/x.csv", "c/flight 1 (x).csv"}),
            (std::vector<std::string>{"flight 1 (x)", "flight 2 (x)", "flight 3 (flight 1 (x))"}));
  // Nor a name of the plot's other series, or one that would take a model's colour.
  EXPECT_EQ(short_flight_labels({"d/the model.csv", "base model, tilt.csv", "B3.csv"}, {"the model", "base model"}),
            (std::vector<std::string>{"flight 1 (the model)", "flight 2 (base model, tilt)", "B3"}));
  EXPECT_EQ(quadgen::output::visible_skeleton("a\xE2\x80\xAE b\x01\xC2\xA0" "c"), "abc");
  EXPECT_EQ(quadgen::output::visible_skeleton("B3_rep2"), "B3_rep2");
  EXPECT_EQ(quadgen::output::visible_skeleton("a\xC2\xAD" "b\xEF\xB8\x8F" "c\xE2\x81\xA2" "d\xE3\x85\xA4" "e"), "abcde");
  EXPECT_EQ(quadgen::output::visible_skeleton("caf\xC3\xA9"), "caf\xC3\xA9");  // a letter stays
}

// Names whose every character a sink shows faithfully can still look alike to a reader: "é"
// precomposed (NFC) and as e plus a combining accent (NFD), a Latin and a Cyrillic "a", "rn"
// and "m". Left open by the label reviews of the forty-ninth and fifty-third sessions; two
// such flights were two series with one legend.
TEST(ReportWords, FlightsWhoseNamesLookAlikeGetTheirNumber) {
  using quadgen::diagnose::words::short_flight_labels;
  using quadgen::output::lookalike_skeleton;
  const std::string nfc = "caf\xC3\xA9", nfd = "cafe\xCC\x81", cyrillic_a = "\xD0\xB0";
  EXPECT_EQ(lookalike_skeleton(nfc), lookalike_skeleton(nfd));
  EXPECT_EQ(lookalike_skeleton("flight a"), lookalike_skeleton("flight " + cyrillic_a));
  EXPECT_EQ(lookalike_skeleton("modern"), lookalike_skeleton("modem"));
  EXPECT_EQ(lookalike_skeleton("x\xE2\x80\x8By"), lookalike_skeleton("xy"));  // and what the visible one drops
  EXPECT_NE(lookalike_skeleton("B3_rep1"), lookalike_skeleton("B3_rep2"));
  EXPECT_NE(lookalike_skeleton("caf\xC3\xA9"), lookalike_skeleton("cafe"));  // an accent is seen
  EXPECT_EQ(lookalike_skeleton("bad\xFF"), lookalike_skeleton("bad?"));  // invalid UTF-8 as the sinks show it

  const auto labels = short_flight_labels({"a/" + nfc + ".csv", "b/" + nfd + ".csv", "flight a.csv",
                                           "flight " + cyrillic_a + ".csv", "B3_rep1.csv", "B3_rep2.csv"});
  for (size_t i = 0; i < 4; ++i) EXPECT_EQ(labels[i].rfind("flight " + std::to_string(i + 1) + " (", 0), 0u) << labels[i];
  EXPECT_EQ(labels[4], "B3_rep1");
  EXPECT_EQ(labels[5], "B3_rep2");
  // A series the plot names itself, spelt with a look-alike letter, is no flight's label either.
  EXPECT_EQ(short_flight_labels({"the m" + std::string("\xD0\xBE") + "del.csv", "B3.csv"}, {"the model"}),
            (std::vector<std::string>{"flight 1 (the m\xD0\xBE" "del)", "B3"}));
}
