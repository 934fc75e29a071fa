// attitude_bias: the logged attitude is the true one rotated by a fixed roll and pitch,
// q_log = q ⊗ q_bias (an IMU or a marker frame mounted askew). It acts in the measurement
// h(x), not in the equations of motion.
#include "derive/effects/definitions.hpp"
#include "derive/dynamics.hpp"
#include "derive/effects/headline_words.hpp"
#include "derive/kinematics.hpp"

namespace quadgen::effects {
using namespace GiNaC;

namespace {

void terms(ModelContext& c) {
  const ex roll = c.add_param("attitude_bias.roll", "rad", 0.0, -0.2, 0.2, true, "logged roll offset");
  const ex pitch = c.add_param("attitude_bias.pitch", "rad", 0.0, -0.2, 0.2, true, "logged pitch offset");
  const matrix q_bias = quaternion_product(axis_quaternion(1, pitch), axis_quaternion(0, roll));
  c.measured_q = quaternion_product(c.measured_q, q_bias);
}

}  // namespace

Effect attitude_bias() {
  Effect e;
  e.name = "attitude_bias";
  e.meaning = "logged attitude = true attitude rotated by roll and pitch";
  e.apply = terms;
  e.parameter_names = "attitude_bias.roll/pitch";  // as --help lists them
  // Vicon attitude and IMU differ by 0.5-2.3 degrees in roll and pitch, by flight (the
  // marker frame is fitted per session; docs/crazyflie_evidence.md).
  e.per_flight = true;
  e.judged_by_force_model = true;
  e.acts_on = Effect::ActsOn::kMeasurement;
  e.plausible = {{"", -0.052, 0.052, PlausibleRange::Scale::kSI, Environment::kUnknown,
                  "an IMU or marker frame misaligned by more than ~3 degrees is visible by eye and corrected"}};
  e.look_alikes = {{"wind", "hover while turning through a full yaw circle: an attitude bias turns with the body, a "
                            "steady wind stays fixed in the world"}};
  e.headline = [](const std::map<std::string, double>& v, const std::string&) {
    using headline::kDegreesPerRadian;
    return "The logged attitude is off by " +
           headline::words(kDegreesPerRadian * headline::value_of(v, "attitude_bias.roll")) + "° in roll and " +
           headline::words(kDegreesPerRadian * headline::value_of(v, "attitude_bias.pitch")) + "° in pitch.";
  };
  return e;
}

}  // namespace quadgen::effects
