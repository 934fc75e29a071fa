// Beyond the catalogue: a term hidden in the residual of a flight is found with its
// regressor and coefficient, on the held-out part too; residual that is only (autocorrelated)
// noise proposes nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "diagnose/term_discovery.hpp"
#include "runtime/portable_random.hpp"

using namespace quadgen;
using namespace quadgen::diagnose;

namespace {

// A manoeuvring flight at 100 Hz from t0: world velocity, a slowly turning heading (body and
// world axes differ), body rates and four rotor commands that climb and sink together
// (the mean command varies) and each vary on their own.
fit::Flight manoeuvre(double t0, double seconds, double phase) {
  fit::Flight f;
  f.source = "synthetic";
  f.has_pose = f.has_gyro = true;
  for (int k = 0; k < static_cast<int>(seconds * 100); ++k) {
    const double t = t0 + k * 0.01, a = t + phase;
    fit::FlightSample s;
    s.t = t;
    s.x.assign(13, 0.0);
    s.x[3] = 1.2 * std::sin(0.7 * a), s.x[4] = 0.9 * std::cos(0.45 * a), s.x[5] = 0.3 * std::sin(1.3 * a);
    const double yaw = 0.8 * std::sin(0.2 * a);
    s.x[6] = std::cos(yaw / 2), s.x[9] = std::sin(yaw / 2);
    s.x[10] = 0.6 * std::sin(2.1 * a), s.x[11] = 0.5 * std::cos(1.7 * a + 0.4), s.x[12] = 0.16 * std::cos(0.2 * a);
    for (int i = 0; i < 4; ++i) s.u.push_back(0.55 + 0.18 * std::sin(0.9 * a) + 0.06 * std::sin((1.3 + 0.37 * i) * a + i));
    f.samples.push_back(s);
  }
  return f;
}

// Residuals (model - measurement) of six channels: AR(1) noise (the correlation of a
// smoothed derivative), plus on `channel` the negative of a term the model lacks.
std::vector<double> residuals(const fit::Flight& f, std::mt19937& rng, int channel,
                              double (*lacks)(const fit::FlightSample&)) {
  quadgen::runtime::Normal n(0, 1);
  std::vector<double> r(f.samples.size() * 6), state(6, 0.0);
  for (size_t k = 0; k < f.samples.size(); ++k)
    for (int c = 0; c < 6; ++c) {
      state[c] = 0.8 * state[c] + 0.6 * 0.3 * n(rng);  // stationary sd 0.3
      r[k * 6 + c] = state[c] - (c == channel && lacks ? lacks(f.samples[k]) : 0.0);
    }
  return r;
}

// Body velocity x times the mean command: the form of rotor drag's moment. About the mean
// command it is -2 mean(U) v_bx - 2 v_bx dU, two terms of the library.
double drag_moment(const fit::FlightSample& s) {
  const double yaw = 2 * std::atan2(s.x[9], s.x[6]);
  const double vbx = std::cos(yaw) * s.x[3] + std::sin(yaw) * s.x[4];
  double U = 0;
  for (double u : s.u) U += u / 4;
  return -2.0 * vbx * U;
}

const std::vector<std::string> kChannels = {"ax_world", "ay_world", "az_world", "pdot", "qdot", "rdot"};
const std::vector<std::string> kUnits = {"m/s^2", "m/s^2", "m/s^2", "rad/s^2", "rad/s^2", "rad/s^2"};

}  // namespace

TEST(TermDiscovery, RegressorLibraryHasBodyVelocityOnlyWithAPose) {
  fit::Flight f = manoeuvre(0, 1, 0);
  const auto with = physical_regressors(f);
  f.has_pose = false;
  const auto without = physical_regressors(f);
  // 1 + 7 base + 28 products; 1 + 4 + 10 without velocity.
  EXPECT_EQ(with.names.size(), 36u);
  EXPECT_EQ(without.names.size(), 15u);
  EXPECT_NE(std::find(with.names.begin(), with.names.end(), "v_bx*dU"), with.names.end());
  EXPECT_EQ(std::find(without.names.begin(), without.names.end(), "v_bx"), without.names.end());
  // Body velocity is the world velocity turned by the heading.
  const auto& s = with.columns;
  const auto& x = f.samples[50].x;
  const double yaw = 2 * std::atan2(x[9], x[6]);
  EXPECT_NEAR(s[1][50], std::cos(yaw) * x[3] + std::sin(yaw) * x[4], 1e-12);
}

// The mean over a flight's samples of the mean rotor command: the centre dU is taken about,
// computed here rather than read from the code under test (-2 U v = -2 c v - 2 (U - c) v
// holds for any c, so a coefficient checked against the code's own centre cannot fail).
double mean_command(const fit::Flight& f) {
  double sum = 0;
  for (const auto& s : f.samples) {
    double u = 0;
    for (double ui : s.u) u += ui;
    sum += u / static_cast<double>(s.u.size());
  }
  return sum / static_cast<double>(f.samples.size());
}

