#include "thrust_stand.hpp"

#include <cmath>
#include <sstream>

#include "flight_data.hpp"
#include "flight_log.hpp"

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

// Sanity bounds (the file's units): weight[g] is signed, the tared scale reads a little
// below zero at rest, but |weight| <= 1e9 g; 0 <= pwm <= 65535 (a 16-bit command);
// 0 <= vbat[V] <= 1000 and > 0 where the motors run (the speed model takes log(vbat));
// 0 <= rpm_i <= 1e9. parse_csv has already refused non-finite values.
std::vector<StandSample> read_thrust_stand(const std::string& path) {
  const runtime::CsvTable t = read_measurement_csv(path);
  for (const char* c : {"weight[g]", "pwm", "vbat[V]", "rpm1", "rpm2", "rpm3", "rpm4"})
    if (t.column(c) < 0) throw FitError(path + ":1: missing column '" + std::string(c) + "' (thrust-stand layout)");
  const double rpm = 2 * M_PI / 60;
  const int cw = t.column("weight[g]"), cu = t.column("pwm"), cv = t.column("vbat[V]");
  std::vector<StandSample> out;
  for (size_t k = 0; k < t.rows.size(); ++k) {
    StandSample s;
    s.thrust = checked(t, k, cw, -1e9, 1e9, "|weight| <= 1e9 g") * 1e-3 * 9.80665;  // grams-force -> N
    s.u = checked(t, k, cu, 0, 65535, "a PWM command in [0, 65535]") / 65535.0;
    s.vbat = checked(t, k, cv, 0, 1000, "a battery voltage in [0, 1000] V");
    for (int i = 0; i < 4; ++i)
      s.w[i] = checked(t, k, t.column("rpm" + std::to_string(i + 1)), 0, 1e9, "a rotor speed in [0, 1e9] rpm") * rpm;
    if (!(s.u > 0 && s.w[0] > 0)) continue;
    if (!(s.vbat > 0)) checked(t, k, cv, 1e-300, 1000, "a positive battery voltage where the motors run");
    out.push_back(s);
  }
  if (out.size() < 10) throw FitError(path + ": too few samples with the motors running");
  return out;
}

std::vector<FitParameter> ThrustVsSpeed::parameters() {
  std::vector<FitParameter> p;
  for (int i = 1; i <= 4; ++i) p.push_back({"k_" + std::to_string(i), "N s^2", 2e-8, 1e-10, 1e-6, true});
  p.push_back({"tare", "N", 0.0, -0.1, 0.1, true});
  return p;
}

void ThrustVsSpeed::evaluate(const double* p, double* r, double* J) const {
  for (size_t k = 0; k < s_.size(); ++k) {
    double T = p[4];
    for (int i = 0; i < 4; ++i) T += p[i] * s_[k].w[i] * s_[k].w[i];
    r[k] = T - s_[k].thrust;
    if (!J) continue;
    for (int i = 0; i < 4; ++i) J[k * 5 + i] = s_[k].w[i] * s_[k].w[i];
    J[k * 5 + 4] = 1;
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
    const double w = (s.w[0] + s.w[1] + s.w[2] + s.w[3]) / 4;
    const double map = p[0] + p[1] * s.u + p[2] * s.u * s.u;
    const double scale = std::pow(s.vbat / vref_, p[3]);
    r[k] = map * scale - w;
    if (!J) continue;
    J[k * 4 + 0] = scale;
    J[k * 4 + 1] = s.u * scale;
    J[k * 4 + 2] = s.u * s.u * scale;
    J[k * 4 + 3] = map * scale * std::log(s.vbat / vref_);
  }
}

}  // namespace quadgen::fit
