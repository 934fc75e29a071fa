#include "thrust_stand.hpp"

#include <cmath>

#include "flight_log.hpp"

namespace quadgen::fit {

std::vector<StandSample> read_thrust_stand(const std::string& path) {
  const runtime::CsvTable t = runtime::read_csv(path);
  for (const char* c : {"weight[g]", "pwm", "vbat[V]", "rpm1", "rpm2", "rpm3", "rpm4"})
    if (t.column(c) < 0) throw FitError(path + ":1: missing column '" + std::string(c) + "' (thrust-stand layout)");
  const double rpm = 2 * M_PI / 60;
  std::vector<StandSample> out;
  for (const auto& row : t.rows) {
    StandSample s;
    s.thrust = row[t.column("weight[g]")] * 1e-3 * 9.80665;  // grams-force -> N
    s.u = row[t.column("pwm")] / 65535.0;
    s.vbat = row[t.column("vbat[V]")];
    for (int i = 0; i < 4; ++i) s.w[i] = row[t.column("rpm" + std::to_string(i + 1))] * rpm;
    if (s.u > 0 && s.w[0] > 0) out.push_back(s);
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
