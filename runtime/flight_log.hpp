// Flight logs as CSV: reading with line-exact errors, the canonical layout of
// docs/formats.md "Flight log" (validation against a model's rotor names), and writing trajectories.
#pragma once
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "runtime/dynamic_model.hpp"
#include "runtime/integrator.hpp"

namespace quadgen::runtime {

struct LogError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A column of a CSV file left out of its table because a cell of it is no finite number
// (text such as a flight mode, an empty cell, nan, inf, an overflowing literal): where the
// first such cell is, for the error should anything ask for the column.
struct UnreadableColumn {
  std::string name;
  int line = 0;     // in the file; 0 while no bad cell was seen
  std::string why;  // ": expected a number, got 'abc'" or " is not finite ('nan'; ...)"
};

struct CsvTable {
  std::string path;
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;
  // Line in `path` of each row (blank lines and the header are skipped, so row k is not
  // always on line k + 2). Tables built in code may leave it empty: see line_of.
  std::vector<int> lines;
  // The index of column `name`, -1 if absent. A column left out as unreadable is a LogError
  // "path:line: column 'name': expected a number, got 'abc'": quadgen reads only what it
  // asks for, so a column nothing asks for may hold anything.
  int column(const std::string& name) const;
  std::vector<UnreadableColumn> unreadable;
  // column()'s error for the first unreadable column `reads(name)` says a command reads
  // (the rotor commands for a replay, every canonical column for a fit); nothing otherwise.
  template <typename Reads>
  void require_readable(Reads reads) const {
    for (const auto& u : unreadable)
      if (reads(u.name)) column(u.name);  // throws, naming the line
  }
  std::vector<double> values(const std::string& name) const;
  int line_of(size_t row) const;  // lines[row], or row + 2 where no line was recorded
  // Above 0 where the rows are not the file's lines but samples at this rate (a CSV log
  // resampled, a ULog or uSD log's topics on a grid): a row is then named by its time.
  double resampled_hz = 0;
  // What reading a binary log noticed that a person should know before trusting it (a topic
  // slower than the grid, logger dropouts, a cut-off end): carried into the flight's notes.
  std::vector<std::string> notes;
  // The log's own configuration when it has one (a ULog's parameters when logging started):
  // where PX4 placed its motors, for fit/read_flight.hpp's check. Empty for other logs.
  std::map<std::string, double> parameters;
  bool time_from_topics_start = false;  // t counts from the mapped topics' common start (ULog, uSD)
  // Where row `row` is, for a message: "log.csv:94", or "log.csv (the row at t = 2.49 s,
  // resampled at 37 Hz)".
  std::string where_row(size_t row) const;
  // Where the column names come from: the header of `path` when empty; a column mapping's
  // file when the table was mapped, with the line of each column's entry in name_lines.
  std::string named_by;
  std::vector<int> name_lines;
  std::string where_named(int c) const;  // "log.csv:1" or "mapping.yaml:12"
  // The columns as a whole, for a message about what the log has: "log.csv:1", or
  // "log.csv (columns named by mapping.yaml)" (several logs may share one mapping).
  std::string where_named() const;
};

// The SI unit of a canonical column (docs/formats.md "Flight log"): "s", "m", "m/s", "rad/s", "m/s^2",
// "1", "rad", "V"; empty for a name that is no canonical column.
std::string canonical_unit(const std::string& column);
// Their names, for messages.
inline const char* const kCanonicalColumns =
    "t, x, y, z, vx, vy, vz, qw, qx, qy, qz, phi, theta, psi, p, q, r, ax, ay, az, vbat, u_<rotor>, w_<rotor>, "
    "phi_ref, theta_ref, landed";

// Sanity bounds on numbers in logs: a value beyond them is a corrupt or mis-scaled log,
// and letting it through overflows the fit (squares of 1e160 are inf). In canonical SI
// units every column satisfies |v| <= kMaxAbsValue, except t, which may be a Unix time
// in seconds (|t| <= kMaxAbsTime, i.e. before the year 2286).
constexpr double kMaxAbsValue = 1e9;
constexpr double kMaxAbsTime = 1e10;

// Largest log read_csv accepts, in bytes: 2 GiB unless the environment variable
// QUADGEN_MAX_INPUT_BYTES (a positive whole number of bytes) says otherwise.
constexpr unsigned long long kDefaultMaxInputBytes = 2ULL << 30;
unsigned long long max_input_bytes();  // throws LogError for a malformed variable

// A column with a cell that is no finite number (empty, text, nan, inf, an overflowing
// literal) is left out of the table and kept in `unreadable`: asking for it is the error,
// with the line of its first bad cell. A row with too few or too many cells is an error at
// once. A UTF-8 byte-order mark before the header is skipped; throws LogError "path:line: ...".
// read_csv refuses anything but a regular file (a FIFO or a device would block or never
// end) and files above max_input_bytes(), and parses line by line.
CsvTable read_csv(const std::string& path);
// Only the header, checked as read_csv checks it: the columns, no rows (to tell a file's kind
// without reading a large log twice).
CsvTable read_csv_header(const std::string& path);
CsvTable parse_csv(const std::string& text, const std::string& path);

// Every value of a canonical column finite and within the sanity bounds above (t against
// kMaxAbsTime); throws LogError "path:line: ..." naming the column. Other columns are not
// read, so an epoch time in seconds or a counter beside the canonical ones is let be.
void check_values(const CsvTable& log);

// Canonical columns a log lacks, and how to say so: what they are ("the body rates (gyro)"),
// the unit of the example entry a mapping should add, and what to append when no mapping
// named the columns (what the caller knows of why).
struct MissingColumns {
  std::string what;
  std::string unit;
  std::string hint_without_mapping;
};

// Which of `columns` the log lacks, every one in one message, blamed on the file that names
// the columns: "log.csv:1: missing column 'u_D': the rotor commands" from a header, or from a
// mapping "m.yaml: maps no column of log.csv to 'u_D': ... (add 'u_D: {source: <the log's
// column>}' under columns:)". Empty when none is missing.
std::string missing_columns_message(const CsvTable& log, const std::vector<std::string>& columns,
                                    const MissingColumns& how);

// Checks the canonical layout for these rotors: t strictly increasing, u_<rotor> present
// for every rotor and no u_ column for an unknown rotor, finite values within the sanity
// bounds above, at least 2 rows.
// `missing_hint` is appended to a missing column's message (what the caller knows of why).
void validate_canonical(const CsvTable& log, const std::vector<std::string>& rotor_names,
                        const std::string& missing_hint = "");

// Canonical-layout CSV of a trajectory: t, u_*, x, y, z, qw..qz, phi, theta, psi, vx, vy,
// vz, p, q, r, then any further states (w_* rotor speeds).
std::string trajectory_csv(const DynamicModel& m, const Trajectory& tr, const InputFunction& u,
                           const std::vector<std::string>& rotor_names);

}  // namespace quadgen::runtime
