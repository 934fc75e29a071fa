// How strongly the airframe answers a change of rotor command, against what the model's
// motor map makes of it, band by band. A map measured on a thrust stand can have the right
// thrust at hover and the wrong slope there: the battery sags over the stand's rows, and an
// airframe hovers where the stand has few. The NanoBench Crazyflie answers at 0.6 of its
// stand map's slope (docs/crazyflie_evidence.md section 7), which a fit cannot see on its
// own: in closed loop the controller answers every slow disturbance with the commands, so
// the fitted answer to a command runs to a bound (the slope fitted ran to 0.2).
//
// The check, per axis (roll and pitch angular acceleration, vertical thrust per mass):
// the measured and the model's accelerations are band-passed alike (differences of running
// means), the model's shifted by the delay (0-80 ms) that correlates best in the band, and
// the measured is regressed on the model's. The model's thrust constant is first scaled to
// the hover's (the ratio of the mean measured and model vertical thrust), so a gain of 1
// says the map's slope at the operating point is right and 0.6 says the airframe answers at
// 0.6 of it. The lowest band carries the controller's answer to slow disturbances and reads
// low on any closed-loop flight; the 4-8 Hz band is the one the lead reads. Checked on
// generated closed-loop flights of known slope (tests/test_command_gain.cpp) and, for the
// real flights, against scripts/motor_map_slope.py (the same measure written apart).
// A lead, never a named cause: the key it suggests is the user's to set.
#pragma once
#include <string>
#include <vector>

#include "fit/equation_error.hpp"
#include "model/vehicle.hpp"

namespace quadgen::diagnose {

struct CommandGainInput {
  std::vector<double> t;         // s, per row, ascending (joined flights may leave gaps)
  std::vector<double> model;     // rows x 6: the model's accelerations (ax, ay, az, pdot, qdot, rdot)
  std::vector<double> measured;  // rows x 6: the log's, in the same channels
  std::vector<double> commands;  // rows x rotors: the rotor commands (0..1)
  size_t rotors = 0;
  double vertical_offset = 0;  // m/s^2 added to az of both to give thrust per mass: g for world
                               // accelerations, 0 for the accelerometer's specific force
  double model_slope = 1;      // the vehicle file's motor_map.slope (1 without one)
};

struct CommandGain {
  struct Band {
    double low_hz = 0, high_hz = 0;
    double gain = 0;     // measured on model, over the hover's thrust scale
    double r = 0;        // correlation at the best delay
    double delay_s = 0;  // the model's shift that correlates best
  };
  struct Axis {
    std::string name;  // "roll", "pitch", "vertical"
    std::vector<Band> bands;
  };
  // Half-widths of the running means [s] whose difference makes each band: ~8-17, 4-8, 2-4
  // and 0.8-2 Hz (scripts/motor_map_slope.py's bands at 100 Hz).
  static constexpr double kBands[4][2] = {{0.03, 0.06}, {0.06, 0.12}, {0.12, 0.25}, {0.25, 0.6}};
  static constexpr size_t kLeadBand = 1;       // 4-8 Hz
  static constexpr double kMaxDelay = 0.08;    // s
  static constexpr double kMinR = 0.5;         // a band whose correlation is lower says nothing
  static constexpr double kRightLow = 0.8, kRightHigh = 1.25;  // a gain in here: the slope is right

  bool measured = false;
  std::string why_not;          // when not measured
  size_t rows = 0;              // rows used
  double hover_command = 0;     // mean rotor command over them
  double thrust_scale = 0;      // mean measured over mean model vertical thrust
  double model_slope = 1;
  std::vector<Axis> axes;       // roll, pitch, vertical

  // Roll and pitch both correlate in the lead band, agree within 25 %, and lie outside
  // [kRightLow, kRightHigh]: the map's slope at the operating point looks off.
  bool slope_looks_off() const;
  double roll_pitch_gain() const;  // their mean in the lead band
  double suggested_slope() const { return model_slope * roll_pitch_gain(); }
};

CommandGain command_gain(const CommandGainInput& in);

// What the check reads from an equation-error model and its residuals at some parameters
// (`residual`, rows() x 6 as all_channels gives them; the diagnosis passes its base fit's):
// the model's accelerations (the residuals plus what they are compared with) and the
// measured ones on every row, and the rotor commands there. `g` [m/s^2] and
// `accelerometer` (the translation is the accelerometer's specific force, not the world
// acceleration) set the vertical thrust per mass; the vehicle file gives its motor map's slope.
CommandGainInput command_gain_input(const fit::EquationErrorModel& ee, const std::vector<double>& residual,
                                    const Vehicle& v, double g, bool accelerometer);

// The rows of each flight of a joint diagnosis (`starts`: where each flight begins on the
// joined clock, ascending), as inputs of their own.
std::vector<CommandGainInput> split_by_flight(const CommandGainInput& in, const std::vector<double>& starts);

}  // namespace quadgen::diagnose
