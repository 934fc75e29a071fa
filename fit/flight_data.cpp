#include "flight_data.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include <Eigen/Dense>
#include <yaml-cpp/yaml.h>

#include "least_squares.hpp"

namespace quadgen::fit {

ColumnMapping load_mapping(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw FitError(path + ": cannot open column mapping");
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_mapping(ss.str(), path);
}

ColumnMapping parse_mapping(const std::string& text, const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw FitError(path + ":" + std::to_string(e.mark.line + 1) + ": malformed YAML: " + e.msg);
  }
  if (!root.IsMap() || !root["columns"] || !root["columns"].IsMap())
    throw FitError(path + ":1: expected a 'columns' mapping");
  ColumnMapping m;
  int line = 1;
  try {  // yaml-cpp's conversion errors (a list where a name belongs, ...) end as one line
    m.name = root["name"] ? root["name"].as<std::string>() : path;
    for (const auto& kv : root["columns"]) {
      ColumnMapping::Entry e;
      line = kv.first.Mark().line + 1;
      e.target = kv.first.as<std::string>();
      const YAML::Node n = kv.second;
      if (!n.IsMap() || !n["source"])
        throw FitError(path + ":" + std::to_string(line) + ": expected {source: COLUMN, scale, offset, unit}");
      e.source = n["source"].as<std::string>();
      if (n["scale"]) e.scale = n["scale"].as<double>();
      if (n["offset"]) e.offset = n["offset"].as<double>();
      if (!std::isfinite(e.scale) || !std::isfinite(e.offset))
        throw FitError(path + ":" + std::to_string(line) + ": scale and offset must be finite numbers");
      if (n["unit"]) e.unit = n["unit"].as<std::string>();
      m.entries.push_back(e);
    }
  } catch (const YAML::Exception& e) {
    throw FitError(path + ":" + std::to_string(e.mark.line >= 0 ? e.mark.line + 1 : line) +
                   ": expected {source: COLUMN, scale: NUMBER, offset: NUMBER, unit: TEXT}");
  }
  return m;
}

runtime::CsvTable apply_mapping(const runtime::CsvTable& raw, const ColumnMapping& m) {
  runtime::CsvTable out;
  out.path = raw.path;
  std::vector<int> src;
  for (const auto& e : m.entries) {
    const int c = raw.column(e.source);
    if (c < 0) throw FitError(raw.path + ":1: column '" + e.source + "' (mapped to '" + e.target + "' by " + m.name + ") is missing");
    src.push_back(c);
    out.columns.push_back(e.target);
  }
  for (const auto& row : raw.rows) {
    std::vector<double> r;
    for (size_t i = 0; i < src.size(); ++i) r.push_back(row[src[i]] * m.entries[i].scale + m.entries[i].offset);
    out.rows.push_back(r);
  }
  return out;
}

runtime::CsvTable resample(const runtime::CsvTable& log, double rate_hz) {
  const int tc = log.column("t");
  if (tc < 0) throw FitError(log.path + ":1: missing column 't'");
  if (log.rows.size() < 2) throw FitError(log.path + ": too few samples to resample");
  runtime::CsvTable out;
  out.path = log.path;
  out.columns = log.columns;
  const double t0 = log.rows.front()[tc], t1 = log.rows.back()[tc];
  size_t i = 0;
  for (long k = 0;; ++k) {
    const double t = t0 + static_cast<double>(k) / rate_hz;
    if (t > t1) break;
    while (i + 2 < log.rows.size() && log.rows[i + 1][tc] <= t) ++i;
    const auto& a = log.rows[i];
    const auto& b = log.rows[i + 1];
    if (!(b[tc] > a[tc])) throw FitError(log.path + ": time not strictly increasing near t = " + std::to_string(t));
    const double w = std::clamp((t - a[tc]) / (b[tc] - a[tc]), 0.0, 1.0);
    std::vector<double> row(a.size());
    for (size_t c = 0; c < a.size(); ++c) row[c] = (1 - w) * a[c] + w * b[c];
    row[tc] = t;
    out.rows.push_back(row);
  }
  return out;
}

std::vector<double> smoothed_derivative(const std::vector<double>& t, const std::vector<double>& y, double w) {
  const size_t n = t.size();
  std::vector<double> d(n, 0.0);
  size_t lo = 0, hi = 0;
  for (size_t k = 0; k < n; ++k) {
    while (t[k] - t[lo] > w) ++lo;
    while (hi + 1 < n && t[hi + 1] - t[k] <= w) ++hi;
    if (hi - lo < 2) continue;
    Eigen::MatrixXd A(hi - lo + 1, 3);
    Eigen::VectorXd b(hi - lo + 1);
    for (size_t i = lo; i <= hi; ++i) {
      const double dt = t[i] - t[k];
      A.row(i - lo) << 1, dt, dt * dt;
      b(i - lo) = y[i];
    }
    d[k] = A.colPivHouseholderQr().solve(b)(1);
  }
  return d;
}

