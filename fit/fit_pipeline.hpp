// The three fits `quadgen fit` runs, each from a log to what it writes (fit.json, plots and
// a summary line), kept apart from the command line that chooses one. The kind of fit
// follows the log's layout: a flight (ULog, or a CSV of poses, IMU and motor commands), the
// thesis' motor step tests (time_ms, throttle_percent, rpm: motor map and lag) or a thrust
// stand (weight[g], rpm1..4: thrust and speed laws).
#pragma once
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "fit/flight_data.hpp"
#include "fit/least_squares.hpp"
#include "fit/profile_likelihood.hpp"
#include "model/vehicle.hpp"
#include "output/accepted_range.hpp"

namespace quadgen::runtime {
class DynamicModel;
}

namespace quadgen::fit {

enum class LogKind { kFlight, kMotorSteps, kThrustStand };

// A ULog is a flight; a CSV is told apart by its columns.
LogKind log_kind(const std::string& path);

// The values FitJobOptions accepts (its IsValid and the command line's checks).
inline constexpr output::AcceptedRange kFitValidationRange{0, 0.9};  // fraction held out
inline constexpr output::AcceptedRange kFitWindowRange{0.01, 100};   // s
inline constexpr int kMaxThreads = 256;                              // profile threads
inline const std::vector<std::string> kFitFormulations = {"equation_error", "multiple_shooting"};

struct FitJobOptions {
  bool robust = false;                 // Huber loss instead of squares
  std::vector<std::string> profiles;   // names to profile; empty with profile_all: every free one
  bool profile_all_free = true;        // false with an empty list: estimates and standard errors only
  int threads = 0;                     // profile threads (0: one per core)
  std::string mapping;                 // flights: column mapping (YAML) for logs not in the canonical layout
  double resample = 0;                 // flights: resample onto a uniform grid at this rate [Hz] (0: no)
  double validation = 0.3;             // flights: fraction at the end held out
  std::string formulation = "equation_error";  // flights: or multiple_shooting
  double window = 0.5;                 // multiple shooting: window length [s]
  std::vector<std::string> channels;   // equation error: residual channels fitted (empty: all)
  // Equation error: the translational channels from the accelerometer (its specific force at
  // each sample) or from the pose (the differentiated velocity, exact for commands held
  // between samples); empty: the accelerometer where the log has one, else the pose. (Not
  // diagnose's "auto", which takes the pose first: fit keeps the sensor it has always used.)
  std::string translational;
  std::vector<std::string> free;       // parameters fitted, overriding the vehicle file's flags
  std::function<void(const std::string&)> progress = [](const std::string&) {};  // one line per step

  // Ceres-style: false with a reason for a value no fit can use.
  bool IsValid(std::string* error) const;
  // IsValid, and no option set away from its default that a fit of `kind` does not read
  // (options_set, why_unused): an option is refused, never dropped silently.
  bool IsValidFor(LogKind kind, std::string* error) const;
};

// The options a fit may be given, named as the command line's flags without "--" (the last is
// app::FitJob's); why_unused throws std::logic_error for any other name.
inline const std::vector<std::string> kFitOptionNames = {
    "robust", "profiles", "threads", "mapping", "resample", "validation",
    "formulation", "window", "channels", "translational", "free", "effects"};
// Which options a fit reads (kFitOptionNames). Empty when a fit of `kind` with
// `formulation` reads `option`, else why not, naming other options with `prefix` before
// them ("--" for the command line). The one rule behind the command line's refusal of the
// flags given and IsValidFor's of the options set.
std::string why_unused(const std::string& option, LogKind kind, const std::string& formulation,
                       const std::string& prefix = "");
// The options of `o` set away from their defaults, named as above.
std::vector<std::string> options_set(const FitJobOptions& o);

// What a fit writes: fit.json, rendered plots (file name, SVG), plots that could not be
// drawn (gnuplot missing: the fit still counts) and the lines the command prints.
struct FitOutputs {
  nlohmann::ordered_json json;
  std::vector<std::pair<std::string, std::string>> plots;
  std::vector<std::string> plot_errors;
  std::string summary;
  std::vector<std::string> warnings;  // what the user should look at before trusting the result (raw: made printable where printed)
};

FitOutputs fit_motor_steps_log(const std::string& path, const Vehicle& v, const FitJobOptions& o);
FitOutputs fit_thrust_stand_log(const std::string& path, const Vehicle& v, const FitJobOptions& o);
// `model` (compiled or interpreted) starts at its parameters' current values, free as their
// fit flags say; it needs no symbolic model.
FitOutputs fit_flight_log(const std::string& path, const Vehicle& v, runtime::DynamicModel& model, const FitJobOptions& o);

}  // namespace quadgen::fit
