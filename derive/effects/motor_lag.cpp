// motor_lag: a first-order lag from commanded to actual rotor speed, tau dw/dt = w_cmd - w.
#include "derive/effects/definitions.hpp"
#include "derive/dynamics.hpp"
#include "derive/effects/headline_words.hpp"

namespace quadgen::effects {
using namespace GiNaC;

namespace {

// The rotor speeds become states; started at w_cmd they reproduce the base model for any
// tau, and as tau -> 0 the trajectories converge to it (a singular perturbation), so the
// nominal tau is small rather than zero.
void terms(ModelContext& c) {
  const ex tau = c.add_param("motor_lag.tau", "s", 1e-3, 1e-6, 1.0, true, "time constant of the rotor speed response");
  for (size_t i = 0; i < c.vehicle.rotors.size(); ++i) {
    const std::string n = c.vehicle.rotors[i].name;
    const ex w = c.add_state("w_" + n, "rad/s", "rotor speed of rotor " + n);
    c.extra_rates.push_back((c.commanded_speed[i] - w) / (tau * c.lag_factor[i]));  // motor_lag_spread's factor
    c.rotor_speed[i] = w;
  }
}

}  // namespace

Effect motor_lag() {
  Effect e;
  e.name = "motor_lag";
  e.meaning = "first-order lag from commanded to actual rotor speed";
  e.apply = terms;
  e.parameter_names = "motor_lag.tau";  // as --help lists them
  e.typical_start = {{"motor_lag.tau", 0.03}};
  e.off_at_lower_bound = true;
  e.plausible = {{"motor_lag.tau", 0.0, 0.25, PlausibleRange::Scale::kSI, Environment::kUnknown,
                  "small electric motors respond in 20-100 ms (Crazyflie: 0.072 s, ARPL log authors)"}};
  e.domain = {{"motor_lag.tau", 0.0, false, "a time constant of zero or below is no lag (the rotor speed's rate divides by it)"}};
  e.look_alikes = {{"input_delay", "fast throttle steps or chirps (1-10 Hz): a lag rounds and attenuates the response, a "
                                   "delay shifts it without changing its shape"}};
  e.headline = [](const std::map<std::string, double>& v, const std::string&) {
    return "The rotors follow a new command with a time constant of " +
           headline::words(1e3 * headline::value_of(v, "motor_lag.tau")) + " ms.";
  };
  return e;
}

}  // namespace quadgen::effects