Flight load_flight(const runtime::CsvTable& log, const std::vector<std::string>& rotors, const FlightOptions& o) {
  runtime::validate_canonical(log, rotors);
  Flight f;
  f.source = log.path;
  if (static_cast<double>(log.rows.size()) < o.min_samples)
    throw FitError(log.path + ": too few samples (" + std::to_string(log.rows.size()) + ", need " +
                   std::to_string(static_cast<int>(o.min_samples)) + ")");
  auto has = [&](std::initializer_list<const char*> cs) {
    for (const char* c : cs)
      if (log.column(c) < 0) return false;
    return true;
  };
  f.has_pose = has({"x", "y", "z", "qw", "qx", "qy", "qz"});
  f.has_gyro = has({"p", "q", "r"});
  f.has_accelerometer = has({"ax", "ay", "az"});
  f.has_vbat = has({"vbat"});
  if (!f.has_gyro) throw FitError(log.path + ":1: missing body rates p, q, r (gyro)");
  if (!f.has_pose && !f.has_accelerometer)
    throw FitError(log.path + ":1: need a pose (x, y, z, qw..qz) or an accelerometer (ax, ay, az)");
  const auto t = log.values("t");
  const double t0 = t.front();
  std::vector<double> trel;
  for (double v : t) trel.push_back(v - t0);
  auto col = [&](const char* c) { return log.column(c) >= 0 ? log.values(c) : std::vector<double>(t.size(), 0.0); };
  const char* names[] = {"x", "y", "z", "vx", "vy", "vz", "qw", "qx", "qy", "qz", "p", "q", "r"};
  std::vector<std::vector<double>> s;
  for (const char* n : names) s.push_back(col(n));
  if (!f.has_pose) s[6].assign(t.size(), 1.0);
  // Velocities from the pose where the log has none.
  const bool has_vel = has({"vx", "vy", "vz"});
  if (f.has_pose && !has_vel)
    for (int i = 0; i < 3; ++i) s[3 + i] = smoothed_derivative(trel, s[i], o.derivative_window);
  std::vector<std::vector<double>> acc(3), rdot(3);
  for (int i = 0; i < 3; ++i) {
    acc[i] = smoothed_derivative(trel, s[3 + i], o.derivative_window);
    rdot[i] = smoothed_derivative(trel, s[10 + i], o.derivative_window);
  }
  const auto ax = col("ax"), ay = col("ay"), az = col("az"), vbat = col("vbat");
  std::vector<std::vector<double>> u;
  for (const auto& r : rotors) u.push_back(log.values("u_" + r));
  for (size_t k = 0; k < t.size(); ++k) {
    FlightSample fs;
    fs.t = trel[k];
    for (int i = 0; i < 13; ++i) fs.x.push_back(s[i][k]);
    double qn = 0;
    for (int i = 6; i < 10; ++i) qn += fs.x[i] * fs.x[i];
    qn = std::sqrt(qn);
    if (!(qn > 0.5 && qn < 1.5))
      throw FitError(log.path + ":" + std::to_string(k + 2) + ": attitude quaternion has norm " + std::to_string(qn));
    for (int i = 6; i < 10; ++i) fs.x[i] /= qn;
    for (const auto& uc : u) fs.u.push_back(uc[k]);
    fs.vbat = vbat[k];
    for (int i = 0; i < 3; ++i) {
      fs.acc_world[i] = acc[i][k];
      fs.rate_dot[i] = rdot[i][k];
    }
    fs.specific_force[0] = ax[k];
    fs.specific_force[1] = ay[k];
    fs.specific_force[2] = az[k];
    bool airborne = true;
    for (double uc : fs.u) airborne = airborne && uc > o.min_command;
    if (f.has_pose) airborne = airborne && fs.x[2] > o.min_height;
    const bool edge = trel[k] < o.edge_trim || trel.back() - trel[k] < o.edge_trim;
    if ((!o.airborne_only || airborne) && !edge) f.samples.push_back(fs);
  }
  if (static_cast<double>(f.samples.size()) < o.min_samples)
    throw FitError(log.path + ": too few airborne samples (" + std::to_string(f.samples.size()) + ")");
  return f;
}

std::pair<Flight, Flight> split_by_time(const Flight& f, double frac) {
  Flight a = f, b = f;
  a.samples.clear();
  b.samples.clear();
  const double cut = f.samples.back().t * frac;
  for (const auto& s : f.samples) (s.t < cut ? a : b).samples.push_back(s);
  return {a, b};
}

}  // namespace quadgen::fit
