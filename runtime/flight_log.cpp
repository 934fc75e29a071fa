#include "runtime/flight_log.hpp"

#include "output/ascii.hpp"
#include "runtime/log_file.hpp"

#include "runtime/attitude.hpp"
#include "runtime/rigid_body_state.hpp"
#include "output/numbers.hpp"
#include "output/joined.hpp"
#include "output/sinks.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <iomanip>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <new>
#include <set>
#include <sstream>

namespace quadgen::runtime {

int CsvTable::column(const std::string& name) const {
  const int c = index_in(columns, name);
  if (c >= 0) return c;
  for (const auto& u : unreadable)
    if (u.name == name) throw LogError(path + ":" + std::to_string(u.line) + ": column '" + name + "'" + u.why);
  return -1;
}

std::vector<double> CsvTable::values(const std::string& name) const {
  const int c = column(name);
  if (c < 0) throw LogError(path + ": no column '" + name + "'");
  std::vector<double> v;
  v.reserve(rows.size());
  for (const auto& r : rows) v.push_back(r[c]);
  return v;
}

int CsvTable::line_of(size_t row) const {
  return row < lines.size() ? lines[row] : static_cast<int>(row) + 2;
}

std::string CsvTable::where_row(size_t row) const {
  if (!(resampled_hz > 0)) return path + ":" + std::to_string(line_of(row));
  const auto t = std::find(columns.begin(), columns.end(), "t");
  std::ostringstream os;
  os << path << " (the row";
  if (t != columns.end() && row < rows.size()) {
    // Fixed decimals fine enough to tell rows apart, also at a Unix time (1.7e9 s).
    const int decimals = std::clamp(static_cast<int>(std::ceil(std::log10(resampled_hz))) + 1, 1, 9);
    os << " at t = " << std::fixed << std::setprecision(decimals) << rows[row][static_cast<size_t>(t - columns.begin())]
       << std::defaultfloat << std::setprecision(6) << " s" << (time_from_topics_start ? " after the mapped topics' common start" : "");
  }
  os << ", resampled at " << resampled_hz << " Hz)";
  return os.str();
}

std::string CsvTable::where_named(int c) const {
  if (named_by.empty()) return path + ":1";
  const auto k = static_cast<size_t>(c);
  return k < name_lines.size() ? named_by + ":" + std::to_string(name_lines[k]) : named_by;
}

std::string CsvTable::where_named() const {
  return named_by.empty() ? path + ":1" : path + " (columns named by " + named_by + ")";
}

namespace {

[[noreturn]] void fail_at(const std::string& path, int line, const std::string& what) {
  throw LogError(path + ":" + std::to_string(line) + ": " + what);
}

[[noreturn]] void fail_at_row(const CsvTable& log, size_t row, const std::string& what) {
  throw LogError(log.where_row(row) + ": " + what);
}

// A cell as it may appear in a one-line message: long or binary junk is cut short (at a
// whole character), control characters shown as \xNN as every message shows them (a tab
// read '?' here, a NUL too, and a Cyrillic letter '??': a review, helper-135).
std::string quoted_cell(const std::string& cell) { return "'" + output::printable_head(cell, 40) + "'"; }

// The cells of one line as RFC 4180 reads them: a cell in double quotes may hold commas, and
// "" in it is one quote (a spreadsheet or pandas quotes a cell that holds a comma or a quote;
// some exporters quote every cell). A quote inside an unquoted cell is kept as it is. A quoted
// cell ends at its closing quote, which a comma or the line's end must follow; a line break
// inside quotes is not read (each line is one row).
void split_cells(const std::string& line, const std::string& path, int lineno, std::vector<std::string>& cells) {
  cells.clear();
  size_t i = 0;
  for (;;) {
    std::string cell;
    if (i < line.size() && line[i] == '"') {
      const size_t open = i++;
      for (;; ++i) {
        if (i >= line.size())
          fail_at(path, lineno, "the quote opened at character " + std::to_string(open + 1) +
                                    " is not closed on this line (a line break inside a quoted cell is not read)");
        if (line[i] != '"') cell += line[i];
        else if (i + 1 < line.size() && line[i + 1] == '"') cell += line[i++];
        else break;
      }
      ++i;  // past the closing quote
      if (i < line.size() && line[i] != ',')
        fail_at(path, lineno, "character " + std::to_string(i + 1) +
                                  " follows a closing quote; expected a comma or the end of the line");
    } else {
      const size_t comma = std::min(line.find(',', i), line.size());
      cell.assign(line, i, comma - i);
      i = comma;
    }
    cells.push_back(std::move(cell));
    if (i >= line.size()) return;
    ++i;  // past the comma; a comma at the end leaves one empty cell after it
  }
}

// Cell i of a row: its number, or NaN with the column's first bad cell kept in `unreadable`.
// The whole cell must be a finite number (output/numbers.hpp, the rule of the vehicle file and
// the command line): strtod alone would accept "1\0junk" (it stops at the NUL), turn "1e400"
// into inf and "1e-400" into 0.
double cell_value(const std::string& cell, const CsvTable& t, size_t i, int lineno,
                  std::vector<UnreadableColumn>& unreadable) {
  double v = 0;
  const output::NumberText kind = output::read_number(cell, &v);
  if (kind == output::NumberText::finite) return v;
  if (unreadable[i].line == 0)
    unreadable[i] = {t.columns[i], lineno,
                     kind == output::NumberText::not_a_number
                         ? ": expected a number, got " + quoted_cell(cell) + output::hexadecimal_hint(cell)
                         : " " + output::number_text_problem(kind) + " (" + quoted_cell(cell) +
                               (kind == output::NumberText::underflow ? ")" : "; expected a finite number)")};
  return std::numeric_limits<double>::quiet_NaN();
}

// One data line into `row`. A cell that is no finite number is NaN in `row`, and the first
// such cell of each column is kept in `unreadable` (the column is left out of the table at
// the end). A line without quotes (every log quadgen writes, and most others) is cut at its
// commas in place; one with quotes goes through split_cells.
void parse_row(const std::string& line, const CsvTable& t, int lineno, std::vector<double>& row,
               std::vector<UnreadableColumn>& unreadable, std::vector<std::string>& cells) {
  const bool quoted = line.find('"') != std::string::npos;
  if (quoted) split_cells(line, t.path, lineno, cells);
  const size_t n = quoted ? cells.size() : static_cast<size_t>(std::count(line.begin(), line.end(), ',')) + 1;
  if (n != t.columns.size())
    fail_at(t.path, lineno, "expected " + std::to_string(t.columns.size()) + " values, got " + std::to_string(n));
  row.clear();
  row.reserve(n);
  std::string cell;
  size_t start = 0;
  for (size_t i = 0; i < n; ++i) {
    if (!quoted) {
      const size_t comma = line.find(',', start);
      const size_t stop = comma == std::string::npos ? line.size() : comma;
      cell.assign(line, start, stop - start);
      start = stop + 1;
    }
    row.push_back(cell_value(quoted ? cells[i] : cell, t, i, lineno, unreadable));
  }
}

// Leaves out the columns with a cell that is no finite number, keeping each one's first bad
// cell in t.unreadable for the message should anything ask for the column.
void leave_out_unreadable(CsvTable& t, const std::vector<UnreadableColumn>& found) {
  std::vector<size_t> keep;
  for (size_t c = 0; c < found.size(); ++c) {
    if (found[c].line == 0) keep.push_back(c);
    else t.unreadable.push_back(found[c]);
  }
  if (keep.size() == t.columns.size()) return;
  std::vector<std::string> columns;
  for (size_t c : keep) columns.push_back(t.columns[c]);
  t.columns = std::move(columns);
  for (auto& row : t.rows) {
    for (size_t k = 0; k < keep.size(); ++k) row[k] = row[keep[k]];
    row.resize(keep.size());
  }
}

// The table from a source of lines ('\n' removed). size_hint (bytes, 0 if unknown) only
// sizes the row vector, so that a large log is not copied again and again as it grows.
// header_only: stop after the header (the table has its columns and no rows).
template <class NextLine>
CsvTable parse_lines(NextLine&& next_line, const std::string& path, unsigned long long size_hint,
                     bool header_only = false) {
  CsvTable t;
  t.path = path;
  std::string line;
  std::vector<double> row;
  std::vector<UnreadableColumn> unreadable;  // per column; line 0 while every cell read
  std::vector<std::string> cells;            // a quoted line's cells
  int lineno = 0;
  while (next_line(line)) {
    if (lineno == std::numeric_limits<int>::max()) fail_at(path, lineno, "too many lines (line numbers are int)");
    ++lineno;
    if (lineno == 1 && line.compare(0, 3, "\xEF\xBB\xBF") == 0) line.erase(0, 3);  // UTF-8 BOM
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    if (t.columns.empty()) {
      // Lines ended by a carriage return alone read as one line, the header then the first
      // row's numbers as "duplicate column '0.35'" (a review, helper-135).
      if (line.find('\r') != std::string::npos)
        fail_at(path, lineno, "lines end in a carriage return alone (CR, as some old programs write them): save the log "
                              "with LF or CRLF line ends");
      if (line.find('\t') != std::string::npos && line.find(',') == std::string::npos)
        fail_at(path, lineno, "the header holds tabs and no ',': quadgen reads comma-separated values (export the log "
                              "with ',' between fields)");
      if (line.find(';') != std::string::npos && line.find(',') == std::string::npos)
        fail_at(path, lineno, "the header holds ';' and no ',': quadgen reads comma-separated values (export the log with ',' "
                              "between fields and '.' as the decimal point)");
      // Every log quadgen reads has a time and at least one more column; a first line without
      // a comma, or a comment, is another kind of file (a vehicle file, a mapping) given where
      // a log belongs.
      if (line.find(',') == std::string::npos || line[0] == '#')
        fail_at(path, lineno, "no CSV header: the first line is " + quoted_cell(line) +
                                  "; expected comma-separated column names such as t,u_M1,... (is this a flight log?)");
      split_cells(line, path, lineno, t.columns);
      std::set<std::string> seen;
      for (const auto& c : t.columns)
        if (!seen.insert(c).second) fail_at(path, lineno, "duplicate column " + quoted_cell(c));
      unreadable.resize(t.columns.size());
      if (header_only) break;
      continue;
    }
    parse_row(line, t, lineno, row, unreadable, cells);
    try {
      if (t.rows.empty() && size_hint > 0) {
        const size_t estimate = static_cast<size_t>(size_hint / (line.size() + 1)) + 16;
        t.rows.reserve(estimate);
        t.lines.reserve(estimate);
      }
      t.rows.push_back(row);
      t.lines.push_back(lineno);
    } catch (const std::bad_alloc&) {  // a narrow table costs more than its text: say so
      fail_at(path, lineno, "out of memory holding the log (" + std::to_string(t.rows.size()) + " rows of " +
                                std::to_string(t.columns.size()) + " columns read)");
    }
  }
  if (t.columns.empty()) fail_at(path, 1, "empty log (expected a header line)");
  leave_out_unreadable(t, unreadable);
  return t;
}

// Lines of an open file descriptor, read in blocks; refuses to read past `limit` bytes
// (the file may grow after its size was checked).
class FdLines {
 public:
  FdLines(int fd, const std::string& path, unsigned long long limit) : fd_(fd), path_(path), limit_(limit) {}
  bool operator()(std::string& line) {
    line.clear();
    for (;;) {
      if (pos_ == len_ && !fill()) return !line.empty();
      const char* begin = buf_.data() + pos_;
      const void* nl = std::memchr(begin, '\n', len_ - pos_);
      const size_t take = nl ? static_cast<const char*>(nl) - begin : len_ - pos_;
      line.append(begin, take);
      pos_ += take;
      if (nl) {
        ++pos_;
        return true;
      }
    }
  }

