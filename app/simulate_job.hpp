// `quadgen simulate` as a library call: a scenario of the thesis, a replay of logged motor
// commands, or a closed-loop test flight of the true model (effects and parameter overrides)
// flown by a controller that believes the nominal base model. Returns the trajectory in the
// canonical flight-log layout and the plot's panels; the caller writes them.
#pragma once
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "runtime/closed_loop.hpp"
#include "output/accepted_range.hpp"
#include "output/progress.hpp"
#include "runtime/plot.hpp"

namespace quadgen::app {

inline constexpr double kMinStep = 1e-7;  // s, the smallest RK4 --step taken

// The numbers SimulateJob accepts (its IsValid and the command line's checks read these).
inline constexpr output::AcceptedRange kDurationRange{1e-6, 1e9};  // s
inline constexpr output::AcceptedRange kStepRange{kMinStep, 1.0};  // s
inline constexpr output::AcceptedRange kRateRange{1e-3, 1e6};      // Hz
// The closed-loop test flight's, one row each: the option that sets it, its field, its range
// and what --help says of it (the command line adds one option per row).
struct FlightNumber {
  const char* option;
  double runtime::ClosedLoopOptions::*field;
  output::AcceptedRange range;
  const char* help;
};
inline const std::vector<FlightNumber> kFlightNumbers = {
    {"--pose-noise", &runtime::ClosedLoopOptions::pose_noise, {0, 10},
     "closed loop: mocap noise [m, rad]"},
    {"--gyro-noise", &runtime::ClosedLoopOptions::gyro_noise, {0, 100},
     "closed loop: gyro noise [rad/s]"},
    {"--gyro-bias", &runtime::ClosedLoopOptions::gyro_bias, {-10, 10},
     "closed loop: gyro bias [rad/s]"},
    {"--accel-noise", &runtime::ClosedLoopOptions::accel_noise, {0, 100},
     "closed loop: accelerometer noise [m/s^2]"},
    {"--accel-bias", &runtime::ClosedLoopOptions::accel_bias, {-100, 100},
     "closed loop: accelerometer bias [m/s^2]"},
    {"--amplitude", &runtime::ClosedLoopOptions::amplitude, {0, 20},
     "closed loop: horizontal excursions of the trajectory [m]"},
    {"--height", &runtime::ClosedLoopOptions::height, {0.05, 100},
     "closed loop: mean height [m]"},
    {"--height-amplitude", &runtime::ClosedLoopOptions::height_amplitude, {0, 10},
     "closed loop: height excursions [m]"},
    {"--yaw-amplitude", &runtime::ClosedLoopOptions::yaw_amplitude, {0, 10},
     "closed loop: heading excursions [rad]"},
    {"--excitation", &runtime::ClosedLoopOptions::excitation, {0, 5},
     "closed loop: multisine (1-8 Hz) on the rate set points [rad/s]"},
    {"--tether", &runtime::ClosedLoopOptions::tether_stiffness, {0, 100},
     "closed loop: horizontal tether to the start point, stiffness [N/m] (an effect outside the catalogue)"},
    {"--yaw-per-speed", &runtime::ClosedLoopOptions::yaw_per_forward_speed, {-50, 50},
     "closed loop: yaw acceleration per m/s of forward body speed [rad/s^2 per m/s] (outside the catalogue)"},
    {"--angular-disturbance", &runtime::ClosedLoopOptions::angular_disturbance, {0, 100},
     "closed loop: random roll and pitch angular acceleration, 10 Hz low-passed white noise [rad/s^2 RMS] (outside the catalogue)"}};

struct SimulateJob {
  std::string vehicle;      // vehicle file (YAML)
  std::string scenario;     // one of the thesis' manoeuvres, or
  std::string inputs;       // a log whose motor commands are replayed, or
  std::string mapping;      // column mapping (YAML) for `inputs` of another layout; "": canonical
  bool closed_loop = false;  // a closed-loop test flight
  std::string effects;      // comma-separated effects of the simulated (true) model
  double duration = 0;      // s
  std::string integrator = "rk4";  // or dopri5
  double step = 1e-3;       // s, RK4
  double rate = 100;        // Hz, output rows
  std::string interpolation = "hold";  // replayed commands between samples: hold or linear
  // A ground the vehicle rests on (runtime/ground_contact.hpp), for a scenario or a replay:
  // none by default; at the start's height (the log's first z; 0 for a scenario) with
  // ground_at_start, else at ground_height [m, world z of the body origin standing on it].
  bool ground_at_start = false;
  std::optional<double> ground_height;  // within +-kMaxGroundHeight
  // Closed loop: the flight generator's seed, trajectory, noise and disturbances, with its
  // defaults (its own duration is replaced by `duration`), and the true model's parameter
  // overrides.
  runtime::ClosedLoopOptions flight;
  std::vector<std::pair<std::string, double>> set;
  bool no_size_limit = false;  // refuse runs beyond kMaxSteps steps or kMaxRows rows unless set
  output::Progress progress;   // "simulating 5 s of ..."; nowhere by default

  // Ceres-style: false with a reason for a number no simulation can use (run_simulate_job
  // throws it before any work).
  bool IsValid(std::string* error) const;
};

// Work beyond these sizes is refused before it starts unless no_size_limit is set: each
// stored sample costs ~0.2 kB, so 1e7 of them is about 2 GB.
inline constexpr double kMaxSteps = 1e7, kMaxRows = 1e7;

// A ground further from the origin than this [m] is a mistyped number, not a ground.
inline constexpr double kMaxGroundHeight = 1e4;

struct SimulateJobResult {
  std::string csv;                     // the trajectory, canonical flight-log layout
  std::string plot_title;
  std::vector<runtime::Panel> plot;    // translation, rotation, thrust; or position and commands
  std::string svg;                     // the plot drawn (TRAJ.svg), or
  std::string plot_error;              // why it could not be (no gnuplot)
  std::string summary;                 // what the command prints
  std::vector<std::string> notes;      // what the user should know about the flight (its commands' limits)
};

// Throws std::invalid_argument for contradicting or oversized requests before any work, and
// the layers' own errors (vehicle file, log) unchanged.
SimulateJobResult run_simulate_job(const SimulateJob& job);

}  // namespace quadgen::app
