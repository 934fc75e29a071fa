// motor_lag_spread: each motor its own time constant, motor_lag.tau (1 + value). It refines
// motor_lag: it scales the lag that effect adds, so without motor_lag it changes nothing (in
// the full catalogue with the lag off, a time constant of 1e-6 s scaled stays negligible:
// the search cannot find it where no lag is), and beside it only the ratios between the
// motors are identifiable, so the first rotor is the reference.

#include "derive/effects/definitions.hpp"
#include "derive/dynamics.hpp"
#include "derive/effects/headline_words.hpp"

namespace quadgen::effects {
using namespace GiNaC;

namespace {

// Applied before motor_lag (canonical order), which reads the factors.
void terms(ModelContext& c) {
  for (size_t i = 0; i < c.vehicle.rotors.size(); ++i) {
    const std::string n = c.vehicle.rotors[i].name;
    const ex s = c.add_param("motor_lag_spread." + n, "1", 0.0, -0.9, 4.0, true,
                             "relative difference of rotor " + n + "'s time constant");
    c.lag_factor[i] = c.lag_factor[i] * (1 + s);
  }
}

// "Motor C's time constant is 80.0 % longer than motor A's; motor D's 10.0 % shorter."
std::string headline(const std::map<std::string, double>& v, const std::string& reference) {
  return headline::motor_comparison(v, reference, {"'s time constant is ", "'s ", "shorter", "longer", "", "'s"});
}

}  // namespace

Effect motor_lag_spread() {
  Effect e;
  e.name = "motor_lag_spread";
  e.meaning = "each motor's time constant motor_lag.tau (1 + value): motors that follow a command at different speeds";
  e.apply = terms;
  e.parameter_names = "motor_lag_spread.<rotor>";  // as --help lists them
  e.ratios_only_beside = "motor_lag.tau";
  e.refines = "motor_lag";
  // No published spread of one batch's time constants was found; the ARPL log's authors give
  // one time constant for all four motors of their Crazyflie (0.072 s).
  e.domain = {{"", -1.0, false, "it scales the shared time constant by 1 + spread, which must stay above zero"}};
  e.plausible = {{"", -0.5, 1.0, PlausibleRange::Scale::kSI, Environment::kUnknown,
                  "motors and propellers of one type share their time constant (the ARPL authors give one, 0.072 s, "
                  "for all four); half or twice the others' is a damaged propeller or a failing motor, beyond that "
                  "something else acts"}};
  e.headline = headline;
  return e;
}

}  // namespace quadgen::effects
