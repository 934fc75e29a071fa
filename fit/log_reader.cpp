#include "log_reader.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>

#include "least_squares.hpp"  // FitError

namespace quadgen::fit {

bool is_ulog(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char magic[7] = {};
  return in.read(magic, 7) && std::string(magic, 7) == std::string("ULog\x01\x12\x35", 7);
}

namespace {

// One mapped signal: its topic's timestamps (s) and values.
struct Signal {
  std::string source;
  std::vector<double> t, v;
};

Signal find_signal(const runtime::Ulog& log, const std::string& source) {
  const auto dot = source.find('.');
  const std::string topic = dot == std::string::npos ? source : source.substr(0, dot);
  const runtime::UlogTopic* tp = log.find(topic);
  if (!tp) {
    std::string have;
    for (const auto& t : log.topics) have += (have.empty() ? "" : ", ") + t.name;
    throw FitError(log.path + ": no topic '" + topic + "' for '" + source + "' (the log has: " + have + ")");
  }
  const int c = dot == std::string::npos ? -1 : tp->column(source.substr(dot + 1));
  if (c < 0) {
    std::string have;
    for (const auto& f : tp->fields) have += (have.empty() ? "" : ", ") + f;
    throw FitError(log.path + ": topic '" + topic + "' has no field for '" + source + "' (fields: " + have + ")");
  }
  Signal s{source, {}, {}};
  for (const auto& row : tp->rows) {
    const double t = row[0] * 1e-6;
    if (!s.t.empty() && t <= s.t.back()) continue;  // repeated or out-of-order timestamps
    s.t.push_back(t);
    s.v.push_back(row[c]);
  }
  if (s.t.size() < 2) throw FitError(log.path + ": topic '" + topic + "' has fewer than two samples");
  return s;
}

double interpolate(const Signal& s, double t) {
  const auto it = std::upper_bound(s.t.begin(), s.t.end(), t);
  if (it == s.t.begin()) return s.v.front();
  if (it == s.t.end()) return s.v.back();
  const size_t k = static_cast<size_t>(it - s.t.begin());
  const double w = (t - s.t[k - 1]) / (s.t[k] - s.t[k - 1]);
  return s.v[k - 1] + w * (s.v[k] - s.v[k - 1]);
}

}  // namespace

runtime::CsvTable ulog_table(const runtime::Ulog& log, const ColumnMapping& m, double rate_hz) {
  if (!(rate_hz > 0) || !std::isfinite(rate_hz)) throw FitError(log.path + ": sampling rate must be positive");
  std::vector<Signal> signals;
  double t0 = -std::numeric_limits<double>::infinity(), t1 = std::numeric_limits<double>::infinity();
  for (const auto& e : m.entries) {
    if (e.source == "t") continue;  // the time base this function makes
    signals.push_back(find_signal(log, e.source));
    t0 = std::max(t0, signals.back().t.front());
    t1 = std::min(t1, signals.back().t.back());
  }
  if (signals.empty()) throw FitError(m.name + ": maps no ULog signal (sources are topic.field)");
  if (!(t1 > t0)) throw FitError(log.path + ": the mapped topics do not overlap in time");
  const double step = 1.0 / rate_hz;
  const double rows = std::floor((t1 - t0) / step) + 1;
  if (rows > 5e7) throw FitError(log.path + ": " + std::to_string(rows) + " rows at this rate is too many");
  runtime::CsvTable out;
  out.path = log.path;
  out.columns.push_back("t");
  for (const auto& s : signals) out.columns.push_back(s.source);
  for (size_t k = 0; k < static_cast<size_t>(rows); ++k) {
    const double t = t0 + static_cast<double>(k) * step;
    std::vector<double> row{t - t0};
    for (const auto& s : signals) row.push_back(interpolate(s, t));
    out.rows.push_back(std::move(row));
  }
  return out;
}

runtime::CsvTable read_log(const std::string& path, const std::string& mapping_path, double resample_hz) {
  if (is_ulog(path)) {
    if (mapping_path.empty())
      throw FitError(path + ": a ULog log needs --mapping naming its signals as topic.field (docs/formats.md)");
    const ColumnMapping m = load_mapping(mapping_path);
    return apply_mapping(ulog_table(runtime::read_ulog(path), m, resample_hz > 0 ? resample_hz : 100.0), m);
  }
  runtime::CsvTable log = runtime::read_csv(path);
  if (!mapping_path.empty()) log = apply_mapping(log, load_mapping(mapping_path));
  if (resample_hz > 0) log = resample(log, resample_hz);
  return log;
}

}  // namespace quadgen::fit
