#include "fit/thrust_stand.hpp"

#include <algorithm>
#include <set>
#include <cmath>
#include <sstream>

#include "fit/flight_data.hpp"
#include "model/units.hpp"
#include "output/numbers.hpp"
#include "runtime/flight_log.hpp"
#include "runtime/thrust_law.hpp"

namespace quadgen::fit {

namespace {

// A value of the stand file within [lo, hi], else FitError "path:line: ...".
double checked(const runtime::CsvTable& t, size_t row, int col, double lo, double hi, const char* expected) {
  const double v = t.rows[row][col];
  if (!(v >= lo && v <= hi)) {
    std::ostringstream os;
    os << t.path << ":" << t.line_of(row) << ": column '" << t.columns[col] << "' is " << v << ", expected " << expected;
    throw FitError(os.str());
  }
  return v;
}

}  // namespace

double StandSample::mean_speed() const {
  double sum = 0;
  for (double v : w) sum += v;
  return sum / static_cast<double>(w.size());
}

double StandSample::sum_of_squared_speeds() const {
  double sum = 0;
  for (double v : w) sum += v * v;
  return sum;
}

// Sanity bounds (the file's units): weight[g] is signed, the tared scale reads a little
// below zero at rest, but |weight| <= 1e9 g; 0 <= pwm <= 65535 (a 16-bit command);
// 0 <= vbat[V] <= 1000 and > 0 where the motors run (the speed model takes log(vbat));
// 0 <= rpm_i <= 1e9. measurement_column has refused columns with a non-finite cell.
std::vector<StandSample> read_thrust_stand(const std::string& path) {
  const runtime::CsvTable t = read_measurement_csv(path);
  for (const char* c : {"weight[g]", "pwm", "vbat[V]", "rpm1"})
    if (measurement_column(t, c) < 0) throw FitError(path + ":1: missing column '" + std::string(c) + "' (thrust-stand layout)");
  std::vector<int> speed_columns;
  for (int c; (c = measurement_column(t, "rpm" + std::to_string(speed_columns.size() + 1))) >= 0;)
    speed_columns.push_back(c);
  // The speeds are read rpm1, rpm2, ... up to the first missing one: an rpm4 after a missing
  // rpm3 was left out without a word, and the shared thrust coefficient came out doubled (a
  // review, helper-135); so were an rpm0 and an rpm01 (a second review, helper-137).
  for (size_t c = 0; c < t.columns.size(); ++c) {
    const std::string& name = t.columns[c];
    if (name.size() > 3 && name.compare(0, 3, "rpm") == 0 && name.find_first_not_of("0123456789", 3) == std::string::npos &&
        std::find(speed_columns.begin(), speed_columns.end(), static_cast<int>(c)) == speed_columns.end())
      throw FitError(path + ":1: column '" + name + "' is not read: the rotor speeds are read as rpm1, rpm2, ... (from 1, "
                     "no leading zeros) up to the first one missing (rpm" + std::to_string(speed_columns.size() + 1) +
                     "); number them so");
  }
  const double rpm = 2 * M_PI / 60;
  const int cw = t.column("weight[g]"), cu = t.column("pwm"), cv = t.column("vbat[V]");
  std::vector<StandSample> out;
  for (size_t k = 0; k < t.rows.size(); ++k) {
    StandSample s;
    s.thrust = checked(t, k, cw, -1e9, 1e9, "|weight| <= 1e9 g") * 1e-3 * kStandardGravity;  // grams-force -> N
    s.u = checked(t, k, cu, 0, 65535, "a PWM command in [0, 65535]") / 65535.0;
    s.vbat = checked(t, k, cv, 0, 1000, "a battery voltage in [0, 1000] V");
    for (int c : speed_columns) s.w.push_back(checked(t, k, c, 0, 1e9, "a rotor speed in [0, 1e9] rpm") * rpm);
    if (!(s.u > 0 && s.w[0] > 0)) continue;
    if (!(s.vbat > 0)) checked(t, k, cv, 1e-300, 1000, "a positive battery voltage where the motors run");
    out.push_back(s);
  }
  if (out.size() < 10) throw FitError(path + ": too few samples with the motors running");
  // The motor map is quadratic in the command (three coefficients): a run at fewer commands
  // cannot give it, and 50 identical rows ended in "J^T J overflows" (a review, helper-135).
  std::set<double> commands;
  for (const auto& s : out) commands.insert(s.u);
  if (commands.size() < runtime::kMotorMapCoefficients)
    throw FitError(path + ": the motors ran at " + std::to_string(commands.size()) + " command" +
                   (commands.size() == 1 ? "" : "s") + " (pwm): the motor map needs a run over at least " +
                   std::to_string(runtime::kMotorMapCoefficients) + " different commands");
  return out;
}

double motor_speed_ratio_variation(const std::vector<StandSample>& s) {
  if (s.size() < 2) return 0.0;
  const size_t motors = s.front().w.size();
  double variance_sum = 0;
  for (size_t i = 0; i < motors; ++i) {
    double sum = 0, sum2 = 0;
    for (const auto& q : s) {
      const double ratio = q.w[i] / q.mean_speed();
      sum += ratio;
      sum2 += ratio * ratio;
    }
    const double n = static_cast<double>(s.size()), mean = sum / n;
    variance_sum += std::max(0.0, sum2 / n - mean * mean);
  }
  return std::sqrt(variance_sum / static_cast<double>(motors));
}

std::vector<FitParameter> ThrustVsSpeed::parameters() const {
  // T = k sum w^2 in closed form (least squares through the origin), and the scale's range.
  double ts = 0, ss = 0, largest = 0;
  for (const auto& q : s_) {
    const double S = q.sum_of_squared_speeds();
    ts += q.thrust * S;
    ss += S * S;
    largest = std::max(largest, std::fabs(q.thrust));
  }
  const double k0 = ss > 0 && ts > 0 ? ts / ss : 2e-8, tare = std::max(0.1, 0.1 * largest);
  std::vector<FitParameter> p;
  if (c_ == Coefficients::kShared) {
    p.push_back({"k", "N s^2", k0, k0 / 1000, k0 * 1000, true});
  } else {
    for (size_t i = 1; i <= motors(); ++i)
      p.push_back({"k_" + std::to_string(i), "N s^2", k0, k0 / 1000, k0 * 1000, true});
  }
  p.push_back({"tare", "N", 0.0, -tare, tare, true});
  return p;
}

void ThrustVsSpeed::evaluate(const double* p, double* r, double* J) const {
  const bool shared = c_ == Coefficients::kShared;
  const size_t motors = this->motors();
  const int np = shared ? 2 : static_cast<int>(motors) + 1, tare = np - 1;
  for (size_t k = 0; k < s_.size(); ++k) {
    double T = p[tare];
    for (size_t i = 0; i < motors; ++i) T += p[shared ? 0 : i] * s_[k].w[i] * s_[k].w[i];
    r[k] = T - s_[k].thrust;
    if (!J) continue;
    for (int j = 0; j < np; ++j) J[k * np + j] = 0;
    for (size_t i = 0; i < motors; ++i) J[k * np + (shared ? 0 : static_cast<int>(i))] += s_[k].w[i] * s_[k].w[i];
    J[k * np + tare] = 1;
  }
}

std::vector<FitParameter> SpeedVsCommand::parameters() {
  return {{"a0", "rad/s", 300, -5000, 5000, true},
          {"a1", "rad/s", 2700, 0, 20000, true},
          {"a2", "rad/s", -600, -20000, 20000, true},
          {"e", "1", 0.5, -3, 3, true}};
}

void SpeedVsCommand::evaluate(const double* p, double* r, double* J) const {
  for (size_t k = 0; k < s_.size(); ++k) {
    const auto& s = s_[k];
    const double w = s.mean_speed();
    const double map = runtime::motor_map(p[0], p[1], p[2], s.u);
    const double scale = std::pow(s.vbat / vref_, p[3]);
    r[k] = map * scale - w;
    if (!J) continue;
    J[k * 4 + 0] = scale;
    J[k * 4 + 1] = s.u * scale;
    J[k * 4 + 2] = s.u * s.u * scale;
    J[k * 4 + 3] = map * scale * std::log(s.vbat / vref_);
  }
}

namespace {

// Every free parameter's profile closed on both sides and no estimate on a bound.
bool all_identified(const FitResult& r, const std::vector<Profile>& profiles) {
  if (!r.at_bound.empty()) return false;
  return std::all_of(profiles.begin(), profiles.end(), [](const Profile& p) { return p.verdict == Identifiability::kIdentifiable; });
}

}  // namespace

StandFit fit_stand(const std::vector<StandSample>& samples, double vref, const FitOptions& fo, const ProfileOptions& po) {
  StandFit out;
  out.ratio_variation = motor_speed_ratio_variation(samples);
  ThrustVsSpeed per_motor(samples, ThrustVsSpeed::Coefficients::kPerMotor);
  out.per_motor = fit_least_squares(per_motor, per_motor.parameters(), fo);
  out.per_motor_profiles = profile_all(per_motor, out.per_motor, fo, po);
  if (all_identified(out.per_motor, out.per_motor_profiles)) {
    out.thrust = out.per_motor;
    out.thrust_profiles = out.per_motor_profiles;
  } else {
    out.coefficients = ThrustVsSpeed::Coefficients::kShared;
    out.coefficients_reason = "the per-motor coefficients are not identifiable from this run (the " +
                              std::to_string(samples.front().w.size()) + " speeds moved together: their ratios to the mean varied by " + output::percent_text(out.ratio_variation) +
                              " RMS, too little to separate them against the thrust noise, so total thrust fixes only "
                              "sum k_i w_i^2): one coefficient k is fitted for all of them";
    ThrustVsSpeed shared(samples, ThrustVsSpeed::Coefficients::kShared);
    out.thrust = fit_least_squares(shared, shared.parameters(), fo);
    out.thrust_profiles = profile_all(shared, out.thrust, fo, po);
  }
  SpeedVsCommand speed(samples, vref);
  std::vector<FitParameter> sp = SpeedVsCommand::parameters();
  out.speed = fit_least_squares(speed, sp, fo);
  out.speed_profiles = profile_all(speed, out.speed, fo, po);
  if (!all_identified(out.speed, out.speed_profiles)) {
    out.voltage_exponent_identified = false;
    out.voltage_reason = "the voltage exponent e is not identifiable from this run (its profile is open or it ends on a "
                         "bound: the battery voltage varied only with the load, confounded with the command); the "
                         "motor map is fitted without it (e fixed at 0)";
    sp[3].value = 0;
    sp[3].free = false;
    out.speed = fit_least_squares(speed, sp, fo);
    out.speed_profiles = profile_all(speed, out.speed, fo, po);
  }
  return out;
}

}  // namespace quadgen::fit