TEST(TermDiscovery, HiddenDragMomentIsFoundWithItsCoefficientAndHeldOutGain) {
  // Over 20 noise realisations: found every time with nothing else; its part about the mean
  // command (v_bx*dU, a sixth of its size here) too on nearly every one, with a 95 %
  // interval that covers the truth most of the time. (Over 200 seeds the pair was found on
  // 185 and covered on 92 % of them: the intervals are about 10 % too narrow, see
  // docs/diagnosis.md.)
  int covered = 0, pairs = 0;
  const int seeds = 20;
  for (int seed = 1; seed <= seeds; ++seed) {
    std::mt19937 rng(static_cast<unsigned>(seed));
    const fit::Flight train = manoeuvre(0, 40, 0), valid = manoeuvre(40, 15, 0);
    const auto terms = discover_terms(train, residuals(train, rng, 4, drag_moment), valid,
                                      residuals(valid, rng, 4, drag_moment), kChannels, kUnits, {0.0});
    ASSERT_EQ(terms.size(), 6u);
    for (const auto& t : terms) {
      SCOPED_TRACE(t.channel + " seed " + std::to_string(seed) + ": " + t.expression() + "; " + t.verdict());
      if (t.channel != "qdot") {
        EXPECT_FALSE(t.proposed);
        continue;
      }
      ASSERT_TRUE(t.proposed);
      ASSERT_GE(t.coefficients.size(), 1u);
      ASSERT_EQ(t.centres.size(), 1u);
      const double mean_u = t.centres[0].second;
      EXPECT_NEAR(mean_u, mean_command(train), 1e-12);  // the training part's, not the held-out one's
      EXPECT_EQ(t.coefficients[0].regressor, "v_bx");
      EXPECT_NEAR(t.coefficients[0].value, -2.0 * mean_u, 0.05);
      if (t.coefficients.size() == 1) continue;  // the weaker half left out (one-SE rule)
      ++pairs;
      ASSERT_EQ(t.coefficients.size(), 2u);
      EXPECT_EQ(t.coefficients[1].regressor, "v_bx*dU");
      EXPECT_EQ(t.coefficients[1].unit, "rad/s^2/(m/s*1)");
      covered += t.coefficients[1].lower < -2.0 && t.coefficients[1].upper > -2.0;
      EXPECT_LT(t.valid_rms_after, 0.36);  // down to the noise (0.3) from 0.7
      EXPECT_GT(t.gain_mean, 0.3);
      EXPECT_EQ(t.cross_validation, "5 time blocks");
    }
  }
  EXPECT_GE(pairs, 17) << "of " << seeds;
  EXPECT_GE(covered, pairs - 4) << "of " << pairs;
}

TEST(TermDiscovery, AutocorrelatedNoiseAloneProposesNothing) {
  int proposed = 0;
  for (unsigned seed = 10; seed < 20; ++seed) {
    std::mt19937 rng(seed);
    const fit::Flight train = manoeuvre(0, 40, 0.3 * seed), valid = manoeuvre(40, 15, 0.3 * seed);
    for (const auto& t : discover_terms(train, residuals(train, rng, -1, nullptr), valid,
                                        residuals(valid, rng, -1, nullptr), kChannels, kUnits, {0.0})) {
      if (t.proposed) ADD_FAILURE() << "seed " << seed << ": " << t.expression() << "; " << t.verdict();
      proposed += t.proposed;
    }
  }
  EXPECT_EQ(proposed, 0);  // 60 channels of noise
}

TEST(TermDiscovery, SeveralFlightsCrossValidateOneFlightAgainstTheOthers) {
  // Three flights on one joined clock (each starts 1 s after the last ends), each with its
  // own manoeuvre; the held-out part is the end of each.
  fit::Flight train, valid;
  train.has_pose = valid.has_pose = true;
  std::vector<double> starts;
  double t0 = 0;
  for (int i = 0; i < 3; ++i) {
    starts.push_back(t0);
    const fit::Flight a = manoeuvre(t0, 20, 1.7 * i), b = manoeuvre(t0 + 20, 8, 1.7 * i);
    train.samples.insert(train.samples.end(), a.samples.begin(), a.samples.end());
    valid.samples.insert(valid.samples.end(), b.samples.begin(), b.samples.end());
    t0 += 29;
  }
  std::mt19937 rng(7);
  const auto terms = discover_terms(train, residuals(train, rng, 4, drag_moment), valid,
                                    residuals(valid, rng, 4, drag_moment), kChannels, kUnits, starts);
  ASSERT_EQ(terms.size(), 6u);
  EXPECT_EQ(terms[4].cross_validation, "leave one flight out, 3 flights");
  ASSERT_TRUE(terms[4].proposed) << terms[4].verdict();
  // Each channel's verdict: a label of the three, and a reason that does not say it again
  // (the report and the terminal print the label their own way).
  for (const auto& t : terms) {
    EXPECT_TRUE(t.verdict_label == (t.proposed ? "proposed" : "not proposed") ||
                (!t.proposed && t.verdict_label == "no term")) << t.verdict();
    EXPECT_FALSE(t.verdict_reason.empty()) << t.channel;
    for (const char* label : {"proposed", "not proposed", "no term"})
      EXPECT_NE(t.verdict_reason.rfind(label, 0), 0u) << t.verdict();
  }
  ASSERT_EQ(terms[4].coefficients.size(), 2u);
  EXPECT_EQ(terms[4].coefficients[1].regressor, "v_bx*dU");
  EXPECT_LT(terms[4].coefficients[1].lower, -2.0);
  EXPECT_GT(terms[4].coefficients[1].upper, -2.0);
  EXPECT_NEAR(terms[4].centres[0].second, mean_command(train), 1e-12);
  const std::string mean_term = std::to_string(-2.0 * terms[4].centres[0].second).substr(0, 4);
  EXPECT_EQ(terms[4].expression().rfind("qdot += " + mean_term, 0), 0u) << terms[4].expression();
}
