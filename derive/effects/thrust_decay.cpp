// thrust_decay: all thrust scaled by (1 - rate t), t the time since the start of the log:
// the battery running down when no voltage is logged.
#include <cmath>

#include "derive/effects/definitions.hpp"
#include "derive/dynamics.hpp"
#include "derive/effects/headline_words.hpp"

namespace quadgen::effects {
using namespace GiNaC;

namespace {

void terms(ModelContext& c) {
  const ex rate = c.add_param("thrust_decay.rate", "1/s", 0.0, -0.05, 0.05, true, "relative thrust loss per second");
  const ex t = c.add_input("t", "s",
                              "time since the start of the log (the factor 1 - rate t is linear, meant for a flight's "
                              "minutes: it reaches 0 at t = 1/rate)");
  for (ex& s : c.thrust_scale) s = s * (1 - rate * t);
}

}  // namespace

Effect thrust_decay() {
  Effect e;
  e.name = "thrust_decay";
  e.meaning = "all thrust scaled by (1 - rate (t - t_start))";
  e.apply = terms;
  e.parameter_names = "thrust_decay.rate";  // as --help lists them
  e.plausible = {{"thrust_decay.rate", -1e-4, 5e-3, PlausibleRange::Scale::kSI, Environment::kUnknown,
                  "a LiPo from full to the end of a flight loses 15-30 % of thrust over minutes; half the thrust "
                  "in 100 s (0.5 %/s) is beyond any battery that still flies"}};
  e.not_in_joint_diagnosis =
      "it runs on the time since each log's start, a per-flight battery state; diagnose flights with a battery log "
      "jointly with battery_sag instead";
  e.look_alikes = {{"battery_sag", "a flight whose battery voltage does not fall linearly in time (e.g. throttle bursts)"}};
  e.headline = [](const std::map<std::string, double>& v, const std::string&) {
    using headline::words;
    const double r = headline::value_of(v, "thrust_decay.rate");
    return "Thrust " + std::string(r >= 0 ? "falls" : "rises") + " by " + words(100 * std::fabs(r)) +
           " % per second of flight (" + words(6000 * std::fabs(r)) + " % per minute).";
  };
  return e;
}

}  // namespace quadgen::effects
