// ground_effect: thrust near the ground scaled by 1 / (1 - (R / 4z)^2) (Cheeseman & Bennett,
// "The effect of the ground on a helicopter rotor in forward flight", ARC R&M 3021, 1955).
#include "derive/effects/definitions.hpp"
#include "derive/dynamics.hpp"
#include "derive/effects/headline_words.hpp"

namespace quadgen::effects {
using namespace GiNaC;

namespace {

void terms(ModelContext& c) {
  const ex radius = c.add_param("ground_effect.radius", "m", 0.0, 0.0, 0.5, true, "rotor radius in the ground-effect law");
  const ex z = c.position(2, 0);
  for (ex& s : c.thrust_scale) s = s / (1 - pow(radius / (4 * z), 2));
}

}  // namespace

Effect ground_effect() {
  Effect e;
  e.name = "ground_effect";
  e.meaning = "thrust scaled by 1 / (1 - (R / 4 z)^2) near the ground";
  e.apply = terms;
  e.parameter_names = "ground_effect.radius";  // as --help lists them
  e.needs = EffectNeeds::kPose;
  e.typical_start = {{"ground_effect.radius", 0.05}};
  e.plausible = {{"ground_effect.radius", 0.0, 3.0, PlausibleRange::Scale::kRotorRadius, Environment::kUnknown,
                  "the Cheeseman-Bennett law's R is the rotor radius; several rotors side by side act like a "
                  "somewhat larger one"}};
  e.headline = [](const std::map<std::string, double>& v, const std::string&) {
    return "Near the ground thrust rises as for a rotor of radius " +
           headline::words(1e3 * headline::value_of(v, "ground_effect.radius")) + " mm.";
  };
  return e;
}

}  // namespace quadgen::effects
