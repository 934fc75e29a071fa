#include "fit/flight_data.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <initializer_list>
#include <map>
#include <set>
#include <sstream>

#include <Eigen/Dense>
#include <yaml-cpp/yaml.h>

#include "fit/grid_mean.hpp"
#include "fit/least_squares.hpp"
#include "model/effect.hpp"
#include "model/yaml_reader.hpp"
#include "output/numbers.hpp"
#include "output/joined.hpp"
#include "output/names.hpp"
#include "runtime/data_side_effects.hpp"
#include "output/nearest_word.hpp"
#include "runtime/attitude.hpp"
#include "runtime/log_file.hpp"
#include "model/units.hpp"
#include "runtime/rigid_body_state.hpp"

namespace quadgen::fit {

using namespace runtime::rigid_body;

runtime::CsvTable read_measurement_csv(const std::string& path) {
  try {
    return runtime::read_csv(path);
  } catch (const runtime::LogError& e) {
    throw FitError(e.what());
  }
}

int measurement_column(const runtime::CsvTable& t, const std::string& name) {
  try {
    return t.column(name);
  } catch (const runtime::LogError& e) {
    throw FitError(e.what());
  }
}

// Column mappings (e.g. data/mappings/nanobench.yaml):
//
//   name: TEXT                       optional, names the mapping in messages
//   environment: indoor|outdoor      optional, where the logs were flown (what is plausible)
//   frame: enu_flu|ned_frd           optional, the axes of the source columns (default enu_flu)
//   columns:
//     CANONICAL: {source: COLUMN, scale: NUMBER, offset: NUMBER, unit: UNIT}
//
// canonical value = (source * scale + offset) converted from `unit` to the canonical
// column's SI unit: `unit` is the unit of (source * scale + offset), parsed by the same
// unit module as the vehicle files (model/units.hpp, parse_unit), and its dimension must
// be the canonical column's (t: s; x, y, z: m; vx, vy, vz: m/s; p, q, r: rad/s;
// ax, ay, az: m/s^2; qw..qz, u_*: 1; phi, theta, psi: rad; w_*: rad/s; vbat: V). So
// "deg/s" for p converts to rad/s by itself, and "m/s" for p is an error. Without `unit`
// the value is taken as already in the canonical unit. scale defaults to 1, offset to 0.
// Only the keys above are allowed, each once (at the top level, in `columns` and in each
// entry), and every target must be a canonical column; anything else is a file:line
// error, so that a typo ("sacle") cannot silently leave a column unscaled.

namespace {

// The mapping being read: its path for the errors, its text for the line of an empty value
// (node_line: yaml-cpp marks one where the next token starts).
struct MappingFile {
  const std::string& path;
  const std::string& text;
};

[[noreturn]] void mapping_error(const MappingFile& file, const YAML::Node& at, const std::string& what) {
  const int line = node_line(file.text, at);
  throw FitError(file.path + ":" + std::to_string(line >= 0 ? line + 1 : 1) + ": " + what);
}

std::string scalar_text(const MappingFile& file, const YAML::Node& n, const std::string& what) {
  if (!n.IsScalar()) mapping_error(file, n, what + ": expected a single value");
  return n.Scalar();
}

// By the one rule for YAML numbers (yaml_number), as the vehicle file reads them: yaml-cpp's
// own conversion read a scale of 1e-400 as 0 (a gyro column read as zeros without a word) and
// took '1 ' but not ' 1' (a review, helper-135).
double number_field(const MappingFile& file, const YAML::Node& n, const std::string& what) {
  const std::string text = scalar_text(file, n, what);
  double v = 0;
  const output::NumberText kind = yaml_number(text, &v);
  if (kind == output::NumberText::underflow)
    mapping_error(file, n, what + ": '" + output::printable(text) + "' " + output::number_text_problem(kind));
  if (kind != output::NumberText::finite)
    mapping_error(file, n, what + ": expected a finite number, got '" + output::printable(text) + "'" + output::hexadecimal_hint(text));
  return v;
}

// The keys of a YAML map, each allowed and present once; returns key -> value node.
std::map<std::string, YAML::Node> checked_keys(const MappingFile& file, const YAML::Node& map, const std::string& where,
                                               const std::vector<std::string>& allowed) {
  std::map<std::string, YAML::Node> out;
  for (const auto& kv : map) {
    const std::string key = scalar_text(file, kv.first, where + ": key");
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end())
      mapping_error(file, kv.first, where + ": unknown key '" + key + "' (allowed: " + output::joined(allowed) + ")" +
                                        output::did_you_mean(key, allowed));
    if (!out.emplace(key, kv.second).second)
      mapping_error(file, kv.first, where + ": duplicate key '" + key + "' (each of " + output::joined(allowed) + " at most once)");
  }
  return out;
}

// The unit conversion of one entry: checked against the canonical column's dimension.
double unit_scale(const MappingFile& file, const YAML::Node& at, const std::string& target, const std::string& unit) {
  const std::string canonical = canonical_unit(target);
  Unit u, want;
  // The two units logs use that the unit parser reads otherwise or not at all: a percentage,
  // and g as an acceleration (the parser's g is the gram).
  const bool acceleration = target == "ax" || target == "ay" || target == "az";
  const std::string hint = unit == "%"                  ? "; for a percentage write scale: 0.01 and unit: \"1\""
                           : unit == "g" && acceleration ? "; for g as an acceleration write scale: 9.80665 and unit: m/s^2 (g is the gram)"
                                                         : "";
  try {
    u = parse_unit(unit);
  } catch (const UnitError& e) {
    mapping_error(file, at, "column '" + target + "': " + e.what() + hint);
  }
  want = parse_unit(canonical);
  if (u.dim != want.dim)
    mapping_error(file, at, "column '" + target + "': unit '" + unit + "' has dimension " + u.dim.str() + ", but '" + target +
                                "' is in " + canonical + " (dimension " + want.dim.str() + ")" + hint);
  return u.scale / want.scale;
}

ColumnMapping::Entry parse_entry(const MappingFile& file, const YAML::Node& key, const YAML::Node& value) {
  ColumnMapping::Entry e;
  e.target = scalar_text(file, key, "column name");
  e.line = key.Mark().line + 1;
  if (canonical_unit(e.target).empty())
    mapping_error(file, key, "'" + output::printable(e.target) + "' is not a canonical column (expected one of " +
                                 runtime::kCanonicalColumns + ")");
  const std::string where = "column '" + e.target + "'";
  if (!value.IsMap()) mapping_error(file, key, where + ": expected {source: COLUMN, scale: NUMBER, offset: NUMBER, unit: UNIT}");
  const auto f = checked_keys(file, value, where, {"source", "scale", "offset", "unit"});
  if (!f.count("source")) mapping_error(file, key, where + ": missing 'source' (the log's column)");
  e.source = scalar_text(file, f.at("source"), where + ": source");
  if (f.count("scale")) {
    e.scale = number_field(file, f.at("scale"), where + ": scale");
    if (e.scale == 0) mapping_error(file, f.at("scale"), where + ": scale: 0 would read every value of the column as 0 (the offset alone)");
  }
  if (f.count("offset")) e.offset = number_field(file, f.at("offset"), where + ": offset");
  if (f.count("unit")) {
    e.unit = scalar_text(file, f.at("unit"), where + ": unit");
    e.unit_scale = unit_scale(file, f.at("unit"), e.target, e.unit);
  }
  return e;
}

}  // namespace

