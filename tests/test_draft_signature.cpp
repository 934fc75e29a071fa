// The draft check (diagnose/draft_signature.hpp) on residuals built from a known draft: air
// moving through the rotors ties the horizontal force residual to the moment residual by the
// rotor-drag / blade-flapping ratio, and nothing else that shares only the slowness does.
// Statistical acceptance over many synthetic flights: the rate of the check's verdict (an
// axis showing the draft on both parts), and the false-alarm rate of one test.
#include <cmath>
#include <iostream>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "diagnose/diagnosis.hpp"
#include "diagnose/draft_signature.hpp"
#include "diagnose/diagnosis_report.hpp"
#include "diagnose/report_words.hpp"
#include "runtime/portable_random.hpp"

namespace {

using quadgen::diagnose::DraftSignature;
using quadgen::diagnose::DraftSignatureInput;

// The joint Crazyflie fit's sizes (docs/validation.md), a 60 s flight at 100 Hz, the last
// 30 % held out.
constexpr double kd = 1.32e-6, kf = 2.9e-8, mass = 0.0271, Jxx = 1.43e-5, Jyy = 1.47e-5, S = 7300;

// A slowly wandering air speed component [m/s]: AR(1) with a 2 s time constant, about 0.2 m/s RMS.
std::vector<double> wandering(std::mt19937& rng, size_t n) {
  quadgen::runtime::Normal step(0.0, 0.02);
  std::vector<double> w(n, 0.0);
  for (size_t k = 1; k < n; ++k) w[k] = 0.995 * w[k - 1] + step(rng);
  return w;
}

enum class Force {
  kSameDraft,      // the force from the draft the moments see
  kOtherDraft,     // an independent slow force
  kOppositeSign,   // tied to the moments with the wrong sign
  kAirspeedScale,  // no draft: k_d and k_f both 20 % too small, a "draft" of -0.2 times the body velocity
};

// Residuals (model - measured) of a flight along a circle at 0.75 m/s, the heading turned by
// about 90 degrees, so that a check that forgot to turn the world force into the heading frame
// would pair each moment with the other axis' force.
// With `accelerometer`, the force residual is given in body axes, as diagnose has it when the
// fit uses the accelerometer instead of the differentiated pose.
DraftSignatureInput flight_with_draft(Force force, unsigned seed, bool accelerometer = false) {
  std::mt19937 rng(seed);
  const size_t n = 6000;
  const auto wx = wandering(rng, n), wy = wandering(rng, n), ox = wandering(rng, n), oy = wandering(rng, n);
  quadgen::runtime::Normal moment_noise(0.0, 3.0), force_noise(0.0, 0.1);
  DraftSignatureInput in;
  in.rotor_drag_k = kd, in.blade_flapping_k = kf, in.mass = mass, in.J_xx = Jxx, in.J_yy = Jyy;
  in.hover_speeds_sum = S;
  in.force_in_world = !accelerometer;
  for (size_t k = 0; k < n; ++k) {
    const double t = 0.01 * k, heading = M_PI / 2 + 0.05 * std::sin(0.3 * t);
    const double c = std::cos(heading), s = std::sin(heading);
    const double vx = 0.75 * std::cos(0.5 * t), vy = 0.75 * std::sin(0.5 * t);  // world
    double mx = wx[k], my = wy[k], fx = wx[k], fy = wy[k], sign = 1;  // air speeds the moment and the force see
    if (force == Force::kOtherDraft) fx = ox[k], fy = oy[k];
    if (force == Force::kOppositeSign) sign = -1;
    if (force == Force::kAirspeedScale) mx = fx = -0.2 * (c * vx + s * vy), my = fy = -0.2 * (-s * vx + c * vy);
    const double body_ax = -sign * kd * S * fx / mass + force_noise(rng), body_ay = -sign * kd * S * fy / mass + force_noise(rng);
    in.t.push_back(t);
    in.heading.push_back(heading);
    in.held_out.push_back(t >= 42.0);
    in.velocity.push_back(vx), in.velocity.push_back(vy);
    const double ax = accelerometer ? body_ax : c * body_ax - s * body_ay, ay = accelerometer ? body_ay : s * body_ax + c * body_ay;
    for (double r : {ax, ay, force_noise(rng),
                     kf * S * my / Jxx + moment_noise(rng), -kf * S * mx / Jyy + moment_noise(rng), moment_noise(rng)})
      in.residual.push_back(r);
  }
  return in;
}

// Flights (of 200) in which the check finds an axis showing the draft on both parts.
int flights_showing_a_draft(Force force, bool both_axes = false) {
  int count = 0;
  for (unsigned seed = 100; seed < 300; ++seed) {
    const auto axes = quadgen::diagnose::draft_signature(flight_with_draft(force, seed)).axes_showing_it();
    count += both_axes ? axes.size() == 2 : !axes.empty();
  }
  return count;
}

TEST(DraftSignature, ADraftThroughTheRotorsShowsItsRatioOnBothAxesAndParts) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const DraftSignature d = quadgen::diagnose::draft_signature(flight_with_draft(Force::kSameDraft, seed));
    ASSERT_TRUE(d.measured) << d.why_not;
    EXPECT_EQ(d.axes_showing_it(), (std::vector<std::string>{"y (roll)", "x (pitch)"})) << seed;
    for (const auto& p : d.parts) {
      EXPECT_NEAR(p.y_roll.slope / p.y_roll.draft_slope, 1.0, 0.15) << seed << " " << p.name;
      EXPECT_NEAR(p.x_pitch.slope / p.x_pitch.draft_slope, 1.0, 0.15) << seed << " " << p.name;
      EXPECT_NEAR(p.y_roll.draft_slope, -kd * Jxx / (kf * mass), 1e-12);
      EXPECT_NEAR(p.x_pitch.draft_slope, kd * Jyy / (kf * mass), 1e-12);  // J_yy, not J_xx (helper-123)
      EXPECT_GT(p.implied_speed, 0.1) << "the draft is about 0.2 m/s per axis";
      EXPECT_LT(p.implied_speed, 0.6);
    }
  }
  EXPECT_GE(flights_showing_a_draft(Force::kSameDraft, true), 190) << "found on both axes in at least 95 % of flights";
  int slopes_within = 0;  // every part and axis within 15 % of the ratio
  for (unsigned seed = 100; seed < 300; ++seed) {
    bool all = true;
    for (const auto& p : quadgen::diagnose::draft_signature(flight_with_draft(Force::kSameDraft, seed)).parts)
      for (const auto* pair : {&p.y_roll, &p.x_pitch}) all = all && std::abs(pair->slope / pair->draft_slope - 1) < 0.15;
    slopes_within += all;
  }
  EXPECT_GE(slopes_within, 180) << "the slope is the ratio (noise in the 1 s moment means is small against the draft's)";
  EXPECT_EQ(quadgen::diagnose::draft_signature(flight_with_draft(Force::kSameDraft, 1, true)).axes_showing_it().size(), 2u)
      << "the accelerometer's force is already in body axes: not turned again";
}

