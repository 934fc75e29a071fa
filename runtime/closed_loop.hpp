// A closed-loop flight generator: a cascaded controller with integrators (position ->
// attitude -> body rates, as real autopilots have, so that it compensates what it does not
// know) flies the "true" model along a smooth random trajectory with yaw and height
// changes; commands are quantised as a flight controller logs them, and the log gets
// mocap-like pose noise and optional IMU noise and bias. Used to hide effects in flights
// that the diagnosis must then find, and as a simulator feature in its own right.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "runtime/dynamic_model.hpp"
#include "runtime/scenarios.hpp"
#include "runtime/thrust_law.hpp"

namespace quadgen::runtime {

// What the controller believes about the vehicle (nominal values, not the truth).
struct ControllerModel {
  double mass = 0, g = 9.81;
  double J[3] = {0, 0, 0};  // principal inertia
  double kappa = 0;
  std::vector<double> rotor_x, rotor_y, spin;  // spin +1 ccw seen from above
  std::vector<ThrustLaw> thrust_laws;          // command <-> thrust
};

// What each rotor's thrust does to the body, per newton, in the believed layout: (total thrust
// [1], roll and pitch moment about the CoG [m], yaw reaction [m]; a counter-clockwise rotor
// turns the body with -kappa F), one column per rotor. The controller allocates through it,
// simulate's scenarios trim hover with it, and derive's vehicle checks read its rank.
std::vector<std::array<double, 4>> allocation_columns(const ControllerModel& b);
// Per-rotor thrusts [N] for a total thrust [N] and body torques [N m]: the least-norm solution
// through the allocation (exact where it has rank 4).
std::vector<double> allocate(const ControllerModel& b, double thrust, const std::array<double, 3>& torque);

// A hover trim: each rotor's thrust [N] holding the weight without a moment, every one
// within its motor's reach: at least what command 0 gives (a motor map with a0 > 0 idles
// above 0 N), at most what command 1 gives. The least-norm trim first, exactly m g / n per
// rotor where the layout is symmetric. With more than four rotors the least-norm trim can
// ask a rotor for less (even a pull) or more than command 1 gives where another trim exists:
// then, up to kExactTrimRotors rotors, every set of rotors is held at command 0 in turn, the
// rest trimmed with least norm, and the least-norm of those trims within reach (commands 0
// to 1) taken; above, the rotor furthest below its least is held and the rest trimmed again,
// greedily. One home for derive's vehicle check and simulate's scenarios.
inline constexpr size_t kExactTrimRotors = 12;
// The likeliest cause of hover at or below the bottom of the command range, said by the
// trim's reason and by derive's check of it (one wording).
inline constexpr const char* kRpmWithoutUnit =
    "a motor map in rpm written without `unit: rpm` reads as rad/s, 9.5 times too fast";

struct HoverTrim {
  std::vector<double> thrusts;   // N, the trim found (the least-norm one where none pushes)
  std::vector<double> commands;  // each rotor's command for its thrust (0 where held); empty if none found
  // rad/s: a model's rotor-speed states (motor_lag) at the commands, in its order of them,
  // where a derivation found them (judge_hover_trim); empty for a model without such states.
  std::vector<double> rotor_speeds;
  std::string why_not;           // empty where a trim was found, else why not (names the rotor)
  // The rotors at command 0 lift the weight or more: no trim can be lower (a motor map in rpm
  // written without its unit reads 9.5 times too fast).
  bool idle_lifts_weight = false;
  bool found() const { return why_not.empty(); }
};
HoverTrim hover_trim(const ControllerModel& b, const std::vector<std::string>& rotor_names);

struct ClosedLoopOptions {
  double duration = 60;        // s
  unsigned seed = 1;
  double log_rate = 100;       // Hz; the controller runs at this rate and its commands are logged
  double sim_step = 1e-3;      // s, RK4
  double amplitude = 0.8;      // m, horizontal excursions of the trajectory
  double height = 1.0;         // m, mean height
  double height_amplitude = 0.3;
  double yaw_amplitude = 0.8;  // rad
  double pose_noise = 1e-3;    // m, and pose_noise rad on attitude (mocap-like)
  double gyro_noise = 0, gyro_bias = 0;    // rad/s
  double accel_noise = 0, accel_bias = 0;  // m/s^2
  // System-identification excitation: a multisine (1-8 Hz, random phases) of this
  // amplitude [rad/s] added to the body-rate set points, and of a tenth of it (relative)
  // to the collective thrust. Fast content separates look-alikes such as a lag and a delay.
  double excitation = 0;
  // A disturbance outside the effect catalogue (for testing that the diagnosis reports it
  // as unexplained instead of naming a wrong cause): a horizontal tether pulling the
  // vehicle back to the start point with this stiffness [N/m].
  double tether_stiffness = 0;
  // Another, within the vocabulary of diagnose's term discovery: a yaw acceleration in
  // proportion to the forward body speed (a bent part acting as a rudder) [rad/s^2 per m/s].
  double yaw_per_forward_speed = 0;
  // A third: a random roll and pitch angular acceleration [rad/s^2 RMS per axis], white
  // noise through a first-order low-pass at 10 Hz (propwash, turbulence, anything the
  // model lacks). The controller answers it within its bandwidth, so that the commands
  // correlate with what disturbs the vehicle: the closed-loop bias of a fitted answer to the
  // commands (diagnose/command_gain.hpp) is measured on such flights.
  double angular_disturbance = 0;
  int command_levels = 65535;  // quantisation of logged/applied commands (16-bit PWM)
  double vbat_start = 4.15, vbat_end = 3.75;  // V, open-circuit sag over the flight (logged)
  double vbat_load_drop = 0.15;  // V, extra drop per unit of relative load above hover (internal resistance)
  // Gains (per axis): position PD + I, attitude P, rate P + I.
  double kp_pos = 3.0, kd_pos = 3.5, ki_pos = 0.6, kp_att = 9.0, kp_rate = 18.0, ki_rate = 4.0;
};

struct GeneratedFlight {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;
  std::string csv() const;
};

// `truth` is integrated; `belief` drives the controller. Throws DivergenceError if the
// flight is lost.
GeneratedFlight fly_closed_loop(const DynamicModel& truth, const ControllerModel& belief,
                                const std::vector<std::string>& rotor_names, const ClosedLoopOptions& opt);

}  // namespace quadgen::runtime
