// Whether what the final model still gets wrong about the roll and pitch moments looks like
// air moving through the rotors: a draft the model does not have, w (horizontal, body
// frame), is seen by the blade-flapping moment and the rotor-drag force alike
// (docs/effects.md), so with residual = model - measured and S the sum of rotor speeds
//
//   pdot = +k_f S w_y / J_xx     qdot = -k_f S w_x / J_yy
//   a_y  = -k_d S w_y / m        a_x  = -k_d S w_x / m
//
// and the force residual follows the moment residual by a fixed ratio whatever S and w are:
// a_y = -(k_d J_xx / (k_f m)) pdot, a_x = +(k_d J_yy / (k_f m)) qdot. A trim or a CoG
// offset has no reason to keep that sign; a common scale error of the airspeed terms does
// (w replaced by a multiple of the body velocity), so the velocity along the axis is
// partialled out first. Measured on the slow part of the residuals (1 s means every 0.1 s,
// where the moment residual that drifts the open loop lives), on the training and the
// held-out part, one-sided in the draft's direction, by a sign-flip test of the moment's
// cosine coefficients (draft_signature.cpp, sign_flip_p). A hypothesis for an unmeasured draft
// (docs/history.md, "Is the slow moment residual moving air?"), never a named cause;
// scripts/air_draft_check.py is the same test on a diagnosis folder.
#pragma once
#include <string>
#include <vector>

namespace quadgen::diagnose {

struct DraftSignatureInput {
  std::vector<double> t;         // s, per sample
  std::vector<double> residual;  // samples x 6 (ax, ay, az, pdot, qdot, rdot), model - measured
  std::vector<double> velocity;  // samples x 2, m/s, world x and y (turned into the heading frame like the force)
  std::vector<double> heading;   // rad, per sample: world vectors are turned by it into the heading frame
  bool force_in_world = true;    // false: the force channels are already body axes (accelerometer)
  std::vector<bool> held_out;    // per sample
  double rotor_drag_k = 0, blade_flapping_k = 0;  // N s^2/m, N s^2
  double mass = 0, J_xx = 0, J_yy = 0;            // kg, kg m^2
  double hover_speeds_sum = 0;  // rad/s, sum of rotor speeds in a hover (for the implied draft speed)
};

struct DraftSignature {
  // One force residual against one moment residual (their slow means, the velocity along the
  // axis partialled out of both).
  struct Pair {
    std::string force, moment;
    double draft_slope = 0;    // the ratio a draft gives
    double raw_r = 0;          // before the velocity is partialled out
    double r = 0;              // partial correlation
    double effective_n = 0;    // Bartlett: n / (1 + 2 sum_k rho_f(k) rho_m(k)), how slow the series are
    double p = 1;              // one-sided, in the draft's direction (cosine sign-flip test)
    double slope = 0;          // least squares of the force on the moment (partialled)
    double reverse_slope = 0;  // 1 / (slope of the moment on the force): noise in the moment pulls `slope`
                               // towards zero, the reverse one away from it
    bool shows_draft() const { return p <= kLevel; }
  };
  struct Part {
    std::string name;  // "training", "held-out"
    size_t means = 0;
    Pair y_roll, x_pitch;
    double implied_speed = 0;  // m/s, at most: from the RMS of the slow pdot and qdot, mean included
  };
  static constexpr double kWindow = 1.0;  // s, running means
  static constexpr double kGrid = 0.1;    // s, where they are taken
  static constexpr double kLevel = 0.05;

  bool measured = false;
  std::string why_not;  // when not measured
  std::vector<Part> parts;
  // The axes whose pair shows the draft on both parts ("y (roll)", "x (pitch)").
  std::vector<std::string> axes_showing_it() const;
};

DraftSignature draft_signature(const DraftSignatureInput& in);

// Flights diagnosed jointly share a clock: the samples from each start time up to the next
// one (`starts`: where each flight begins, ascending), as inputs of their own. A draft's
// direction in the room differs from flight to flight, so pooled flights dilute it; each
// flight is checked alone, with the joint model's residuals.
std::vector<DraftSignatureInput> split_by_flight(const DraftSignatureInput& in, const std::vector<double>& starts);

}  // namespace quadgen::diagnose
