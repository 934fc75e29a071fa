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
  // (R / 4z)^2 with z^2 + (1 um)^2 for z^2: on the ground (z = 0) the law has R^2 / 0, which
  // with the effect off (R = 0, as in every all-effects model until it is fitted) made the
  // whole model NaN there. Now it is exactly 1 then; above 1 cm the change is below 1e-8 of
  // the term. The law itself holds only well above z = R / 4, where it is singular.
  const ex z = c.position(2, 0);
  const ex floor = c.add_constant("ground_effect.floor", "m", 1e-6, "height below which the ground-effect law is not resolved");
  const ex z_squared = pow(z, 2) + pow(floor, 2);
  for (ex& s : c.thrust_scale) s = s / (1 - pow(radius, 2) / (16 * z_squared));
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