TEST(DraftSignature, SlowForcesThatAreNotTheSameDraftRarelyShowIt) {
  EXPECT_LE(flights_showing_a_draft(Force::kOtherDraft), 10) << "an independent slow force: at most 5 % of flights";
  EXPECT_LE(flights_showing_a_draft(Force::kOppositeSign), 2) << "the force tied to the moment with the wrong sign";
  EXPECT_LE(flights_showing_a_draft(Force::kAirspeedScale), 10)
      << "a common scale error of the airspeed terms: the velocity is partialled out";
  // One test alone: an independent slow force shows the draft's sign at the 5 % level in
  // about 5 % of the tests of each part (400 each; 3 standard errors above 5 % is 8.3 %).
  // Bartlett's effective sample size with n_eff - 3 degrees of freedom gave 6-10.5 % here.
  int alarms[2] = {0, 0}, tests[2] = {0, 0};  // training, held-out
  for (unsigned seed = 100; seed < 300; ++seed)
    for (const auto& p : quadgen::diagnose::draft_signature(flight_with_draft(Force::kOtherDraft, seed)).parts) {
      const int i = p.name == "held-out" ? 1 : 0;
      for (const auto* pair : {&p.y_roll, &p.x_pitch}) alarms[i] += pair->shows_draft() ? 1 : 0, ++tests[i];
    }
  for (int i : {0, 1}) {
    EXPECT_EQ(tests[i], 400);
    EXPECT_LE(alarms[i], 33) << (i ? "held-out" : "training") << ": " << alarms[i] << " of " << tests[i];
    std::cout << (i ? "held-out" : "training") << " part: " << alarms[i] << " of " << tests[i] << " tests at 5 %\n";
  }
  DraftSignatureInput no_drag = flight_with_draft(Force::kSameDraft, 1);
  no_drag.rotor_drag_k = 0;
  const DraftSignature d = quadgen::diagnose::draft_signature(no_drag);
  EXPECT_FALSE(d.measured);
  EXPECT_FALSE(d.why_not.empty());
}

