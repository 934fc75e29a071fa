#include "fit/log_reader.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include "fit/grid_mean.hpp"
#include "fit/least_squares.hpp"  // FitError
#include "runtime/log_file.hpp"
#include "output/joined.hpp"
#include "output/numbers.hpp"

namespace quadgen::fit {

bool is_ulog(const std::string& path) {
  return runtime::read_head(path, 7) == std::string("ULog\x01\x12\x35", 7);
}

bool is_topic_log(const std::string& path) { return is_ulog(path) || runtime::is_usd_log(path); }

std::optional<std::string> stem_before(const std::string& name, const std::string& suffix) {
  if (name.size() <= suffix.size() || name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
    return std::nullopt;
  return name.substr(0, name.size() - suffix.size());
}

namespace {

// One mapped signal: its topic's timestamps (s) and finite values, the longest interval
// between them that still counts as continuous, and the samples after which a longer one
// (a gap) follows.
struct Signal {
  std::string source, target;
  std::vector<double> t, v;
  double gap = 0;
  std::vector<size_t> breaks;
  // Samples k after which the estimator was reset (a jump, not motion): a gap like a time gap,
  // and around it no grid point from kResetMargin before sample k to as long after k + 1.
  std::vector<size_t> resets;
  std::vector<std::string> reset_counters;  // the counters that changed
  double median_interval = 0;  // s
};

// A topic as a mapping names it: "actuator_outputs" (instance 0) or "actuator_outputs[1]",
// the second instance of a topic logged more than once (PX4 logs up to three of
// actuator_outputs; with DShot the motors may be on another than the first).
std::string topic_label(const runtime::LogTopic& t) {
  return t.multi_id == 0 ? t.name : t.name + "[" + std::to_string(t.multi_id) + "]";
}

const runtime::LogTopic& find_topic(const runtime::TopicLog& log, const std::string& topic, const std::string& source) {
  std::string name = topic;
  int instance = 0;
  if (const auto open = topic.find('['); open != std::string::npos) {
    const std::string digits = topic.substr(open + 1, topic.size() - open - 2);
    if (topic.back() != ']' || digits.empty() || digits.size() > 3 ||
        digits.find_first_not_of("0123456789") != std::string::npos || (digits.size() > 1 && digits[0] == '0'))
      throw FitError(log.path + ": '" + source + "': a topic's instance is written topic[k].field, k a number (0 to 255)");
    name = topic.substr(0, open);
    instance = std::stoi(digits);
  }
  if (const runtime::LogTopic* tp = log.find(name, instance)) return *tp;
  std::vector<std::string> instances;
  for (const auto& t : log.topics)
    if (t.name == name) instances.push_back(topic_label(t));
  if (!instances.empty())
    throw FitError(log.path + ": no instance " + std::to_string(instance) + " of topic '" + name + "' for '" + source +
                   "' (the log has " + output::joined(instances) + "; name one as topic[k].field)");
  const std::string have = output::joined(log.topics, ", ", topic_label);
  throw FitError(log.path + ": no topic '" + topic + "' for '" + source + "' (the log has: " + have + ")");
}

// PX4 logs NaN for values not set yet, and a battery voltage of exactly 0 where it is not
// known (battery_status.voltage_v): such samples are left out, not interpolated over.
bool unset(const ColumnMapping::Entry& e, double value) {
  return !std::isfinite(value) || (e.target == "vbat" && value == 0);
}

// PX4's actuator_outputs says in `noutputs` how many of its channels the driver set; a channel
// at or beyond it is not a command (it reads 0: throttle -1 through PWM's usual mapping). For
// a field "name[i]" of a topic with that field: the column of noutputs and i, else -1.
std::pair<int, long> channel_count_column(const runtime::LogTopic& tp, const std::string& field) {
  const int count = tp.column("noutputs");
  const auto open = field.rfind('[');
  if (count < 0 || open == std::string::npos || field.back() != ']') return {-1, 0};
  return {count, std::stol(field.substr(open + 1, field.size() - open - 2))};
}

// When a field's value was measured, in microseconds. PX4 stamps a message when it is
// published (`timestamp`, column 0); a topic estimated from a sensor carries the sensor's time
// as `timestamp_sample` (vehicle_attitude, vehicle_local_position: a few ms earlier), and
// sensor_combined its accelerometer's offset from the gyro's time (`accelerometer_timestamp_
// relative`, INT32_MAX where not valid; a review, helper-152). Joined on the publication time,
// the accelerometer and the attitude would sit ms away from the gyro on the grid. A command or
// set point acts when it is published: its `timestamp_sample` (actuator_motors has one) is the
// time of the gyro sample it was computed from, and placing it there would move every command
// earlier by the controller's latency (a review, helper-155).
bool is_command_topic(const std::string& topic) {
  return topic.rfind("actuator_", 0) == 0 || topic.find("setpoint") != std::string::npos;
}

class SampleTime {
 public:
  SampleTime(const runtime::LogTopic& tp, const std::string& field)
      : sample_(is_command_topic(tp.name) ? -1 : tp.column("timestamp_sample")) {
    for (size_t c = 0; c < tp.fields.size(); ++c) {
      const std::string& name = tp.fields[c];
      const auto stem = stem_before(name, "_timestamp_relative");
      if (!stem) continue;
      const std::string& sensor = *stem;
      const bool of_sensor = field == sensor || field.compare(0, sensor.size() + 1, sensor + "_") == 0 ||
                             field.compare(0, sensor.size() + 1, sensor + "[") == 0;
      if (of_sensor && field != name) relative_ = static_cast<int>(c);
    }
  }
  // Microseconds, or NaN where the row says its time is not valid.
  double of(const std::vector<double>& row) const {
    double us = sample_ >= 0 && row[static_cast<size_t>(sample_)] > 0 ? row[static_cast<size_t>(sample_)] : row[0];
    if (relative_ >= 0) {
      const double offset = row[static_cast<size_t>(relative_)];
      if (offset == kInvalidRelative) return std::numeric_limits<double>::quiet_NaN();
      us += offset;
    }
    return us;
  }

 private:
  static constexpr double kInvalidRelative = 2147483647;  // PX4's RELATIVE_TIMESTAMP_INVALID
  int sample_ = -1, relative_ = -1;
};

// A flag published when it changes (and PX4's landed flag once a second besides) holds its
// value until the next sample; drawn as straight lines it would cross 0.5 up to half a second
// early. A copy of the old value half a microsecond before each change makes the line a step.
void hold_between_samples(Signal& s) {
  std::vector<double> t, v;
  for (size_t k = 0; k < s.t.size(); ++k) {
    if (k > 0 && s.v[k] != s.v[k - 1] && s.t[k] - 0.5e-6 > s.t[k - 1]) {
      t.push_back(s.t[k] - 0.5e-6);
      v.push_back(s.v[k - 1]);
    }
    t.push_back(s.t[k]);
    v.push_back(s.v[k]);
  }
  s.t = std::move(t);
  s.v = std::move(v);
}

// PX4's estimator resets its states now and then (a yaw alignment at take-off, a GPS glitch)
// and counts each in the topic: the value jumps there, which read as motion would be a spike
// of acceleration (a review, helper-152). A counter `P_reset_counter` belongs to the fields it
// counts: PX4's xy (x, y), vxy (vx, vy), quat (q[...]), lat_lon (lat, lon), else the field P
// itself or P's elements and members (z, vz, dist_bottom, heading, alt); a yaw reset then
// cuts the attitude, not the position (helper-156).
bool counts_resets_of(const std::string& prefix, const std::string& field) {
  static const std::map<std::string, std::vector<std::string>> kGroups = {
      {"xy", {"x", "y"}}, {"vxy", {"vx", "vy"}}, {"quat", {"q"}}, {"lat_lon", {"lat", "lon"}}};
  const auto group = kGroups.find(prefix);
  const std::vector<std::string> names = group == kGroups.end() ? std::vector<std::string>{prefix} : group->second;
  for (const auto& n : names)
    if (field == n || field.compare(0, n.size() + 1, n + "[") == 0 || field.compare(0, n.size() + 1, n + ".") == 0)
      return true;
  return false;
}

std::vector<int> reset_counter_columns(const runtime::LogTopic& tp, const std::string& field) {
  std::vector<int> columns;
  for (size_t c = 0; c < tp.fields.size(); ++c)
    if (const auto stem = stem_before(tp.fields[c], "_reset_counter"); stem && counts_resets_of(*stem, field))
      columns.push_back(static_cast<int>(c));
  return columns;
}

// Around a reset no grid point is read: the table's hole must outlast what reads across a
// short one (a rollout's and multiple shooting's 0.1 s, the derivatives' 0.05 s window).
constexpr double kResetMargin = 0.1;  // s

Signal find_signal(const runtime::TopicLog& log, const ColumnMapping::Entry& e) {
  const auto dot = e.source.find('.');
  const std::string topic = e.source.substr(0, dot);
  const runtime::LogTopic& tp = find_topic(log, topic, e.source);
  const int c = dot == std::string::npos ? -1 : tp.column(e.source.substr(dot + 1));
  if (c < 0) {
    throw FitError(log.path + ": topic '" + topic + "' has no field for '" + e.source + "' (fields: " +
                   output::joined(tp.fields) + ")");
  }
  Signal s;
  s.source = e.source;
  s.target = e.target;
  const auto [count, channel] = channel_count_column(tp, e.source.substr(dot + 1));
  double most_channels = 0;
  const SampleTime sample_time(tp, e.source.substr(dot + 1));
  const std::vector<int> counters = reset_counter_columns(tp, e.source.substr(dot + 1));
  const std::vector<double>* last_kept = nullptr;
  std::set<std::string> changed;
  for (const auto& row : tp.rows) {
    const double t = sample_time.of(row) * 1e-6;
    if (std::isnan(t)) continue;
    if (count >= 0) most_channels = std::max(most_channels, row[count]);
    if (count >= 0 && !(static_cast<double>(channel) < row[count])) continue;  // a channel the driver did not set
    if (unset(e, row[c]) || (!s.t.empty() && t <= s.t.back())) continue;  // unset, repeated or out of order
    bool reset = false;
    for (const int k : counters)
      if (last_kept && (*last_kept)[static_cast<size_t>(k)] != row[static_cast<size_t>(k)]) {
        reset = true;
        changed.insert(tp.fields[static_cast<size_t>(k)]);
      }
    if (reset) s.resets.push_back(s.t.size() - 1);
    last_kept = &row;
    s.t.push_back(t);
    s.v.push_back(row[c]);
  }
  s.reset_counters.assign(changed.begin(), changed.end());
  if (s.t.size() < 2 && count >= 0 && !(static_cast<double>(channel) < most_channels))
    throw FitError(log.path + ": '" + e.source + "' is a channel its driver never set: every message of '" + topic +
                   "' has noutputs " + output::short_number(most_channels) + " or fewer" +
                   (most_channels >= 1 ? " (channels 0.." + output::short_number(most_channels - 1) + ")" : "") +
                   "; which channel drives which motor is PX4's PWM_MAIN_FUNCn (or the AUX, DShot ones)");
  if (s.t.size() < 2)
    throw FitError(log.path + ": '" + e.source + "' has fewer than two samples with a value" +
                   (e.target == "vbat" ? " (NaN or 0 V, PX4's \"not known\"): a log without a battery voltage is read "
                                         "without it, so leave vbat out of the mapping"
                                       : " (NaN is PX4's \"not set\")"));
  std::vector<double> dt;
  for (size_t k = 1; k < s.t.size(); ++k) dt.push_back(s.t[k] - s.t[k - 1]);
  std::nth_element(dt.begin(), dt.begin() + dt.size() / 2, dt.end());
  s.median_interval = dt[dt.size() / 2];
  s.gap = std::max(3 * s.median_interval, 0.1);  // a dropout or a paused topic beyond this
  // The landed flag, published when it changes and at least once a second: its intervals say
  // little of a dropout (a burst of changes near the ground shortens their median), so only a
  // pause beyond 3 s is a gap; held as a step, its steps measured before (helper-156).
  if (e.target == "landed" && s.resets.empty()) {
    s.gap = std::max(s.gap, 3.0);
    hold_between_samples(s);
  }
  for (size_t k = 0; k + 1 < s.t.size(); ++k)
    if (s.t[k + 1] - s.t[k] > s.gap || std::binary_search(s.resets.begin(), s.resets.end(), k)) s.breaks.push_back(k);
  return s;
}

// The four quaternion components from one topic, sign-aligned sample to sample
// (fit/grid_mean.hpp says why).
void align_mapped_quaternion(std::vector<Signal>& signals) {
  Signal* q[4] = {};
  const char* names[4] = {"qw", "qx", "qy", "qz"};
  for (auto& s : signals)
    for (int i = 0; i < 4; ++i)
      if (s.target == names[i]) q[i] = &s;
  for (int i = 0; i < 4; ++i)
    if (!q[i] || q[i]->t != q[0]->t) return;  // not four components on one clock
  align_quaternion_signs({&q[0]->v, &q[1]->v, &q[2]->v, &q[3]->v});
}

// The grid value at t: the signal's mean over the grid interval around t, within its stretch
// without a gap (fit/grid_mean.hpp), or false when t falls in a gap of the signal (or outside it).
bool value_on_grid(const Signal& s, double t, double half_step, double* v) {
  const auto it = std::upper_bound(s.t.begin(), s.t.end(), t);
  if (it == s.t.begin()) return false;
  if (it == s.t.end() && t - s.t.back() > 1e-9) return false;
  const size_t k = static_cast<size_t>(it - s.t.begin()) - 1;  // the last sample at or before t
  if (it != s.t.end() && s.t[k + 1] - s.t[k] > s.gap) return false;
  for (const size_t r : s.resets)  // a few at most
    if (t > s.t[r] - kResetMargin && t < s.t[r + 1] + kResetMargin) return false;
  const auto next_break = std::lower_bound(s.breaks.begin(), s.breaks.end(), k);
  const size_t last = next_break == s.breaks.end() ? s.t.size() - 1 : *next_break;
  const size_t first = next_break == s.breaks.begin() ? 0 : *(next_break - 1) + 1;
  *v = grid_weights(s.t, first, last, std::min(t, s.t[last]), half_step).apply(s.v);
  return true;
}

// An Euler angle judged as logged, before the roll is unwrapped, averaged and wrapped again: a
// roll in degrees read as radians would pass once wrapped (hostile-input audit, helper-105).
void check_euler_range(const Signal& s, const ColumnMapping::Entry& e, const std::string& path) {
  for (size_t k = 0; k < s.v.size(); ++k) {
    const std::string problem = euler_range_problem(e.target, s.v[k] * e.scale * e.unit_scale);
    if (!problem.empty())
      throw FitError(path + " ('" + e.source + "' at t = " + output::six_digits(s.t[k]) + " s of the log's clock): " +
                     problem);
  }
}

// An Euler angle mapped from a topic is averaged unwrapped (fit/grid_mean.hpp), its period in
// the source's unit from the mapping's scale and unit (360 for degrees).
void unwrap_if_angle(Signal& s, const ColumnMapping::Entry& e) {
  const double to_radians = std::fabs(e.scale * e.unit_scale);
  if ((e.target == "phi" || e.target == "psi") && to_radians > 0) s.v = unwrapped(s.v, 2 * M_PI / to_radians);
}

// The roll back into (-pi, pi] after averaging (the reading checks refuse a roll beyond it;
// a yaw may stay unwrapped).
void wrap_roll(runtime::CsvTable& t) {
  const int c = t.column("phi");
  if (c >= 0)
    for (auto& row : t.rows) row[static_cast<size_t>(c)] = wrapped_to_pi(row[static_cast<size_t>(c)]);
}

// Signals logged more slowly than the grid, one note per topic: between their samples the
// grid holds straight lines, and what changed faster is not in the log (PX4's default logging
// profile writes actuator_outputs and vehicle_local_position at 10 Hz: a review, helper-152).
// The battery voltage is left out: it changes slowly, and PX4 logs it at 5 Hz; so is the landed
// flag, published when it changes.
std::vector<std::string> slow_signal_notes(const std::vector<Signal>& signals, double rate_hz, const std::string& path) {
  std::map<std::string, std::pair<double, std::vector<std::string>>> slow;  // topic: interval, sources
  for (const auto& s : signals)
    if (s.median_interval > 1.5 / rate_hz && s.target != "vbat" && s.target != "landed") {
      auto& [interval, sources] = slow[s.source.substr(0, s.source.find('.'))];
      interval = std::max(interval, s.median_interval);
      sources.push_back(s.source);
    }
  std::vector<std::string> notes;
  for (const auto& [topic, slowest] : slow)
    notes.push_back(path + ": " + output::joined(slowest.second) + " logged every " +
                    output::short_number(slowest.first * 1e3) + " ms, slower than the " + output::short_number(rate_hz) +
                    " Hz grid: between its samples the grid holds straight lines, and what changed faster is not in "
                    "the log");
  return notes;
}

// The estimator's resets, one note per topic (find_signal says why they are gaps).
std::vector<std::string> reset_notes(const std::vector<Signal>& signals, const std::string& path) {
  std::map<std::string, std::pair<size_t, std::set<std::string>>> resets;  // topic: resets, counters
  for (const auto& s : signals)
    if (!s.resets.empty()) {
      auto& [count, counters] = resets[s.source.substr(0, s.source.find('.'))];
      count = std::max(count, s.resets.size());
      counters.insert(s.reset_counters.begin(), s.reset_counters.end());
    }
  std::vector<std::string> notes;
  for (const auto& [topic, r] : resets)
    notes.push_back(path + ": the estimate in " + topic + " was reset " + std::to_string(r.first) + " time" +
                    (r.first == 1 ? "" : "s") + " (" + output::joined(r.second) +
                    " changed): its signals have a gap at each, where the value jumps, rather than a jump read as "
                    "motion");
  return notes;
}

// A cap on the table a few bytes of timestamps could ask for: 2^28 cells (2 GiB of doubles).
constexpr double kMaxCells = 268435456.0;

}  // namespace

runtime::CsvTable topic_table(const runtime::TopicLog& log, const ColumnMapping& m, double rate_hz,
                              const std::string& how_to_log_faster) {
  if (!(rate_hz > 0) || !std::isfinite(rate_hz)) throw FitError(log.path + ": sampling rate must be positive");
  std::vector<Signal> signals;
  double t0 = -std::numeric_limits<double>::infinity(), t1 = std::numeric_limits<double>::infinity();
  for (const auto& e : m.entries) {
    if (e.source == "t") continue;  // the time base this function makes
    signals.push_back(find_signal(log, e));
    check_euler_range(signals.back(), e, log.path);
    unwrap_if_angle(signals.back(), e);
    t0 = std::max(t0, signals.back().t.front());
    t1 = std::min(t1, signals.back().t.back());
  }
  if (signals.empty()) throw FitError(m.name + ": maps no signal of the log's topics (sources are topic.field)");
  if (!(t1 > t0)) throw FitError(log.path + ": the mapped topics do not overlap in time");
  align_mapped_quaternion(signals);
  const double step = 1.0 / rate_hz, rows = std::floor((t1 - t0) / step) + 1;
  if (rows * static_cast<double>(signals.size() + 1) > kMaxCells)
    throw FitError(log.path + ": " + std::to_string(static_cast<long long>(rows)) + " rows of " +
                   std::to_string(signals.size() + 1) + " columns at " + output::six_digits(rate_hz) +
                   " Hz over the logged span is more than quadgen holds; lower --resample");
  runtime::CsvTable out;
  out.path = log.path;
  out.resampled_hz = rate_hz;
  out.time_from_topics_start = true;
  out.notes = slow_signal_notes(signals, rate_hz, log.path);
  if (!out.notes.empty() && !how_to_log_faster.empty()) out.notes.push_back(how_to_log_faster);
  for (auto& note : reset_notes(signals, log.path)) out.notes.push_back(std::move(note));
  out.columns.push_back("t");
  for (const auto& s : signals) out.columns.push_back(s.source);
  // Grid points inside a gap of any signal are left out: the table then has a gap there too,
  // which fits and simulations treat as the end of a contiguous stretch.
  for (size_t k = 0; k < static_cast<size_t>(rows); ++k) {
    const double t = t0 + static_cast<double>(k) * step;
    std::vector<double> row{t - t0};
    bool inside = true;
    for (const auto& s : signals) {
      double v = 0;
      inside = inside && value_on_grid(s, t, 0.5 * step, &v);
      row.push_back(v);
    }
    if (inside) out.rows.push_back(std::move(row));
  }
  if (out.rows.size() < 2) throw FitError(log.path + ": fewer than two samples where every mapped signal is logged");
  return out;
}

std::vector<std::string> ulog_notes(const runtime::Ulog& log) {
  std::vector<std::string> notes;
  if (log.dropouts > 0)
    notes.push_back(log.path + ": the logger dropped data " + std::to_string(log.dropouts) + " time" +
                    (log.dropouts == 1 ? "" : "s") + " (" + output::short_number(log.dropout_ms) +
                    " ms in all): a signal's pause longer than three of its intervals and 0.1 s is a gap, not bridged");
  // One note however many stretches were skipped (a log may be corrupt in many places).
  if (!log.skipped.empty()) {
    std::uint64_t bytes = 0;
    for (const auto& skip : log.skipped) bytes += skip.to - skip.from;
    const auto& first = log.skipped.front();
    const bool one = log.skipped.size() == 1;
    notes.push_back(log.path + ": reading found the log corrupt " +
                    (one ? "at byte " + std::to_string(first.from) + " (" + first.cause + "): reading resumed at its next sync message, byte " + std::to_string(first.to)
                         : "in " + std::to_string(log.skipped.size()) + " places (the first at byte " + std::to_string(first.from) + ": " + first.cause +
                               "): each time reading resumed at the next sync message") +
                    " (" + std::to_string(bytes) + " bytes skipped" + (one ? "" : " in all") +
                    ": what they held is lost, a gap in the signals where it lasts longer than their gap threshold" +
                    (log.data_without_subscription > 0
                         ? "; " + std::to_string(log.data_without_subscription) +
                               " data messages after it of subscriptions lost with it skipped too"
                         : "") +
                    ")");
  }
  if (log.truncated)
    notes.push_back(log.path + ": the log ends inside a message (byte " + std::to_string(log.truncated_at) +
                    ", as after a power loss): that message is dropped, everything before it read");
  return notes;
}

runtime::CsvTable read_log(const std::string& path, const ColumnMapping* mapping, double resample_hz) {
  if (is_topic_log(path)) {
    const bool ulog = is_ulog(path);
    if (!mapping)
      throw FitError(path + (ulog ? ": a ULog log" : ": a Crazyflie uSD log") +
                     " needs --mapping naming its signals as topic.field (docs/formats.md)");
    const double rate = resample_hz > 0 ? resample_hz : kTopicLogRate;
    runtime::CsvTable table;
    if (ulog) {
      const runtime::Ulog log = runtime::read_ulog(path);
      // How to log faster (docs.px4.io, "Logging": the logging profiles raise other topics'
      // rates, not actuator_outputs' or vehicle_local_position's: helper-153).
      table = topic_table(log, *mapping, rate,
                          path + ": PX4 logs a topic faster when a line of etc/logging/logger_topics.txt on its SD "
                                 "card names it (with no interval: at full rate; docs.px4.io, \"Logging\"); the file "
                                 "takes the place of PX4's default list, so it must name every topic the mapping reads");
      for (const auto& note : ulog_notes(log)) table.notes.push_back(note);
      table.parameters = log.parameters;
    } else {
      table = topic_table(runtime::read_usd_log(path), *mapping, rate);
    }
    runtime::CsvTable mapped = apply_mapping(table, *mapping);
    wrap_roll(mapped);
    return mapped;
  }
  runtime::CsvTable log = runtime::read_csv(path);
  if (mapping) log = apply_mapping(log, *mapping);
  require_known_columns_readable(log);
  if (resample_hz > 0) log = resample(log, resample_hz);
  return log;
}

runtime::CsvTable read_log(const std::string& path, const std::string& mapping_path, double resample_hz) {
  if (mapping_path.empty()) return read_log(path, static_cast<const ColumnMapping*>(nullptr), resample_hz);
  const ColumnMapping m = load_mapping(mapping_path);
  return read_log(path, &m, resample_hz);
}

}  // namespace quadgen::fit
