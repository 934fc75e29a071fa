#include "fit/read_flight.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "fit/log_reader.hpp"
#include "output/joined.hpp"
#include "output/numbers.hpp"

namespace quadgen::fit {

namespace {

// PX4's output functions "Motor 1".."Motor 12" (src/lib/mixer_module/output_functions.yaml).
constexpr double kMotorFunction1 = 101, kMotorFunctionLast = 112;
// A logged motor within this of its rotor's direction from the rotors' centre is that rotor:
// under half the spacing of an octocopter's (45 degrees).
constexpr double kSameDirection = 20 * M_PI / 180;

// The number k of a field "name[k]", or -1.
long index_of(const std::string& field, const std::string& name) {
  if (field.size() < name.size() + 3 || field.compare(0, name.size() + 1, name + "[") != 0 || field.back() != ']') return -1;
  const std::string digits = field.substr(name.size() + 1, field.size() - name.size() - 2);
  if (digits.empty() || digits.size() > 3 || digits.find_first_not_of("0123456789") != std::string::npos) return -1;
  return std::stol(digits);
}

// The PX4 motor (1, 2, ...) a mapped source reads, and the log's words for it; motor 0 where
// the log does not say, with `how` naming the channel's functions where none is a motor.
struct LoggedMotor {
  int motor = 0;
  std::string how;
};

LoggedMotor motor_of(const std::string& source, const std::map<std::string, double>& parameters) {
  const auto dot = source.find('.');
  if (dot == std::string::npos) return {};
  const std::string topic = source.substr(0, source.find('[') < dot ? source.find('[') : dot);
  const std::string field = source.substr(dot + 1);
  if (topic == "actuator_motors") {
    const long k = index_of(field, "control");
    return k < 0 ? LoggedMotor{} : LoggedMotor{static_cast<int>(k) + 1, "actuator_motors.control[k] is motor k + 1"};
  }
  const long channel = topic == "actuator_outputs" ? index_of(field, "output") : -1;
  if (channel < 0) return {};
  // Every output-function family naming a motor for this channel (PWM_MAIN_FUNC1 is channel 0).
  const std::string suffix = "_FUNC" + std::to_string(channel + 1);
  std::map<int, std::vector<std::string>> motors;
  std::vector<std::string> functions;  // every family's function for the channel
  for (const auto& [name, value] : parameters)
    if (stem_before(name, suffix)) {
      functions.push_back(name + " = " + output::short_number(value));
      if (value >= kMotorFunction1 && value <= kMotorFunctionLast && value == std::floor(value))
        motors[static_cast<int>(value - kMotorFunction1) + 1].push_back(functions.back());
    }
  if (motors.empty()) return {0, output::joined(functions)};  // a channel set to no motor (or not set at all)
  if (motors.size() > 1) return {};  // families that disagree: which driver logged the instance is not said
  return {motors.begin()->first, output::joined(motors.begin()->second)};
}

// A rotor in the model's forward-left-up axes, and its spin: +1 counter-clockwise seen from
// above, -1 clockwise, 0 not said.
struct Place {
  double x = 0, y = 0;
  int spin = 0;
};

std::optional<Place> logged_place(const std::map<std::string, double>& parameters, int motor) {
  const std::string key = "CA_ROTOR" + std::to_string(motor - 1) + "_";
  const auto px = parameters.find(key + "PX"), py = parameters.find(key + "PY"), km = parameters.find(key + "KM");
  // (0, 0), PX4's default, is a position never set: a rotor at the CoG lifts nothing to judge.
  if (px == parameters.end() || py == parameters.end() || (px->second == 0 && py->second == 0)) return std::nullopt;
  const int spin = km == parameters.end() ? 0 : (km->second > 0 ? 1 : (km->second < 0 ? -1 : 0));
  return Place{px->second, -py->second, spin};  // forward-right-down -> forward-left-up
}

// The mean place of `places` (x, y), the origin for none.
std::pair<double, double> centre(const std::vector<Place>& places) {
  double x = 0, y = 0;
  for (const auto& p : places) x += p.x, y += p.y;
  const double n = places.empty() ? 1 : static_cast<double>(places.size());
  return {x / n, y / n};
}

double angle_between(double a, double b) { return std::fabs(std::remainder(a - b, 2 * M_PI)); }

// "front-left" for a direction (rad, 0 forward, counter-clockwise seen from above).
std::string direction_word(double azimuth) {
  static const char* const kWords[8] = {"front", "front-left", "left", "rear-left", "rear", "rear-right", "right", "front-right"};
  const long sector = std::lround(azimuth / (M_PI / 4));
  return kWords[((sector % 8) + 8) % 8];
}

std::string spin_word(int spin) { return spin > 0 ? "counter-clockwise" : "clockwise"; }

// The logged motors as PX4 places them (those with a position), motor number -> place.
std::map<int, Place> logged_places(const std::map<std::string, double>& parameters, int count) {
  std::map<int, Place> places;
  for (int m = 1; m <= count; ++m)
    if (const auto p = logged_place(parameters, m)) places[m] = *p;
  return places;
}

// What the log says of the motor the vehicle file's rotor i is read from, against that rotor:
// a note where they differ, else "". `file` holds the file's rotors, `fx`, `fy` their centre.
struct RotorJudge {
  const std::string& path;
  const std::map<std::string, double>& parameters;
  const Vehicle& v;
  int count;
  const std::map<int, Place>& logged;
  const std::vector<Place>& file;
  double fx, fy;