ColumnMapping load_mapping(const std::string& path) {
  std::string text;
  try {  // opened as a log is: a FIFO or a directory is refused, not waited on; size-limited
    text = runtime::LogFile(path, "a column mapping (YAML)", runtime::kMaxYamlBytes).read_all();
  } catch (const runtime::LogError& e) {
    throw FitError(e.what());
  }
  return parse_mapping(text, path);
}

ColumnMapping parse_mapping(const std::string& text, const std::string& path) {
  YAML::Node root;
  int dropped = -1;
  try {
    root = load_one_document(text, &dropped);
  } catch (const YAML::ParserException& e) {
    throw FitError(path + ":" + std::to_string(e.mark.line + 1) + ": " + malformed_yaml(e, text));
  }
  if (dropped >= 0) throw FitError(path + ":" + std::to_string(dropped + 1) + ": " + kSecondYamlDocument);
  if (!root.IsMap()) throw FitError(path + ":1: expected a mapping with 'name' and 'columns'");
  ColumnMapping m;
  m.path = path;
  const MappingFile file{path, text};
  try {  // yaml-cpp's own errors (ill-formed nodes) still end as one file:line
    const auto top = checked_keys(file, root, "mapping", {"name", "columns", "environment", "frame"});
    constexpr const char* kNoColumns = "expected a 'columns' mapping (canonical column: {source, scale, offset, unit})";
    if (!top.count("columns")) throw FitError(path + ":1: " + kNoColumns);
    if (!top.at("columns").IsMap()) mapping_error(file, top.at("columns"), kNoColumns);
    m.name = top.count("name") ? scalar_text(file, top.at("name"), "name") : path;
    if (top.count("frame")) {
      m.frame = scalar_text(file, top.at("frame"), "frame");
      if (m.frame != "enu_flu" && m.frame != "ned_frd")
        mapping_error(file, top.at("frame"), "frame: expected enu_flu (the model's axes) or ned_frd (PX4's)");
    }
    if (top.count("environment")) {
      m.environment = scalar_text(file, top.at("environment"), "environment");
      if (!output::is_one_of(m.environment, kEnvironmentNames))
        mapping_error(file, top.at("environment"), "environment: expected one of " + output::joined(kEnvironmentNames));
    }
    std::set<std::string> targets;
    for (const auto& kv : top.at("columns")) {
      ColumnMapping::Entry e = parse_entry(file, kv.first, kv.second);
      if (!targets.insert(e.target).second)
        mapping_error(file, kv.first,
                      "columns: duplicate key '" + output::printable(e.target) + "' (each canonical column at most once)");
      m.entries.push_back(std::move(e));
    }
  } catch (const YAML::Exception& e) {
    throw FitError(path + ":" + std::to_string(e.mark.line >= 0 ? e.mark.line + 1 : 1) + ": " + output::printable(e.msg) +
                   " (expected {source: COLUMN, scale: NUMBER, offset: NUMBER, unit: UNIT})");
  }
  return m;
}

namespace {

// North-east-down world / forward-right-down body columns to east-north-up / forward-left-up:
// world vectors (y, x, -z); body vectors (x, -y, -z); the attitude q_enu<-flu =
// q_enu<-ned (x) q_ned<-frd (x) q_frd<-flu, with q_enu<-ned = (0, 1/sqrt2, 1/sqrt2, 0) and
// q_frd<-flu = (0, 1, 0, 0).
void ned_frd_to_enu_flu(runtime::CsvTable& t, const std::string& mapping_name) {
  const auto col = [&](const char* n) { return t.column(n); };
  for (const char* euler : {"phi", "theta", "psi", "phi_ref", "theta_ref"})
    if (col(euler) >= 0)
      throw FitError(mapping_name + ": frame ned_frd converts a quaternion attitude (qw..qz), not Euler angles ('" +
                     std::string(euler) + "')");
  const auto world = [&](const char* a, const char* b, const char* c) {
    const int x = col(a), y = col(b), z = col(c);
    if ((x < 0) != (y < 0))
      throw FitError(mapping_name + ": frame ned_frd needs both '" + a + "' and '" + b + "' to swap them");
    for (auto& r : t.rows) {
      if (x >= 0) std::swap(r[x], r[y]);
      if (z >= 0) r[z] = -r[z];
    }
  };
  world("x", "y", "z");
  world("vx", "vy", "vz");
  for (const char* body : {"q", "r", "ay", "az"})
    if (col(body) >= 0)
      for (auto& r : t.rows) r[col(body)] = -r[col(body)];
  const int qw = col("qw"), qx = col("qx"), qy = col("qy"), qz = col("qz");
  if (qw < 0 || qx < 0 || qy < 0 || qz < 0) return;
  const double h = std::sqrt(0.5);
  for (auto& r : t.rows) {
    const double w = r[qw], x = r[qx], y = r[qy], z = r[qz];
    // (0, h, h, 0) (x) q (x) (0, 1, 0, 0) multiplied out, sign flipped (q and -q are one
    // attitude) so that the identity becomes +90 degrees of yaw with w > 0
    r[qw] = h * (w + z);
    r[qx] = h * (x + y);
    r[qy] = h * (x - y);
    r[qz] = h * (w - z);
  }
}

}  // namespace