// Flights diagnosed jointly share a clock, and a draft's direction differs from flight to
// flight: each flight is checked alone. Two flights joined 1 s apart, the first with a draft,
// the second with its force tied to the moments by the wrong sign: only the first shows it.
TEST(DraftSignature, JoinedFlightsAreCheckedOneByOne) {
  const DraftSignatureInput with = flight_with_draft(Force::kSameDraft, 1), without = flight_with_draft(Force::kOppositeSign, 2);
  DraftSignatureInput joined = with;
  const double second_start = with.t.back() + 1.0;
  for (size_t k = 0; k < without.t.size(); ++k) {
    joined.t.push_back(second_start + without.t[k]);
    joined.heading.push_back(without.heading[k]), joined.held_out.push_back(without.held_out[k]);
    joined.velocity.insert(joined.velocity.end(), without.velocity.begin() + 2 * k, without.velocity.begin() + 2 * k + 2);
    joined.residual.insert(joined.residual.end(), without.residual.begin() + 6 * k, without.residual.begin() + 6 * k + 6);
  }
  const auto flights = quadgen::diagnose::split_by_flight(joined, {0.0, second_start});
  ASSERT_EQ(flights.size(), 2u);
  EXPECT_EQ(flights[0].t, with.t);
  EXPECT_EQ(flights[1].residual, without.residual);
  EXPECT_EQ(flights[1].velocity, without.velocity);
  EXPECT_EQ(quadgen::diagnose::draft_signature(flights[0]).axes_showing_it().size(), 2u);
  EXPECT_TRUE(quadgen::diagnose::draft_signature(flights[1]).axes_showing_it().empty());
}

// What the draft check reads from a diagnosis (draft_signature_input): each sample's heading
// (the yaw of its attitude, whatever its roll and pitch), its world velocity, whether it lies
// in the held-out part, the final fit's coefficients by name (in a joint diagnosis the first
// flight's copies), and the hover's rotor speeds, which must carry the weight through the
// thrust law F = c_t rho A (omega r)^2.
TEST(DraftSignature, ReadsHeadingsPartsAndCoefficientsFromADiagnosis) {
  using quadgen::fit::FitParameter;
  // Body to world, Z-Y-X: yaw psi, then pitch theta, then roll phi (half-angle products).
  auto quaternion = [](double psi, double theta, double phi) {
    const double cy = std::cos(psi / 2), sy = std::sin(psi / 2), cp = std::cos(theta / 2), sp = std::sin(theta / 2),
                 cr = std::cos(phi / 2), sr = std::sin(phi / 2);
    return std::vector<double>{cy * cp * cr + sy * sp * sr, cy * cp * sr - sy * sp * cr, cy * sp * cr + sy * cp * sr,
                               sy * cp * cr - cy * sp * sr};
  };
  const double psi[] = {0.3, -2.0, 3.0, 1.0}, vx[] = {0.5, -0.25, 1.0, 0.0}, vy[] = {0.0, 0.75, -0.5, 2.0};
  quadgen::diagnose::Diagnosis d;
  quadgen::fit::Flight used, valid;
  for (int k = 0; k < 4; ++k) {
    quadgen::fit::FlightSample s;
    s.t = 0.01 * k;
    const auto q = quaternion(psi[k], 0.2, -0.15);
    s.x = {0, 0, 1, vx[k], vy[k], -0.1, q[0], q[1], q[2], q[3], 0.1, 0.2, 0.3};
    used.samples.push_back(s);
    if (k >= 2) valid.samples.push_back(s);
    d.t.push_back(s.t);
    for (int c = 0; c < 6; ++c) d.residual_after.push_back(10.0 * k + c);
  }
  quadgen::Vehicle v;
  for (int r = 0; r < 4; ++r) v.rotors.push_back({"M" + std::to_string(r + 1), {}, quadgen::Spin::ccw, 0.0231, 0.00168, 0});
  const double c_t = 0.0139, rho = 1.2, g = 9.81;
  std::vector<FitParameter> fit;
  for (const auto& [name, value] : std::vector<std::pair<std::string, double>>{
           {"rotor_drag.k", kd}, {"blade_flapping.k", kf}, {"mass", mass}, {"J_xx", Jxx}, {"J_yy", Jyy},
           {"c_t", c_t}, {"c_t@2", 2 * c_t}, {"rho", rho}, {"g", g}})
    fit.push_back({name, "", value, 0, 0, true});
  const DraftSignatureInput in = quadgen::diagnose::draft_signature_input(d, used, valid, v, fit, false);
  EXPECT_EQ(in.t, d.t);
  EXPECT_EQ(in.residual, d.residual_after);
  EXPECT_FALSE(in.force_in_world);
  ASSERT_EQ(in.heading.size(), 4u);
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(in.heading[k], psi[k], 1e-12) << "sample " << k;
  EXPECT_EQ(in.velocity, (std::vector<double>{0.5, 0.0, -0.25, 0.75, 1.0, -0.5, 0.0, 2.0}));
  EXPECT_EQ(in.held_out, (std::vector<bool>{false, false, true, true}));
  EXPECT_EQ(in.rotor_drag_k, kd);
  EXPECT_EQ(in.blade_flapping_k, kf);
  EXPECT_EQ(in.mass, mass);
  EXPECT_EQ(in.J_xx, Jxx);
  EXPECT_EQ(in.J_yy, Jyy);
  const double omega = in.hover_speeds_sum / 4, weight = mass * g;
  EXPECT_NEAR(4 * c_t * rho * 0.00168 * std::pow(omega * 0.0231, 2), weight, 1e-12 * weight)
      << "the first flight's c_t: the hover's four thrusts carry the weight";
  EXPECT_FALSE(quadgen::diagnose::draft_signature(in).measured) << "four samples: both parts too short";
  fit.erase(fit.begin() + 1);  // no blade flapping in the final model
  EXPECT_EQ(quadgen::diagnose::draft_signature_input(d, used, valid, v, fit, true).blade_flapping_k, 0.0);
}

}  // namespace