  double direction(size_t j) const { return std::atan2(file[j].y - fy, file[j].x - fx); }

  // The file's rotor nearest in direction to `azimuth`; of two in one direction (a coaxial
  // pair) the one spinning as the logged motor does.
  size_t nearest(double azimuth, int spin, size_t start) const {
    const auto nearer = [&](size_t j, size_t than) {
      const double a = angle_between(azimuth, direction(j)), b = angle_between(azimuth, direction(than));
      if (std::fabs(a - b) > 1e-9) return a < b;
      return file[j].spin == spin && file[than].spin != spin;
    };
    size_t best = start;
    for (size_t j = 0; j < file.size(); ++j)
      if (nearer(j, best)) best = j;
    return best;
  }

  std::string note(size_t i, const std::string& source) const {
    const Rotor& rotor = v.rotors[i];
    const LoggedMotor m = motor_of(source, parameters);
    const std::string column = path + ": u_" + rotor.name + " reads " + source;
    if (m.motor == 0 && !m.how.empty())
      return column + ", a channel whose output function is no motor (" + m.how +
             "; 101..112 are motors 1..12): the channel that drives this rotor is the one whose function is its motor";
    if (m.motor > count)
      return column + ", PX4's motor " + std::to_string(m.motor) + " (" + m.how + "), but the log's CA_ROTOR_COUNT is " +
             std::to_string(count) + ": PX4 allocated no thrust to it";
    const auto place = logged.find(m.motor);
    if (m.motor == 0 || place == logged.end()) return "";
    const Place& p = place->second;
    const double azimuth = std::atan2(p.y, p.x);  // from the CoG, PX4's origin
    const std::string head = column + ", PX4's motor " + std::to_string(m.motor) + " (" + m.how +
                             "), which the log's CA_ROTOR" + std::to_string(m.motor - 1) + "_";
    const std::string where_file = v.source_path + ":" + std::to_string(rotor.line);
    const size_t there = nearest(azimuth, p.spin, i);
    if (angle_between(azimuth, direction(i)) > kSameDirection && there != i)
      return head + "PX/PY place " + direction_word(azimuth) + " (x " + output::short_number(p.x) + ", y " +
             output::short_number(p.y) + " m, forward-left-up); the vehicle file's " + rotor.name + " (" + where_file +
             ") sits " + direction_word(direction(i)) + ", its " + v.rotors[there].name +
             " where that motor is: number the vehicle file's rotors as the log's motors, or map each u_ column to its "
             "own rotor's channel (data/mappings/px4.yaml says how)";
    if (p.spin != 0 && p.spin != spin_sign(rotor))
      return head + "KM (" + output::short_number(parameters.at("CA_ROTOR" + std::to_string(m.motor - 1) + "_KM")) +
             ") spins " + spin_word(p.spin) + " seen from above; the vehicle file's " + rotor.name + " (" + where_file +
             ") spins " + spin_word(spin_sign(rotor));
    return "";
  }
};

}  // namespace

std::vector<std::string> logged_rotor_notes(const std::string& path, const std::map<std::string, double>& parameters,
                                            const ColumnMapping& mapping, const Vehicle& v) {
  const auto count_it = parameters.find("CA_ROTOR_COUNT");
  if (count_it == parameters.end() || !(count_it->second >= 1)) return {};
  std::vector<std::string> notes;
  const int count = static_cast<int>(std::min(count_it->second, 64.0));
  if (static_cast<size_t>(count) != v.rotors.size())
    notes.push_back(path + ": the log's CA_ROTOR_COUNT is " + std::to_string(count) + " (PX4 allocated thrust to " +
                    std::to_string(count) + " motors), the vehicle file " + v.source_path + " has " +
                    std::to_string(v.rotors.size()) + " rotors");
  // Directions: the log's from PX4's origin, the CoG (a motor whose place is not set moves no
  // centre); the file's from its rotors' centre (a file's body origin may be anywhere).
  const std::map<int, Place> logged = logged_places(parameters, count);
  std::vector<Place> file_list;
  for (const auto& r : v.rotors) file_list.push_back({r.position[0], r.position[1], spin_sign(r)});
  const auto [fx, fy] = centre(file_list);
  const RotorJudge judge{path, parameters, v, count, logged, file_list, fx, fy};
  for (size_t i = 0; i < v.rotors.size(); ++i) {
    const auto entry = std::find_if(mapping.entries.begin(), mapping.entries.end(),
                                    [&](const ColumnMapping::Entry& e) { return e.target == "u_" + v.rotors[i].name; });
    if (entry == mapping.entries.end()) continue;
    if (std::string note = judge.note(i, entry->source); !note.empty()) notes.push_back(std::move(note));
  }
  return notes;
}

Flight read_flight(const std::string& path, const ColumnMapping* mapping, double resample_hz, const Vehicle& v) {
  const runtime::CsvTable log = read_log(path, mapping, resample_hz);
  Flight flight = load_flight(log, rotor_names(v), {});
  if (mapping)
    for (auto& note : logged_rotor_notes(path, log.parameters, *mapping, v)) flight.notes.push_back(std::move(note));
  return flight;
}

Flight read_flight(const std::string& path, const std::string& mapping_path, double resample_hz, const Vehicle& v) {
  if (mapping_path.empty()) return read_flight(path, static_cast<const ColumnMapping*>(nullptr), resample_hz, v);
  const ColumnMapping m = load_mapping(mapping_path);
  return read_flight(path, &m, resample_hz, v);
}

}  // namespace quadgen::fit
