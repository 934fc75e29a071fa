// motor_gain: the thrust of each rotor scaled by (1 + gain). Beside a fitted c_t only the
// ratios between rotors are identifiable, so the first rotor is the reference; beside a held
// c_t each rotor's gain is its own.

#include "derive/effects/definitions.hpp"
#include "derive/dynamics.hpp"
#include "derive/effects/headline_words.hpp"

namespace quadgen::effects {
using namespace GiNaC;

namespace {

void terms(ModelContext& c) {
  for (size_t i = 0; i < c.vehicle.rotors.size(); ++i) {
    const std::string n = c.vehicle.rotors[i].name;
    const ex g = c.add_param("motor_gain." + n, "1", 0.0, -0.5, 0.5, true, "relative thrust error of rotor " + n);
    c.thrust_scale[i] = c.thrust_scale[i] * (1 + g);
  }
}

// "Motor C gives 8.0 % less thrust than motor A; motor D 3.1 % more."
std::string headline(const std::map<std::string, double>& v, const std::string& reference) {
  return headline::motor_comparison(v, reference, {" gives ", " ", "less", "more", " thrust", ""});
}

}  // namespace

Effect motor_gain() {
  Effect e;
  e.name = "motor_gain";
  e.meaning = "thrust of each rotor scaled by (1 + value)";
  e.apply = terms;
  e.parameter_names = "motor_gain.<rotor>";  // as --help lists them
  e.ratios_only_beside = "c_t";
  // The NanoBench flights of one Crazyflie trim their motors differently on every flight
  // (M4/M1 mean duty 1.03-1.20; docs/crazyflie_evidence.md).
  e.per_flight = true;
  e.domain = {{"", -1.0, true, "at -1 (-100 %) a rotor gives no thrust (a dead motor), below it a thrust that pulls"}};
  e.plausible = {{"", -0.35, 0.35, PlausibleRange::Scale::kSI, Environment::kUnknown,
                  "motors of one type differ by up to ~20 % in thrust at one command, worn brushed motors by ~30 % "
                  "(the NanoBench trims reach a duty ratio of 1.2); beyond, a motor is broken or something else acts"}};
  // Thrust levels do not separate them: gains proportional to each rotor's arm give a CoG
  // offset's torque (total thrust x offset) at every thrust level, and on a hexacopter also
  // under every roll, pitch and yaw command of its mixer. What is left to tell them apart is
  // the offset's lever arm at the logged origin (omega_dot x c, omega x (omega x c)), the
  // gains' change of total thrust with a pitch or roll acceleration, and, for a single weak
  // motor, its reaction torque in yaw.
  e.look_alikes = {{"cog_offset",
                    "fast yaw turns and sharp roll and pitch rate steps: a CoG offset moves the logged origin's "
                    "acceleration by omega x (omega x c) and omega_dot x c, which motor gains that copy its torque "
                    "do not (thrust levels do not separate them: both torques grow with thrust); a single weak "
                    "motor's torque also shows in yaw (its reaction torque)"}};
  e.headline = headline;
  return e;
}

}  // namespace quadgen::effects
