// rotor_drag: the horizontal body force -k (sum of w_i) v_air,body,xy (rotor drag / induced
// drag, linear in airspeed and rotor speed), acting at the CoG: a pure force.
//
// The moment a multirotor feels in forward flight is blade_flapping's, with its own
// coefficient. Putting each rotor's share at its hub would tie the moment to the hub's height
// above the CoG, which the blocks give only roughly (8 mm on the Crazyflie file): fitted to
// real flights, the force then stood in for the flapping moment through that lever, or was
// rejected because the moment it forced conflicted with the gyro. With force and moment apart,
// their ratio is the effective point of action, estimated rather than assumed.
#include "derive/effects/definitions.hpp"
#include "derive/dynamics.hpp"
#include "derive/effects/headline_words.hpp"
#include "derive/kinematics.hpp"
#include "output/numbers.hpp"

namespace quadgen::effects {
using namespace GiNaC;

namespace {

constexpr const char* kUnit = "N s^2/m";  // newtons per m/s of airspeed and per rad/s of rotor speed

void terms(ModelContext& c) {
  const ex k = c.add_param("rotor_drag.k", kUnit, 0.0, 0.0, 1e-3, true, "rotor drag per rotor speed sum");
  const matrix vb = c.R.transpose().mul(c.air_velocity_world);
  ex speed_sum = 0;
  for (const ex& w : c.rotor_speed) speed_sum += w;
  c.extra_body_force = c.extra_body_force.add(vec3(-k * speed_sum * vb(0, 0), -k * speed_sum * vb(1, 0), 0));
}

}  // namespace

Effect rotor_drag() {
  Effect e;
  e.name = "rotor_drag";
  e.meaning = "horizontal body force -k (sum of rotor speeds) v_body,xy";
  e.apply = terms;
  e.parameter_names = "rotor_drag.k";  // as --help lists them
  e.domain = {{"rotor_drag.k", 0.0, true, "a negative drag would push the vehicle along its airspeed"}};
  e.look_alikes = {{"blade_flapping", "straight legs at several constant speeds: rotor drag slows the vehicle (a "
                                      "horizontal force), flapping only tilts it (a moment the attitude loop must hold)"}};
  e.headline = [](const std::map<std::string, double>& v, const std::string&) {
    return "The rotors drag the vehicle back against its airspeed (k = " +
           headline::words(headline::value_of(v, "rotor_drag.k")) + output::unit_after_number(kUnit) + ": newtons of drag per m/s of airspeed and per rad/s of summed rotor speed).";
  };
  return e;
}

}  // namespace quadgen::effects