namespace {

// A source column the log does not have is the mapping's line to fix (or the wrong log):
// named there, with the log's column it probably meant.
std::string missing_source(const runtime::CsvTable& raw, const ColumnMapping& m, const ColumnMapping::Entry& e) {
  const std::string where = m.path.empty() ? raw.path + ":1" : m.path + (e.line > 0 ? ":" + std::to_string(e.line) : "");
  std::string said = where + ": column '" + e.source + "' (for '" + e.target + "') is not in the header of " + raw.path;
  return said + output::did_you_mean(e.source, raw.columns);
}

}  // namespace

runtime::CsvTable apply_mapping(const runtime::CsvTable& raw, const ColumnMapping& m) {
  runtime::CsvTable out;
  out.path = raw.path;
  out.lines = raw.lines;
  out.resampled_hz = raw.resampled_hz;
  out.time_from_topics_start = raw.time_from_topics_start;
  out.notes = raw.notes;
  out.parameters = raw.parameters;
  std::vector<int> src;
  for (const auto& e : m.entries) {
    const int c = raw.column(e.source);
    if (c < 0) throw FitError(missing_source(raw, m, e));
    src.push_back(c);
    out.columns.push_back(e.target);
    out.name_lines.push_back(e.line);
  }
  out.named_by = m.path;
  out.rows.reserve(raw.rows.size());
  for (const auto& row : raw.rows) {
    std::vector<double> r;
    r.reserve(src.size());
    for (size_t i = 0; i < src.size(); ++i) {
      const auto& e = m.entries[i];
      const double v = row[src[i]] * e.scale + e.offset;
      r.push_back(e.unit_scale == 1 ? v : v * e.unit_scale);  // exactly v in the canonical unit
    }
    out.rows.push_back(std::move(r));
  }
  if (m.frame == "ned_frd") ned_frd_to_enu_flu(out, m.name);
  return out;
}

namespace {

// The columns resample averages from a prepared copy rather than as logged, by index: the
// quaternion's four components sign-aligned row to row, the Euler roll and yaw unwrapped.
std::map<size_t, std::vector<double>> columns_to_average(const runtime::CsvTable& log) {
  std::map<size_t, std::vector<double>> out;
  const auto column = [&](const char* name) {
    std::vector<double> v;
    const int c = log.column(name);
    if (c >= 0)
      for (const auto& row : log.rows) v.push_back(row[static_cast<size_t>(c)]);
    return std::make_pair(c, v);
  };
  for (const char* angle : {"phi", "psi"})
    if (auto [c, v] = column(angle); c >= 0) out[static_cast<size_t>(c)] = unwrapped(v, 2 * M_PI);
  std::array<std::pair<int, std::vector<double>>, 4> q{column("qw"), column("qx"), column("qy"), column("qz")};
  if (std::any_of(q.begin(), q.end(), [](const auto& c) { return c.first < 0; })) return out;
  align_quaternion_signs({&q[0].second, &q[1].second, &q[2].second, &q[3].second});
  for (auto& [c, v] : q) out[static_cast<size_t>(c)] = std::move(v);
  return out;
}

}  // namespace

