// ground_effect: thrust near the ground scaled by 1 / (1 - (R / 4z)^2) (Cheeseman & Bennett,
// "The effect of the ground on a helicopter rotor in forward flight", ARC R&M 3021, 1955),
// held below twice the thrust where the law runs to its pole.
#include "derive/effects/definitions.hpp"
#include "derive/dynamics.hpp"
#include "derive/effects/headline_words.hpp"

namespace quadgen::effects {
using namespace GiNaC;

namespace {

void terms(ModelContext& c) {
  const ex radius = c.add_param("ground_effect.radius", "m", 0.0, 0.0, 0.5, true, "rotor radius in the ground-effect law");
  // The law's x = (R / 4z)^2 reaches 1 at z = R / 4, where the thrust would be infinite, and
  // turns it negative below: a vehicle taking off or landing, or a fit trying a large R, met
  // that pole. So z^2 is taken as (z^8 + z_min^8 + floor^8)^(1/4), z_min = R / (4 sqrt(x_max))
  // the height where x = x_max = 1/2: x is then x / (1 + (x / x_max)^4)^(1/4), held below 1/2
  // (thrust at most doubled), within 0.5 % of the law's factor where the law is used (z >= R/2;
  // 0.08 % at z = 0.6 R) and smooth; the law, a point source above its mirror image, is no
  // guide closer to the ground anyway. Written in z rather than x, no power overflows a float
  // on the ground. The floor keeps the effect off (R = 0) exact 1 there, where R^2 / z^2 was
  // 0/0 and made every all-effects model NaN, and its derivatives finite: their
  // (...)^(-5/4) is floor^-10, 1e30 at 1 mm, which a float holds (0.1 mm gave 1e40, inf, and
  // NaN Jacobians in float). At 5 cm the floor changes z^2 by 6e-15 of itself.
  const ex z = c.position(2, 0);
  const ex floor = c.add_constant("ground_effect.floor", "m", 1e-3, "height below which the ground-effect law is not resolved");
  const ex x_max = c.add_constant("ground_effect.x_max", "1", 0.5, "largest (R / 4z)^2 the ground-effect law is given");
  const ex z_min = radius / (4 * sqrt(x_max));
  const ex z_squared = pow(pow(z, 8) + pow(z_min, 8) + pow(floor, 8), numeric(1, 4));
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
  e.domain = {{"ground_effect.radius", 0.0, true, "a rotor radius is no negative length"}};
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
