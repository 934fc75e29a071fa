// A replica of a flight controller's cascaded PID attitude loop for roll and pitch: angle
// error -> PID -> body-rate set point, rate error -> PID -> a differential motor command. It
// flies a model along the attitude set points a log holds (predict's "set points flown"
// view), so that a simulation is kept upright the way the vehicle's own firmware kept it,
// slow disturbances included, instead of drifting open loop under the logged commands.
//
// The defaults are the Crazyflie firmware's `controller_pid` (bitcraze/crazyflie-firmware,
// src/modules/src/controller/attitude_pid_controller.c with the CF2 platform defaults;
// docs/simulation.md "Flying the logged set points" cites the values), in its units: angles
// in degrees, rates in deg/s, the output in PWM counts of which each motor takes plus or
// minus half (the quad-X power distribution). Not replicated: the yaw loop (the yaw command
// stays the logged one), the derivative filters (off by default in the firmware) and the
// battery compensation between the mixer and the logged motor commands, whose local slope
// `output_scale` stands for (1: none; on the NanoBench flights the collective measures
// 0.48-0.77, and the 1 s errors are 0.084-0.163 m at 0.6, 0.075-0.203 m at 1: docs/simulation.md).
#pragma once
#include <array>
#include <vector>

namespace quadgen::runtime {

struct PidGains {
  double kp = 0, ki = 0, kd = 0;
  double integral_limit = 0;  // |integral of the error| at most this (0: no limit)
};

struct AttitudePidOptions {
  PidGains attitude{6.0, 3.0, 0.0, 20.0};    // deg -> deg/s
  PidGains rate{250.0, 500.0, 2.5, 33.3};    // deg/s -> PWM counts
  double rate_hz = 500;                      // both loops
  double counts_per_command = 65535;         // PWM counts at a command (throttle fraction) of 1
  double output_limit = 32767;               // |output| at most this (the firmware's int16)
  // Logged command counts per count of the loop's output (the battery compensation's local
  // slope between them; 1: none).
  double output_scale = 1;
};

// How a roll or pitch output moves each rotor's command: per rotor, the counts it takes per
// count of output, the firmware's +-1/2 of the quad X: roll by the side a rotor is on (+1/2
// at y > 0: a positive output rolls the body about +x), pitch by its end (-1/2 at x > 0: a
// positive output pitches about +y, nose down, in the body frame x forward, z up).
struct AttitudeMixer {
  std::vector<double> roll, pitch;
  // From the rotor positions [m, body frame] and spins (+1 counter-clockwise seen from
  // above). Only a quad X: four rotors, one in each quadrant, whose roll and pitch columns
  // leave the collective and the yaw (the spins' pattern) alone, as the firmware's mixing
  // assumes; anything else throws std::invalid_argument saying why.
  static AttitudeMixer quad_x(const std::vector<std::array<double, 3>>& rotor_positions, const std::vector<int>& spins);
  // The roll and pitch outputs [counts] the commands `u` (throttle fractions) hold: their
  // least-squares projection on each axis' mixing column.
  std::array<double, 2> outputs_in(const double* u, double counts_per_command) const;
};

class AttitudePid {
 public:
  explicit AttitudePid(const AttitudePidOptions& o = {}) : o_(o) {}

  // Starts the loop where the vehicle's was, as far as a log tells: its integrals are what a
  // loop holds that tracks its set points on average over a window before the start (the
  // integrals are slow: kp / ki is 2 s and 0.5 s in the firmware): the attitude loop's the
  // mean measured rate minus kp times the mean angle error, the rate loop's the mean output
  // the logged commands hold (their mean rate error being zero so). Means, not the start's
  // values: a single sample's output carries the derivative term's noise and the rate error
  // of that instant, which an integral set from it would hold for seconds. Angles and rates
  // in rad, rad/s; integrals within their limits; the previous angle and rate the present.
  void start(const std::array<double, 2>& angle, const std::array<double, 2>& rate, const std::array<double, 2>& mean_output,
             const std::array<double, 2>& mean_rate, const std::array<double, 2>& mean_angle_error);
  // One step of 1 / rate_hz: the roll and pitch outputs [counts].
  std::array<double, 2> update(const std::array<double, 2>& angle, const std::array<double, 2>& rate,
                               const std::array<double, 2>& ref);
  double period() const { return 1.0 / o_.rate_hz; }
  const AttitudePidOptions& options() const { return o_; }

 private:
  struct Axis {
    double attitude_integral = 0, rate_integral = 0;  // deg s, deg/s s
    double previous_angle = 0, previous_rate = 0;    // deg, deg/s
  };
  AttitudePidOptions o_;
  std::array<Axis, 2> axes_{};
};

}  // namespace quadgen::runtime