// A lead the flights of a joint diagnosis share is said once, with each flight's numbers on a
// line of its own below it (each flight repeated the 400-500 character sentence before); a
// flight whose lead differs (another axis) gets its own.
TEST(DraftSignature, ALeadSharedByFlightsIsSaidOnceWithEachFlightsNumbers) {
  using quadgen::diagnose::DraftSignature;
  const auto showing = [](bool roll, bool pitch, double r) {
    DraftSignature s;
    s.measured = true;
    for (const char* name : {"training", "held-out"}) {
      DraftSignature::Part p;
      p.name = name;
      p.y_roll.p = roll ? 0.001 : 0.5;
      p.x_pitch.p = pitch ? 0.001 : 0.5;
      p.y_roll.r = r;
      s.parts.push_back(p);
    }
    return s;
  };
  quadgen::diagnose::Diagnosis d;
  d.flights = {"a.csv", "b.csv", "c.csv"};
  d.draft = showing(true, false, -0.47);
  d.draft_per_flight = {showing(true, false, -0.5), showing(false, false, 0), showing(true, true, -0.61)};
  const auto leads = quadgen::diagnose::words::draft_leads(d);
  ASSERT_EQ(leads.size(), 2u);
  ASSERT_EQ(leads[0].evidence.size(), 2u);  // the flights together and flight 1; flight 2 shows nothing
  EXPECT_EQ(leads[0].evidence[0].first, "the flights together");
  EXPECT_EQ(leads[0].evidence[1].first, "flight 1 (a.csv)");
  EXPECT_NE(leads[1].claim.find("on axis y (roll) and x (pitch)"), std::string::npos) << leads[1].claim;
  const std::string text = quadgen::diagnose::diagnosis_summary(d);
  const std::string claim = "air moving through the rotors would, on axis y (roll) (1 s means";
  EXPECT_NE(text.find(claim), std::string::npos) << text;
  EXPECT_EQ(text.find(claim, text.find(claim) + 1), std::string::npos) << "said twice:\n" << text;
  EXPECT_NE(text.find("\n  the flights together: training r = -0.47"), std::string::npos) << text;
  EXPECT_NE(text.find("\n  flight 1 (a.csv): training r = -0.5"), std::string::npos) << text;
  EXPECT_NE(text.find("\n  flight 3 (c.csv): training y: r = -0.61"), std::string::npos) << text;
  EXPECT_EQ(text.find("flight 2 (b.csv)"), std::string::npos) << text;
  const std::string html = quadgen::diagnose::diagnosis_html(d, "a.csv", {});
  EXPECT_NE(html.find("<li>flight 1 (a.csv): training r = -0.5"), std::string::npos);
}
