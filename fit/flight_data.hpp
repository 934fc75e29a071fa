// Flight logs prepared for fitting: a column mapping (source column, scale, offset, unit)
// turns a dataset's own layout into the canonical one; the samples are checked, the
// attitude normalised, accelerations estimated where the log has none, and the flight
// split by time into a training and a validation part.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "runtime/flight_log.hpp"

namespace quadgen::fit {

// canonical = (source * scale + offset) * unit_scale, where unit_scale converts `unit` to
// the canonical column's SI unit (see load_mapping in flight_data.cpp for the rules).
struct ColumnMapping {
  std::string name;
  // Where the logs were flown, when the mapping says: "indoor", "outdoor" ("" if not said).
  std::string environment;
  // The axes of the mapped columns: "enu_flu" (the model's: east-north-up world, forward-
  // left-up body) or "ned_frd" (PX4's north-east-down, forward-right-down), converted.
  std::string frame = "enu_flu";
  std::string path;  // the file, for messages about the names it gives
  struct Entry {
    std::string target, source, unit;
    double scale = 1, offset = 0;
    double unit_scale = 1;  // from parse_unit(unit); 1 without a unit
    int line = 0;           // of the entry in the mapping file
  };
  std::vector<Entry> entries;
};

// A CSV file of measurements (thrust stand, motor steps): the reader's errors (file:line,
// non-finite cells, size) as this layer's FitError.
runtime::CsvTable read_measurement_csv(const std::string& path);
// Column `name` of such a file, -1 if absent; one with a cell that is no finite number is a
// FitError naming that cell's line (columns the layout does not read may hold anything).
int measurement_column(const runtime::CsvTable& t, const std::string& name);

// How a log gives its attitude: a complete quaternion qw..qz, else complete Z-Y-X Euler
// angles phi, theta, psi (docs/formats.md), else not at all.
enum class AttitudeColumns { kNone, kQuaternion, kEuler };
AttitudeColumns attitude_columns(const runtime::CsvTable& log);
// Said when a log has some attitude columns but neither form complete (a misnamed or
// unmapped column, which would otherwise be read as no attitude at all): "it has phi, theta
// but not psi". Empty when a form is complete or the log has no attitude column.
std::string incomplete_attitude(const runtime::CsvTable& log);
// An attitude's columns, for messages (a pose is x, y, z and these).
inline constexpr const char* kAttitudeColumnSets = "qw, qx, qy, qz or phi, theta, psi";
// What keeps a log that has part of a pose from having one ("it lacks z; it has phi, theta
// but not psi"; "it has no attitude"): empty when it has a pose or none of its columns.
std::string pose_lacks(const runtime::CsvTable& log);
// Row `row`'s attitude as a quaternion (scalar first, body to world; not normalised), the
// identity for kNone.
std::array<double, 4> logged_attitude(const runtime::CsvTable& log, AttitudeColumns form, size_t row);

// Every canonical column (docs/formats.md's table) the log has must hold a finite number in
// every row, whether or not this command reads it: throws the reader's LogError naming the
// first bad cell's line. Columns quadgen does not know may hold anything.
void require_known_columns_readable(const runtime::CsvTable& log);

ColumnMapping load_mapping(const std::string& path);  // throws FitError with file:line
ColumnMapping parse_mapping(const std::string& yaml_text, const std::string& source_name);
runtime::CsvTable apply_mapping(const runtime::CsvTable& raw, const ColumnMapping& m);

using runtime::canonical_unit;  // the canonical columns' units live with the layout (runtime/flight_log.hpp)

// One time-aligned sample of a flight in canonical units.
struct FlightSample {
  double t = 0;
  std::vector<double> x;     // 13 base states: x y z vx vy vz qw qx qy qz p q r
  std::vector<double> u;     // rotor commands in vehicle rotor order
  double vbat = 0;
  double acc_world[3] = {0, 0, 0};  // d(v)/dt, world frame (smoothed derivative)
  double rate_dot[3] = {0, 0, 0};   // d(p,q,r)/dt, body (smoothed derivative)
  double specific_force[3] = {0, 0, 0};  // accelerometer, body frame, where logged
  // The roll and pitch set points the flight controller's attitude loop followed (Z-Y-X Euler
  // angles, rad), where logged (phi_ref, theta_ref): what predict's set-points-flown view flies.
  double attitude_ref[2] = {0, 0};
};

struct Flight {
  std::string source;
  std::vector<FlightSample> samples;
  bool has_accelerometer = false, has_gyro = false, has_pose = false, has_vbat = false;
  bool has_attitude_ref = false;  // phi_ref and theta_ref logged
  // What the log holds but the loader could not read, for the user ("log.csv:1: no pose is
  // read: ..."), and what reading a binary log noticed (a topic slower than the grid); the
  // commands pass them on (fit's warnings, diagnose's and predict's notes).
  std::vector<std::string> notes;
  bool pose_partly_logged = false;  // a note says why the part of a pose logged is not read
};

// Where a fit's translational channels (ax, ay, az) may come from: the pose's differentiated
// velocity or the accelerometer's specific force (fit's --translational; diagnose's adds
// "auto").
inline const std::vector<std::string> kTranslationalSources = {"pose", "accelerometer"};

struct FlightOptions {
  double derivative_window = 0.05;  // s, half-width of the local quadratic fit
  double min_samples = 20;
  // Keep only airborne samples: every command above min_command, with a pose the height above
  // min_height, and where the log has the controller's landed flag (column `landed`) that
  // flag below 0.5. Ground contact is not in the model.
  bool airborne_only = true;
  double min_command = 0.05;
  double min_height = 0.1;
  // Derivatives within this many seconds of the log's ends come from one-sided windows;
  // those samples are dropped.
  double edge_trim = 0.1;
};

// Every column onto a uniform grid at `rate_hz` (streams logged at different rates and
// forward-filled, or irregular sample times), each grid value the column's mean over the grid
// interval around it (fit/grid_mean.hpp: a faster log folds nothing into the slow band); the
// quaternion sign-aligned and the Euler roll and yaw unwrapped before averaging.
runtime::CsvTable resample(const runtime::CsvTable& log, double rate_hz);

// What a gyro that disagrees with the attitude's turns most likely means, from the slope of
// the attitude's turn on the gyro's integral and its standard error (1 where they agree): a
// unit's factor (deg/s read as rad/s gives 1/57) only where the slope is that factor and the
// data tell it from zero; otherwise a convention or axes. `euler`: the attitude is logged as
// Euler angles (which may be in degrees).
std::string gyro_disagreement_hint(double slope, double se, bool euler);

// Refuse a log whose time or attitude angles are plainly in another unit than the canonical
// layout's, naming file, line and the likely fix; load_flight runs both. check_time_unit: a
// median sample interval of 0.5 s or more (ms read as s; a flight log holds tens to
// thousands of samples a second; a replay's command schedule may be sparse and is not
// judged). check_euler_range: a roll beyond +-pi or a pitch beyond +-pi/2 (degrees read as
// radians; simulate --inputs runs it for its start attitude).
void check_time_unit(const runtime::CsvTable& log);
void check_euler_range(const runtime::CsvTable& log);
// The rule behind check_euler_range for one value of column "phi" or "theta" (any other column
// passes): "" or what is wrong, without the place (a mapped topic log judges its samples).
std::string euler_range_problem(const std::string& column, double value_rad);

// Reads a canonical log (or a raw log through a mapping), validates it for these rotors.
Flight load_flight(const runtime::CsvTable& canonical, const std::vector<std::string>& rotors, const FlightOptions& o);

// Where the held-out part begins: train_fraction of the flight's duration after its first
// sample. The samples are the airborne ones (load_flight drops the rows before take-off), so
// the fraction is of the flight, not of the log's clock: until 2026-12-05 split_by_time cut at
// train_fraction times the last sample's time, counted from the log's first row, which held
// out more than the fraction of a flight with ground time before it and did not match
// split_each_by_time (a read-only audit, helper-114).
double training_cut(const Flight& f, double train_fraction);

// Samples before training_cut (training) and the rest (validation).
std::pair<Flight, Flight> split_by_time(const Flight& f, double train_fraction);

// Several flights of one vehicle as one log: each next flight's clock continues the
// previous one's after `gap` seconds, longer than any sample interval, so derivative
// windows, contiguous stretches and simulation windows never run from one flight into the
// next. The flags are those every flight has. split_each_by_time holds out the end of each
// flight (its own `1 - train_fraction` of its duration) on the same joined clock.
Flight join_flights(const std::vector<Flight>& flights, double gap = 1.0);
std::pair<Flight, Flight> split_each_by_time(const std::vector<Flight>& flights, double train_fraction,
                                             double gap = 1.0);
// Where each flight begins on that joined clock.
std::vector<double> joined_start_times(const std::vector<Flight>& flights, double gap = 1.0);
// Each flight's clock offset in the joined log: its own time t reads t + offset there.
std::vector<double> join_offsets(const std::vector<Flight>& flights, double gap = 1.0);
// Which of the joined flights (0-based, by those start times, ascending) time t lies in; -1
// before the first.
int joined_flight_at(const std::vector<double>& starts, double t);

// Derivative at each sample by a local quadratic least-squares fit over +-window seconds
// (a Savitzky–Golay filter that also works for uneven sampling).
std::vector<double> smoothed_derivative(const std::vector<double>& t, const std::vector<double>& y, double window);

}  // namespace quadgen::fit
