// blade_flapping: the moment from blade flapping. Flying through the air tilts each rotor
// disc away from the relative wind, and the stiff hub of a small propeller passes the tilt to
// the body as a moment proportional to rotor speed and airspeed (blade flapping, as in Mahony,
// Kumar and Corke, "Multirotor Aerial Vehicles", IEEE Robotics & Automation Magazine 19(3),
// 2012). With its own coefficient rather than through an assumed hub height (rotor_drag.cpp):
//   tau_body = k (sum of rotor speeds) (v_y, -v_x, 0), body-frame air velocity;
// k > 0 pitches the nose up when flying forward. Typical size: the NanoBench Crazyflie's
// residuals give 2-2.7e-4 N m per m/s at a rotor speed sum near 9,000 rad/s, k ~ 3e-8 N s^2
// (docs/crazyflie_evidence.md); no published Crazyflie value was found.
#include "derive/effects/definitions.hpp"
#include "derive/dynamics.hpp"
#include "derive/effects/headline_words.hpp"
#include "derive/kinematics.hpp"
#include "output/numbers.hpp"

namespace quadgen::effects {
using namespace GiNaC;

namespace {

constexpr const char* kUnit = "N s^2";  // N m per m/s of airspeed and per rad/s of rotor speed

void terms(ModelContext& c) {
  const ex k = c.add_param("blade_flapping.k", kUnit, 0.0, -1e-4, 1e-4, true,
                           "flapping moment per rotor speed sum and airspeed");
  const matrix vb = c.R.transpose().mul(c.air_velocity_world);
  ex speed_sum = 0;
  for (const ex& w : c.rotor_speed) speed_sum += w;
  c.extra_body_torque = c.extra_body_torque.add(vec3(k * speed_sum * vb(1, 0), -k * speed_sum * vb(0, 0), 0));
}

}  // namespace

Effect blade_flapping() {
  Effect e;
  e.name = "blade_flapping";
  e.meaning = "body moment k (sum of rotor speeds) (v_y, -v_x, 0) on the body-frame airspeed";
  e.apply = terms;
  e.parameter_names = "blade_flapping.k";  // as --help lists them
  e.headline = [](const std::map<std::string, double>& v, const std::string&) {
    const double k = headline::value_of(v, "blade_flapping.k");
    return std::string("Flying through the air ") + (k > 0 ? "pitches the nose up" : "pitches the nose down") +
           " (flapping moment k = " + headline::words(k) +
           output::unit_after_number(kUnit) + ": N m per m/s of airspeed and per rad/s of summed rotor speed).";
  };
  return e;
}

}  // namespace quadgen::effects