 private:
  bool fill() {
    ssize_t got;
    do got = ::read(fd_, buf_.data(), buf_.size());
    while (got < 0 && errno == EINTR);
    if (got < 0) throw LogError(path_ + ": read error: " + std::strerror(errno));
    total_ += static_cast<unsigned long long>(got);
    if (total_ > limit_)
      throw LogError(path_ + ": grew beyond the limit of " + std::to_string(limit_) +
                     " bytes while being read (set QUADGEN_MAX_INPUT_BYTES to raise it)");
    pos_ = 0;
    len_ = static_cast<size_t>(got);
    return got > 0;
  }
  int fd_;
  const std::string& path_;
  unsigned long long limit_, total_ = 0;
  std::vector<char> buf_ = std::vector<char>(1 << 16);
  size_t pos_ = 0, len_ = 0;
};

}  // namespace

unsigned long long max_input_bytes() {
  const char* env = std::getenv("QUADGEN_MAX_INPUT_BYTES");
  if (!env) return kDefaultMaxInputBytes;
  const std::string s = env;
  unsigned long long v = 0;
  bool ok = !s.empty() && s.size() <= 19;  // 19 digits cannot overflow 64 bits
  for (char c : s) ok = ok && c >= '0' && c <= '9';
  if (ok) v = std::stoull(s);
  if (!ok || v == 0)
    throw LogError("QUADGEN_MAX_INPUT_BYTES='" + s + "': expected a positive whole number of bytes");
  return v;
}

CsvTable parse_csv(const std::string& text, const std::string& path) {
  std::istringstream in(text);
  return parse_lines([&](std::string& line) { return static_cast<bool>(std::getline(in, line)); }, path, text.size());
}

namespace {
CsvTable read_csv_file(const std::string& path, bool header_only) {
  const LogFile file(path, "a CSV log");
  file.set_blocking();
  FdLines lines(file.fd(), path, file.limit());
  return parse_lines(lines, path, file.size(), header_only);
}
}  // namespace

CsvTable read_csv(const std::string& path) { return read_csv_file(path, false); }

CsvTable read_csv_header(const std::string& path) { return read_csv_file(path, true); }

std::string canonical_unit(const std::string& c) {
  static const std::map<std::string, std::string> units = {
      {"t", "s"},       {"x", "m"},       {"y", "m"},         {"z", "m"},       {"vx", "m/s"},    {"vy", "m/s"},
      {"vz", "m/s"},    {"qw", "1"},      {"qx", "1"},        {"qy", "1"},      {"qz", "1"},      {"phi", "rad"},
      {"theta", "rad"}, {"psi", "rad"},   {"p", "rad/s"},     {"q", "rad/s"},   {"r", "rad/s"},   {"ax", "m/s^2"},
      {"ay", "m/s^2"},  {"az", "m/s^2"},  {"vbat", "V"},     {"phi_ref", "rad"}, {"theta_ref", "rad"},
      {"landed", "1"},
  };
  const auto it = units.find(c);
  if (it != units.end()) return it->second;
  if (c.size() > 2 && c.rfind("u_", 0) == 0) return "1";
  if (c.size() > 2 && c.rfind("w_", 0) == 0) return "rad/s";
  return "";
}

void check_values(const CsvTable& log) {
  const int tc = log.column("t");
  // Motor commands are throttle fractions: a percentage or a raw PWM count would run the model
  // far outside its thrust map and end in NaN or parameters on their bounds. Below 0 is a
  // motor off (a disarmed PX4 output maps there) and is let through; a rounded scale may
  // overshoot 1 by a hair (65535 * 1.52590219e-5 = 1.0000000002).
  constexpr double kMaxThrottle = 1 + 1e-6;
  std::vector<bool> throttle(log.columns.size());
  for (size_t c = 0; c < log.columns.size(); ++c) throttle[c] = log.columns[c].rfind("u_", 0) == 0;
  // A battery voltage is positive: battery_sag scales thrust by a power of it and its
  // derivatives take its logarithm, so 0 (a logger before its first reading) would be NaN.
  const int vbat = log.column("vbat");
  // The flight controller's landed flag, 1 on the ground (a grid mean of it lies between).
  const int landed = log.column("landed");
  std::vector<size_t> canonical;
  for (size_t c = 0; c < log.columns.size(); ++c)
    if (!canonical_unit(log.columns[c]).empty()) canonical.push_back(c);
  for (size_t i = 0; i < log.rows.size(); ++i)
    for (size_t c : canonical) {
      const double v = log.rows[i][c];
      if (!std::isfinite(v)) fail_at_row(log, i, "column '" + log.columns[c] + "' is not finite");
      const double bound = static_cast<int>(c) == tc ? kMaxAbsTime : kMaxAbsValue;
      if (std::fabs(v) > bound)
        fail_at_row(log, i,
                "column '" + log.columns[c] + "' is " + output::six_digits(v) + ", beyond the sanity bound |value| <= " +
                    output::six_digits(bound) + " (canonical SI units)");
      if (static_cast<int>(c) == vbat && !(v > 0))
        fail_at_row(log, i,
                "column 'vbat' is " + output::six_digits(v) +
                    " V; a battery voltage must be positive (a logger writes 0 before its first reading: drop those "
                    "rows, or the column where battery_sag is not wanted)");
      if (static_cast<int>(c) == landed && !(v >= 0 && v <= 1))
        fail_at_row(log, i,
                    "column 'landed' is " + output::six_digits(v) +
                        "; expected the flight controller's landed flag, 0 in the air to 1 on the ground (PX4's "
                        "vehicle_land_detected.landed)");
      if (throttle[c] && v > kMaxThrottle)
        fail_at_row(log, i,
                "column '" + log.columns[c] + "' is " + output::six_digits(v) + "; expected a throttle fraction 0..1 (" +
                    (log.named_by.empty() ? "" : "its entry at " + log.where_named(static_cast<int>(c)) + "; ") +
                    "in a log mapping, a percentage takes scale: 0.01, a pulse width of 1000 to 2000 us scale: 0.001 "
                    "and offset: -1, a 16-bit PWM count scale: 1.5259e-05)");
    }
}

std::string missing_columns_message(const CsvTable& log, const std::vector<std::string>& columns,
                                    const MissingColumns& how) {
  std::vector<std::string> missing;
  for (const auto& c : columns)
    if (log.column(c) < 0) missing.push_back(c);
  if (missing.empty()) return "";
  std::string list;
  for (const auto& c : missing) list += (list.empty() ? "'" : ", '") + c + "'";
  const std::string what = how.what.empty() ? "" : ": " + how.what;
  // A header written "t, u_A, ..." or "U_A": the name is there with a blank or in another case
  // (a review, helper-135: the message said only that 'u_A' was missing).
  const auto folded = [](const std::string& s) {
    const size_t a = s.find_first_not_of(" \t"), b = s.find_last_not_of(" \t");
    return output::ascii_lower(a == std::string::npos ? "" : s.substr(a, b - a + 1));
  };
  std::string near;
  for (const auto& c : log.columns)
    if (near.empty() && folded(c) == folded(missing.front()))
      near = " (the header has " + quoted_cell(c) + ": column names are read exactly, blanks and case included)";
  if (log.named_by.empty())
    return log.path + ":1: missing column" + (missing.size() > 1 ? "s " : " ") + list + what + near + how.hint_without_mapping;
  const std::string entry = "'" + missing.front() + ": {source: <the log's column>" +
                            (how.unit.empty() ? "" : ", unit: " + how.unit) + "}'";
  return log.named_by + ": maps no column of " + log.path + " to " + list + what +
         (missing.size() > 1 ? " (add each under columns:, e.g. " + entry + ")" : " (add " + entry + " under columns:)");
}

void validate_canonical(const CsvTable& log, const std::vector<std::string>& rotors, const std::string& missing_hint) {
  // A name the mapping gave is the mapping's mistake: its file and line are named, not the log's.
  const std::string maps = log.named_by.empty() ? "" : " (in the mapping read for " + log.path + ")";
  std::set<std::string> known(rotors.begin(), rotors.end());
  const std::string list = output::joined(rotors);
  // A command column for a rotor the vehicle lacks first: a misspelt rotor is why its own
  // column is then missing. One with a cell that is no number is that error (column() says it).
  log.require_readable([](const std::string& name) { return name.rfind("u_", 0) == 0; });
  for (size_t c = 0; c < log.columns.size(); ++c) {
    const std::string& name = log.columns[c];
    if (name.rfind("u_", 0) == 0 && !known.count(name.substr(2)))
      throw LogError(log.where_named(static_cast<int>(c)) + ": column '" + name + "' names no rotor of this vehicle (rotors: " +
                     list + ")" + maps);
  }
  std::vector<std::string> needed{"t"};
  for (const auto& r : rotors) needed.push_back("u_" + r);
  const int tc = log.column("t");
  const bool lacks_time = tc < 0;
  const bool lacks_commands = std::any_of(rotors.begin(), rotors.end(), [&](const auto& r) { return log.column("u_" + r) < 0; });
  const std::string what = lacks_time && lacks_commands ? "the time and the rotor commands"
                           : lacks_time                 ? "the time (s)"
                                                        : "the rotor commands";
  const std::string missing = missing_columns_message(log, needed, {what, "", missing_hint});
  if (!missing.empty()) throw LogError(missing);
  if (log.rows.size() < 2) throw LogError(log.path + ": too few samples (" + std::to_string(log.rows.size()) + ")");
  check_values(log);
  for (size_t i = 0; i < log.rows.size(); ++i) {
    if (i > 0 && !(log.rows[i][tc] > log.rows[i - 1][tc]))
      fail_at_row(log, i, "time not strictly increasing (" +
                                  output::one_then_other(log.rows[i - 1][tc], log.rows[i][tc]) + ")");
  }
}

std::string trajectory_csv(const DynamicModel& m, const Trajectory& tr, const InputFunction& u,
                           const std::vector<std::string>& rotors) {
  std::ostringstream os;
  os.precision(10);
  os << "t";
  for (const auto& r : rotors) os << ",u_" << r;
  os << ",x,y,z,qw,qx,qy,qz,phi,theta,psi,vx,vy,vz,p,q,r";
  for (int i = rigid_body::kNumStates; i < m.num_states(); ++i) os << "," << m.state_names()[i];
  os << "\n";
  std::vector<double> ub(m.num_inputs());
  for (size_t k = 0; k < tr.t.size(); ++k) {
    const auto& x = tr.x[k];
    const auto states = [&](int first, int count) {
      for (int i = first; i < first + count; ++i) os << "," << x[i];
    };
    u(tr.t[k], ub.data());
    os << tr.t[k];
    for (size_t r = 0; r < rotors.size(); ++r) os << "," << ub[r];
    const auto [phi, theta, psi] = rigid_body::euler_angles(x.data());
    states(rigid_body::kPosition, 3);
    states(rigid_body::kAttitude, 4);
    os << "," << phi << "," << theta << "," << psi;
    states(rigid_body::kVelocity, 3);
    states(rigid_body::kBodyRate, 3);
    states(rigid_body::kNumStates, m.num_states() - rigid_body::kNumStates);
    os << "\n";
  }
  return os.str();
}

}  // namespace quadgen::runtime
