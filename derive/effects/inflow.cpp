// inflow: thrust loss with inflow. Air flowing through a rotor disc from above (the rotor
// climbing, or rising as the body rolls or pitches) lowers the blades' angle of attack, and
// the thrust at a given rotor speed falls; a descending rotor gains thrust. For an axial speed
// v_i small against the tip speed w_i r_p, blade-element theory with momentum inflow
// (Leishman, Principles of Helicopter Aerodynamics, 2nd ed., 2006, ch. 3) gives a thrust
// linear in the climb inflow ratio v_i / (w_i r_p):
//   F_i = c_t rho A_p r_p^2 w_i^2 (1 - k v_i / (w_i r_p)) = ... w_i (w_i - k v_i / r_p),
// with v_i the body-z speed of rotor i's hub through the air, (R^T v_air)_z + (omega x arm_i)_z.
// Its rotational part damps roll and pitch. Typical size: uniform-inflow BEMT at hover gives
// dC_T/C_T per unit climb ratio = 1 / (lambda_h + 16 lambda_h^2 / (sigma a)), lambda_h =
// sqrt(C_T / 2); for the Crazyflie (C_T ~ 0.02, solidity sigma ~ 0.1-0.15, lift slope
// a ~ 5.7 /rad, both assumed) k ~ 2.5-3.5: a 1 m/s climb at a 40 m/s tip speed costs ~7 %.
#include "derive/effects/definitions.hpp"
#include "derive/dynamics.hpp"
#include "derive/effects/headline_words.hpp"

namespace quadgen::effects {
using namespace GiNaC;

namespace {

void terms(ModelContext& c) {
  const ex k = c.add_param("inflow.k", "1", 0.0, -5.0, 20.0, true, "thrust loss per climb inflow ratio v / (w r_p)");
  const matrix vb = c.R.transpose().mul(c.air_velocity_world);
  for (size_t i = 0; i < c.rotor_speed.size(); ++i) {
    const matrix arm = c.rotor_position[i].sub(c.cog);
    const ex climb = vb(2, 0) + c.omega(0, 0) * arm(1, 0) - c.omega(1, 0) * arm(0, 0);  // (v + omega x arm)_z
    c.thrust_speed_loss[i] += k * climb / c.rotor_radius[i];
  }
}

}  // namespace

Effect inflow() {
  Effect e;
  e.name = "inflow";
  e.meaning = "thrust lowered by k (climb speed of each rotor through the air) / (tip speed)";
  e.apply = terms;
  e.parameter_names = "inflow.k";  // as --help lists them
  e.domain = {{"inflow.k", 0.0, true, "a negative k would raise the thrust as the rotor climbs (positive feedback)"}};
  e.plausible = {{"inflow.k", 0.0, 8.0, PlausibleRange::Scale::kSI, Environment::kUnknown,
                  "blade-element theory with momentum inflow gives 1 / (lambda_h + 16 lambda_h^2 / (sigma a)): "
                  "about 1-6 for small rotors; negative would mean thrust grows with climb"}};
  e.look_alikes = {{"thrust_decay", "climbs and descents at several speeds at one battery state: inflow follows the "
                                    "climb rate, a decay follows the clock"}};
  e.headline = [](const std::map<std::string, double>& v, const std::string&) {
    using headline::words;
    const double k = headline::value_of(v, "inflow.k");
    return "Climbing costs thrust: each rotor loses " + words(k) +
           " times its climb-to-tip-speed ratio (a 1 m/s climb at a 40 m/s tip speed: " + words(100 * k / 40) +
           " %), which also damps roll and pitch.";
  };
  return e;
}

}  // namespace quadgen::effects