runtime::CsvTable resample(const runtime::CsvTable& log, double rate_hz) {
  const int tc = log.column("t");
  if (tc < 0) throw FitError(log.path + ":1: missing column 't'");
  if (log.rows.size() < 2) throw FitError(log.path + ": too few samples to resample");
  // Checked here, where the rows still have their lines: averaging would spread a bad value
  // over its neighbours and the error would name a resampled row.
  runtime::check_values(log);
  // The range of the Euler angles too: the resampled roll is wrapped into (-pi, pi], where a
  // roll in degrees read as radians would pass (hostile-input audit, helper-105).
  check_euler_range(log);
  // Every row's time after the one before, checked before resampling: the interpolating loop
  // this replaced saw only the pair it interpolated between and walked past rows whose time
  // went back (a review: 100 reversed rows were resampled without a word).
  for (size_t i = 1; i < log.rows.size(); ++i)
    if (!(log.rows[i][tc] > log.rows[i - 1][tc]))
      throw FitError(log.where_row(i) + ": time not strictly increasing (" +
                     output::one_then_other(log.rows[i - 1][tc], log.rows[i][tc]) + ")");
  const double t0 = log.rows.front()[tc], t1 = log.rows.back()[tc];
  if (!(rate_hz > 0) || !std::isfinite(rate_hz)) throw FitError("resample: rate must be a positive number of Hz");
  // A bound on the resampled table's size, so that a high rate ends in a message rather
  // than in std::bad_alloc: 1e8 values (800 MB).
  const double n_out = std::floor(std::max(0.0, t1 - t0) * rate_hz) + 1;
  if (n_out * static_cast<double>(log.columns.size()) > 1e8)
    throw FitError(log.path + ": resampling " + output::six_digits(t1 - t0) + " s at " + output::six_digits(rate_hz) + " Hz gives " +
                   std::to_string(static_cast<long long>(std::min(n_out, 1e18))) + " samples of " +
                   std::to_string(log.columns.size()) + " columns, above the limit of 1e8 values");
  runtime::CsvTable out;
  out.path = log.path;
  out.columns = log.columns;
  out.named_by = log.named_by;
  out.name_lines = log.name_lines;
  out.unreadable = log.unreadable;  // asking for one stays the error at its line
  out.resampled_hz = rate_hz;
  out.time_from_topics_start = log.time_from_topics_start;
  // Each column's mean over the grid interval around each grid point, not its value there
  // (fit/grid_mean.hpp): a log faster than the grid would fold its fast content into the rest.
  // Columns that must not be averaged as logged are averaged from a copy: the quaternion's
  // components sign-aligned row to row (q and -q are one attitude), the Euler roll and yaw
  // unwrapped.
  const std::map<size_t, std::vector<double>> prepared = columns_to_average(log);
  std::vector<double> times(log.rows.size());
  for (size_t i = 0; i < times.size(); ++i) times[i] = log.rows[i][tc];
  std::vector<const std::vector<double>*> from_copy(log.columns.size(), nullptr);
  for (const auto& [c, v] : prepared) from_copy[c] = &v;
  const int phi = log.column("phi");
  for (long k = 0;; ++k) {
    const double t = t0 + static_cast<double>(k) / rate_hz;
    if (t > t1) break;
    const GridWeights g = grid_weights(times, 0, times.size() - 1, t, 0.5 / rate_hz);
    std::vector<double> row(log.columns.size(), 0.0);
    for (size_t i = 0; i < g.weight.size(); ++i) {
      const size_t r = g.first_sample + i;
      for (size_t c = 0; c < row.size(); ++c) row[c] += g.weight[i] * (from_copy[c] ? (*from_copy[c])[r] : log.rows[r][c]);
    }
    row[tc] = t;
    if (phi >= 0) row[static_cast<size_t>(phi)] = wrapped_to_pi(row[static_cast<size_t>(phi)]);
    out.rows.push_back(std::move(row));
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

namespace {
// Too few airborne samples is most often a unit: time in ms (the edge trim then takes all of
// it), commands that never pass min_command, a height in mm. The message gives what tells.
[[noreturn]] void throw_too_few_airborne(const std::string& path, const std::vector<double>& trel, const Flight& f,
                                         const FlightOptions& o, bool landed_logged) {
  std::vector<double> dt;
  for (size_t k = 1; k < trel.size(); ++k) dt.push_back(trel[k] - trel[k - 1]);
  std::nth_element(dt.begin(), dt.begin() + static_cast<long>(dt.size() / 2), dt.end());
  std::ostringstream os;
  os << path << ": too few airborne samples (" << f.samples.size() << " of " << trel.size() << "; need "
     << static_cast<int>(o.min_samples) << "): a sample counts when every motor command is above " << o.min_command
     << (f.has_pose ? " and z above " + output::short_number(o.min_height) + " m" : std::string())
     << (landed_logged ? ", the log's landed flag below 0.5" : "") << ", more than "
     << o.edge_trim << " s from either end; the log spans " << trel.back() << " s with a median sample interval of "
     << dt[dt.size() / 2] << " s (is t in seconds?)";
  throw FitError(os.str());
}
}  // namespace

std::string gyro_disagreement_hint(double slope, double se, bool euler) {
  // A unit's hint only where the slope is that unit's factor and the data tell the factor from
  // zero (a mapping with p and q swapped gave -0.13 +- 0.058, and was told "deg/s read as
  // rad/s?": a user trial, helper-91); any other disagreement is one of convention or axes.
  const double per_degree = M_PI / 180;
  const auto near = [&](double factor) {
    return slope > 0 && 3 * se < factor && std::fabs(slope - factor) < 3 * se + 0.25 * factor;
  };
  const std::string convention =
      "the attitude and the gyro disagree in convention or axes: a world-to-body quaternion (in the mapping, scale: "
      "-1 on qx, qy, qz), gyro axes of another frame (frame: ned_frd), or gyro columns mapped to the wrong axes?";
  if (near(per_degree)) return "deg/s read as rad/s? (in the mapping, unit: deg/s)";
  if (near(1 / per_degree))
    return euler ? "attitude angles in degrees read as radians (in the mapping, unit: deg), or a gyro in rad/s read as deg/s?"
                 : "rad/s read as deg/s?";
  // Turning far less than the gyro says, on data too noisy to tell 1/57 from zero: both.
  if (slope > 0 && slope < 0.2) return "deg/s read as rad/s (in the mapping, unit: deg/s)? Or " + convention;
  return convention;
}

namespace {
// Where a message about the unit of a sensor's columns starts: at the mapping's entry for the
// first of them, where the fix is, not at the log (a newcomer's trial, helper-118: "mylog.csv:
// ... deg/s read as rad/s?" left the mapping's lines to be found). "M.yaml:12: the gyro's
// entries (p, q, r: lines 12, 13, 14) for log.csv", or the log's path alone where it names its
// own columns.
std::string log_and_entries(const runtime::CsvTable& log, std::initializer_list<const char*> columns, const char* what) {
  std::vector<std::string> names, lines;
  int first = -1;
  for (const char* name : columns) {
    const int c = log.column(name);
    if (c < 0 || static_cast<size_t>(c) >= log.name_lines.size()) continue;
    if (first < 0) first = c;
    names.push_back(name);
    lines.push_back(std::to_string(log.name_lines[static_cast<size_t>(c)]));
  }
  if (log.named_by.empty() || first < 0) return log.path;
  return log.where_named(first) + ": " + what + "'s entries (" + output::joined(names) + ": lines " +
         output::joined(lines) + ") for " + log.path;
}

// Two unit mistakes a mapping can make that no dimension check sees, because the unit is
// right and the number is not: a gyro in deg/s declared rad/s (57 times the rates the
// attitude shows) and an accelerometer in g declared m/s^2 (a specific force near 1 in
// flight, where it is near 9.8). Judged on airborne samples, only where the data can tell.
// Over windows of up to 0.2 s: whether the attitude turns as far as the gyro says (a gyro in
// deg/s declared rad/s turns it 57 times too little).
// `euler`: the log's attitude is given as Euler angles (which may be in degrees).
void check_gyro_against_attitude(const std::string& path, const Flight& f, bool euler) {
  const auto& S = f.samples;
  if (f.has_pose && f.has_gyro && S.size() > 10) {
    // Over windows of up to 0.2 s: the attitude's turn A (rotation vector of q_a^-1 q_b, body
    // axes) against the gyro's integral G. The slope of A on G is 1 for a gyro in the right
    // unit and is not biased by the attitude's noise (it is in A, not in G); in deg/s declared
    // rad/s it is 1/57. A window ends once G reaches 1 rad, before A could wrap past pi in a
    // flip. Judged only where its standard error is small.
    double ag = 0, gg = 0, aa = 0;
    size_t n = 0;
    for (size_t k = 0; k + 1 < S.size();) {
      Eigen::Vector3d G = Eigen::Vector3d::Zero();
      size_t j = k;
      bool gap = false;
      while (j + 1 < S.size() && S[j].t - S[k].t < 0.2 && G.norm() < 1) {
        const double dt = S[j + 1].t - S[j].t;
        gap = gap || !(dt > 0 && dt < 0.1);
        G += Eigen::Map<const Eigen::Vector3d>(&S[j].x[kBodyRate]) * dt;
        ++j;
      }
      const auto quat = [&](size_t i) {
        const double* q = &S[i].x[kAttitude];
        return Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
      };
      if (!gap && j > k) {
        const Eigen::AngleAxisd turn(quat(k).conjugate() * quat(j));
        const Eigen::Vector3d A = turn.axis() * turn.angle();
        ag += A.dot(G), gg += G.squaredNorm(), aa += A.squaredNorm(), ++n;
      }
      k = j;
    }
    if (n > 20 && gg > 0) {
      const double slope = ag / gg;
      const double se = std::sqrt(std::max(0.0, aa - slope * ag) / static_cast<double>(3 * n - 1) / gg);
      if ((slope + 3 * se < 0.2 || slope - 3 * se > 5) && se < 0.1 * std::max(1.0, std::fabs(slope))) {
        std::ostringstream os;
        os << path << ": the logged attitude turns " << slope << " times as far as the gyro's rates say (+- " << se
           << ", over " << n << " windows of up to 0.2 s): " << gyro_disagreement_hint(slope, se, euler);
        throw FitError(os.str());
      }
    }
  }
}

// Whether the accelerometer's specific force is in m/s^2 (an IMU in g reads near 1 in flight).
void check_accelerometer_unit(const std::string& path, const Flight& f) {
  const auto& S = f.samples;
  if (f.has_accelerometer && !S.empty()) {
    const auto median_of = [](std::vector<double> v) {
      std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
      return v[v.size() / 2];
    };
    std::vector<double> measured, from_pose;
    for (const auto& sample : S) {
      measured.push_back(Eigen::Vector3d(sample.specific_force[0], sample.specific_force[1], sample.specific_force[2]).norm());
      // What the pose says it must be: |a - g|, the acceleration less gravity (z up).
      from_pose.push_back(Eigen::Vector3d(sample.acc_world[0], sample.acc_world[1], sample.acc_world[2] + kStandardGravity).norm());
    }
    const double median = median_of(measured);
    // Near 1 where flight gives near 9.8; with a pose, only where the pose says so too (a drop
    // test or a throw measures little specific force in the right unit).
    const bool pose_disagrees = !f.has_pose || median < 0.25 * median_of(from_pose);
    if (median > 0.5 && median < 2 && pose_disagrees) {
      std::ostringstream os;
      os << path << ": the accelerometer's specific force in flight is " << median
         << " m/s^2 (median), where it is near 9.8: in g? (in the mapping, scale: 9.80665 and unit: m/s^2; quadgen "
            "reads the specific force with gravity in it, as an IMU measures it)";
      throw FitError(os.str());
    }
  }
}

// Which signals the log holds, refused where it lacks what a fit needs (the gyro, and a pose
// or an accelerometer).
void read_signals(const runtime::CsvTable& log, Flight& f) {
  auto has = [&](std::initializer_list<const char*> cs) {
    return std::all_of(cs.begin(), cs.end(), [&](const char* c) { return log.column(c) >= 0; });
  };
  f.has_pose = has({"x", "y", "z"}) && attitude_columns(log) != AttitudeColumns::kNone;
  f.has_gyro = has({"p", "q", "r"});
  f.has_accelerometer = has({"ax", "ay", "az"});
  f.has_vbat = has({"vbat"});
  f.has_attitude_ref = has({"phi_ref", "theta_ref"});
  if (!f.has_gyro)
    throw FitError(runtime::missing_columns_message(log, {"p", "q", "r"}, {"the body rates (gyro)", "rad/s", ""}));
  // Part of the accelerometer logged (a header misspelt, or spelt with a look-alike letter):
  // the fit would change its formulation without a word.
  std::vector<std::string> accel_has, accel_lacks;
  for (const char* c : {"ax", "ay", "az"}) (log.column(c) >= 0 ? accel_has : accel_lacks).push_back(c);
  if (!accel_has.empty() && !accel_lacks.empty())
    f.notes.push_back(log.where_named() + ": the accelerometer is not read: it has " + output::joined(accel_has) +
                      " but not " + output::joined(accel_lacks));
  if (f.has_pose) return;
  const std::string lacks = pose_lacks(log), pose = std::string("x, y, z and ") + kAttitudeColumnSets;
  if (!f.has_accelerometer)
    throw FitError(log.where_named() + ": need a pose (" + pose + ") or an accelerometer (ax, ay, az)" +
                   (lacks.empty() ? "" : "; " + lacks));
  // Part of a pose logged: the user may expect it read.
  if (!lacks.empty()) {
    f.notes.push_back(log.where_named() + ": no pose is read, only the accelerometer: a pose needs " + pose + "; " + lacks);
    f.pose_partly_logged = true;
  }
}

// The log's columns as the samples take them: time from the first row, the states (velocities
// from the pose where none are logged), the derivatives, the sensors and the commands.
struct FlightColumns {
  std::vector<double> t;                          // s, from the first row
  std::vector<std::vector<double>> states;        // kStateNames, 0 where not logged
  std::vector<std::vector<double>> acc, rate_dot;  // world acceleration, body-rate derivative
  std::vector<double> ax, ay, az, vbat, phi_ref, theta_ref;
  std::vector<std::vector<double>> commands;      // per rotor
  std::vector<double> landed;                     // the controller's landed flag; empty where not logged
};

FlightColumns read_columns(const runtime::CsvTable& log, const std::vector<std::string>& rotors, const Flight& f,
                           const FlightOptions& o) {
  FlightColumns c;
  const auto t = log.values("t");
  for (double v : t) c.t.push_back(v - t.front());
  auto col = [&](const char* name) { return log.column(name) >= 0 ? log.values(name) : std::vector<double>(t.size(), 0.0); };
  for (const char* n : kStateNames) c.states.push_back(col(n));
  if (!f.has_pose) c.states[kAttitude].assign(t.size(), 1.0);
  if (f.has_pose && attitude_columns(log) == AttitudeColumns::kEuler)
    for (size_t k = 0; k < t.size(); ++k) {
      const auto q = logged_attitude(log, AttitudeColumns::kEuler, k);
      for (int i = 0; i < 4; ++i) c.states[kAttitude + i][k] = q[i];
    }
  const bool has_velocity = log.column("vx") >= 0 && log.column("vy") >= 0 && log.column("vz") >= 0;
  if (f.has_pose && !has_velocity)
    for (int i = 0; i < 3; ++i) c.states[kVelocity + i] = smoothed_derivative(c.t, c.states[kPosition + i], o.derivative_window);
  for (int i = 0; i < 3; ++i) {
    c.acc.push_back(smoothed_derivative(c.t, c.states[kVelocity + i], o.derivative_window));
    c.rate_dot.push_back(smoothed_derivative(c.t, c.states[kBodyRate + i], o.derivative_window));
  }
  c.ax = col("ax"), c.ay = col("ay"), c.az = col("az"), c.vbat = col("vbat");
  c.phi_ref = col("phi_ref"), c.theta_ref = col("theta_ref");
  if (log.column("landed") >= 0) c.landed = log.values("landed");
  for (const auto& r : rotors) c.commands.push_back(log.values("u_" + r));
  return c;
}

// Row k as a sample, its attitude quaternion normalised (refused far from unit norm).
FlightSample sample_at(const FlightColumns& c, size_t k, const runtime::CsvTable& log) {
  FlightSample fs;
  fs.t = c.t[k];
  for (int i = 0; i < kNumStates; ++i) fs.x.push_back(c.states[i][k]);
  double qn = 0;
  for (int i = kAttitude; i < kAttitude + 4; ++i) qn += fs.x[i] * fs.x[i];
  qn = std::sqrt(qn);
  if (!(qn > 0.5 && qn < 1.5))
    throw FitError(log.where_row(k) + ": attitude quaternion has norm " + output::six_digits(qn));
  for (int i = kAttitude; i < kAttitude + 4; ++i) fs.x[i] /= qn;
  for (const auto& uc : c.commands) fs.u.push_back(uc[k]);
  fs.vbat = c.vbat[k];
  for (int i = 0; i < 3; ++i) {
    fs.acc_world[i] = c.acc[i][k];
    fs.rate_dot[i] = c.rate_dot[i][k];
  }
  fs.specific_force[0] = c.ax[k];
  fs.specific_force[1] = c.ay[k];
  fs.specific_force[2] = c.az[k];
  fs.attitude_ref[0] = c.phi_ref[k];
  fs.attitude_ref[1] = c.theta_ref[k];
  return fs;
}

// Whether a sample is kept: airborne (every command above min_command, with a pose above
// min_height, and not on the ground by the log's landed flag) unless all rows are asked for,
// and away from the log's ends. The flag is what tells an armed idle on the ground from flight
// where the height is an estimator's, which drifts on the ground by more than min_height (a
// review of the PX4 reading, helper-152).
bool kept(const FlightSample& fs, const Flight& f, double duration, const FlightOptions& o, bool landed) {
  bool airborne = !landed && std::all_of(fs.u.begin(), fs.u.end(), [&](double uc) { return uc > o.min_command; });
  if (f.has_pose) airborne = airborne && fs.x[2] > o.min_height;
  const bool edge = fs.t < o.edge_trim || duration - fs.t < o.edge_trim;
  return (!o.airborne_only || airborne) && !edge;
}
}  // namespace

namespace {
// Samples in the air with a motor command at or below min_command, within the flight (between
// the first and the last sample in the air with every rotor running): left out as not
// airborne, which hides a controller out of authority (a rotor stopped in flight) or a
// throttle cut. Take-off and landing lie outside that span (a Crazyflie cuts its motors at
// about 0.12 m). Said when more than 1 % of the span's samples are left out so.
struct IdleInTheAir {
  enum Kind : char { kOnTheGround, kRunning, kIdle };
  std::vector<Kind> kinds;  // per row
  void count(const FlightSample& fs, const Flight& f, const FlightOptions& o, bool landed) {
    if (!f.has_pose || !o.airborne_only || !(fs.x[2] > o.min_height) || landed) return kinds.push_back(kOnTheGround);
    const bool idle = std::any_of(fs.u.begin(), fs.u.end(), [&](double uc) { return !(uc > o.min_command); });
    kinds.push_back(idle ? kIdle : kRunning);
  }
  std::string note(const std::string& where, const FlightOptions& o) const {
    const auto first = std::find(kinds.begin(), kinds.end(), kRunning);
    const auto last = std::find(kinds.rbegin(), kinds.rend(), kRunning).base();
    if (first >= last) return "";
    const auto idle = static_cast<size_t>(std::count(first, last, kIdle));
    const auto in_the_air = idle + static_cast<size_t>(std::count(first, last, kRunning));
    if (static_cast<double>(idle) <= 0.01 * static_cast<double>(in_the_air)) return "";
    std::ostringstream os;
    os << where << ": " << idle << " of the " << in_the_air << " samples above " << o.min_height
       << " m between take-off and landing have a motor command at or below " << o.min_command
       << " and are left out (a rotor at idle is not in the model): a controller out of authority, or a throttle cut?";
    return os.str();
  }
};

const std::array<std::string, 4> kQuaternionColumns{"qw", "qx", "qy", "qz"};
const std::array<std::string, 3> kEulerColumns{"phi", "theta", "psi"};
}  // namespace

AttitudeColumns attitude_columns(const runtime::CsvTable& log) {
  const auto has = [&](const auto& cs) {
    return std::all_of(cs.begin(), cs.end(), [&](const std::string& c) { return log.column(c) >= 0; });
  };
  if (has(kQuaternionColumns)) return AttitudeColumns::kQuaternion;
  if (has(kEulerColumns)) return AttitudeColumns::kEuler;
  return AttitudeColumns::kNone;
}

std::string incomplete_attitude(const runtime::CsvTable& log) {
  if (attitude_columns(log) != AttitudeColumns::kNone) return "";
  std::vector<std::string> has_q, has_e, lacks_q, lacks_e;
  for (const auto& c : kQuaternionColumns) (log.column(c) >= 0 ? has_q : lacks_q).push_back(c);
  for (const auto& c : kEulerColumns) (log.column(c) >= 0 ? has_e : lacks_e).push_back(c);
  if (has_q.empty() && has_e.empty()) return "";
  // The form the log comes nearer to is the one it meant.
  const bool meant_euler = has_e.size() * 4 > has_q.size() * 3;
  std::vector<std::string> has = has_q;
  has.insert(has.end(), has_e.begin(), has_e.end());
  return "it has " + output::joined(has) + " but not " + output::joined(meant_euler ? lacks_e : lacks_q);
}

std::string pose_lacks(const runtime::CsvTable& log) {
  std::vector<std::string> positions;
  for (const char* c : {"x", "y", "z"})
    if (log.column(c) < 0) positions.push_back(c);
  const bool attitude = attitude_columns(log) != AttitudeColumns::kNone;
  const std::string partial = incomplete_attitude(log);
  const bool none_of_it = positions.size() == 3 && !attitude && partial.empty();
  if (none_of_it || (positions.empty() && attitude)) return "";
  std::vector<std::string> said;
  if (!positions.empty()) said.push_back("it lacks " + output::joined(positions));
  if (!partial.empty()) said.push_back(partial);
  else if (!attitude) said.push_back("it has no attitude");
  return output::joined(said, "; ");
}

std::array<double, 4> logged_attitude(const runtime::CsvTable& log, AttitudeColumns form, size_t row) {
  const auto at = [&](const char* c) { return log.rows[row][log.column(c)]; };
  switch (form) {
    case AttitudeColumns::kQuaternion: return {at("qw"), at("qx"), at("qy"), at("qz")};
    case AttitudeColumns::kEuler: return runtime::quaternion_from_euler_zyx(at("phi"), at("theta"), at("psi"));
    case AttitudeColumns::kNone: break;
  }
  return {1, 0, 0, 0};
}

// Z-Y-X Euler angles in degrees read as radians make a random attitude that no later check
// reliably catches (the gyro check's windows turn less than pi; these turn tens of radians):
// a roll beyond +-pi or a pitch beyond +-pi/2 is no Z-Y-X angle in radians. The yaw may be
// logged unwrapped, so it is not judged.
std::string euler_range_problem(const std::string& column, double value_rad) {
  const bool roll = column == "phi";
  if (!roll && column != "theta") return "";
  const double limit = roll ? M_PI : M_PI / 2;
  if (!(std::fabs(value_rad) > limit + 1e-3)) return "";  // NaN is judged where values are read
  std::ostringstream os;
  os << column << " = " << value_rad << " rad lies outside the range of a Z-Y-X Euler angle, "
     << (roll ? "+-pi (180 deg)" : "+-pi/2 (90 deg)")
     << ": angles in degrees? (the canonical log takes radians; in a mapping, unit: deg)";
  return os.str();
}

void check_euler_range(const runtime::CsvTable& log) {
  if (attitude_columns(log) != AttitudeColumns::kEuler) return;
  for (const char* column : {"phi", "theta"}) {
    const int c = log.column(column);
    for (size_t k = 0; k < log.rows.size(); ++k) {
      const std::string problem = euler_range_problem(column, log.rows[k][static_cast<size_t>(c)]);
      if (!problem.empty()) throw FitError(log.where_row(k) + ": " + problem);
    }
  }
}

// Time in milliseconds read as seconds: samples seconds apart. A flight log holds tens to
// thousands of samples a second; a median interval of half a second or more is no such log.
void check_time_unit(const runtime::CsvTable& log) {
  if (log.column("t") < 0 || log.rows.size() < 3) return;
  const double median = runtime::median_interval(log.values("t"));
  if (!(median >= 0.5)) return;
  std::ostringstream os;
  if (log.resampled_hz > 0) {  // the rate asked for, not the log's time unit (a review)
    os << log.path << ": --resample " << log.resampled_hz << " gives samples " << median
       << " s apart: a flight log holds tens to thousands a second (the rate is in Hz)";
    throw FitError(os.str());
  }
  os << log.where_named() << ": its samples are " << median << " s apart (the median interval of " << log.rows.size()
     << " samples): a flight log holds tens to thousands a second; is t in seconds? (milliseconds: in a mapping, "
        "scale: 0.001 on t)";
  throw FitError(os.str());
}

void require_known_columns_readable(const runtime::CsvTable& log) {
  log.require_readable([](const std::string& name) { return !canonical_unit(name).empty(); });
}

Flight load_flight(const runtime::CsvTable& log, const std::vector<std::string>& rotors, const FlightOptions& o) {
  // The likeliest cause of a missing column in a log read without a mapping: it needs one.
  runtime::validate_canonical(log, rotors,
                              log.named_by.empty() ? "; a log in another layout is read with --mapping M.yaml "
                                                     "(docs/formats.md, \"Column mapping\")"
                                                   : "");
  require_known_columns_readable(log);
  check_time_unit(log);
  check_euler_range(log);
  Flight f;
  f.source = log.path;
  f.notes = log.notes;  // what reading it noticed (a slow topic, dropouts)
  if (static_cast<double>(log.rows.size()) < o.min_samples)
    throw FitError(log.path + ": too few samples (" + std::to_string(log.rows.size()) + ", need " +
                   std::to_string(static_cast<int>(o.min_samples)) + ")");
  read_signals(log, f);
  const FlightColumns columns = read_columns(log, rotors, f, o);
  IdleInTheAir idle;
  size_t flagged = 0;  // rows the landed flag alone keeps out
  for (size_t k = 0; k < columns.t.size(); ++k) {
    FlightSample fs = sample_at(columns, k, log);
    const bool landed = !columns.landed.empty() && columns.landed[k] >= 0.5;  // on the ground for most of the row
    idle.count(fs, f, o, landed);
    if (kept(fs, f, columns.t.back(), o, landed)) f.samples.push_back(std::move(fs));
    else if (landed && kept(fs, f, columns.t.back(), o, false)) ++flagged;
  }
  // Said, as the flag decides silently where a column of that name means something else.
  if (flagged > 0)
    f.notes.push_back(log.where_named() + ": " + std::to_string(flagged) +
                      " rows the controller's landed flag marks on the ground are left out (by their height and "
                      "commands alone they would count as airborne)");
  if (static_cast<double>(f.samples.size()) < o.min_samples)
    throw_too_few_airborne(log.path, columns.t, f, o, !columns.landed.empty());
  if (const std::string note = idle.note(log.where_named(), o); !note.empty()) f.notes.push_back(note);
  check_gyro_against_attitude(log_and_entries(log, {"p", "q", "r"}, "the gyro"), f,
                              attitude_columns(log) == AttitudeColumns::kEuler);
  check_accelerometer_unit(log_and_entries(log, {"ax", "ay", "az"}, "the accelerometer"), f);
  return f;
}

double training_cut(const Flight& f, double train_fraction) {
  if (f.samples.empty()) return 0;
  const double front = f.samples.front().t, back = f.samples.back().t;
  return front + train_fraction * (back - front);
}

std::pair<Flight, Flight> split_by_time(const Flight& f, double frac) {
  Flight a = f, b = f;
  a.samples.clear();
  b.samples.clear();
  const double cut = training_cut(f, frac);
  for (const auto& s : f.samples) (s.t < cut ? a : b).samples.push_back(s);
  return {a, b};
}

std::vector<double> join_offsets(const std::vector<Flight>& flights, double gap) {
  std::vector<double> offsets;
  double end = 0;
  for (size_t i = 0; i < flights.size(); ++i) {
    if (flights[i].samples.empty()) throw FitError(flights[i].source + ": no samples to join");
    const double t0 = flights[i].samples.front().t;
    offsets.push_back(i == 0 ? 0.0 : end + gap - t0);
    end = flights[i].samples.back().t + offsets.back();
  }
  return offsets;
}

namespace {

Flight empty_join(const std::vector<Flight>& flights) {
  Flight out;
  out.has_accelerometer = out.has_gyro = out.has_pose = out.has_vbat = out.has_attitude_ref = true;
  for (const auto& f : flights) {
    out.source += (out.source.empty() ? "" : " + ") + f.source;
    out.has_accelerometer = out.has_accelerometer && f.has_accelerometer;
    out.has_gyro = out.has_gyro && f.has_gyro;
    out.has_pose = out.has_pose && f.has_pose;
    out.has_vbat = out.has_vbat && f.has_vbat;
    out.has_attitude_ref = out.has_attitude_ref && f.has_attitude_ref;
  }
  return out;
}

}  // namespace

Flight join_flights(const std::vector<Flight>& flights, double gap) {
  const auto offsets = join_offsets(flights, gap);
  Flight out = empty_join(flights);
  for (size_t i = 0; i < flights.size(); ++i)
    for (FlightSample s : flights[i].samples) {
      s.t += offsets[i];
      out.samples.push_back(std::move(s));
    }
  return out;
}

std::vector<double> joined_start_times(const std::vector<Flight>& flights, double gap) {
  const auto offsets = join_offsets(flights, gap);
  std::vector<double> starts;
  for (size_t i = 0; i < flights.size(); ++i) starts.push_back(flights[i].samples.front().t + offsets[i]);
  return starts;
}

int joined_flight_at(const std::vector<double>& starts, double t) {
  return static_cast<int>(std::upper_bound(starts.begin(), starts.end(), t) - starts.begin()) - 1;
}

std::pair<Flight, Flight> split_each_by_time(const std::vector<Flight>& flights, double train_fraction, double gap) {
  const auto offsets = join_offsets(flights, gap);
  Flight train = empty_join(flights), valid = empty_join(flights);
  for (size_t i = 0; i < flights.size(); ++i) {
    const double cut = training_cut(flights[i], train_fraction);
    for (FlightSample s : flights[i].samples) {
      Flight& part = s.t < cut ? train : valid;
      s.t += offsets[i];
      part.samples.push_back(std::move(s));
    }
  }
  return {train, valid};
}

}  // namespace quadgen::fit
