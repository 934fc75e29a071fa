#include "diagnose/command_gain.hpp"

#include <algorithm>
#include <cmath>

#include "fit/flight_data.hpp"

namespace quadgen::diagnose {

namespace {

constexpr int kVertical = 2, kRoll = 3, kPitch = 4;
constexpr size_t kMinRows = 200;
// A command this close to either end of its range is saturated (or the rotor is idle): the
// motor does not follow the command there.
constexpr double kIdle = 0.05, kSaturated = 0.99;

// Where each contiguous stretch of rows begins: a step over three typical sample intervals
// (a restart, or the gap between joined flights) starts a new one.
std::vector<size_t> stretch_of_rows(const std::vector<double>& t, double* typical_step) {
  std::vector<double> steps;
  for (size_t k = 1; k < t.size(); ++k)
    if (t[k] > t[k - 1]) steps.push_back(t[k] - t[k - 1]);
  std::nth_element(steps.begin(), steps.begin() + static_cast<long>(steps.size() / 2), steps.end());
  *typical_step = steps.empty() ? 0.0 : steps[steps.size() / 2];
  std::vector<size_t> stretch(t.size(), 0);
  for (size_t k = 1; k < t.size(); ++k) stretch[k] = stretch[k - 1] + (t[k] - t[k - 1] > 3 * *typical_step ? 1 : 0);
  return stretch;
}

// Means of x over [t - w, t + w] within each row's stretch (two pointers over prefix sums).
std::vector<double> running_mean(const std::vector<double>& t, const std::vector<size_t>& stretch,
                                 const std::vector<double>& x, double w) {
  const size_t n = t.size();
  std::vector<double> sum(n + 1, 0.0), out(n, 0.0);
  for (size_t k = 0; k < n; ++k) sum[k + 1] = sum[k] + x[k];
  size_t lo = 0, hi = 0;
  for (size_t k = 0; k < n; ++k) {
    while (t[lo] < t[k] - w || stretch[lo] != stretch[k]) ++lo;
    if (hi < k) hi = k;
    while (hi + 1 < n && stretch[hi + 1] == stretch[k] && t[hi + 1] <= t[k] + w) ++hi;
    out[k] = (sum[hi + 1] - sum[lo]) / static_cast<double>(hi + 1 - lo);
  }
  return out;
}

// x at t - delay by linear interpolation within the row's stretch (clamped at its start).
std::vector<double> delayed(const std::vector<double>& t, const std::vector<size_t>& stretch,
                            const std::vector<double>& x, double delay) {
  std::vector<double> out(t.size());
  size_t j = 0;
  for (size_t k = 0; k < t.size(); ++k) {
    const double at = t[k] - delay;
    while (j < k && (stretch[j] != stretch[k] || t[j + 1] <= at)) ++j;
    if (stretch[j] != stretch[k] || t[j] >= at || j == k) {
      out[k] = x[j];
      continue;
    }
    const double a = (at - t[j]) / (t[j + 1] - t[j]);
    out[k] = (1 - a) * x[j] + a * x[j + 1];
  }
  return out;
}

struct Regression {
  double slope = 0, r = 0;
};

Regression regress(const std::vector<double>& x, const std::vector<double>& y, const std::vector<size_t>& rows) {
  double mx = 0, my = 0;
  for (size_t k : rows) mx += x[k], my += y[k];
  mx /= static_cast<double>(rows.size()), my /= static_cast<double>(rows.size());
  double sxy = 0, sxx = 0, syy = 0;
  for (size_t k : rows) {
    sxy += (x[k] - mx) * (y[k] - my);
    sxx += (x[k] - mx) * (x[k] - mx);
    syy += (y[k] - my) * (y[k] - my);
  }
  if (sxx <= 0 || syy <= 0) return {};
  return {sxy / sxx, sxy / std::sqrt(sxx * syy)};
}

std::vector<double> channel(const std::vector<double>& rows6, int c, double offset) {
  std::vector<double> out(rows6.size() / 6);
  for (size_t k = 0; k < out.size(); ++k) out[k] = rows6[k * 6 + static_cast<size_t>(c)] + offset;
  return out;
}

// The rows' clock: contiguous stretches and the typical step, and the band-pass and the
// delay on it.
struct Clock {
  const std::vector<double>& t;
  double step = 0;               // before `stretch`: stretch_of_rows sets it
  std::vector<size_t> stretch;
  explicit Clock(const std::vector<double>& times) : t(times), stretch(stretch_of_rows(times, &step)) {}
  std::vector<double> band(const std::vector<double>& x, size_t b) const {
    const std::vector<double> fine = running_mean(t, stretch, x, CommandGain::kBands[b][0]);
    const std::vector<double> coarse = running_mean(t, stretch, x, CommandGain::kBands[b][1]);
    std::vector<double> out(x.size());
    for (size_t k = 0; k < x.size(); ++k) out[k] = fine[k] - coarse[k];
    return out;
  }
  std::vector<double> delayed_by(const std::vector<double>& x, double delay) const { return delayed(t, stretch, x, delay); }
};

// The rows whose widest window (and the longest delay before it) lies within their stretch
// and at which every rotor is between idle and saturation; their mean command.
std::vector<size_t> usable_rows(const CommandGainInput& in, const Clock& clock, double* mean_command) {
  const size_t n = in.t.size();
  std::vector<double> first(clock.stretch.back() + 1, 0.0), last(clock.stretch.back() + 1, 0.0);
  for (size_t k = n; k-- > 0;) first[clock.stretch[k]] = in.t[k];
  for (size_t k = 0; k < n; ++k) last[clock.stretch[k]] = in.t[k];
  const double widest = CommandGain::kBands[3][1];
  std::vector<size_t> rows;
  double sum = 0;
  for (size_t k = 0; k < n; ++k) {
    const auto u = in.commands.begin() + static_cast<long>(k * in.rotors);
    const auto [lo, hi] = std::minmax_element(u, u + static_cast<long>(in.rotors));
    const size_t s = clock.stretch[k];
    const bool inside = in.t[k] - CommandGain::kMaxDelay - widest >= first[s] && in.t[k] + widest <= last[s];
    if (!inside || *lo <= kIdle || *hi >= kSaturated) continue;
    rows.push_back(k);
    for (size_t i = 0; i < in.rotors; ++i) sum += u[static_cast<long>(i)];
  }
  *mean_command = rows.empty() ? 0.0 : sum / static_cast<double>(rows.size() * in.rotors);
  return rows;
}

// Band b of one axis: the measured regressed on the model's at each whole-step delay up to
// kMaxDelay, kept at the delay of the highest correlation.
CommandGain::Band best_band(const Clock& clock, const std::vector<double>& model, const std::vector<double>& measured,
                            const std::vector<size_t>& rows, size_t b, double thrust_scale) {
  CommandGain::Band best;
  best.low_hz = 0.5 / CommandGain::kBands[b][1], best.high_hz = 0.5 / CommandGain::kBands[b][0];
  best.r = -2;
  const std::vector<double> y = clock.band(measured, b);
  const int delays = static_cast<int>(std::floor(CommandGain::kMaxDelay / clock.step + 1e-9));
  for (int d = 0; d <= delays; ++d) {
    const Regression fit = regress(clock.band(clock.delayed_by(model, d * clock.step), b), y, rows);
    if (fit.r <= best.r) continue;
    best.r = fit.r, best.gain = fit.slope / thrust_scale, best.delay_s = d * clock.step;
  }
  return best;
}

}  // namespace

bool CommandGain::slope_looks_off() const {
  if (!measured || axes.size() < 2) return false;
  const Band& roll = axes[0].bands[kLeadBand];
  const Band& pitch = axes[1].bands[kLeadBand];
  if (roll.r < kMinR || pitch.r < kMinR) return false;
  const double mean = roll_pitch_gain();
  if (std::fabs(roll.gain - pitch.gain) > 0.25 * mean) return false;
  return mean < kRightLow || mean > kRightHigh;
}

double CommandGain::roll_pitch_gain() const {
  if (axes.size() < 2) return 0;
  return 0.5 * (axes[0].bands[kLeadBand].gain + axes[1].bands[kLeadBand].gain);
}

CommandGain command_gain(const CommandGainInput& in) {
  CommandGain g;
  g.model_slope = in.model_slope;
  if (in.t.size() < kMinRows || in.rotors == 0) {
    g.why_not = "fewer than " + std::to_string(kMinRows) + " samples";
    return g;
  }
  const Clock clock(in.t);
  const std::vector<size_t> rows = usable_rows(in, clock, &g.hover_command);
  if (rows.size() < kMinRows || clock.step <= 0) {
    g.why_not = "fewer than " + std::to_string(kMinRows) + " samples with every rotor between idle and saturation";
    return g;
  }
  g.rows = rows.size();
  // The hover's thrust scale: mean measured over mean model vertical thrust per mass.
  const std::vector<double> model_v = channel(in.model, kVertical, in.vertical_offset);
  const std::vector<double> measured_v = channel(in.measured, kVertical, in.vertical_offset);
  double sum_model = 0, sum_measured = 0;
  for (size_t k : rows) sum_model += model_v[k], sum_measured += measured_v[k];
  if (sum_model <= 0 || sum_measured <= 0) {
    g.why_not = "the model or the log does not hold the vehicle up over these samples";
    return g;
  }
  g.thrust_scale = sum_measured / sum_model;
  static const std::pair<const char*, int> kAxes[] = {{"roll", kRoll}, {"pitch", kPitch}, {"vertical", kVertical}};
  for (const auto& [name, c] : kAxes) {
    CommandGain::Axis axis;
    axis.name = name;
    const std::vector<double> model = channel(in.model, c, 0.0), measured = channel(in.measured, c, 0.0);
    for (size_t b = 0; b < 4; ++b) axis.bands.push_back(best_band(clock, model, measured, rows, b, g.thrust_scale));
    g.axes.push_back(axis);
  }
  g.measured = true;
  return g;
}

CommandGainInput command_gain_input(const fit::EquationErrorModel& ee, const std::vector<double>& residual,
                                    const Vehicle& v, double g, bool accelerometer) {
  CommandGainInput in;
  in.rotors = v.rotors.size();
  in.vertical_offset = accelerometer ? 0.0 : g;
  if (const auto slope = v.params.find("motor_slope"); slope != v.params.end()) in.model_slope = slope->second.nominal;
  in.measured = ee.measured_channels();
  in.model = residual;
  for (size_t i = 0; i < in.model.size(); ++i) in.model[i] += in.measured[i];
  for (size_t k : ee.rows()) {
    const auto& s = ee.flight().samples[k];
    in.t.push_back(s.t);
    in.commands.insert(in.commands.end(), s.u.begin(), s.u.begin() + static_cast<long>(in.rotors));
  }
  return in;
}

std::vector<CommandGainInput> split_by_flight(const CommandGainInput& in, const std::vector<double>& starts) {
  std::vector<CommandGainInput> out(starts.size());
  for (auto& f : out) f.rotors = in.rotors, f.vertical_offset = in.vertical_offset, f.model_slope = in.model_slope;
  const auto rows_of = [](const std::vector<double>& from, size_t k, size_t width, std::vector<double>& to) {
    to.insert(to.end(), from.begin() + static_cast<long>(k * width), from.begin() + static_cast<long>((k + 1) * width));
  };
  for (size_t k = 0; k < in.t.size(); ++k) {
    const int flight = fit::joined_flight_at(starts, in.t[k]);
    if (flight < 0) continue;
    auto& f = out[static_cast<size_t>(flight)];
    f.t.push_back(in.t[k]);
    rows_of(in.model, k, 6, f.model), rows_of(in.measured, k, 6, f.measured), rows_of(in.commands, k, in.rotors, f.commands);
  }
  return out;
}

}  // namespace quadgen::diagnose
